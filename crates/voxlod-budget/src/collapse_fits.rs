//! The chain's collapses of the input fitted to it (beyond the paper; the fit is
//! [`crate::select::fitted_level`]): each level that is a collapse of the input (not of a voxel
//! level, nor fitted already) with at most 1/[`FITTED_SHARE`] of its triangles is fitted where
//! that keeps every promise and measures no farther. The chain is the one the unfitted levels
//! make, since a collapse of a fitted level is not always the closer (the ogre at 1 000: 4.2 %
//! of the diagonal against 1.3 %, measured carefully).
//!
//! A level's fit needs only the level and its promises, so it is made ahead
//! ([`fitted_ahead`]), while the chain chooses the next budget's level; refining from below
//! (module `below`) may then replace a level, or the level above it, whose handles cap its
//! promises. [`apply_fits`] keeps each fit made ahead whose level and promises are as they
//! were, and fits the others then: the levels are those fitting once the chain is final would
//! give.
//!
//! Cost: per such level, one fit, a crossing count where the fit did not make one, and a
//! careful measurement; a level that refining replaced, or whose promises its new level
//! above changed, is fitted twice.

use rayon::prelude::*;

use crate::candidate::Candidate;
use crate::input::Input;
use crate::measure::{Distance, Measure};
use crate::promises::Promises;
use crate::select::fitted_level;
use crate::{Level, PortfolioOptions};

/// A level that is a collapse of the input is fitted only where it has at most this share of
/// the input's triangles: the fit of the ogre's level at an eighth (15 501 of 124 008
/// triangles) takes 0.16 s of a chain whose time target is 1.5–1.7 s, where the levels at a
/// sixteenth and below take 0.07 s together. What the cap costs: on the budget bench, 46
/// levels at an eighth measure 9 % farther (Hausdorff) than fitted.
pub const FITTED_SHARE: usize = 10;

/// A level's fit made ahead: the promises it kept, and the fitted level where the fit is
/// the level (`None` where the level stays as it is).
pub struct Ahead {
    promises: Promises,
    fitted: Option<Candidate>,
}

/// `level`, chosen for `promises`, fitted to the input where it is a collapse of the input
/// that the fit serves (module docs). Nothing is fitted without fit options, for a proxy, or
/// where [`PortfolioOptions::fit_collapses`] is off.
pub fn fitted_ahead(
    level: &Level,
    promises: &Promises,
    input: &Input,
    measure: &Measure,
    options: &PortfolioOptions,
) -> Ahead {
    Ahead {
        promises: *promises,
        fitted: fitted(level, promises, input, measure, options),
    }
}

/// The fitted level, where it is the level (see [`fitted_ahead`]).
fn fitted(
    level: &Level,
    promises: &Promises,
    input: &Input,
    measure: &Measure,
    options: &PortfolioOptions,
) -> Option<Candidate> {
    let fit = options.fit.as_ref()?;
    if options.remesh || !options.fit_collapses {
        return None;
    }
    let r = &level.report;
    if r.resolution.is_some() || r.fitted_to_input || !r.hausdorff.is_finite() {
        return None;
    }
    if r.triangles * FITTED_SHARE > input.mesh.triangle_count() {
        return None;
    }
    let mut c = Candidate::new(r.method, level.mesh.clone());
    c.careful = Some(Distance {
        hausdorff: r.hausdorff,
        shape: r.shape_distance,
        mean: r.mean_distance,
    });
    let fitted = fitted_level(c, promises, input, measure, fit);
    (fitted.fitted && fitted.careful.is_some()).then_some(fitted)
}

