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
//! the resolution squared). Small grids are tried beside a finer and a coarser neighbour, and
//! at small budgets beside one twice as fine ([`far_finer_too`]). The grids themselves are
//! made once for the whole chain (module `grids`).
//!
//! **Two stages at small budgets** (beyond §5): the far finer grid's levels are also collapsed
//! to [`STAGE`] times the budget, fitted to the input, and collapsed on ([`staged`]).
//!
//! **Sharp edges for proxies** (beyond the paper): a proxy's level has its vertices beside the
//! input's sharp edges moved onto them before the collapse ([`sharpened`]), so that a scene's
//! boxes collapse to little more than their faces.
//!
//! **Levels out of reach** (ours): where the input's own collapse keeps every promise, a level
//! more than [`REACH`] times as far from the input before its collapse is not collapsed.
//!
//! Cost: one or two samplings (the lattice lines' crossings with the input, O(N²) lines, and
//! the density, O(N³)), one marching cubes pass for the three isodensities, a quick
//! measurement per level where the input's collapse keeps the promises, and a checked quadric
//! collapse per isodensity within reach (the isodensities' collapses, and a small grid's two
//! neighbours, side by side on the cores; module `chain` runs the solids' searches so too).

use rayon::prelude::*;
use voxlod_contouring::triangle_estimate::resolution_for_triangles;
use voxlod_fit::{snap_to_features, FeatureOptions};
use voxlod_quadric::{simplify_dropping_parts, simplify_unchecked, PartsOptions, QuadricOptions};

use crate::candidate::{Candidate, Fill, Method};
use crate::grids::{isos_of, Grids};
use crate::input::Input;
use crate::measure::{Care, Measure};
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

/// The first grid of `budget`'s search: the resolution whose level would have
/// [`level_triangles`].
pub fn first_resolution(input: &Input, options: &PortfolioOptions, budget: usize) -> usize {
    let want = level_triangles(budget, options.remesh);
    let start = resolution_for_triangles(&input.mesh, want as usize).unwrap_or(COARSEST);
    start.clamp(COARSEST, FINEST)
}

/// The grids `budget`'s search asks for first, for every solid: [`first_resolution`] and,
/// where that is at most [`SMALL`], its [`neighbours`].
pub fn planned_grids(
    input: &Input,
    options: &PortfolioOptions,
    solids: usize,
    budget: usize,
) -> Vec<(usize, usize)> {
    let first = first_resolution(input, options, budget);
    let mut resolutions = vec![first];
    if first <= small(options.remesh) {
        resolutions.extend(neighbours(first, far_finer_too(input, options, budget)));
    }
    (0..solids)
        .flat_map(|s| resolutions.iter().map(move |&r| (s, r)))
        .collect()
}

/// The finer ([`FINER`]) and coarser ([`COARSER`]) resolutions beside `resolution`, and with
/// `far` the [`FAR_FINER`] one, within [`COARSEST`]..[`FINEST`], other than it.
fn neighbours(resolution: usize, far: bool) -> impl Iterator<Item = usize> {
    let at = resolution as f64;
    let finer = ((at * FINER) as usize).min(FINEST);
    let coarser = ((at * COARSER) as usize).max(COARSEST);
    let far = far.then(|| ((at * FAR_FINER) as usize).min(FINEST));
    [finer, coarser]
        .into_iter()
        .chain(far)
        .filter(move |&r| r != resolution)
}

/// Budgets up to this many triangles get a third neighbour, [`FAR_FINER`] times finer than
/// their first grid ([`far_finer_too`]).
pub const FAR_BUDGET: usize = 500;

/// See [`FAR_BUDGET`]: about four times the triangles, sixteen times the budget's.
pub const FAR_FINER: f64 = 2.0;

/// Whether `budget`'s small grid gets its [`FAR_FINER`] neighbour: at most [`FAR_BUDGET`]
/// triangles, where that grid's level (about `FAR_FINER² × HEADROOM` times the budget) would
/// have no more triangles than the input; not for a proxy.
///
/// Why (beyond the paper, whose level of a budget is one resolution): at small budgets the
/// filter at [`HEADROOM`] removes features the budget could afford (a sphereflake's small
/// spheres, a robot part's bosses), and the quadric stage of a finer level keeps the ones that
/// matter most: of the 68 voxel levels chosen among 377 (the shared meshes, the corpus, 25 of
/// `odedstein/meshes`, 30 robot arm parts; BENCHMARKS.md), 38 are the far grid's. Where its
/// level would outnumber the input's triangles, it is the input resampled, whose collapse the
/// portfolio has already. Cost: one more sampling and up to three checked collapses of levels
/// of about 16 times the budget.
fn far_finer_too(input: &Input, options: &PortfolioOptions, budget: usize) -> bool {
    let far_level = FAR_FINER * FAR_FINER * HEADROOM * budget as f64;
    !options.remesh && budget <= FAR_BUDGET && far_level <= input.mesh.triangle_count() as f64
}

