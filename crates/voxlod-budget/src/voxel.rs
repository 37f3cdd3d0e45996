//! Voxel candidates (He et al. 1995): the input's solid low-pass filtered on a grid fine
//! enough for about [`HEADROOM`] times the budget's triangles (§2–3, equation 1), contoured by
//! marching cubes (§4) at the solid's isodensity 0.5 and at two lower ones, then collapsed to
//! the budget with the topology kept (§5: the voxel method removes what the budget cannot
//! afford, small parts, thin walls and handles below a voxel; a geometric method then spends
//! the triangles).
//!
//! **Lower isodensities** (our addition to §4, which contours at 0.5): a slab of thickness `t`
//! under the hyper-cone of radius `R` peaks at a density of about `t / R`, so 0.25 keeps walls
//! half as thick as 0.5 does, and 0.15 a third as thick, at the price of moving flat surfaces
//! outwards (by 0.27 `R` and 0.40 `R`); the portfolio's measured distances weigh the two.
//!
//! **The resolution** comes from the input's area ([`resolution_for_triangles`]); where every
//! isodensity's level has too few triangles for the budget (a surface with much detail below
//! the filter), the grid is refined once by the square root of the shortfall (counts grow as
//! the resolution squared).
//!
//! Cost: one or two samplings (the lattice lines' crossings with the input, O(N²) lines, and
//! the density, O(N³)), one marching cubes pass for the three isodensities, and a checked
//! quadric collapse per isodensity.

use voxlod_contouring::marching_cubes_multi;
use voxlod_contouring::triangle_estimate::resolution_for_triangles;
use voxlod_metrics::MeshDistance;
use voxlod_quadric::{simplify_dropping_parts, simplify_unchecked, PartsOptions, QuadricOptions};
use voxlod_sampling::closing::closing_fill;
use voxlod_sampling::{filtered_density, level_grid, DensityOptions, MeshSolid};

use crate::candidate::{Candidate, Fill, Method};
use crate::input::Input;
use crate::measure::{Care, Measure};
use crate::open_parts::add_open_shells;
use crate::promises::within_budget;
use crate::{BudgetError, PortfolioOptions};
use voxlod_contouring::clean_mesh::without_zero_area;

/// The marching-cubes level aimed at has this many times the budget's triangles: room for the
/// quadric stage to choose where the triangles go.
pub const HEADROOM: f64 = 4.0;

/// For a proxy ([`PortfolioOptions::remesh`]) the level aims at this many times the budget:
/// a scene's boxes and panels, sampled at a voxel of a quarter of their side, come out of the
/// quadric stage as flat faces and corners, where at [`HEADROOM`] they are blobs it collapses
/// into spikes (measured on the generated scenes: 0.5 dB PSNR more on average, 1–2 dB on the
/// props, the room and the tree at 1 %, 1 dB less on the building).
pub const REMESH_HEADROOM: f64 = 16.0;
/// ... but a proxy's level aims at no more triangles than this where [`HEADROOM`] alone asks
/// for fewer: a million-triangle scene's largest budget would otherwise cost seconds of
/// collapse.
pub const REMESH_LEVEL: f64 = 80_000.0;

/// The triangles the marching-cubes level of `budget` aims at ([`HEADROOM`], or for a proxy
/// [`REMESH_HEADROOM`] within [`REMESH_LEVEL`]).
pub fn level_triangles(budget: usize, remesh: bool) -> f64 {
    let plain = HEADROOM * budget as f64;
    match remesh {
        true => (REMESH_HEADROOM * budget as f64)
            .min(REMESH_LEVEL)
            .max(plain),
        false => plain,
    }
}

/// The isodensities contoured (module docs).
pub const ISOS: [f32; 3] = [0.5, 0.25, 0.15];

/// Resolutions tried: at least this coarse, at most this fine.
pub const COARSEST: usize = 4;
/// See [`COARSEST`].
pub const FINEST: usize = 512;

/// What one budget's voxel search found: its candidates, and what the report should know.
#[derive(Default)]
pub struct VoxelFound {
    /// The collapsed levels, one per isodensity whose level had enough triangles.
    pub candidates: Vec<Candidate>,
    /// The resolution of the last grid sampled (0 when none was).
    pub resolution: usize,
    /// Whether every isodensity's level was empty (a sheet thinner than the filter).
    pub vanished: bool,
}

/// The input as one solid of the voxel candidates: what of its inside is filled, the solid
/// sampled, and the open parts sampled as shells beside it (module `open_parts`).
pub struct Sampled {
    /// What the solid fills.
    pub fill: Fill,
    /// The solid (with [`Fill::OpenShells`], of the closed parts only).
    pub solid: MeshSolid,
    /// The open parts, whose shells join the solid (with [`Fill::OpenShells`] only).
    pub shells: Option<MeshDistance>,
}

impl Sampled {
    /// `solid`, with `fill` filled, no shells.
    pub fn solid(fill: Fill, solid: MeshSolid) -> Sampled {
        Sampled {
            fill,
            solid,
            shells: None,
        }
    }
}

