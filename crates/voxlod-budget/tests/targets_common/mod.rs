//! The targets of levels by budget, shared by `tests/targets.rs` and `examples/portfolio.rs`:
//! the budgets to test an input at, a level measured by one independent measure (50 000
//! samples a side, none of the portfolio's own), and the verdict against meshoptimizer's
//! `simplify` and `simplifySloppy` on the same input.

use voxlod_core::{mesh_topology, TriangleMesh};
use voxlod_metrics::{mesh_distance, DistanceOptions};

/// Samples a side of the independent measure.
pub const SAMPLES: usize = 50_000;

/// The targets' budgets for an input of `f` triangles: 1/8, 1/32 and 1/128 of it, and 1 000
/// and 300 where below 1/8, largest first.
pub fn target_budgets(f: usize) -> Vec<usize> {
    let mut b = vec![f / 8, f / 32, f / 128];
    for fixed in [1000, 300] {
        if fixed < f / 8 && !b.contains(&fixed) {
            b.push(fixed);
        }
    }
    b.retain(|&x| x >= 4);
    b.sort_unstable_by(|a, b| b.cmp(a));
    b.dedup();
    b
}

/// A method's level measured against the input.
#[derive(serde::Serialize, Clone, Copy, Debug)]
pub struct Measured {
    /// Triangles of the level.
    pub triangles: usize,
    /// Two-sided Hausdorff distance over the input's diagonal.
    pub hausdorff: f64,
    /// Two-sided mean distance over the input's diagonal.
    pub mean: f64,
    /// No edge of three or more triangles, no pinched vertex, no degenerate triangle.
    pub manifold: bool,
}

/// `mesh` measured against `input`; `None` where it has no area.
pub fn measured(input: &TriangleMesh, mesh: &TriangleMesh) -> Option<Measured> {
    let d = mesh_distance(input, mesh, &DistanceOptions::for_samples(SAMPLES)).ok()?;
    let mut m = mesh.clone();
    m.remove_unreferenced_vertices();
    let t = mesh_topology(&m);
    let diagonal = input.bounds().diagonal();
    Some(Measured {
        triangles: mesh.triangle_count(),
        hausdorff: d.hausdorff / diagonal,
        mean: d.mean / diagonal,
        manifold: t.is_manifold() && t.degenerate_triangles == 0,
    })
}

/// Whether `count` is within 10 % of `budget` (or one triangle).
pub fn within(count: usize, budget: usize) -> bool {
    (count as f64 - budget as f64).abs() <= (0.1 * budget as f64).max(1.0)
}

/// What the targets say of one level beside the peers' at the same budget.
#[derive(Debug, Default)]
pub struct Verdict {
    /// Our Hausdorff distance over the better eligible peer's, where one is eligible (reaches
    /// the budget within 10 % with a manifold result).
    pub hausdorff_ratio: Option<f64>,
    /// Our mean distance over `simplify`'s, where `simplify` is eligible.
    pub mean_ratio: Option<f64>,
    /// Our level is within 10 % of the budget.
    pub within_budget: bool,
}

impl Verdict {
    /// Every target met: Hausdorff at most 1.1 times the better eligible peer's, mean at most
    /// 1.25 times `simplify`'s, within the budget.
    pub fn met(&self) -> bool {
        self.within_budget
            && self.hausdorff_ratio.is_none_or(|r| r <= 1.1)
            && self.mean_ratio.is_none_or(|r| r <= 1.25)
    }
}

/// `ours` over `peer`, where a peer at distance 0 (a flat sheet's collapse) is matched only by
/// 0 (ratio 1), not divided by.
fn ratio(ours: f64, peer: f64) -> f64 {
    match peer > 0.0 {
        true => ours / peer,
        false if ours <= peer => 1.0,
        false => f64::INFINITY,
    }
}

/// The verdict on `ours` at `budget` beside `simplify` and `sloppy`.
pub fn verdict(
    budget: usize,
    ours: &Measured,
    simplify: Option<&Measured>,
    sloppy: Option<&Measured>,
) -> Verdict {
    let eligible = |m: Option<&Measured>| {
        m.copied()
            .filter(|m| within(m.triangles, budget) && m.manifold)
    };
    let best = [eligible(simplify), eligible(sloppy)]
        .into_iter()
        .flatten()
        .map(|m| m.hausdorff)
        .fold(f64::INFINITY, f64::min);
    Verdict {
        hausdorff_ratio: best.is_finite().then(|| ratio(ours.hausdorff, best)),
        mean_ratio: eligible(simplify).map(|s| ratio(ours.mean, s.mean)),
        within_budget: within(ours.triangles, budget),
    }
}
