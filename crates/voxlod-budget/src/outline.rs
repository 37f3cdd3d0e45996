//! A level's outline beside the input's plain collapse (our addition: He et al. 1995 judge
//! levels by distance alone).
//!
//! The choice by Hausdorff distance (module `select`, step 3) can spend a budget's triangles on
//! keeping a small part far from the rest, or an inner surface, where the input's plain collapse
//! (meshoptimizer `simplify`, as gltfpack runs it) drops the part and spends them on the outer
//! surface: the level is closer, yet shows a worse outline than that collapse. A CT skull at
//! 1 000 triangles keeps a wire 60 mm away at 6 % of the diagonal where the collapse is 20 %
//! away, and its silhouette differs from the input's by 10 % where the collapse's does by 6 %.
//!
//! Where the chosen level's silhouette difference (crate `voxlod-render`'s, `measure::VIEWS`
//! views of `measure::SIZE`² pixels, the measure `voxlod evaluate` reports) exceeds the plain
//! collapse's, the candidates that keep every promise are weighed by their outline: those
//! whose silhouette differs less than the collapse's, the [`TRIES`] best, with the input's
//! parts they lost put back (module `restore`), are checked for crossings and measured
//! carefully. The closest of them whose careful Hausdorff distance is at most [`CLOSER`] times
//! the plain collapse's (so that the level stays closer than the collapse too; and than
//! `simplifySloppy`'s, where that reaches the budget as a manifold) and at most [`SLACK`]
//! times the chosen level's, and whose mean distance keeps [`crate::promises::MEAN_SLACK`], is
//! the level instead.
//!
//! Cost: nothing where the level is the plain collapse or no candidate could be close enough;
//! else the input's silhouettes once a run (one render per view, O(T + pixels)), two renders
//! per budget, and where the level's outline is the worse, a render per candidate, up to
//! [`TRIES`] restorations, crossing counts and careful measurements.

use rayon::prelude::*;

use crate::candidate::{Candidate, Method};
use crate::input::Input;
use crate::measure::{Care, Distance, Measure};
use crate::promises::{crosses_no_more, mean_reference, Promise, Promises, MEAN_SLACK};
use crate::report::Outline;
use crate::restore::{with_parts_restored, StandIns};

/// A level chosen for its outline is at most this many times as far as the plain collapse.
pub const CLOSER: f64 = 0.9;
/// A level chosen for its outline is at most this many times as far as the level chosen by
/// distance: the outline may cost some distance, not any.
pub const SLACK: f64 = 1.5;
/// Candidates with a better outline than the collapse's tried at most, best outline first.
pub const TRIES: usize = 3;

/// The index among `candidates` of the level for `promises`, given the level chosen by
/// distance at `index` (module docs); candidates restored here are pushed to `candidates` and
/// their broken promises to `broken`. With the silhouette differences of the new level and of
/// the plain collapse, where the outline chose.
pub fn by_outline(
    candidates: &mut Vec<Candidate>,
    broken: &mut Vec<Vec<Promise>>,
    index: usize,
    promises: &Promises,
    input: &Input,
    measure: &Measure,
    stand_ins: &StandIns,
) -> (usize, Option<Outline>) {
    let unchanged = (index, None);
    let Some(plain) = (0..candidates.len()).find(|&i| candidates[i].method == Method::Collapse)
    else {
        return unchanged;
    };
    let Some(chosen_h) = candidates[index].careful.map(|d| d.hausdorff) else {
        return unchanged;
    };
    if plain == index || promises.remesh {
        return unchanged;
    }
    let room = |plain_h: f64| (CLOSER * plain_h).min(SLACK * chosen_h);
    // The most room the candidates can have (the limit below is at most this): where none
    // but the level is within it, nothing is drawn.
    let most = candidates[plain]
        .careful
        .map_or(SLACK * chosen_h, |d| room(d.hausdorff));
    if most <= chosen_h || pool(candidates, broken, index, most).is_empty() {
        return unchanged;
    }
    let (Some(chosen_s), Some(plain_s)) = (
        measure.silhouette(&candidates[index].mesh),
        measure.silhouette(&candidates[plain].mesh),
    ) else {
        return unchanged;
    };
    if chosen_s <= plain_s {
        return unchanged;
    }
    let Some(plain_d) = careful(&candidates[plain], measure, f64::INFINITY) else {
        return unchanged;
    };
    let limit = room(plain_d.hausdorff).min(CLOSER * sloppy_hausdorff(candidates, broken, measure));
    if limit <= chosen_h {
        return unchanged;
    }
    let keeping: Vec<usize> = (0..candidates.len())
        .filter(|&i| broken[i].is_empty())
        .collect();
    let mean_limit = mean_reference(candidates, &keeping).map(|m| MEAN_SLACK * m);
    let tries = better_outlines(candidates, broken, index, limit, plain_s, measure);
    let mut best: Option<(usize, f64, f64)> = None;
    for (i, outline) in tries {
        let Some(k) = restored(candidates, broken, i, promises, input, measure, stand_ins) else {
            continue;
        };
        // A twin with parts put back is drawn again; the candidate itself was drawn already.
        let silhouette = match k == i {
            true => Some(outline),
            false => measure.silhouette(&candidates[k].mesh),
        };
        let Some(s) = silhouette else {
            continue;
        };
        if s >= plain_s || !crosses_no_more(input, &mut candidates[k]) {
            continue;
        }
        let d = careful(&candidates[k], measure, limit);
        candidates[k].careful = d;
        let Some(d) = d.filter(|d| d.hausdorff <= limit) else {
            continue;
        };
        if mean_limit.is_some_and(|m| d.mean > m) {
            continue;
        }
        if best.is_none_or(|(_, h, _)| d.hausdorff < h) {
            best = Some((k, d.hausdorff, s));
        }
    }
    match best {
        Some((k, _, s)) => {
            let outline = Outline {
                silhouette_difference: s,
                collapse_silhouette_difference: plain_s,
            };
            (k, Some(outline))
        }
        None => unchanged,
    }
}