/// The isodensities a solid is contoured at: all of [`ISOS`] for the input as given, with its
/// closed cavities filled, and with its open parts as shells; only 0.5 where its hollows are
/// filled or lined (module `enclosed`), whose walls are thick by construction.
pub fn isos_of(fill: Fill) -> &'static [f32] {
    match fill {
        Fill::None | Fill::Cavities | Fill::OpenShells => &ISOS,
        Fill::Hollows | Fill::HollowLining => &ISOS[..1],
    }
}

/// The voxel candidates of `budget` from `sampled` (the input as a solid), filtered by
/// `options.filter`, gaps closed as `options.close_gaps` asks, collapsed within
/// `options.max_error`.
pub fn voxel_candidates(
    input: &Input,
    measure: &Measure,
    sampled: &Sampled,
    options: &PortfolioOptions,
    budget: usize,
) -> Result<VoxelFound, BudgetError> {
    let max_error = options.max_error;
    let want = level_triangles(budget, options.remesh);
    let start = resolution_for_triangles(&input.mesh, want as usize).unwrap_or(COARSEST);
    let mut resolution = start.clamp(COARSEST, FINEST);
    let mut found = VoxelFound::default();
    let (mut refined, mut coarsened) = (false, 0);
    let fill = sampled.fill;
    loop {
        let levels = contoured(input, sampled, options, resolution)?;
        let most = levels.iter().map(|m| m.triangle_count()).max().unwrap_or(0);
        found.resolution = resolution;
        found.vanished = most == 0;
        let enough = most as f64 >= budget as f64 * (1.0 - crate::BUDGET_TOLERANCE);
        if !enough && !refined && resolution < FINEST {
            refined = true;
            let factor = (want / most.max(1) as f64).sqrt().clamp(1.25, 4.0);
            resolution = ((resolution as f64 * factor) as usize).min(FINEST);
            continue;
        }
        let levels = closest_if_large(levels, measure);
        let at = (resolution, fill);
        let reached = add_collapsed(&mut found, input, levels, at, budget, max_error);
        // A level with more handles than the budget can carry stalls the collapse: coarser
        // grids filter more of them away (where they are cheap).
        let large = most > LARGE_LEVEL;
        if reached || refined || large || resolution <= COARSEST || coarsened >= MAX_COARSER {
            break;
        }
        coarsened += 1;
        resolution = ((resolution as f64 * COARSER) as usize).max(COARSEST);
    }
    // Coarse grids are cheap, and which resolution's level collapses closest is hard to
    // foretell (a finer one keeps more shape, a coarser one has fewer handles to stall on):
    // the neighbours on both sides too.
    if found.resolution <= SMALL && !found.vanished && coarsened == 0 {
        let at = found.resolution as f64;
        let finer = ((at * FINER) as usize).min(FINEST);
        let coarser = ((at * COARSER) as usize).max(COARSEST);
        for r in [finer, coarser] {
            if r != found.resolution {
                let levels = contoured(input, sampled, options, r)?;
                add_collapsed(&mut found, input, levels, (r, fill), budget, max_error);
            }
        }
    }
    Ok(found)
}

/// Where the collapse of every isodensity's level stalls above the budget, the grid is made
/// this much coarser, at most [`MAX_COARSER`] times.
pub const COARSER: f64 = 0.7;
/// See [`COARSER`].
pub const MAX_COARSER: usize = 3;

/// Marching-cubes levels above this many triangles are collapsed for one isodensity only, the
/// one whose level measures closest (a checked collapse of a large level costs seconds), and
/// a stall there does not send the search to coarser grids.
pub const LARGE_LEVEL: usize = 60_000;

/// `levels` (one per isodensity of [`ISOS`]), or where the largest is above [`LARGE_LEVEL`],
/// only the one measured closest to the input, the others left empty.
fn closest_if_large(
    mut levels: Vec<voxlod_core::TriangleMesh>,
    measure: &Measure,
) -> Vec<voxlod_core::TriangleMesh> {
    if levels.iter().all(|l| l.triangle_count() <= LARGE_LEVEL) {
        return levels;
    }
    let shape = |l: &voxlod_core::TriangleMesh| {
        (measure.distance(l, Care::Quick, f64::INFINITY)).map_or(f64::INFINITY, |d| d.shape)
    };
    let distances: Vec<f64> = levels.iter().map(shape).collect();
    let best = (0..levels.len()).min_by(|&a, &b| distances[a].total_cmp(&distances[b]));
    for (i, level) in levels.iter_mut().enumerate() {
        if Some(i) != best {
            *level = voxlod_core::TriangleMesh::default();
        }
    }
    levels
}

/// Grids up to this resolution get a finer neighbour ([`FINER`] times finer) and a coarser one
/// ([`COARSER`]) too.
pub const SMALL: usize = 48;
/// See [`SMALL`]: about twice the triangles.
pub const FINER: f64 = std::f64::consts::SQRT_2;

