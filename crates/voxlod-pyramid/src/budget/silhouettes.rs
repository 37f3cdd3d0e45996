//! The choice between the levels of different solids (our addition): the
//! input as given, and the input with its cavities filled or lined (modules `filled` and
//! `enclosed`). Each solid's search keeps its level closest by Hausdorff distance (step 4);
//! between the solids, the distance alone is a poor judge. A filled skull's level buries the
//! inner surface of the cranial cavity, which the two-sided distance counts in full although no
//! viewer outside sees it; the given skull's level keeps that surface but perforates the dome,
//! which the distance barely counts although every viewer sees it. So the levels in the best
//! tier of the search's rule (within 10 % of the budget, the genus cap, no crossings) are also
//! rendered, and their silhouette differences from the input measured
//! ([`voxlod_render::silhouette`], the 14 views of `voxlod evaluate` at 256²).
//!
//! **The rule.** Each level's two errors are divided by the smallest of its kind among the
//! levels compared, and the level whose larger ratio is the smallest is kept: the level that
//! is nowhere far behind the best on either measure. The silhouette differences are floored
//! at [`SILHOUETTE_FLOOR`] (1 % of the covered pixels, about what one pixel's width of outline
//! amounts to at this size), so that two nearly identical silhouettes do not decide between
//! levels whose distances differ. Ties go to the smaller Hausdorff distance.
//!
//! Measured on the CT head's bone surface (545 796 triangles, genus 675) at 1 000 triangles:
//! the given skull's level is 6.75 % of the diagonal from the input (search samples) with a
//! silhouette difference of 0.085, the lined skull's 8.39 % with 0.034; the rule keeps the lined
//! one, whose dome is whole (BENCHMARKS.md).
//!
//! Cost: only where levels of several solids compete (inputs with cavities): 14 renders of the
//! input once per run, and 14 renders of each competing level per budget.

use std::cmp::Ordering;

use voxlod_core::TriangleMesh;
use voxlod_render::SilhouetteReference;

/// Views and their side in pixels: those of `voxlod evaluate`'s silhouette difference.
pub(super) const VIEWS: usize = 14;
pub(super) const SIZE: u32 = 256;

/// Silhouette differences below this count as this (see the module docs).
pub(super) const SILHOUETTE_FLOOR: f64 = 0.01;

/// The input's silhouettes, rendered once per run, or why they could not be.
pub(super) fn input_silhouettes(input: &TriangleMesh) -> Result<SilhouetteReference, String> {
    SilhouetteReference::new(input, VIEWS, SIZE)
        .map_err(|e| format!("the input's silhouettes could not be rendered ({e})"))
}

/// The index of the level kept among levels with these Hausdorff distances and silhouette
/// differences (see the module docs); `None` for no levels.
pub(super) fn balanced_choice(errors: &[(f64, f64)]) -> Option<usize> {
    let smallest = |f: fn(&(f64, f64)) -> f64| errors.iter().map(f).fold(f64::INFINITY, f64::min);
    let best_distance = smallest(|e| e.0);
    let best_silhouette = smallest(|e| e.1).max(SILHOUETTE_FLOOR);
    let worse_ratio = |&(distance, silhouette): &(f64, f64)| {
        let distance = if best_distance > 0.0 {
            distance / best_distance
        } else if distance > 0.0 {
            f64::INFINITY
        } else {
            1.0
        };
        distance.max(silhouette.max(SILHOUETTE_FLOOR) / best_silhouette)
    };
    (0..errors.len()).min_by(|&a, &b| {
        (worse_ratio(&errors[a]).partial_cmp(&worse_ratio(&errors[b])))
            .unwrap_or(Ordering::Equal)
            .then(errors[a].0.total_cmp(&errors[b].0))
    })
}

#[cfg(test)]
mod tests {
    use super::balanced_choice;

    #[test]
    fn the_lined_skull_wins_at_1000_and_300() {
        // (Hausdorff % of the diagonal, silhouette difference) of the CT bone surface's levels:
        // as given, cavities filled, enclosed hollows filled, enclosed hollows lined.
        let at_1000 = [
            (6.75, 0.0848),
            (8.23, 0.0784),
            (11.07, 0.0304),
            (8.39, 0.0337),
        ];
        assert_eq!(balanced_choice(&at_1000), Some(3));
        let at_300 = [
            (11.04, 0.1761),
            (11.04, 0.1781),
            (10.92, 0.0641),
            (8.49, 0.0694),
        ];
        assert_eq!(balanced_choice(&at_300), Some(3));
    }

    #[test]
    fn silhouettes_under_the_floor_leave_the_choice_to_the_distance() {
        assert_eq!(balanced_choice(&[(2.0, 0.002), (1.5, 0.009)]), Some(1));
        // Equal silhouettes: the closer one; equal ratios: the closer one too.
        assert_eq!(balanced_choice(&[(2.0, 0.05), (1.0, 0.05)]), Some(1));
        assert_eq!(balanced_choice(&[(2.0, 0.02), (1.0, 0.04)]), Some(1));
        // A silhouette three times the best's outweighs a distance 1.5 times the best's.
        assert_eq!(balanced_choice(&[(1.0, 0.06), (1.5, 0.02)]), Some(1));
        assert_eq!(balanced_choice(&[]), None);
        assert_eq!(balanced_choice(&[(0.0, 0.0)]), Some(0));
    }
}
