//! Levels by triangle budget or error target ([`lod_by_budget`], He et al. 1995 §5): for a mesh
//! with the quadric stage, the portfolio of crate `voxlod-budget` (the input's own collapse,
//! voxel levels, the level above, each budget answered by the candidate measured closest that
//! keeps the levels' promises), its levels and reports in the shape of [`Lod`]; volumes, an
//! error target alone, and the envelope or no geometric stage go through [`crate::budget`]'s
//! voxel-first search.

use std::time::Instant;

use voxlod_budget::{levels_with, InputReport, Method};
use voxlod_core::{Topology, TriangleMesh};
use voxlod_sampling::{level_grid, LevelPlan, MeshPreparation};

use crate::budget::{BudgetLevel, Stage};
use crate::budget_options::BudgetOptions;
use crate::error::PyramidError;
use crate::lod::LodLevel;
use crate::lod_options::Lod;
use crate::progress::{run_to_end, Control, Event, Progress, ProgressFn};
use crate::source::{Route, Source};

/// Levels of `source` by the budgets or error target of `options` (module docs), one per
/// budget in the order given, each within 10 % of its budget or its report says why not. Fails
/// on options out of range (before any work), a source the route cannot take, the memory limit.
/// Cost: the portfolio's for a mesh (a collapse and a few voxel levels per budget), the
/// voxel-first search's otherwise ([`crate::budget`]).
pub fn lod_by_budget(source: &Source, options: &BudgetOptions) -> Result<Lod, PyramidError> {
    lod_by_budget_with(source, options, &run_to_end)
}

/// [`lod_by_budget`], reporting progress to `progress` and stopping with
/// [`PyramidError::Cancelled`] when it answers [`Control::Stop`]. The levels are moved into
/// [`BudgetOptions::frame`] once made.
pub fn lod_by_budget_with(
    source: &Source,
    options: &BudgetOptions,
    progress: &ProgressFn,
) -> Result<Lod, PyramidError> {
    options.check()?;
    let to_frame = source.to_frame(options.frame)?;
    let mut lod = match source {
        Source::Mesh(mesh) if options.uses_portfolio(source) => {
            portfolio_lod(mesh, options, progress)?
        }
        _ => crate::budget::voxel_first(source, options, progress)?,
    };
    for level in &mut lod.levels {
        to_frame.apply(&mut level.mesh);
    }
    Ok(lod)
}

/// The levels of `mesh` for `options.triangles` (module docs).
pub(crate) fn portfolio_lod(
    mesh: &TriangleMesh,
    options: &BudgetOptions,
    progress: &ProgressFn,
) -> Result<Lod, PyramidError> {
    let start = Instant::now();
    let (portfolio, mut warnings) = options.portfolio(mesh);
    let ask = |done: usize, total: usize| {
        let step = Progress {
            done,
            total,
            event: Event::Step {
                level: 0,
                what: "budget levels",
            },
        };
        progress(step) == Control::Continue
    };
    let run = levels_with(mesh, &portfolio, &ask)?;
    warnings.extend(run.warnings.iter().cloned());
    let normals = options.normals;
    let levels = run.levels.into_iter().map(|mut l| {
        if normals && l.mesh.normals.is_empty() {
            l.mesh.compute_vertex_normals();
        }
        (l.mesh, l.topology, l.report)
    });
    let error = portfolio.max_error;
    let mut lod = as_lod(mesh, levels, &run.input, error, warnings)?;
    lod.seconds = start.elapsed().as_secs_f64();
    Ok(lod)
}