/// Each of `levels` (contoured at [`isos_of`] `fill` on a grid of `resolution`) collapsed to
/// `budget`; whether a collapse that kept the topology reached it.
fn add_collapsed(
    found: &mut VoxelFound,
    input: &Input,
    levels: Vec<voxlod_core::TriangleMesh>,
    (resolution, fill): (usize, Fill),
    budget: usize,
    max_error: Option<f64>,
) -> bool {
    let voxel = input.bounds.longest_extent() / resolution as f64;
    let mut reached = false;
    for (mesh, &iso) in levels.into_iter().zip(isos_of(fill)) {
        let collapsed = collapsed(Method::Voxel, mesh, budget, voxel, max_error);
        reached |= collapsed
            .first()
            .is_some_and(|c| c.cut_vertices == 0 && within_budget(c.triangles(), budget));
        found
            .candidates
            .extend(collapsed.into_iter().map(|c| Candidate {
                fill,
                ..c.at(resolution, iso)
            }));
    }
    reached
}

/// The input's solid filtered at `resolution` (radius one voxel, as the paper's pyramid), its
/// open parts' shells added where it has them, its gaps closed where `options` asks, and
/// contoured at each of [`isos_of`] its fill.
fn contoured(
    input: &Input,
    sampled: &Sampled,
    options: &PortfolioOptions,
    resolution: usize,
) -> Result<Vec<voxlod_core::TriangleMesh>, BudgetError> {
    let radius = input.bounds.longest_extent() / resolution as f64;
    let grid = level_grid(&input.bounds, resolution, radius)?;
    let density_options = DensityOptions::new(options.filter, radius);
    let (mut density, _) = filtered_density(&sampled.solid, &grid, &density_options)?;
    if let Some(open) = &sampled.shells {
        add_open_shells(&mut density, open, radius)?;
    }
    if let Some(gap) = options.close_gaps {
        close_gaps(&mut density, gap)?;
    }
    let isos = isos_of(sampled.fill);
    let levels = marching_cubes_multi(&density, isos, false).map_err(|e| BudgetError::NoLevel {
        budget: 0,
        why: format!("marching cubes: {e}"),
    })?;
    Ok(levels.into_iter().map(|l| l.mesh).collect())
}

/// `density` with the gaps of its solid (isodensity 1/2) narrower than `gap` (mesh units)
/// closed: a morphological closing by a ball of radius `gap / 2`, rounded to whole samples
/// ([`closing_fill`]: dilated, what the outside cannot reach kept, eroded again), whose new
/// samples are raised to 1. A gap under a sample's width is left to the filter. Cost:
/// O(r N³) for radius r in samples.
fn close_gaps(density: &mut voxlod_core::Volume, gap: f64) -> Result<(), BudgetError> {
    let radius = (0.5 * gap / density.grid.spacing[0]).round() as usize;
    if radius == 0 {
        return Ok(());
    }
    let dims = density.grid.dims;
    let inside: Vec<bool> = density.as_slice().iter().map(|&d| d >= 0.5).collect();
    let closing = closing_fill(&inside, dims, radius)?;
    let values = density.as_slice_mut();
    for i in closing.filled {
        values[i] = 1.0;
    }
    Ok(())
}

/// meshoptimizer passes of a level's checked collapse (each also checks the result's topology
/// and crossings): a level that needs more is better answered by a coarser one.
pub const ATTEMPTS: usize = 4;

/// `mesh` collapsed to `budget` with its topology kept (the smallest parts dropped where it
/// stalls above), without zero-area triangles judged against `cell`, as candidates of
/// `method`; where that stalls above the budget, meshoptimizer's plain collapse of it too
/// (which may break a promise: the choice checks). Empty for an empty mesh.
pub fn collapsed(
    method: Method,
    mesh: voxlod_core::TriangleMesh,
    budget: usize,
    cell: f64,
    max_error: Option<f64>,
) -> Vec<Candidate> {
    if mesh.triangles.is_empty() {
        return Vec::new();
    }
    if mesh.triangle_count() <= budget {
        return vec![Candidate::new(method, mesh)];
    }
    let options = PartsOptions {
        quadric: QuadricOptions {
            max_attempts: ATTEMPTS,
            ..QuadricOptions::budget(max_error.unwrap_or(f64::INFINITY))
        },
        max_rounds: 2,
        ..PartsOptions::default()
    };
    let mut out = Vec::new();
    if let Ok(done) = simplify_dropping_parts(&mesh, budget, &options) {
        let mut c = Candidate::new(method, without_zero_area(done.simplified.mesh, cell));
        c.parts_dropped = done.dropped_parts;
        out.push(c);
    }
    let stalled = out.iter().all(|c| !within_budget(c.triangles(), budget));
    if stalled && max_error.is_none() {
        if let Ok((plain, _)) = simplify_unchecked(&mesh, budget, false) {
            out.push(Candidate::new(method, without_zero_area(plain, cell)));
        }
    }
    out
}
