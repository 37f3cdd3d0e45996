//! The level for an error target alone (module docs of [`crate::budget`], "PyramidError target"): the
//! resolution whose voxel is the error, then the quadric stage bounded by half of it. Cost: one
//! sampling and marching cubes, one quadric collapse, one distance measurement.

use std::time::Instant;

use voxlod_quadric::{simplify_to_budget, QuadricOptions};

use super::context::BudgetContext;
use super::report::report;
use super::{BudgetLevel, Stage, Then, COARSEST, FINEST};
use crate::error::PyramidError;
use crate::lod::LodLevel;

/// The level for an error target alone: the resolution whose voxel is `error`, then the
/// quadric stage within `error`.
pub(crate) fn error_level(
    ctx: &BudgetContext,
    error: f64,
) -> Result<(LodLevel, BudgetLevel, Vec<String>), PyramidError> {
    let start = Instant::now();
    let longest = ctx.source.bounds().longest_extent();
    let resolution = ((longest / error).ceil() as usize).clamp(COARSEST, FINEST);
    let (mut level, cut, _) = ctx.uncapped(resolution)?;
    let mut warnings = Vec::new();
    if level.mesh.is_empty() {
        warnings.push(format!(
            "error {error}: the level at resolution {resolution} vanished (parts thinner than a \
             voxel); the level is empty"
        ));
        let report = report(ctx, &level, None, Some(error), cut, 0, start);
        return Ok((level, report, warnings));
    }
    let voxel_triangles = level.mesh.triangle_count();
    let mut stage = (Stage::Voxel, 0.5 * level.plan.voxel_size);
    if ctx.then != Then::None {
        let options = QuadricOptions::bounded(0.5 * error);
        if let Ok(done) = simplify_to_budget(&level.mesh, 4, &options) {
            level.mesh = done.mesh;
            level.topology = done.topology;
            stage = (Stage::Quadric, done.error_bound);
        }
    }
    let mut report = report(ctx, &level, None, Some(error), cut, 1, start);
    report.voxel_triangles = voxel_triangles;
    (report.stage, report.error_bound) = stage;
    let distance = ctx.measure(&level.mesh);
    report.hausdorff = distance.as_ref().map(|d| d.hausdorff);
    report.mean_distance = distance.as_ref().map(|d| d.mean);
    Ok((level, report, warnings))
}