/// The voxel candidates of `budget` from solid `solid` of `grids` (the input as a solid),
/// filtered by `options.filter`, gaps closed as `options.close_gaps` asks, collapsed within
/// `options.max_error`.
pub fn voxel_candidates(
    input: &Input,
    measure: &Measure,
    grids: &Grids,
    (solid, closest): (usize, f64),
    options: &PortfolioOptions,
    budget: usize,
) -> Result<VoxelFound, BudgetError> {
    let max_error = options.max_error;
    let want = level_triangles(budget, options.remesh);
    let mut resolution = first_resolution(input, options, budget);
    let mut found = VoxelFound::default();
    let (mut refined, mut coarsened) = (false, 0);
    let fill = grids.solids()[solid].fill;
    // `near`: the levels of a grid of resolution `r`, sharpened for a proxy, those out of
    // reach left empty; `add`: those collapsed to the budget.
    let near = |levels, r| {
        let levels = sharpened(levels, input, measure, (r, budget, fill), options.remesh);
        within_reach(levels, measure, closest, options.remesh)
    };
    let add = |found: &mut VoxelFound, levels, r| {
        add_collapsed(found, input, near(levels, r), (r, fill), budget, max_error)
    };
    loop {
        let levels = grids.levels(solid, resolution)?;
        let most = levels.iter().map(|m| m.triangle_count()).max().unwrap_or(0);
        found.resolution = resolution;
        found.vanished = most == 0;
        let enough = most as f64 >= budget as f64 * (1.0 - crate::BUDGET_TOLERANCE);
        // Refined once at most, and never after a coarser grid was asked for because the
        // collapse stalled: a finer grid than the one that stalled stalls too, and a coarser
        // one has fewer triangles still.
        if !enough && coarsened > 0 {
            break;
        }
        if !enough && !refined && resolution < FINEST {
            refined = true;
            let factor = (want / most.max(1) as f64).sqrt().clamp(1.25, 4.0);
            resolution = ((resolution as f64 * factor) as usize).min(FINEST);
            continue;
        }
        let reached = add(&mut found, closest_if_large(&levels, measure), resolution);
        // A level with more handles than the budget can carry stalls the collapse: coarser
        // grids filter more of them away (where they are cheap, or for a proxy, whose level
        // must come out closed, where the level is no larger than its budget aimed at).
        let aim = if options.remesh {
            LARGE_OVER_AIM * want
        } else {
            0.0
        };
        let large = most as f64 > (LARGE_LEVEL as f64).max(aim);
        if reached || refined || large || resolution <= COARSEST || coarsened >= MAX_COARSER {
            break;
        }
        coarsened += 1;
        resolution = ((resolution as f64 * COARSER) as usize).max(COARSEST);
    }
    // Coarse grids are cheap, and which resolution's level collapses closest is hard to
    // foretell (a finer one keeps more shape, a coarser one has fewer handles to stall on):
    // the neighbours on both sides too, and at small budgets a far finer one.
    if found.resolution <= small(options.remesh) && !found.vanished && coarsened == 0 {
        // Not after a refinement: a grid refined from one where thin parts had vanished often
        // overshoots the level it aims at (the linked rings at 300: 24 times the budget's
        // triangles, where HEADROOM asks for 4), so the far grid's levels would be 60–120
        // times the budget, and their collapses the search's largest cost (on the budget
        // bench, no level changed without them; the rings' chain 1.69 → 1.19 s).
        let far = !refined && far_finer_too(input, options, budget);
        let far_grid = far
            .then(|| neighbours(found.resolution, true).last())
            .flatten();
        let beside: Vec<usize> = neighbours(found.resolution, far).collect();
        let more = (beside.into_par_iter())
            .map(|r| {
                let mut more = VoxelFound::default();
                let levels = near(grids.levels(solid, r)?.to_vec(), r);
                let staged = match Some(r) == far_grid {
                    true => staged(&levels, input, measure, options, (r, budget)),
                    false => Vec::new(),
                };
                add_collapsed(&mut more, input, levels, (r, fill), budget, max_error);
                let mut two = VoxelFound::default();
                add_collapsed(&mut two, input, staged, (r, fill), budget, max_error);
                let staged = (two.candidates.into_iter()).map(|c| Candidate { staged: true, ..c });
                Ok(more
                    .candidates
                    .into_iter()
                    .chain(staged)
                    .collect::<Vec<_>>())
            })
            .collect::<Result<Vec<_>, BudgetError>>()?;
        found.candidates.extend(more.into_iter().flatten());
    }
    Ok(found)
}

