//! Step 7 of [`crate::budget`] (our addition, beyond He et al. 1995): each budget's level, once
//! chosen, has its vertices fitted to the input surface with its triangles kept
//! ([`voxlod_fit`], the inner problem of Hoppe et al. 1993's mesh optimization, §4.1).
//!
//! Why: every earlier step looks at the input only through the filtered volume or through the
//! distances that judge the candidates; the geometric stage simplifies the voxel level, not
//! the input, so a crease that the filter filled in (the sphereflake's spheres where they meet)
//! stays filled at every budget. Fitting looks at the input again: on the sphereflake's level
//! of 1 000 triangles the sampled Hausdorff distance falls from 3.1 % to 2.4 % of the diagonal.
//!
//! **Kept only where it is better.** The fitted level is measured like every candidate
//! (step 4, with the input's samples of the search, not the fit's own, which are drawn with a
//! seed of their own) and kept only if its two-sided Hausdorff and mean distances are no
//! larger, no more of its triangle pairs cross, it has no zero-area triangle where the level
//! had none, its topology is the level's, and, where the level's silhouette difference was
//! measured (step 5), that is no larger either. Otherwise the level stays as it was, and the
//! report says which ([`super::BudgetLevel::fitted_to_input`]). Moving vertices never changes
//! the connectivity, so a closed, manifold, oriented level stays so.
//!
//! Each level is fitted after the whole chain is found: the search, the genus cap and the
//! level above that a smaller budget may be simplified from (module `genus_cap`) are those of
//! the unfitted levels, so a budget's level still depends on that budget and the options alone.
//!
//! Cost per level: [`voxlod_fit::FitOptions`]'s rounds (each a BVH of the level and
//! `samples + V` closest-point queries, and a sparse solve), then one distance measurement and
//! one crossing test.

use voxlod_core::{mesh_topology, TriangleMesh};
use voxlod_fit::FitOptions;
use voxlod_metrics::health::count_zero_area_triangles;

use super::context::BudgetContext;
use super::geometric::without_degenerate;
use super::BudgetLevel;
use crate::lod::LodLevel;

/// Each of `levels` (with its report in `reports`) fitted to the input where that measures
/// better (module docs); levels without an input mesh, or whose fit fails, are left alone.
pub(super) fn fit_levels(
    ctx: &BudgetContext,
    options: &FitOptions,
    levels: &mut [LodLevel],
    reports: &mut [BudgetLevel],
) {
    for (level, report) in levels.iter_mut().zip(reports.iter_mut()) {
        if let Some((mesh, fitted)) = fitted_level(ctx, options, level, report) {
            level.topology = mesh_topology(&mesh);
            level.mesh = mesh;
            *report = fitted;
        }
    }
}

/// `level` fitted to the input and its report, if the fit is kept (module docs).
fn fitted_level(
    ctx: &BudgetContext,
    options: &FitOptions,
    level: &LodLevel,
    report: &BudgetLevel,
) -> Option<(TriangleMesh, BudgetLevel)> {
    let (hausdorff, mean) = (report.hausdorff?, report.mean_distance?);
    let measure = ctx.measure.as_ref()?;
    let fitted = measure.fit(&level.mesh, options)?;
    if fitted.iterations == 0 {
        return None;
    }
    let mesh = without_degenerate(fitted.mesh, level.plan.voxel_size);
    let distance = ctx.measure(&mesh)?;
    let topology = mesh_topology(&mesh);
    let same_topology = (topology.genus, topology.components, topology.boundary_loops)
        == (report.genus, report.components, report.boundary_loops)
        && topology.is_closed_manifold() == level.topology.is_closed_manifold();
    let zero_area_ok =
        count_zero_area_triangles(&mesh) == 0 || count_zero_area_triangles(&level.mesh) > 0;
    if distance.hausdorff > hausdorff || distance.mean > mean || !same_topology || !zero_area_ok {
        return None;
    }
    let crossings = voxlod_contouring::crossing_pairs(&mesh).len();
    if crossings > report.self_intersections {
        return None;
    }
    let silhouette = match report.silhouette_difference {
        Some(before) => {
            let reference = ctx.silhouettes()?.as_ref().ok()?;
            let after = reference.mesh_difference(&mesh).ok()?.fraction;
            (after <= before).then_some(Some(after))?
        }
        None => None,
    };
    let mut fitted_report = report.clone();
    fitted_report.hausdorff = Some(distance.hausdorff);
    fitted_report.mean_distance = Some(distance.mean);
    fitted_report.self_intersections = crossings;
    fitted_report.silhouette_difference = silhouette;
    fitted_report.triangles = mesh.triangle_count();
    fitted_report.fitted_to_input = true;
    Some((mesh, fitted_report))
}
