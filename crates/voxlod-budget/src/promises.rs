//! What every level promises ([`Promises`]), and which of them a candidate breaks.
//!
//! A level is a manifold (every edge shared by at most two triangles, every vertex one fan)
//! and consistently oriented (the input is made one first, by cutting it where it is not:
//! module `input`), closed where the input is closed (or where every level was asked to be), has no more handles than the level above it (the input, for the largest budget: the
//! genus never rises along the chain), has no crossing triangles where the input has none (an
//! input that crosses itself, parts passing through each other, allows its levels no more
//! crossing pairs than it has, or crossings only where it crosses), and has its budget's
//! triangles within
//! [`crate::BUDGET_TOLERANCE`] (or one triangle, for a budget so small that a closed surface's
//! even count cannot come within 10 %). The checks run cheapest first; the crossing
//! count (O(F log F) on all threads) only where the others hold.

use serde::Serialize;
use voxlod_core::{crossing_pairs, TriangleMesh};

use crate::candidate::{Candidate, Method};
use crate::input::{crossing_place, Input};
use crate::BUDGET_TOLERANCE;

/// One promise.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Promise {
    /// Within 10 % of the budget.
    Budget,
    /// A manifold.
    Manifold,
    /// Consistently oriented.
    Oriented,
    /// Closed where it must be.
    Closed,
    /// No more handles than the level above.
    Genus,
    /// No crossing triangles.
    NoCrossings,
    /// A mean distance to the input at most [`MEAN_SLACK`] times that of the input's own
    /// collapse, where that collapse keeps the other promises (else its checked form's, where
    /// that one does): the portfolio's rule, so that a
    /// level closer by Hausdorff distance does not bury much of the surface (a voxel level
    /// closing a skull's inner surfaces) where the collapse follows all of it.
    MeanDistance,
}

/// See [`Promise::MeanDistance`].
pub const MEAN_SLACK: f64 = 1.25;

/// The careful mean distance that [`Promise::MeanDistance`] holds the candidates at `among`
/// to: the input's plain collapse's where it is among them and measured, else its checked
/// collapse's.
pub fn mean_reference(candidates: &[Candidate], among: &[usize]) -> Option<f64> {
    let of = |method: Method| {
        (among.iter())
            .filter(|&&i| candidates[i].method == method)
            .find_map(|&i| candidates[i].careful)
            .map(|d| d.mean)
    };
    of(Method::Collapse).or_else(|| of(Method::CollapseKept))
}

impl Promise {
    /// The promise's name in reports and warnings.
    pub fn name(self) -> &'static str {
        match self {
            Promise::Budget => "budget",
            Promise::Manifold => "manifold",
            Promise::Oriented => "oriented",
            Promise::Closed => "closed",
            Promise::Genus => "genus",
            Promise::NoCrossings => "no-crossings",
            Promise::MeanDistance => "mean-distance",
        }
    }

    /// How much breaking it costs a level that must break some: the least severe is given up
    /// first where no candidate keeps them all (crossings first, then the genus, closedness
    /// (a level cut open along a few pinches), the budget, and a manifold last).
    pub fn severity(self) -> u8 {
        match self {
            Promise::MeanDistance => 0,
            Promise::NoCrossings => 1,
            Promise::Genus => 2,
            Promise::Closed => 3,
            Promise::Budget => 4,
            Promise::Oriented => 5,
            Promise::Manifold => 6,
        }
    }
}

/// What one budget's level must keep.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Promises {
    /// The budget.
    pub budget: usize,
    /// The level must be closed.
    pub closed: bool,
    /// The most handles it may have (`None`: no cap, where the level above has no genus).
    pub max_handles: Option<i64>,
    /// A new surface only ([`crate::PortfolioOptions::remesh`]): no candidate made of the
    /// input's own triangles is added at the choice.
    pub remesh: bool,
}

/// Whether `count` triangles are within the tolerance of `budget` (module docs).
pub fn within_budget(count: usize, budget: usize) -> bool {
    let slack = (BUDGET_TOLERANCE * budget as f64).max(1.0);
    (count as f64 - budget as f64).abs() <= slack
}

impl Promises {
    /// Whether `count` triangles are within the tolerance of the budget.
    pub fn within_budget(&self, count: usize) -> bool {
        within_budget(count, self.budget)
    }