/// The far finer grid's levels ([`far_finer_too`]) are also collapsed in two stages
/// ([`staged`]): first to this many times the budget, then, fitted to the input, on to it.
pub const STAGE: f64 = 2.5;

/// Each of `levels` (on a grid of `resolution`) collapsed to [`STAGE`] times `budget` with its
/// topology kept and fitted to the input (`options.fit`, module `measure`), for
/// [`add_collapsed`] to collapse on to the budget; a level left empty where it is empty, its
/// collapse failed or the fit moved nothing, and no levels at all where `options.fit` is
/// `None`.
///
/// Why (beyond the paper, whose §5 collapses a voxel level straight to its budget): a far finer
/// grid's level has about sixteen times the budget's triangles, and a collapse that long
/// places the last vertices by quadrics of the filtered surface, which the filter has moved
/// off the input; fitted halfway, the second collapse starts from the input's own shape
/// (the sphereflake at 300 triangles asked alone: Hausdorff distance 5.50 % of the diagonal
/// straight, 3.46 % staged; on the budget bench, BENCHMARKS.md, 68 of 377 levels changed, 47
/// of them closer, geometric mean 0.91). The straight collapse stays a candidate: without it,
/// 18 levels changed, 14 of them farther (geometric mean 1.10). Cost: per level, a second
/// checked collapse of the far grid's level and a fit of about [`STAGE`] times the budget's
/// triangles (the bench's chains: 7–10 % more CPU).
fn staged(
    levels: &[voxlod_core::TriangleMesh],
    input: &Input,
    measure: &Measure,
    options: &PortfolioOptions,
    (resolution, budget): (usize, usize),
) -> Vec<voxlod_core::TriangleMesh> {
    let Some(fit) = options.fit.as_ref() else {
        return Vec::new();
    };
    let stage = (STAGE * budget as f64) as usize;
    let voxel = input.voxel(resolution);
    (levels.par_iter())
        .map(|level| {
            let mid = collapsed(
                Method::Voxel,
                level.clone(),
                stage,
                voxel,
                options.max_error,
            );
            let mid = mid.into_iter().next().map(|c| c.mesh).unwrap_or_default();
            (measure.fitted(&mid, fit)).map_or_else(Default::default, |done| done.mesh)
        })
        .collect()
}

/// How far a voxel level's vertices may move onto the input's sharp features, in voxels of its
/// grid: the filter rounds an edge over about a voxel (its radius).
pub const FEATURE_REACH: f64 = 1.5;

/// Where the input's faces meet at more than this many degrees, a proxy's marching-cubes level
/// is given the edge back before its collapse ([`sharpened`]). Lower angles also catch the
/// curvature of a smooth shape across a vertex's neighbours (measured on Spot: at 30°, 0.8 dB
/// PSNR less at 5 %; at 60°, as without).
pub const PROXY_FEATURE_ANGLE: f64 = 60.0;

/// Proxy budgets above this many triangles keep their levels' rounded edges: their grids are
/// fine enough (levels of up to [`REMESH_LEVEL`] triangles) that the rounding spans little of
/// the scene, and sharp edges split their atlases into many more charts (the 20 000-triangle
/// level of the 1 M-triangle scene: 1 173 charts rounded, 3 016 sharpened, its atlas 8.6 s and
/// 17.1 s).
pub const SHARPENED_AT_MOST: usize = 10_000;

