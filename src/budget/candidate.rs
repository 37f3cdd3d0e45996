//! A budget's candidates and how they compete (step 4 of [`crate::budget`]): within 10 % of the
//! budget beats outside it, then the smaller measured Hausdorff distance to the input.

use voxlod_core::TriangleMesh;

use super::measure::Measured;
use super::{Stage, BUDGET_TOLERANCE};

/// One candidate for a budget: the level and its report.
pub(super) struct Candidate {
    pub(super) mesh: TriangleMesh,
    pub(super) stage: Stage,
    pub(super) error_bound: f64,
    pub(super) distance: Option<Measured>,
    /// Components of the voxel level that the quadric stage dropped.
    pub(super) parts_dropped: usize,
    /// The isodensity of the voxel level it came from.
    pub(super) iso: f32,
}

/// Whether `candidate` is within 10 % of `budget` (as a ratio, the same above and below).
pub(super) fn fits(candidate: &Candidate, budget: usize) -> bool {
    let miss = (candidate.mesh.triangle_count() as f64 / budget as f64)
        .ln()
        .abs();
    miss <= (1.0 + BUDGET_TOLERANCE).ln()
}

/// Whether `candidate` beats `best` for `budget`: within 10 % beats outside; then the smaller
/// measured Hausdorff distance (or, unmeasured, the count nearer the budget).
pub(super) fn better(candidate: &Candidate, best: Option<&Candidate>, budget: usize) -> bool {
    let Some(best) = best else {
        return true;
    };
    let miss = |c: &Candidate| (c.mesh.triangle_count() as f64 / budget as f64).ln().abs();
    match (fits(candidate, budget), fits(best, budget)) {
        (true, false) => true,
        (false, true) => false,
        (false, false) => miss(candidate) < miss(best),
        (true, true) => match (&candidate.distance, &best.distance) {
            (Some(a), Some(b)) => a.hausdorff < b.hausdorff,
            _ => false,
        },
    }
}
