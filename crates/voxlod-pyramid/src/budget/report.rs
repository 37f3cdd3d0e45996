//! The report of a budget's level ([`super::BudgetLevel`]) and the note of a missed budget.

use std::time::Instant;

use voxlod_core::{mesh_topology, Topology};

use super::candidate::Candidate;
use super::context::BudgetContext;
use super::{BudgetLevel, Stage, FINEST};
use crate::lod::LodLevel;

/// What a budget asks: its triangles, and the distance target where there is one.
#[derive(Clone, Copy, Debug)]
pub(super) struct Target {
    /// The triangle budget.
    pub budget: usize,
    /// The distance target, in mesh units.
    pub error: Option<f64>,
}

/// The candidate chosen for a budget, on the level it came from.
pub(super) struct Choice {
    /// The candidate.
    pub candidate: Candidate,
    /// The voxel level it was made from.
    pub level: LodLevel,
    /// Caps cut from that level.
    pub caps_cut: usize,
    /// Triangles of that level before the geometric stages.
    pub voxel_triangles: usize,
}

/// How a budget's search went: candidates tried, when it started, the warnings so far.
pub(super) struct Tally {
    /// Candidates tried.
    pub tried: usize,
    /// When the budget's search started.
    pub start: Instant,
    /// Warnings so far.
    pub warnings: Vec<String>,
}

/// The level and report of the chosen candidate (on the level it came from, with the caps cut
/// from that level), and the warnings with the note of a missed budget.
pub(super) fn finish(
    ctx: &BudgetContext,
    choice: Choice,
    target: Target,
    tally: Tally,
) -> (LodLevel, BudgetLevel, Vec<String>) {
    let Choice {
        candidate: chosen,
        mut level,
        caps_cut: cut,
        voxel_triangles,
    } = choice;
    let Target { budget, error } = target;
    let Tally {
        tried,
        start,
        mut warnings,
    } = tally;
    level.mesh = chosen.mesh;
    level.topology = mesh_topology(&level.mesh);
    let cut = if chosen.stage == Stage::InputQuadric {
        0
    } else {
        cut
    };
    let mut report = report(ctx, &level, Some(budget), error, cut, tried, start);
    report.voxel_triangles = voxel_triangles;
    report.stage = chosen.stage;
    report.error_bound = chosen.error_bound;
    report.hausdorff = chosen.distance.as_ref().map(|d| d.hausdorff);
    report.mean_distance = chosen.distance.as_ref().map(|d| d.mean);
    report.parts_dropped = chosen.parts_dropped;
    report.parts_restored = chosen.parts_restored;
    report.iso = chosen.iso;
    report.note = miss_note(&level.topology, budget);
    if let Some(note) = &report.note {
        warnings.push(format!("budget {budget}: {note}"));
    }
    if report.self_intersections > 0 {
        warnings.push(format!(
            "budget {budget}: {} pairs of triangles cross (where the input crossed itself, or \
             a stage other than the quadric collapse, which refuses folds, made them)",
            report.self_intersections
        ));
    }
    (level, report, warnings)
}

/// The report of `level` before its stage is known: the voxel level's figures.
pub(super) fn report(
    ctx: &BudgetContext,
    level: &LodLevel,
    budget: Option<usize>,
    error: Option<f64>,
    caps_cut: usize,
    candidates: usize,
    start: Instant,
) -> BudgetLevel {
    let t = &level.topology;
    BudgetLevel {
        budget,
        error_target: error,
        resolution: level.resolution,
        voxel_triangles: level.mesh.triangle_count(),
        caps_cut,
        stage: Stage::Voxel,
        error_bound: 0.5 * level.plan.voxel_size,
        hausdorff: None,
        silhouette_difference: None,
        mean_distance: None,
        triangles: level.mesh.triangle_count(),
        genus: t.genus,
        components: t.components,
        boundary_loops: t.boundary_loops,
        handles_removed: ctx.input_genus.zip(t.genus).map(|(a, b)| a - b),
        parts_dropped: 0,
        iso: ctx.level_options.iso,
        cavities_filled: 0,
        parts_restored: 0,
        simplified_from: None,
        staged: false,
        fitted_to_input: false,
        self_intersections: voxlod_contouring::crossing_pairs(&level.mesh).len(),
        candidates,
        method: None,
        shape_distance: None,
        ruled_out: Vec::new(),
        portfolio: Vec::new(),
        note: None,
        seconds: start.elapsed().as_secs_f64(),
    }
}

/// Why a level misses its budget by more than 10 %, if it does.
fn miss_note(topology: &Topology, budget: usize) -> Option<String> {
    let got = topology.triangles;
    if voxlod_budget::within_budget(got, budget) {
        return None;
    }
    Some(if got > budget {
        format!(
            "{got} triangles, more than 10 % over the budget: the level's topology (genus {}, \
             {} components, {} boundary loops) or the error bound stopped the simplification",
            topology.genus.map_or("?".to_string(), |g| g.to_string()),
            topology.components,
            topology.boundary_loops
        )
    } else {
        format!(
            "{got} triangles, more than 10 % under the budget: no voxel resolution up to {FINEST} \
             gives more"
        )
    })
}

#[cfg(test)]
mod tests {
    use super::miss_note;
    use voxlod_core::mesh_topology;

    /// A level is noted as missing its budget beyond 10 % of it counted in triangles: 44 and
    /// 36 for a budget of 40 are within, 45 and 35 are not.
    #[test]
    fn miss_note_counts_ten_per_cent_in_triangles() {
        let mut topology = mesh_topology(&voxlod_testkit::shapes::icosphere(1));
        let mut note = |got| {
            topology.triangles = got;
            miss_note(&topology, 40)
        };
        assert_eq!(note(44), None);
        assert_eq!(note(36), None);
        assert!(note(45).is_some_and(|n| n.contains("over the budget")));
        assert!(note(35).is_some_and(|n| n.contains("under the budget")));
    }
}