/// For a proxy (`remesh`) of at most [`SHARPENED_AT_MOST`] triangles, each of `levels` (on a
/// grid of `resolution`) with its vertices beside the input's sharp edges and corners moved
/// onto them (`voxlod_fit::snap_to_features`) and the triangles that left without area
/// collapsed; the levels as they are otherwise, and where open parts are sampled as shells
/// ([`Fill::OpenShells`]): both faces of a shell around a card would snap onto the card (and
/// snapping such a level to its closed parts alone measured worse on the generated building
/// and tree).
///
/// Why before the collapse: a scene's boxes and panels come out of the filter with their edges
/// rounded over a voxel, and the quadric collapse spends triangles on the rounding, which a
/// snap after it (module `select`) can no longer take back; given their edges, boxes collapse
/// to little more than their faces (the generated props at 5 %: 26.1 → 27.5 dB PSNR,
/// BENCHMARKS.md). A budget level keeps its levels as they are: its candidates are judged by
/// distance, where the snap's few misplaced vertices weigh more than its many placed ones.
/// Cost: per level, (1 + mean valence) closest-point queries per vertex on the input.
fn sharpened(
    levels: Vec<voxlod_core::TriangleMesh>,
    input: &Input,
    measure: &Measure,
    (resolution, budget, fill): (usize, usize, Fill),
    remesh: bool,
) -> Vec<voxlod_core::TriangleMesh> {
    if !(remesh && sharpened_before_collapse(budget, fill)) {
        return levels;
    }
    let voxel = input.voxel(resolution);
    let options = FeatureOptions {
        angle: PROXY_FEATURE_ANGLE,
        ..FeatureOptions::within(FEATURE_REACH * voxel)
    };
    let closest = measure.input_closest();
    let sharp = |level: voxlod_core::TriangleMesh| {
        if level.triangles.is_empty() {
            return level;
        }
        let (snapped, _) = snap_to_features(&level, input.measured(), closest, &options);
        without_zero_area(snapped, input.cell())
    };
    levels.into_iter().map(sharp).collect()
}

/// Whether a proxy's marching-cubes levels of `fill` for `budget` are sharpened before their
/// collapse ([`sharpened`]): at most [`SHARPENED_AT_MOST`] triangles, open parts not sampled
/// as shells.
pub fn sharpened_before_collapse(budget: usize, fill: Fill) -> bool {
    budget <= SHARPENED_AT_MOST && fill != Fill::OpenShells
}

/// Where the collapse of every isodensity's level stalls above the budget, the grid is made
/// this much coarser, at most [`MAX_COARSER`] times.
pub const COARSER: f64 = 0.7;
/// See [`COARSER`].
pub const MAX_COARSER: usize = 3;

/// Marching-cubes levels above this many triangles are collapsed for one isodensity only, the
/// one whose level measures closest (a checked collapse of a large level costs seconds), and
/// a stall there does not send the search to coarser grids (a proxy's, only above
/// [`LARGE_OVER_AIM`] times what its budget aimed at).
pub const LARGE_LEVEL: usize = 60_000;

/// A proxy's level counts as large only above this many times the triangles its budget aimed
/// at ([`level_triangles`]): its grid aims above [`LARGE_LEVEL`], and where its collapse
/// stalls (too many parts and handles for the budget), only a coarser grid gives a closed
/// level.
pub const LARGE_OVER_AIM: f64 = 1.5;

/// `levels` (one per isodensity of [`crate::grids::ISOS`]), or where the largest is above
/// [`LARGE_LEVEL`], only the one measured closest to the input, the others left empty.
fn closest_if_large(
    levels: &[voxlod_core::TriangleMesh],
    measure: &Measure,
) -> Vec<voxlod_core::TriangleMesh> {
    if levels.iter().all(|l| l.triangle_count() <= LARGE_LEVEL) {
        return levels.to_vec();
    }
    let shape = |l: &voxlod_core::TriangleMesh| {
        (measure.distance(l, Care::Quick, f64::INFINITY)).map_or(f64::INFINITY, |d| d.shape)
    };
    let distances: Vec<f64> = levels.iter().map(shape).collect();
    let best = (0..levels.len()).min_by(|&a, &b| distances[a].total_cmp(&distances[b]));
    (levels.iter().enumerate())
        .map(|(i, level)| match Some(i) == best {
            true => level.clone(),
            false => voxlod_core::TriangleMesh::default(),
        })
        .collect()
}

/// A marching-cubes level measured this many times farther from the input than the input's
/// own collapse, where that keeps every promise, is not collapsed ([`within_reach`]).
pub const REACH: f64 = 2.0;

