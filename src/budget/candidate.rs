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
    /// Detached parts of the input restored beside the level (module `detached`).
    pub(super) parts_restored: usize,
    /// The isodensity of the voxel level it came from.
    pub(super) iso: f32,
}

/// Whether `candidate` is within 10 % of `budget` (as a ratio, the same above and below).
pub(super) fn fits(candidate: &Candidate, budget: usize) -> bool {
    count_fits(candidate.mesh.triangle_count(), budget)
}

/// Whether `count` triangles are within 10 % of `budget` (as a ratio).
fn count_fits(count: usize, budget: usize) -> bool {
    miss(count, budget) <= (1.0 + BUDGET_TOLERANCE).ln()
}

/// How far `count` is from `budget`, as the absolute log of their ratio.
fn miss(count: usize, budget: usize) -> f64 {
    (count as f64 / budget as f64).ln().abs()
}

/// Whether `candidate` beats `best` for `budget` (see [`beats`]).
pub(super) fn better(candidate: &Candidate, best: Option<&Candidate>, budget: usize) -> bool {
    let Some(best) = best else {
        return true;
    };
    let standing = |c: &Candidate| (c.mesh.triangle_count(), c.distance.map(|d| d.hausdorff));
    beats(standing(candidate), standing(best), budget)
}

/// Whether a level of `a.0` triangles at measured Hausdorff distance `a.1` beats one at `b`
/// for `budget`: within 10 % beats outside; then the smaller measured distance (an unmeasured
/// level does not win); between two outside, the count nearer the budget.
pub(super) fn beats(a: (usize, Option<f64>), b: (usize, Option<f64>), budget: usize) -> bool {
    match (count_fits(a.0, budget), count_fits(b.0, budget)) {
        (true, false) => true,
        (false, true) => false,
        (false, false) => miss(a.0, budget) < miss(b.0, budget),
        (true, true) => match (a.1, b.1) {
            (Some(x), Some(y)) => x < y,
            _ => false,
        },
    }
}
