//! [`crate::lod()`] by triangle budget for a mesh: the portfolio of crate `voxlod-budget` (the
//! input's own collapse, voxel levels after He et al. 1995 §5, the level above, each budget
//! answered by the candidate measured closest that keeps the levels' promises), its levels and
//! reports in the shape of [`Lod`]. Volumes, an error target alone, and the envelope or no
//! geometric stage still go through [`crate::budget`].

use std::time::Instant;

use voxlod_budget::{levels_with, InputReport, Method, PortfolioOptions};
use voxlod_core::{Topology, TriangleMesh};
use voxlod_sampling::{level_grid, LevelPlan, MeshPreparation, PyramidOptions};

use crate::budget::{BudgetLevel, Stage, Then};
use crate::error::PyramidError;
use crate::lod::LodLevel;
use crate::lod_options::{Lod, LodOptions};
use crate::progress::{Control, Event, Progress, ProgressFn};
use crate::source::Route;

/// Whether [`portfolio_lod`] answers `options` for a mesh: budgets given, and the quadric
/// stage (or the automatic choice) asked.
pub(crate) fn answers(options: &LodOptions) -> bool {
    options.triangles.is_some() && matches!(options.then, Then::Auto | Then::Quadric)
}

/// The levels of `mesh` for `options.triangles` (module docs).
pub(crate) fn portfolio_lod(
    mesh: &TriangleMesh,
    options: &LodOptions,
    progress: &ProgressFn,
) -> Result<Lod, PyramidError> {
    let start = Instant::now();
    let (budget_options, mut warnings) = budget_options(mesh, options);
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
    let run = levels_with(mesh, &budget_options, &ask)?;
    warnings.extend(run.warnings.iter().cloned());
    let levels = run
        .levels
        .into_iter()
        .map(|l| (l.mesh, l.topology, l.report));
    let error = budget_options.max_error;
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

/// The portfolio's options for `options`, and a warning for each option of `options` that
/// the portfolio does not use.
pub(crate) fn budget_options(
    mesh: &TriangleMesh,
    options: &LodOptions,
) -> (PortfolioOptions, Vec<String>) {
    let defaults = LodOptions::default();
    let mut warnings = Vec::new();
    let mut unused = |name: &str, given: bool| {
        if given {
            warnings.push(format!(
                "{name} does not apply to budget levels of a mesh (the portfolio chooses each \
                 level's resolution and isodensity): ignored"
            ));
        }
    };
    let pyramid = &options.pyramid;
    let default_pyramid = PyramidOptions::default();
    unused("iso", options.iso.is_some());
    unused("time_cap", options.time_cap != defaults.time_cap);
    unused(
        "radius",
        pyramid.radius_voxels != default_pyramid.radius_voxels,
    );
    unused(
        "lines_per_radius",
        pyramid.lines_per_radius != default_pyramid.lines_per_radius,
    );
    let diagonal = mesh.bounds().diagonal();
    let budget = PortfolioOptions {
        triangles: options.triangles.clone().unwrap_or_default(),
        filter: pyramid.filter,
        monotone: options.monotone.is_some(),
        closed: options.closed,
        max_error: options.error.map(|e| e.distance(diagonal)),
        fit: options.fit.clone(),
        ..PortfolioOptions::default()
    };
    (budget, warnings)
}

/// The facade's report of a portfolio level.
fn report(r: &voxlod_budget::BudgetLevel, error: Option<f64>, genus: Option<i64>) -> BudgetLevel {
    let stage = match r.method {
        Method::Collapse | Method::CollapseAsGiven | Method::CollapseKept | Method::Sloppy => {
            Stage::InputQuadric
        }
        Method::Voxel | Method::Shell | Method::Above => Stage::Quadric,
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
        silhouette_difference: None,
        triangles: r.triangles,
        genus: r.genus,
        components: r.components,
        boundary_loops: r.boundary_loops,
        handles_removed: genus.zip(r.genus).map(|(i, l)| i - l),
        parts_dropped: r.parts_dropped,
        iso: r.iso.unwrap_or(0.5),
        cavities_filled: usize::from(r.fill != voxlod_budget::Fill::None),
        parts_restored: r.parts_restored,
        simplified_from: r.simplified_from,
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