/// `levels` with those farther than [`REACH`] times `closest` (the quick shape distance of the
/// input's collapse that keeps every promise; infinite where there is none) left empty; all of
/// them for a proxy, whose choice weighs appearance, not distance. Why before the collapse: a
/// collapse only adds to a level's distance from the input, and the fit of the closest voxel
/// candidate (module `select`) takes back far less than half of it, so a level that starts
/// twice as far as a candidate that keeps every promise is never chosen (on the corpus, the
/// shared meshes and ten more generated cases: the same 180 levels, the searches of many
/// parts, linked rings and thin tubes 13–23 % faster), while its checked collapse is the
/// search's largest cost. Only a candidate that keeps every promise sets the limit: a level
/// closer than the others whose collapse then breaks one (handles, closedness) would rule out
/// the levels that keep them (at 1.5 times the closest level, a spring's level kept none and
/// crossed itself). Cost: a quick measurement per level, cut short at the limit.
fn within_reach(
    levels: Vec<voxlod_core::TriangleMesh>,
    measure: &Measure,
    closest: f64,
    remesh: bool,
) -> Vec<voxlod_core::TriangleMesh> {
    if remesh || closest == f64::INFINITY {
        return levels;
    }
    let near = |level: &voxlod_core::TriangleMesh| {
        !level.triangles.is_empty()
            && measure
                .distance(level, Care::Quick, REACH * closest)
                .is_some_and(|d| d.shape <= REACH * closest)
    };
    (levels.into_iter())
        .map(|level| match near(&level) {
            true => level,
            false => voxlod_core::TriangleMesh::default(),
        })
        .collect()
}

/// Grids up to this resolution get a finer neighbour ([`FINER`] times finer) and a coarser one
/// ([`COARSER`]) too.
pub const SMALL: usize = 48;
/// [`SMALL`] for a proxy (`remesh`): its time goes to the bake, and which grid's level comes
/// closest is as hard to foretell.
pub const SMALL_REMESH: usize = 64;