/// The candidates other than `index` that keep the cheap promises, whose quick shape distance
/// is within `limit` and whose silhouette differs less than `bar`: at most [`TRIES`], the best
/// outline first, each with its silhouette difference. Cost: a render per candidate within
/// `limit`, side by side.
fn better_outlines(
    candidates: &[Candidate],
    broken: &[Vec<Promise>],
    index: usize,
    limit: f64,
    bar: f64,
    measure: &Measure,
) -> Vec<(usize, f64)> {
    let pool = pool(candidates, broken, index, limit);
    let outlines: Vec<Option<f64>> = (pool.par_iter())
        .map(|&i| measure.silhouette(&candidates[i].mesh))
        .collect();
    let mut better: Vec<(usize, f64)> = (pool.into_iter().zip(outlines))
        .filter_map(|(i, s)| Some((i, s?)))
        .filter(|&(_, s)| s < bar)
        .collect();
    better.sort_by(|a, b| a.1.total_cmp(&b.1));
    better.truncate(TRIES);
    better
}

/// The candidates other than `index` that keep the cheap promises and whose quick shape
/// distance is within `limit`.
fn pool(candidates: &[Candidate], broken: &[Vec<Promise>], index: usize, limit: f64) -> Vec<usize> {
    (0..candidates.len())
        .filter(|&i| i != index && broken[i].is_empty())
        .filter(|&i| candidates[i].quick.is_some_and(|d| d.shape <= limit))
        .collect()
}

/// The index of candidate `i` with the input's parts it lost put back (a twin pushed to
/// `candidates`), or `i` itself where it lost none that can come back; `None` where the twin
/// breaks a cheap promise.
fn restored(
    candidates: &mut Vec<Candidate>,
    broken: &mut Vec<Vec<Promise>>,
    i: usize,
    promises: &Promises,
    input: &Input,
    measure: &Measure,
    stand_ins: &StandIns,
) -> Option<usize> {
    let Some(mut twin) = with_parts_restored(&candidates[i], input, stand_ins, promises.budget)
    else {
        return Some(i);
    };
    let b = promises.broken_cheap(&twin);
    if !b.is_empty() {
        return None;
    }
    twin.quick = measure.distance(&twin.mesh, Care::Quick, f64::INFINITY);
    candidates.push(twin);
    broken.push(b);
    Some(candidates.len() - 1)
}

/// The careful Hausdorff distance of meshoptimizer's `simplifySloppy` where it reaches the
/// budget as a manifold (then a peer the level must stay closer than), else infinity.
fn sloppy_hausdorff(candidates: &[Candidate], broken: &[Vec<Promise>], measure: &Measure) -> f64 {
    let peer = |b: &[Promise]| !b.contains(&Promise::Budget) && !b.contains(&Promise::Manifold);
    let sloppy =
        (0..candidates.len()).find(|&i| candidates[i].method == Method::Sloppy && peer(&broken[i]));
    let distance = sloppy.and_then(|i| careful(&candidates[i], measure, f64::INFINITY));
    distance.map_or(f64::INFINITY, |d| d.hausdorff)
}