    /// The promises `candidate` breaks, apart from the crossings (see [`Promises::crossings`]).
    pub fn broken_cheap(&self, candidate: &Candidate) -> Vec<Promise> {
        let t = &candidate.topology;
        let mut broken = Vec::new();
        if !self.within_budget(candidate.triangles()) {
            broken.push(Promise::Budget);
        }
        if !t.is_manifold() || t.degenerate_triangles > 0 || t.duplicate_triangles > 0 {
            broken.push(Promise::Manifold);
        }
        if !t.is_consistently_oriented() {
            broken.push(Promise::Oriented);
        }
        if self.closed && t.boundary_edges > 0 {
            broken.push(Promise::Closed);
        }
        let over_cap = match (self.max_handles, t.genus) {
            (Some(cap), Some(genus)) => genus > cap,
            (Some(_), None) => true,
            (None, _) => false,
        };
        if over_cap {
            broken.push(Promise::Genus);
        }
        broken
    }

    /// How many of `candidate`'s triangle pairs cross, counted once (kept in the candidate).
    pub fn crossings(candidate: &mut Candidate) -> usize {
        *candidate
            .crossings
            .get_or_insert_with(|| crossing_pairs(&candidate.mesh).len())
    }
}

/// Whether `candidate` crosses itself no more than the input does: none where the input has
/// none; no more pairs than the input has, or pairs only where the input crosses itself too
/// (within each pair's reach, [`crossing_place`]: a collapse of a self-intersecting scan moves
/// its crossings and may cut them into more pairs, but makes no new ones elsewhere). The
/// input's crossings are looked for only where the candidate has some.
pub fn crosses_no_more(input: &Input, candidate: &mut Candidate) -> bool {
    // The pairs themselves where the count is not known yet: found once, kept for the places.
    let pairs = candidate
        .crossings
        .is_none()
        .then(|| crossing_pairs(&candidate.mesh));
    if let Some(pairs) = &pairs {
        candidate.crossings = Some(pairs.len());
    }
    let count = Promises::crossings(candidate);
    if count == 0 {
        return true;
    }
    let limit = input.crossings();
    if count <= limit {
        return true;
    }
    let pairs = pairs.unwrap_or_else(|| crossing_pairs(&candidate.mesh));
    limit > 0 && crosses_where_the_input_does(input, &candidate.mesh, &pairs)
}

/// Comparisons of the input's crossings with a candidate's at most, beyond which only their
/// counts decide ([`crosses_no_more`]).
pub const PLACES_COMPARED: usize = 4_000_000;

/// Whether every crossing pair (`pairs`) of `mesh` has one of the input's crossings within its
/// reach (none where the input has none). Cost: each pair against each input crossing, at most
/// [`PLACES_COMPARED`].
fn crosses_where_the_input_does(input: &Input, mesh: &TriangleMesh, pairs: &[(u32, u32)]) -> bool {
    let places = input.crossing_places();
    if places.is_empty() || places.len().saturating_mul(pairs.len()) > PLACES_COMPARED {
        return false;
    }
    pairs.iter().all(|&pair| {
        let (centre, reach) = crossing_place(mesh, pair);
        places.iter().any(|p| p.distance(centre) <= reach)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::candidate::Method;
    use voxlod_core::glam::Vec3;
    use voxlod_testkit::shapes::{append, icosphere_at};

    /// Unit spheres of subdivision `levels` at `centres` (off the axes, so that no two share a
    /// vertex position), in one mesh.
    fn spheres(levels: u32, centres: &[f32]) -> voxlod_core::TriangleMesh {
        let at = |x: f32| icosphere_at(levels, 1.0, Vec3::new(x, 0.1 * x, 0.05 * x));
        let mut mesh = at(centres[0]);
        for &x in &centres[1..] {
            append(&mut mesh, &at(x));
        }
        mesh
    }

    #[test]
    fn a_self_crossing_input_allows_crossings_only_where_it_crosses() {
        // Two spheres passing through each other: they cross along a circle.
        let input = Input::prepare(&spheres(3, &[0.0, 0.7])).unwrap();
        assert!(input.crossings() > 0);
        // Finer, they cross in more pairs along the same circle: the promise holds.
        let mut finer = Candidate::new(Method::Voxel, spheres(4, &[0.0, 0.7]));
        assert!(Promises::crossings(&mut finer) > input.crossings());
        assert!(crosses_no_more(&input, &mut finer));
        // A third sphere through the second crosses where the input does not: broken.
        let mut more = Candidate::new(Method::Voxel, spheres(3, &[0.0, 0.7, 2.1]));
        assert!(Promises::crossings(&mut more) > input.crossings());
        assert!(!crosses_no_more(&input, &mut more));
        // An input that does not cross itself allows none.
        let clean = Input::prepare(&spheres(3, &[0.0, 3.0])).unwrap();
        assert_eq!(clean.crossings(), 0);
        assert!(!crosses_no_more(&clean, &mut finer));
    }
}