/// `levels` (the chain, from the largest budget down) with their fits: `ahead[k]` where level
/// `k` was not `replaced` and its promises now (`now[k]`, from the chain as it is) are those
/// the fit was made for, else a fit made now, side by side.
pub fn apply_fits(
    levels: &mut [Level],
    ahead: Vec<Ahead>,
    (replaced, now): (&[bool], &[Promises]),
    (input, measure, options): (&Input, &Measure, &PortfolioOptions),
) {
    let fits: Vec<Option<Candidate>> = (ahead.into_par_iter().enumerate())
        .map(|(k, a)| match !replaced[k] && a.promises == now[k] {
            true => a.fitted,
            false => fitted(&levels[k], &now[k], input, measure, options),
        })
        .collect();
    for (level, fitted) in levels.iter_mut().zip(fits) {
        let Some((fitted, d)) = fitted.and_then(|f| f.careful.map(|d| (f, d))) else {
            continue;
        };
        let r = &mut level.report;
        r.fitted_to_input = true;
        (r.hausdorff, r.mean_distance, r.shape_distance) = (d.hausdorff, d.mean, d.shape);
        r.hausdorff_fraction = d.hausdorff / input.diagonal;
        r.self_intersections = fitted.crossings.unwrap_or(r.self_intersections);
        level.mesh = fitted.mesh;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::chain::chained_promises;
    use voxlod_testkit::{corpus, shapes::icosphere};

    #[test]
    fn a_fit_made_ahead_is_kept_only_where_its_level_and_promises_are_as_they_were() {
        // Interpenetrating parts: their levels at 1 000 and 300 are collapses of the input,
        // and fitting moves at least one of them (crate test `collapse_levels_are_fitted_...`).
        let part = corpus::interpenetrating();
        let fitting = PortfolioOptions::for_triangles(&[1000, 300]);
        let options = PortfolioOptions {
            fit_collapses: false,
            ..fitting.clone()
        };
        let unfitted = crate::levels(&part, &options).unwrap().levels;
        let fitted = crate::levels(&part, &fitting).unwrap().levels;
        assert!(fitted.iter().any(|l| l.report.fitted_to_input));
        let input = Input::prepare(&part).unwrap();
        let measure = Measure::new(&input, fitting.quick_samples, fitting.careful_samples);
        let measure = measure.unwrap();
        let now: Vec<Promises> = (0..unfitted.len())
            .map(|k| {
                let above = k.checked_sub(1).map(|a| &unfitted[a]);
                chained_promises(&input, &fitting, unfitted[k].report.budget, above)
            })
            .collect();
        let run = (&input, &measure, &fitting);
        let applied = |ahead: Vec<Ahead>, replaced: &[bool], now: &[Promises]| {
            let mut levels = unfitted.clone();
            apply_fits(&mut levels, ahead, (replaced, now), run);
            levels
        };
        let meshes =
            |levels: &[Level]| -> Vec<_> { levels.iter().map(|l| l.mesh.clone()).collect() };
        // Made ahead for the levels as they are: the levels fitting the final chain gives.
        let ahead = (unfitted.iter().zip(&now))
            .map(|(l, p)| fitted_ahead(l, p, &input, &measure, &fitting))
            .collect();
        assert_eq!(meshes(&applied(ahead, &[false; 2], &now)), meshes(&fitted));
        // A stand-in fit (a sphere) made ahead is used where nothing changed...
        let stand_in = || {
            let mut c = Candidate::new(crate::Method::Collapse, icosphere(1));
            c.careful = Some(Distance {
                hausdorff: 1.0,
                shape: 1.0,
                mean: 1.0,
            });
            c
        };
        let ahead_of = |promises: &[Promises]| -> Vec<Ahead> {
            (promises.iter())
                .map(|&promises| Ahead {
                    promises,
                    fitted: Some(stand_in()),
                })
                .collect()
        };
        let kept = applied(ahead_of(&now), &[false; 2], &now);
        assert!(kept
            .iter()
            .all(|l| l.mesh.triangles == icosphere(1).triangles));
        // ...and fitted again where its level was replaced, or its promises differ.
        let refit = applied(ahead_of(&now), &[true; 2], &now);
        assert_eq!(meshes(&refit), meshes(&fitted));
        let mut other = now.clone();
        for p in &mut other {
            p.max_handles = Some(p.max_handles.unwrap_or(0) + 1);
        }
        let refit = applied(ahead_of(&other), &[false; 2], &now);
        assert_eq!(meshes(&refit), meshes(&fitted));
    }
}