/// The portfolio's levels of `mesh` (each with its topology and report) in the shape of
/// [`Lod`]: a plan per level from its resolution, the facade's budget report. `seconds` is 0.
/// A level's cell (`voxel_size`) is its voxel where voxels made it, else the side of an
/// equilateral triangle of its mean triangle area; each level's cell is larger than the finer
/// level's, so that a chain's screen coverages fall from the finest level to the coarsest.
pub(crate) fn as_lod(
    mesh: &TriangleMesh,
    run: impl Iterator<Item = (TriangleMesh, Topology, voxlod_budget::BudgetLevel)>,
    input: &InputReport,
    error: Option<f64>,
    warnings: Vec<String>,
) -> Result<Lod, PyramidError> {
    let bounds = mesh.bounds();
    let mut levels = Vec::new();
    let mut budgets = Vec::new();
    for (i, (level_mesh, topology, r)) in run.enumerate() {
        let resolution = r.resolution.unwrap_or(0);
        let voxel = bounds.longest_extent() / resolution.max(1) as f64;
        let grid = level_grid(&bounds, resolution.max(1), voxel)?;
        let cell = if resolution > 0 {
            voxel
        } else {
            triangle_side(&level_mesh).unwrap_or(voxel)
        };
        let finer = levels.last().map_or(0.0, |l: &LodLevel| l.plan.voxel_size);
        let cell = if cell > finer {
            cell
        } else {
            finer * (1.0 + 1e-6)
        };
        budgets.push(report(&r, error, input.genus));
        levels.push(LodLevel {
            resolution,
            plan: LevelPlan {
                level: i,
                resolution,
                voxel_size: cell,
                radius: cell,
                grid,
                estimated_bytes: 0,
            },
            topology,
            mesh: level_mesh,
            density: None,
            sample_seconds: 0.0,
            contour_seconds: 0.0,
            band: None,
            envelope: None,
            monotone: None,
            monotone_seconds: 0.0,
            clean_skipped: false,
        });
    }
    let p = input.preparation;
    Ok(Lod {
        levels,
        route: Route::Mesh,
        preparation: Some(MeshPreparation {
            welded_vertices: p.welded_vertices,
            degenerate_triangles: p.degenerate_triangles,
            duplicate_triangles: p.duplicate_triangles,
            flipped_triangles: p.flipped_triangles,
            holes_closed: 0,
            closed: input.closed,
        }),
        iso: 0.5,
        warnings,
        budgets,
        finest: None,
        seconds: 0.0,
    })
}

/// The side of an equilateral triangle of `mesh`'s mean triangle area; none without area.
fn triangle_side(mesh: &TriangleMesh) -> Option<f64> {
    let t = mesh.triangles.len();
    let area = (t > 0).then(|| mesh.area())?;
    let side = (4.0 * area / (3f64.sqrt() * t as f64)).sqrt();
    (side.is_finite() && side > 0.0).then_some(side)
}

/// The facade's report of a portfolio level.
fn report(r: &voxlod_budget::BudgetLevel, error: Option<f64>, genus: Option<i64>) -> BudgetLevel {
    let stage = match r.method {
        Method::Collapse
        | Method::CollapseAsGiven
        | Method::CollapseKept
        | Method::CollapseInTwoSteps
        | Method::CollapseUncrossed
        | Method::Sloppy
        | Method::Plate => Stage::InputQuadric,
        Method::Voxel | Method::Shell | Method::Above | Method::Below => Stage::Quadric,
    };
    BudgetLevel {
        budget: Some(r.budget),
        error_target: error,
        resolution: r.resolution.unwrap_or(0),
        voxel_triangles: 0,
        caps_cut: 0,
        stage,
        error_bound: r.shape_distance,
        hausdorff: Some(r.hausdorff),
        mean_distance: Some(r.mean_distance),
        silhouette_difference: r.outline.map(|o| o.silhouette_difference),
        triangles: r.triangles,
        genus: r.genus,
        components: r.components,
        boundary_loops: r.boundary_loops,
        handles_removed: genus.zip(r.genus).map(|(i, l)| i - l),
        parts_dropped: r.parts_dropped,
        iso: r.iso.unwrap_or(0.5),
        cavities_filled: usize::from(r.fill.fills_inside()),
        parts_restored: r.parts_restored,
        simplified_from: r.simplified_from,
        staged: r.staged,
        fitted_to_input: r.fitted_to_input,
        self_intersections: r.self_intersections,
        candidates: r.candidates.len(),
        method: Some(r.method),
        shape_distance: Some(r.shape_distance),
        ruled_out: r.ruled_out.clone(),
        portfolio: r.candidates.clone(),
        note: r.note.clone(),
        seconds: r.seconds,
    }
}