/// `c`'s careful distance: as measured, else measured now (`None` past `limit`).
fn careful(c: &Candidate, measure: &Measure, limit: f64) -> Option<Distance> {
    c.careful
        .or_else(|| measure.distance(&c.mesh, Care::Careful, limit))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::Distance;
    use voxlod_core::glam::Vec3;
    use voxlod_core::TriangleMesh;
    use voxlod_testkit::shapes::{append, icosphere_at};

    /// A unit ball of 1 280 triangles scaled by `scale`, with a small ball of 80 far off where
    /// `far` is set.
    fn balls(scale: f32, far: bool) -> TriangleMesh {
        let mut mesh = icosphere_at(3, scale, Vec3::ZERO);
        if far {
            append(&mut mesh, &icosphere_at(1, 0.15, Vec3::new(4.0, 0.0, 0.0)));
        }
        mesh
    }

    /// A candidate of `mesh` measured at `hausdorff` (shape and mean preset, as the choice
    /// found them).
    fn measured(method: Method, mesh: TriangleMesh, hausdorff: f64) -> Candidate {
        let mut c = Candidate::new(method, mesh);
        let d = Distance {
            hausdorff,
            shape: hausdorff,
            mean: 0.01,
        };
        (c.quick, c.careful) = (Some(d), Some(d));
        c
    }

    /// The outline's choice among the plain collapse (the large ball alone, 3.0 away: it lost
    /// the small one), the level chosen by distance (`chosen`) and one more candidate.
    fn outline_of(chosen: Candidate, other: Candidate) -> (usize, Option<Outline>) {
        outline_among(vec![chosen, other])
    }

    /// [`outline_of`] with the chosen level first among `others`.
    fn outline_among(others: Vec<Candidate>) -> (usize, Option<Outline>) {
        let mut both = icosphere_at(4, 1.0, Vec3::ZERO);
        append(&mut both, &icosphere_at(2, 0.15, Vec3::new(4.0, 0.0, 0.0)));
        let input = Input::prepare(&both).unwrap();
        let measure = Measure::new(&input, 2_000, 10_000).unwrap();
        let promises = Promises {
            budget: 1_360,
            closed: true,
            max_handles: Some(0),
            remesh: false,
        };
        let count = 1 + others.len();
        let mut candidates = vec![measured(Method::Collapse, balls(1.0, false), 3.0)];
        candidates.extend(others);
        let mut broken: Vec<Vec<Promise>> = candidates
            .iter()
            .map(|c| promises.broken_cheap(c))
            .collect();
        // The collapse, the chosen level and the next keep every promise.
        assert!(broken[..3].iter().all(|b| b.is_empty()), "{broken:?}");
        let stand_ins = StandIns::default();
        let (index, outline) = by_outline(
            &mut candidates,
            &mut broken,
            1,
            &promises,
            &input,
            &measure,
            &stand_ins,
        );
        assert_eq!(candidates.len(), count, "no part was lost, none restored");
        (index, outline)
    }

    #[test]
    fn a_level_with_a_worse_outline_than_the_collapse_gives_way_to_one_with_a_better() {
        // Chosen: the large ball shrunk by 15 %, the small one kept: closest by distance, but
        // its outline lacks a ring around the large ball.
        let chosen = measured(Method::Voxel, balls(0.85, true), 0.15);
        let better = measured(Method::Voxel, balls(1.0, true), 0.2);
        let (index, outline) = outline_of(chosen, better);
        assert_eq!(index, 2);
        let Outline {
            silhouette_difference: level,
            collapse_silhouette_difference: collapse,
        } = outline.unwrap();
        // The better outline differs by the ball's faceting only; the collapse's also lacks
        // the small ball.
        assert!(level < collapse && collapse < 0.1, "{level} {collapse}");
    }

    #[test]
    fn the_outline_costs_at_most_half_again_the_distance_and_stays_closer_than_the_collapse() {
        let chosen = || measured(Method::Voxel, balls(0.85, true), 0.15);
        let too_far = measured(Method::Voxel, balls(1.0, true), SLACK * 0.15 * 1.01);
        assert_eq!(outline_of(chosen(), too_far), (1, None));
        let within = measured(Method::Voxel, balls(1.0, true), SLACK * 0.15 * 0.99);
        assert_eq!(outline_of(chosen(), within).0, 2);
        // A chosen level already 0.9 times as far as the collapse leaves no room.
        let near_collapse = measured(Method::Voxel, balls(0.85, true), CLOSER * 3.0);
        let better = measured(Method::Voxel, balls(1.0, true), CLOSER * 3.0);
        assert_eq!(outline_of(near_collapse, better), (1, None));
    }

    #[test]
    fn the_outline_stays_closer_than_a_manifold_sloppy_collapse_within_the_budget() {
        let chosen = || measured(Method::Voxel, balls(0.85, true), 0.15);
        let better = || measured(Method::Voxel, balls(1.0, true), 0.2);
        // Sloppy's level (here a ball of its own) measured at 0.21: the better outline at 0.2
        // is not 0.9 times closer.
        let sloppy = measured(Method::Sloppy, balls(0.9, true), 0.21);
        assert_eq!(outline_among(vec![chosen(), better(), sloppy]), (1, None));
        // At 0.3 it is; and one that misses the budget is no peer.
        let sloppy = measured(Method::Sloppy, balls(0.9, true), 0.3);
        assert_eq!(outline_among(vec![chosen(), better(), sloppy]).0, 2);
        let mut short = measured(Method::Sloppy, icosphere_at(2, 0.9, Vec3::ZERO), 0.01);
        short.careful = None;
        assert_eq!(outline_among(vec![chosen(), better(), short]).0, 2);
    }

    #[test]
    fn a_level_whose_outline_is_as_good_as_the_collapses_stays() {
        let chosen = measured(Method::Voxel, balls(1.0, true), 0.15);
        let other = measured(Method::Voxel, balls(1.0, true), 0.16);
        assert_eq!(outline_of(chosen, other), (1, None));
    }
}
