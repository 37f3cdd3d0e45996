//! A level no farther from the input than the level below it, and often closer: the next
//! smaller budget's level refined to the larger budget ([`Method::Below`]): its edges split at
//! their midpoints, the longest first (`voxlod_core::split`, which leaves its surface,
//! topology and crossings as they were), then fitted to the input ([`Measure::fitted`]) as the
//! closest voxel candidate is. It is as close as the level below before the fit and usually
//! closer after it, keeps that level's handles (no more than the larger level's, so the
//! chain's genus still never rises) and spends the larger budget's triangles where the level
//! below was coarsest. It replaces a level that came out farther than the level below (every
//! collapse of a scan at the larger budget folded through itself, and what kept the promises
//! was a shell; a many-part model's larger grid lost parts its smaller grid kept), and one
//! that the fit of a level below within [`REACH`] times its distance brings closer (a fine
//! sphere at 1 000 triangles: the level at 640 refined and fitted is half as far as the
//! input's collapse).
//!
//! Beyond the paper: He et al. (1995) make each level from the original; a chain of budgets
//! chosen by measurement can come out farther at a larger budget, which no user of levels of
//! detail expects.
//!
//! Cost: per level whose level below is within [`REACH`], a split (O(E log E)), a fit, and one
//! careful measurement, which stops at the first point farther than the level it would
//! replace; the crossings are counted only for a closer one.

use voxlod_core::split::split_longest_edges;
use voxlod_fit::FitOptions;

use crate::candidate::{Candidate, Method};
use crate::input::Input;
use crate::measure::{Care, Measure};
use crate::promises::{crosses_no_more, Promises};
use crate::Level;

/// How many times as far from the input as a budget's level the level below it may be and
/// still be refined as its candidate. Of the corpus's pairs beyond 2.5 times (28 of 120) none
/// came out closer; within it, one in four did.
pub const REACH: f64 = 2.5;

/// The level below (`smaller`, a level of the chain) refined to `promises.budget` and fitted
/// where `fit` is given, measured carefully, where it keeps every promise of `promises`, is
/// closer than `hausdorff` (the larger budget's level's careful Hausdorff distance) and has a
/// mean distance of at most `mean`; `None` otherwise.
pub fn refined_below(
    smaller: &Level,
    promises: &Promises,
    input: &Input,
    measure: &Measure,
    fit: Option<&FitOptions>,
    (hausdorff, mean): (f64, f64),
) -> Option<Candidate> {
    let split = split_longest_edges(&smaller.mesh, promises.budget);
    let fitted = fit.and_then(|options| measure.fitted(&split, options));
    let r = &smaller.report;
    let was_fitted = fitted.is_some() || r.fitted_to_input;
    let crossings = fitted.as_ref().and_then(|f| f.crossings);
    let mut below = Candidate::new(Method::Below, fitted.map_or(split, |f| f.mesh));
    below.crossings = crossings;
    (below.resolution, below.iso, below.fill) = (r.resolution, r.iso, r.fill);
    below.fitted = was_fitted;
    if !promises.broken_cheap(&below).is_empty() {
        return None;
    }
    // Measured before the crossings are counted: most tries end here, and early.
    let distance = measure.distance(&below.mesh, Care::Careful, hausdorff)?;
    if !(distance.hausdorff < hausdorff && distance.mean <= mean) {
        return None;
    }
    below.careful = Some(distance);
    crosses_no_more(input, &mut below).then_some(below)
}
