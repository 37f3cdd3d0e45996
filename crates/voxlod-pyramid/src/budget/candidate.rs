//! A budget's candidates and how they compete (step 4 of [`crate::budget`]): within 10 % of the
//! budget (and, in a chain of budgets, within the genus cap of module `genus_cap`), without
//! crossing triangles, beats the rest, then the smaller measured Hausdorff distance to the
//! input.

use std::cmp::Ordering;
use std::sync::OnceLock;

use voxlod_core::{mesh_topology, TriangleMesh};

use super::measure::Measured;
use super::{BudgetLevel, Stage, BUDGET_TOLERANCE};

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
    /// Its genus and crossing pairs, found on first use.
    pub(super) facts: Facts,
}

/// What the competition asks of a candidate's mesh beyond its count, each found once.
#[derive(Default)]
pub(super) struct Facts {
    genus: OnceLock<Option<i64>>,
    crossings: OnceLock<usize>,
}

impl Candidate {
    /// Pairs of its triangles that cross ([`voxlod_contouring::crossing_pairs`]), counted once.
    pub(super) fn crossings(&self) -> usize {
        *(self.facts.crossings).get_or_init(|| voxlod_contouring::crossing_pairs(&self.mesh).len())
    }

    /// Whether it has no more handles than `genus_cap` (always without a cap or a genus); its
    /// genus is found once.
    pub(super) fn within_cap(&self, genus_cap: Option<i64>) -> bool {
        genus_cap.is_none_or(|cap| {
            let genus = self
                .facts
                .genus
                .get_or_init(|| mesh_topology(&self.mesh).genus);
            genus.is_none_or(|g| g <= cap)
        })
    }
}

/// Whether `candidate` is within 10 % of `budget` (as a ratio, the same above and below).
pub(super) fn fits(candidate: &Candidate, budget: usize) -> bool {
    count_fits(candidate.mesh.triangle_count(), budget)
}

/// Whether `candidate` is within 10 % of `budget`, has no more handles than `genus_cap` and no
/// crossing triangles: what the search looks for.
pub(super) fn fits_capped(candidate: &Candidate, budget: usize, genus_cap: Option<i64>) -> bool {
    fits(candidate, budget) && candidate.within_cap(genus_cap) && candidate.crossings() == 0
}

/// The most triangles within 10 % of `budget`, as [`fits`] and the report count it: the room a
/// level that stalled above its share leaves for the parts restored beside it (module
/// `detached`).
pub(super) fn most_fitting(budget: usize) -> usize {
    let within = |n: usize| count_fits(n, budget) && voxlod_budget::within_budget(n, budget);
    let mut most = (budget as f64 * (1.0 + BUDGET_TOLERANCE)).ceil() as usize;
    while most > budget && !within(most) {
        most -= 1;
    }
    most
}

/// Whether `count` triangles are within 10 % of `budget` (as a ratio).
fn count_fits(count: usize, budget: usize) -> bool {
    miss(count, budget) <= (1.0 + BUDGET_TOLERANCE).ln()
}

/// How far `count` is from `budget`, as the absolute log of their ratio.
fn miss(count: usize, budget: usize) -> f64 {
    (count as f64 / budget as f64).ln().abs()
}

/// How a level stands for a budget: its count, its measured Hausdorff distance to the input,
/// whether its genus is within the chain's cap, and whether no two of its triangles cross.
#[derive(Clone, Copy, Debug)]
pub(super) struct Standing {
    pub(super) triangles: usize,
    pub(super) hausdorff: Option<f64>,
    pub(super) within_cap: bool,
    pub(super) clean: bool,
}

impl Standing {
    /// How a finished level stands under `genus_cap`, from its report.
    pub(super) fn of(level: &BudgetLevel, genus_cap: Option<i64>) -> Standing {
        Standing {
            triangles: level.triangles,
            hausdorff: level.hausdorff,
            within_cap: genus_cap.is_none_or(|cap| level.genus.is_none_or(|g| g <= cap)),
            clean: level.self_intersections == 0,
        }
    }
}

/// Whether `candidate` beats `best` for `budget` under `genus_cap` (see [`beats`]).
pub(super) fn better(
    candidate: &Candidate,
    best: Option<&Candidate>,
    budget: usize,
    genus_cap: Option<i64>,
) -> bool {
    let Some(best) = best else {
        return true;
    };
    // The genus and the crossings decide only between levels within 10 % of the budget: a
    // level outside is not examined (a stalled one can be large).
    let standing = |c: &Candidate| {
        let fit = fits(c, budget);
        Standing {
            triangles: c.mesh.triangle_count(),
            hausdorff: c.distance.map(|d| d.hausdorff),
            within_cap: !fit || c.within_cap(genus_cap),
            clean: !fit || c.crossings() == 0,
        }
    };
    beats(standing(candidate), standing(best), budget)
}

/// Where level `s` stands for `budget`, best first: 0 within 10 %, within the genus cap and
/// without crossing triangles; 1 within 10 % and within the cap; 2 within 10 %; 3 outside.
pub(super) fn tier(s: &Standing, budget: usize) -> u8 {
    match (count_fits(s.triangles, budget), s.within_cap, s.clean) {
        (true, true, true) => 0,
        (true, true, false) => 1,
        (true, false, _) => 2,
        (false, _, _) => 3,
    }
}

/// Whether level `a` beats level `b` for `budget`: the better [`tier`]; within one tier inside
/// 10 %, the smaller measured distance (an unmeasured level does not win); between two
/// outside, the count nearer the budget.
pub(super) fn beats(a: Standing, b: Standing, budget: usize) -> bool {
    match tier(&a, budget).cmp(&tier(&b, budget)) {
        Ordering::Less => true,
        Ordering::Greater => false,
        Ordering::Equal if count_fits(a.triangles, budget) => match (a.hausdorff, b.hausdorff) {
            (Some(x), Some(y)) => x < y,
            _ => false,
        },
        Ordering::Equal => miss(a.triangles, budget) < miss(b.triangles, budget),
    }
}

#[cfg(test)]
mod tests {
    use super::{count_fits, most_fitting};

    #[test]
    fn the_most_fitting_count_fits_and_one_more_does_not() {
        for budget in (1..3000).chain([10_000, 20_000, 65_536, 1_000_003]) {
            let most = most_fitting(budget);
            let report_fits = |n: usize| voxlod_budget::within_budget(n, budget);
            assert!(
                count_fits(most, budget) && report_fits(most),
                "{budget}: {most}"
            );
            assert!(
                !(count_fits(most + 1, budget) && report_fits(most + 1)),
                "{budget}: {most}"
            );
            assert!(most >= budget);
        }
        // 10 % of 1 000 is 100 triangles, counted in triangles (the ratio 1 100 / 1 000 - 1
        // rounds to just above 0.1 in floating point).
        assert_eq!(most_fitting(1000), 1100);
        assert_eq!(most_fitting(40), 44);
    }
}