/// [`SMALL`], or [`SMALL_REMESH`] for a proxy.
fn small(remesh: bool) -> usize {
    if remesh {
        SMALL_REMESH
    } else {
        SMALL
    }
}

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
    let voxel = input.voxel(resolution);
    // Each isodensity's collapse on a core of its own (a budget's search is often the last
    // one running, and a collapse is one thread's work).
    let collapses: Vec<(Vec<Candidate>, f32)> = (levels.into_par_iter())
        .zip(isos_of(fill))
        .map(|(mesh, &iso)| {
            let made = collapsed(Method::Voxel, mesh, budget, voxel, max_error);
            (made, iso)
        })
        .collect();
    let mut reached = false;
    for (collapsed, iso) in collapses {
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

/// meshoptimizer passes of a level's checked collapse (each also checks the result's topology
/// and crossings): a level that needs more is better answered by a coarser one.
pub const ATTEMPTS: usize = 4;

/// `mesh` collapsed to `budget` with its topology kept (the smallest parts dropped where it
/// stalls above, but not from the level above, whose parts the choice weighed already),
/// without zero-area triangles judged against `cell`, as candidates of `method`; where that
/// stalls above the budget or dropped parts, and always for the level above, meshoptimizer's
/// plain collapse of it too (which may break a promise: the choice checks). Empty for an empty
/// mesh.
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
        max_rounds: match method {
            Method::Above => 0,
            _ => 2,
        },
        ..PartsOptions::default()
    };
    let plain_of = || {
        let (plain, _) = simplify_unchecked(&mesh, budget, false).ok()?;
        Some(Candidate::new(method, without_zero_area(plain, cell)))
    };
    // The level above's plain collapse is made anyway: beside the checked one.
    let always = method == Method::Above && max_error.is_none();
    let (checked, plain) = rayon::join(
        || {
            let done = simplify_dropping_parts(&mesh, budget, &options).ok()?;
            let mut c = Candidate::new(method, without_zero_area(done.simplified.mesh, cell));
            c.parts_dropped = done.dropped_parts;
            Some(c)
        },
        || always.then(plain_of).flatten(),
    );
    let mut out: Vec<Candidate> = checked.into_iter().collect();
    let stalled = out.iter().all(|c| !within_budget(c.triangles(), budget));
    let dropped = out.iter().any(|c| c.parts_dropped > 0);
    // The level above's plain collapse is often closer where it keeps the promises anyway;
    // where it is the checked one over again (its first pass kept everything), it is not
    // measured twice.
    let plain = match always {
        true => plain,
        false => ((stalled || dropped) && max_error.is_none())
            .then(plain_of)
            .flatten(),
    };
    if let Some(plain) = plain {
        let same = |c: &Candidate| {
            c.mesh.triangles == plain.mesh.triangles && c.mesh.positions == plain.mesh.positions
        };
        if !out.iter().any(same) {
            out.push(plain);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use voxlod_core::glam::Vec3;
    use voxlod_testkit::shapes::{icosphere, icosphere_at};

    #[test]
    fn small_grids_have_a_finer_and_a_coarser_neighbour_and_at_small_budgets_a_far_one() {
        let beside = |r, far| neighbours(r, far).collect::<Vec<_>>();
        assert_eq!(beside(10, false), [14, 7]);
        assert_eq!(beside(10, true), [14, 7, 20]);
        // At the coarsest grid the coarser neighbour is the grid itself, left out.
        assert_eq!(beside(COARSEST, true), [5, 8]);
        // An icosphere of 1 280 triangles: 16 times 80 is its count, 16 times 81 more.
        let input = Input::prepare(&icosphere(3)).unwrap();
        let options = PortfolioOptions::default();
        assert!(far_finer_too(&input, &options, 80));
        assert!(!far_finer_too(&input, &options, 81));
        let proxy = PortfolioOptions::remesh(&[80]);
        assert!(!far_finer_too(&input, &proxy, 80));
        let large = Input::prepare(&icosphere(6)).unwrap();
        assert!(far_finer_too(&large, &options, FAR_BUDGET));
        assert!(!far_finer_too(&large, &options, FAR_BUDGET + 1));
    }

    #[test]
    fn a_staged_level_is_collapsed_halfway_and_fitted_to_the_input() {
        // A sphere of radius 1.05 (5 120 triangles) stands for the unit sphere: collapsed to
        // 250 triangles (STAGE times 100) and fitted, its vertices come back to the unit
        // sphere; an empty level stays empty, and without fit options nothing is staged.
        let input = Input::prepare(&icosphere(4)).unwrap();
        let measure = Measure::new(&input, 2_000, 10_000).unwrap();
        let options = PortfolioOptions::for_triangles(&[100]);
        let levels = [icosphere_at(4, 1.05, Vec3::ZERO), Default::default()];
        let mids = staged(&levels, &input, &measure, &options, (32, 100));
        assert_eq!(mids.len(), 2);
        assert!(mids[1].triangles.is_empty());
        assert!(within_budget(mids[0].triangle_count(), 250));
        let positions = &mids[0].positions;
        let off = positions
            .iter()
            .map(|p| (p.length() - 1.0).abs())
            .sum::<f32>();
        let mean_off = off / positions.len() as f32;
        assert!(mean_off < 0.01, "{mean_off}");
        let unfitted = PortfolioOptions {
            fit: None,
            ..options
        };
        assert!(staged(&levels, &input, &measure, &unfitted, (32, 100)).is_empty());
    }

    #[test]
    fn a_level_twice_as_far_as_the_kept_collapse_is_not_collapsed() {
        let input = Input::prepare(&icosphere(3)).unwrap();
        let measure = Measure::new(&input, 2_000, 10_000).unwrap();
        // Concentric spheres 0.02 and 0.3 from the unit sphere, and an empty level.
        let levels = || {
            vec![
                icosphere_at(3, 1.02, Vec3::ZERO),
                icosphere_at(3, 1.3, Vec3::ZERO),
                voxlod_core::TriangleMesh::default(),
            ]
        };
        let kept = |closest: f64, remesh: bool| -> Vec<bool> {
            (within_reach(levels(), &measure, closest, remesh).iter())
                .map(|l| !l.triangles.is_empty())
                .collect()
        };
        // A collapse 0.1 away: 0.3 is beyond twice that, 0.02 within.
        assert_eq!(kept(0.1, false), [true, false, false]);
        assert_eq!(kept(0.2, false), [true, true, false]);
        // No collapse that keeps every promise, or a proxy: every level.
        assert_eq!(kept(f64::INFINITY, false), [true, true, false]);
        assert_eq!(kept(0.1, true), [true, true, false]);
    }

    #[test]
    fn the_level_above_collapsed_gives_its_plain_collapse_only_where_it_differs() {
        // A sphere collapses to 200 triangles in one accepted pass: the plain collapse is the
        // same mesh, and is not given again.
        let sphere = icosphere(3);
        let once = collapsed(Method::Above, sphere, 200, 1e-3, None);
        assert_eq!(once.len(), 1);
        assert!(within_budget(once[0].triangles(), 200));
    }
}
