//! One budget's choice among its candidates: the portfolio, never worse than its best member.
//!
//! 1. Every candidate is checked against the promises that cost nothing to check (count,
//!    manifold, orientation, closedness, handles; [`crate::promises`]).
//! 2. Those that keep them are measured quickly ([`Care::Quick`]), each rejected early once it
//!    is three times farther than the closest so far (by shape distance, module `measure`);
//!    the closest voxel candidates of up to two grids are fitted to the input ([`voxlod_fit`],
//!    beyond the paper; [`fitted_best`]) and compete beside their unfitted selves.
//!    The closest few that lost input parts get twins with the parts put back beside them
//!    (module `restore`), which compete too.
//! 3. The closest few ([`FINALISTS`]) have their crossing triangles counted and are measured
//!    carefully ([`Care::Careful`]); the input's own collapse, where it keeps every promise, is
//!    always among them (its plain form, and its closest checked form), and a finalist whose
//!    mean distance exceeds [`MEAN_SLACK`] times the collapse's (the plain one's, else the
//!    checked one's) is ruled out ([`Promise::MeanDistance`]). The finalist with the smallest
//!    careful Hausdorff distance is the level, the smallest shape distance among equals (where
//!    every finalist lost the same far speck); finalists within [`TIE`] of it are measured again
//!    with twice the samples ([`Care::Precise`]) to settle the choice. Where that level shows a
//!    worse outline than the input's plain collapse (silhouette difference), a candidate with a
//!    better one, at most 1.5 times as far and closer than the collapse, is the level instead
//!    (module `outline`, beyond the paper).
//! 4. Candidates that broke a promise are measured too, with the level's distance as the early
//!    rejection limit: those that would have been closer are reported with the promise that
//!    ruled them out and what it cost (the level's distance over theirs).
//! 5. Where no candidate keeps every promise, the one whose most severe broken promise is the
//!    least severe ([`Promise::severity`]) is kept, the nearest among equals, with a warning.
//! 6. A proxy's level whose voxel level kept its rounded edges through the collapse (open
//!    parts sampled as shells, or a large budget: `voxel::sharpened_before_collapse`) is given
//!    them back where that lowers its mean distance by more than it raises its shape distance
//!    (`sharpened_level`).
//!
//! Cost: per candidate, one quick measurement (often cut short); per finalist, a crossing count
//! and a careful measurement; up to two fits; up to two silhouettes (module `outline`); for a
//! proxy, one snap.
//!
//! Once the chain is chosen, a level that is a collapse of the input is fitted to the input
//! where that measures no farther (`fitted_level`, from module `chain`).

use rayon::prelude::*;
use voxlod_core::TriangleMesh;
use voxlod_fit::{snap_to_features, FeatureOptions, FitOptions};

use crate::candidate::{Candidate, Method};
use crate::input::Input;
use crate::measure::{Care, Distance, Measure};
use crate::outline::by_outline;
use crate::promises::{crosses_no_more, mean_reference, Promise, Promises, MEAN_SLACK};
use crate::report::{CandidateReport, Outline, RuledOut};
use crate::restore::{stood_in, with_parts_restored, StandIns, LOST};
use crate::voxel::{sharpened_before_collapse, FEATURE_REACH};
use voxlod_contouring::clean_mesh::without_zero_area;

/// Candidates measured carefully at most (the input's collapse comes in addition).
pub const FINALISTS: usize = 3;

/// The quick measurement rejects a candidate this many times farther than the closest so far.
const REJECT_FACTOR: f64 = 3.0;

/// A budget's choice.
pub struct Chosen {
    /// The level.
    pub level: Candidate,
    /// Every candidate, as measured and checked.
    pub candidates: Vec<CandidateReport>,
    /// Candidates closer than the level that a promise ruled out.
    pub ruled_out: Vec<RuledOut>,
    /// What the level had to give up, where no candidate kept every promise.
    pub warning: Option<String>,
    /// Where the level was chosen for its outline (module `outline`).
    pub outline: Option<Outline>,
    /// The closest candidate that keeps the cheap promises and is not known to cross, of the
    /// other lineage than the level (made of a voxel level where the level is a collapse of the
    /// input, or the reverse), for the chain to collapse beside the level.
    pub runner_up: Option<Candidate>,
}

/// The portfolio's choice for `promises` among `candidates` (module docs), with the
/// runner-up where `with_runner_up` (a chain whose next budget collapses it).
pub fn choose(
    mut candidates: Vec<Candidate>,
    promises: &Promises,
    input: &Input,
    measure: &Measure,
    fit: Option<&FitOptions>,
    stand_ins: &StandIns,
    with_runner_up: bool,
) -> Option<Chosen> {
    if candidates.is_empty() {
        return None;
    }
    let mut broken: Vec<Vec<Promise>> = candidates
        .iter()
        .map(|c| promises.broken_cheap(c))
        .collect();
    measure_quickly(&mut candidates, &broken, measure);
    for fitted in fitted_best(&candidates, &broken, input, measure, fit) {
        broken.push(promises.broken_cheap(&fitted));
        candidates.push(fitted);
    }
    // The small parts stood in for, where no collapse of the input keeps the promises or the
    // closest candidate lost parts.
    let stood = (!promises.remesh && needs_stand_ins(&candidates, &broken))
        .then(|| stood_in(input, stand_ins, promises.budget, 1))
        .flatten();
    let twins = restored_twins(&candidates, &broken, input, stand_ins, promises.budget);
    for twin in twins.into_iter().chain(stood) {
        let mut twin = twin;
        let b = promises.broken_cheap(&twin);
        if b.is_empty() {
            twin.quick = measure.distance(&twin.mesh, Care::Quick, f64::INFINITY);
        }
        broken.push(b);
        candidates.push(twin);
    }
    let mut winner = finalists(&mut candidates, &mut broken, input, measure);
    if winner.is_none() {
        // The closest broke a promise late (crossings, mean): those rejected early against
        // them may hold the level.
        let rejected =
            (candidates.iter_mut().zip(&broken)).filter(|(c, b)| b.is_empty() && c.quick.is_none());
        let mut any = false;
        for (c, _) in rejected {
            c.quick = measure.distance(&c.mesh, Care::Quick, f64::INFINITY);
            any = true;
        }
        if any {
            winner = finalists(&mut candidates, &mut broken, input, measure);
        }
    }
    let (index, warning) = match winner {
        Some(i) => (i, None),
        None => relaxed(&mut candidates, &broken, measure, promises.budget)?,
    };
    let (index, outline) = match warning {
        None => by_outline(
            &mut candidates,
            &mut broken,
            index,
            promises,
            input,
            measure,
            stand_ins,
        ),
        Some(_) => (index, None),
    };
    let chosen_h = careful(&mut candidates[index], measure).map_or(f64::INFINITY, |d| d.shape);
    let ruled_out = closer_but_broken(&mut candidates, &broken, index, chosen_h, measure);
    let reports = candidates
        .iter()
        .zip(&broken)
        .map(|(c, b)| CandidateReport::of(c, b))
        .collect();
    let runner = with_runner_up.then(|| {
        measure_other_lineage(&mut candidates, &broken, index, measure);
        runner_up(&candidates, &broken, index)
    });
    let runner = runner.flatten();
    let (level, runner_up) = take_two(candidates, index, runner);
    let level = match promises.remesh && !sharpened_before_collapse(promises.budget, level.fill) {
        true => sharpened_level(level, promises, input, measure),
        false => level,
    };
    Some(Chosen {
        level,
        candidates: reports,
        ruled_out,
        warning,
        outline,
        runner_up,
    })
}

/// The closest candidate (by quick shape distance) that keeps the cheap promises and is not
/// known to cross, of the other lineage than the level at `index`: made of a voxel level where
/// the level is a collapse of the input, or the reverse. The chain collapses it beside the
/// level for the next budget, so that a lineage that loses at one budget but collapses better
/// (a voxel level, smoother than the scan it stands for, where the scan's own collapse must
/// lock its folds) is still there at the smaller ones. Cost: O(candidates).
fn runner_up(candidates: &[Candidate], broken: &[Vec<Promise>], index: usize) -> Option<usize> {
    let lineage = of_a_voxel_level(&candidates[index]);
    (0..candidates.len())
        .filter(|&i| i != index && broken[i].is_empty() && candidates[i].quick.is_some())
        .filter(|&i| of_a_voxel_level(&candidates[i]) != lineage)
        .filter(|&i| candidates[i].crossings.unwrap_or(0) == 0)
        .min_by(|&a, &b| quick_h(&candidates[a]).total_cmp(&quick_h(&candidates[b])))
}

/// Where every candidate of the other lineage than the level at `index` (see [`runner_up`])
/// that keeps the cheap promises was rejected early, those measured quickly again, each
/// rejected early against the closest of them only, so that the chain has a runner-up.
/// Cost: a quick measurement per such candidate, often cut short.
fn measure_other_lineage(
    candidates: &mut [Candidate],
    broken: &[Vec<Promise>],
    index: usize,
    measure: &Measure,
) {
    let lineage = of_a_voxel_level(&candidates[index]);
    let other: Vec<usize> = (0..candidates.len())
        .filter(|&i| broken[i].is_empty() && of_a_voxel_level(&candidates[i]) != lineage)
        .collect();
    if other.iter().any(|&i| candidates[i].quick.is_some()) {
        return;
    }
    let mut best = f64::INFINITY;
    for i in other {
        let c = &mut candidates[i];
        c.quick = measure.distance(&c.mesh, Care::Quick, REJECT_FACTOR * best);
        best = best.min(quick_h(c));
    }
}

/// Whether `c` is made of a voxel level (a voxel or shell level, or one collapsed from one),
/// not of the input's own collapse: its lineage.
fn of_a_voxel_level(c: &Candidate) -> bool {
    c.resolution.is_some()
}

/// The candidates at `level` and `other` taken out of `candidates`.
fn take_two(
    mut candidates: Vec<Candidate>,
    level: usize,
    other: Option<usize>,
) -> (Candidate, Option<Candidate>) {
    match other {
        // The larger index first, so that the other does not move.
        Some(o) if o > level => {
            let runner = candidates.swap_remove(o);
            (candidates.swap_remove(level), Some(runner))
        }
        Some(o) => {
            let level = candidates.swap_remove(level);
            (level, Some(candidates.swap_remove(o)))
        }
        None => (candidates.swap_remove(level), None),
    }
}

/// Step 2's quick measurements made ahead, before the chain's choice: of `candidates` that keep
/// `promises`' cheap ones (the chain's cap on handles is not known yet, so the promises are the
/// budget's first). Budgets run this side by side; the choice then measures only what was
/// added since (the level above, a fit, twins) and what was rejected early here.
pub fn measure_ahead(candidates: &mut [Candidate], promises: &Promises, measure: &Measure) {
    let broken: Vec<Vec<Promise>> = candidates
        .iter()
        .map(|c| promises.broken_cheap(c))
        .collect();
    measure_quickly(candidates, &broken, measure);
}

/// Step 2's quick measurements of the candidates that keep the cheap promises.
fn measure_quickly(candidates: &mut [Candidate], broken: &[Vec<Promise>], measure: &Measure) {
    let mut best = f64::INFINITY;
    for (c, b) in candidates.iter_mut().zip(broken) {
        if b.is_empty() {
            if c.quick.is_none() {
                c.quick = measure.distance(&c.mesh, Care::Quick, REJECT_FACTOR * best);
            }
            best = best.min(quick_h(c));
        }
    }
}

/// Voxel candidates of this many grids at most are fitted to the input ([`fitted_best`]).
pub const FITTED_GRIDS: usize = 2;

/// A second grid's closest voxel candidate is fitted only where it is at most this many times
/// farther (quick shape distance) than the closest one ([`fitted_best`]).
pub const FIT_RIVAL: f64 = 1.25;

/// The closest voxel candidate keeping the cheap promises, and the closest of another grid
/// within [`FIT_RIVAL`] of it ([`FITTED_GRIDS`] in all), each fitted to the input where the fit
/// measures closer or nearly so (`fitted_one`). Why two: the fit moves levels unequally, and
/// the closest before it is not always the closest after (the generated linked rings at 300:
/// grid 30's level was the closer, grid 15's fitted the closer by a tenth). Cost: up to two
/// fits, each with its quick measurements.
fn fitted_best(
    candidates: &[Candidate],
    broken: &[Vec<Promise>],
    input: &Input,
    measure: &Measure,
    fit: Option<&FitOptions>,
) -> Vec<Candidate> {
    let Some(options) = fit else {
        return Vec::new();
    };
    (fit_sources(candidates, broken).into_iter())
        .flat_map(|(source, h)| fitted_one(source, h, input, measure, options))
        .collect()
}

/// The voxel candidates [`fitted_best`] fits, with their quick shape distances: of those that
/// keep the cheap promises, the closest, then the closest of each other grid while within
/// [`FIT_RIVAL`] of it, [`FITTED_GRIDS`] at most.
fn fit_sources<'c>(
    candidates: &'c [Candidate],
    broken: &[Vec<Promise>],
) -> Vec<(&'c Candidate, f64)> {
    let mut ranked: Vec<(&Candidate, f64)> = (candidates.iter().zip(broken))
        .filter(|(c, b)| b.is_empty() && c.method == Method::Voxel)
        .filter_map(|(c, _)| Some((c, c.quick?.shape)))
        .collect();
    ranked.sort_by(|a, b| a.1.total_cmp(&b.1));
    let mut sources: Vec<(&Candidate, f64)> = Vec::new();
    for (c, h) in ranked {
        let beyond = sources
            .first()
            .is_some_and(|&(_, best)| h > FIT_RIVAL * best);
        if sources.len() >= FITTED_GRIDS || beyond {
            break;
        }
        if sources.iter().all(|(s, _)| s.resolution != c.resolution) {
            sources.push((c, h));
        }
    }
    sources
}

/// A fitted level competes where its quick shape distance is at most this many times its
/// source's (`fitted_one`): the quick set's samples find a level's farthest point only to
/// within a few per cent, and the careful measurement of the finalists decides (the
/// sphereflake's fitted level of grid 20 at 300: 0.6 % farther quickly, 0.6 % closer
/// carefully).
pub const FIT_SLACK: f64 = 1.05;

/// `source` (measured `h` quickly) fitted to the input, where the fit measures closer or at
/// most [`FIT_SLACK`] times farther; and that fit with its vertices beside the input's sharp
/// features moved onto them (`voxlod_fit::snap_to_features`, within [`FEATURE_REACH`] voxels),
/// where that moved any and measures closer still.
fn fitted_one(
    source: &Candidate,
    h: f64,
    input: &Input,
    measure: &Measure,
    options: &FitOptions,
) -> Vec<Candidate> {
    let closest = measure.input_closest();
    let Some(done) = measure.fitted(&source.mesh, options) else {
        return Vec::new();
    };
    let like_source = |mesh| fitted_like(source, mesh);
    let mut fitted = like_source(done.mesh);
    fitted.crossings = done.crossings;
    fitted.quick = measure.distance(&fitted.mesh, Care::Quick, FIT_SLACK * h);
    let Some(fit_h) = fitted.quick.map(|d| d.shape) else {
        return Vec::new();
    };
    let voxel = input.voxel(source.resolution.unwrap_or(1).max(1));
    let features = FeatureOptions::within(FEATURE_REACH * voxel);
    let (snapped, moved) = snap_to_features(&fitted.mesh, input.measured(), closest, &features);
    let mut out = vec![fitted];
    if moved > 0 {
        let mut snapped = like_source(snapped);
        snapped.quick = measure.distance(&snapped.mesh, Care::Quick, fit_h);
        out.extend(snapped.quick.is_some().then_some(snapped));
    }
    out
}

/// `level`, a collapse of the input measured carefully, fitted to the input
/// ([`Measure::fitted`]) where the fit keeps every promise and measures no farther carefully,
/// by Hausdorff and by mean distance; `level` otherwise (beyond the paper). The collapse
/// places its vertices by the quadric error of the input's planes, not by distance; the fit
/// moves them towards the surface they stand for (the sphereflake's collapse to 1 000
/// triangles: mean distance 0.64 % of the diagonal fitted to 0.58 %, silhouette difference
/// 14.7 % to 13.2 %). Cost: one fit, a crossing count and a careful measurement.
pub(crate) fn fitted_level(
    level: Candidate,
    promises: &Promises,
    input: &Input,
    measure: &Measure,
    options: &FitOptions,
) -> Candidate {
    let (Some(before), false) = (level.careful, level.fitted) else {
        return level;
    };
    let Some(done) = measure.fitted(&level.mesh, options) else {
        return level;
    };
    let mut fitted = fitted_like(&level, done.mesh);
    fitted.crossings = done.crossings;
    if !promises.broken_cheap(&fitted).is_empty() || !crosses_no_more(input, &mut fitted) {
        return level;
    }
    match measure.distance(&fitted.mesh, Care::Careful, before.hausdorff) {
        Some(d) if d.hausdorff <= before.hausdorff && d.mean <= before.mean => {
            fitted.careful = Some(d);
            fitted
        }
        _ => level,
    }
}

/// `mesh`, moved from `source`'s vertices towards the input, as a candidate of `source`'s
/// method and lineage (resolution, isodensity, fill, parts dropped, cut vertices, stages),
/// fitted.
fn fitted_like(source: &Candidate, mesh: TriangleMesh) -> Candidate {
    let mut c = Candidate::new(source.method, mesh);
    (c.resolution, c.iso, c.fill) = (source.resolution, source.iso, source.fill);
    (c.parts_dropped, c.cut_vertices) = (source.parts_dropped, source.cut_vertices);
    (c.staged, c.fitted) = (source.staged, true);
    c
}

/// A proxy's snapped level may measure this many times farther (careful shape distance) than
/// the level it was snapped from (`sharpened_level`).
pub const SNAP_SLACK: f64 = 1.5;

/// For a proxy, `level` (of a voxel level's lineage, measured carefully) with its vertices
/// beside the input's sharp edges and corners moved onto them (`voxlod_fit::snap_to_features`,
/// within [`FEATURE_REACH`] voxels, the triangles left without area collapsed), where that
/// keeps every promise, lowers the careful mean distance by a larger factor than it raises the
/// careful shape distance (their product falls), and leaves the shape distance within
/// [`SNAP_SLACK`] times the level's; `level` otherwise. Beyond the choice by distance (step 3):
/// a proxy is judged by how it looks, where its many vertices put back on the edges weigh more
/// than the few the snap misplaces (the generated room's walls snapped square: mean distance
/// halved, shape distance up to 28 % farther, 2–3 dB PSNR more; a machine whose mean fell 5 %
/// as its shape distance rose 10 % looked worse). Cost: one snap, a crossing count and a
/// careful measurement.
fn sharpened_level(
    level: Candidate,
    promises: &Promises,
    input: &Input,
    measure: &Measure,
) -> Candidate {
    let (Some(resolution), Some(before)) = (level.resolution, level.careful) else {
        return level;
    };
    let voxel = input.voxel(resolution.max(1));
    let features = FeatureOptions::within(FEATURE_REACH * voxel);
    let closest = measure.input_closest();
    let (mesh, moved) = snap_to_features(&level.mesh, input.measured(), closest, &features);
    if moved == 0 {
        return level;
    }
    let mut snapped = fitted_like(&level, without_zero_area(mesh, input.cell()));
    if !promises.broken_cheap(&snapped).is_empty() || !crosses_no_more(input, &mut snapped) {
        return level;
    }
    let after = measure.distance(&snapped.mesh, Care::Careful, SNAP_SLACK * before.shape);
    match after {
        Some(d) if d.mean * d.shape < before.mean * before.shape => {
            snapped.careful = Some(d);
            snapped
        }
        _ => level,
    }
}

/// Whether the input's small parts should be stood in for (module `restore`): no collapse of
/// the input keeps the cheap promises, or the closest candidate that does lost parts (its
/// Hausdorff distance, which counts every part, well above its shape distance).
fn needs_stand_ins(candidates: &[Candidate], broken: &[Vec<Promise>]) -> bool {
    let keeping = || (candidates.iter().zip(broken)).filter(|(_, b)| b.is_empty());
    let collapse_keeps = keeping().any(|(c, _)| c.method == Method::Collapse);
    let closest = keeping()
        .filter_map(|(c, _)| c.quick)
        .min_by(|a, b| a.shape.total_cmp(&b.shape));
    !collapse_keeps || closest.is_some_and(|d| d.hausdorff > LOST * d.shape)
}

/// Twins of the closest candidates that lost input parts (their Hausdorff distance, which
/// counts every part, well above their shape distance), with the parts put back.
fn restored_twins(
    candidates: &[Candidate],
    broken: &[Vec<Promise>],
    input: &Input,
    stand_ins: &StandIns,
    budget: usize,
) -> Vec<Candidate> {
    let mut order: Vec<usize> = (0..candidates.len())
        .filter(|&i| broken[i].is_empty())
        .filter(|&i| {
            candidates[i]
                .quick
                .is_some_and(|d| d.hausdorff > LOST * d.shape)
        })
        .collect();
    order.sort_by(|&a, &b| quick_h(&candidates[a]).total_cmp(&quick_h(&candidates[b])));
    order
        .into_iter()
        .take(FINALISTS)
        .filter_map(|i| with_parts_restored(&candidates[i], input, stand_ins, budget))
        .collect()
}

/// Step 3: the winner among the finalists, by careful Hausdorff distance; `None` where no
/// candidate keeps every promise.
fn finalists(
    candidates: &mut [Candidate],
    broken: &mut [Vec<Promise>],
    input: &Input,
    measure: &Measure,
) -> Option<usize> {
    let mut order: Vec<usize> = (0..candidates.len())
        .filter(|&i| broken[i].is_empty() && candidates[i].quick.is_some())
        .collect();
    order.sort_by(|&a, &b| quick_h(&candidates[a]).total_cmp(&quick_h(&candidates[b])));
    // The input's collapses, always finalists: the plain one, and the closest checked one,
    // the mean distance's reference where the plain one is ruled out.
    let rank_of = |method: Method| order.iter().position(|&i| candidates[i].method == method);
    let collapses = [rank_of(Method::Collapse), rank_of(Method::CollapseKept)];
    let is_collapse = |rank: usize| collapses.contains(&Some(rank));
    // The likely finalists' checks, side by side; the loop below repeats them in order, from
    // what they found, and checks further candidates where some were ruled out.
    let likely: Vec<usize> = (order.iter().enumerate())
        .filter(|&(rank, _)| rank < FINALISTS || is_collapse(rank))
        .map(|(_, &i)| i)
        .collect();
    (candidates.par_iter_mut().enumerate())
        .filter(|(i, _)| likely.contains(i))
        .for_each(|(_, c)| {
            if crosses_no_more(input, c) {
                careful(c, measure);
            }
        });
    let mut chosen: Vec<usize> = Vec::new();
    for (rank, &i) in order.iter().enumerate() {
        if chosen.len() >= FINALISTS && !is_collapse(rank) {
            continue;
        }
        if !crosses_no_more(input, &mut candidates[i]) {
            broken[i].push(Promise::NoCrossings);
            continue;
        }
        if careful(&mut candidates[i], measure).is_some() {
            chosen.push(i);
        }
    }
    if let Some(mean) = mean_reference(candidates, &chosen) {
        for &i in &chosen {
            if careful_d(&candidates[i]).mean > MEAN_SLACK * mean {
                broken[i].push(Promise::MeanDistance);
            }
        }
    }
    let passing: Vec<usize> = chosen
        .into_iter()
        .filter(|&i| broken[i].is_empty())
        .collect();
    let best = closest_of(&passing, |i| careful_d(&candidates[i]))?;
    // A near tie between the closest two is settled with the precise set.
    let tied: Vec<usize> = (passing.iter().copied())
        .filter(|&i| {
            careful_d(&candidates[i]).hausdorff
                <= (1.0 + TIE) * careful_d(&candidates[best]).hausdorff
        })
        .collect();
    if tied.len() < 2 {
        return Some(best);
    }
    measure.prepare_precise();
    let precise: Vec<Option<Distance>> = (tied.par_iter())
        .map(|&i| measure.distance(&candidates[i].mesh, Care::Precise, f64::INFINITY))
        .collect();
    let by_precise = |i: usize| {
        let k = tied.iter().position(|&t| t == i).unwrap_or(0);
        precise[k].unwrap_or(careful_d(&candidates[i]))
    };
    closest_of(&tied, by_precise)
}

/// Careful Hausdorff distances within this fraction of the closest are a near tie.
pub const TIE: f64 = 0.05;

/// The index among `indices` whose distance (`distance(index)`) is smallest: by Hausdorff
/// distance, and where two are within 1 % of each other, by shape distance (every candidate
/// lost the same far speck), then by mean.
fn closest_of(indices: &[usize], distance: impl Fn(usize) -> Distance) -> Option<usize> {
    indices.iter().copied().min_by(|&a, &b| {
        let (da, db) = (distance(a), distance(b));
        let near = |x: f64, y: f64| (x - y).abs() <= 0.01 * x.max(y);
        if !near(da.hausdorff, db.hausdorff) {
            da.hausdorff.total_cmp(&db.hausdorff)
        } else if !near(da.shape, db.shape) {
            da.shape.total_cmp(&db.shape)
        } else {
            da.mean.total_cmp(&db.mean)
        }
    })
}

/// Step 5: the candidate giving up the least, with the warning that says what.
/// Among those that break the budget too, one with fewer triangles than the budget beats one
/// with more (the closest of them), and of those with more, the fewest triangles win: a level
/// sixty times its budget is no level of it, however close it measures.
fn relaxed(
    candidates: &mut [Candidate],
    broken: &[Vec<Promise>],
    measure: &Measure,
    budget: usize,
) -> Option<(usize, Option<String>)> {
    let worst = |b: &[Promise]| b.iter().map(|p| p.severity()).max().unwrap_or(0);
    for c in candidates.iter_mut().filter(|c| c.quick.is_none()) {
        c.quick = measure.distance(&c.mesh, Care::Quick, f64::INFINITY);
    }
    let rank = |i: usize| {
        let c = &candidates[i];
        let over = broken[i].contains(&Promise::Budget) && c.triangles() > budget;
        let then = if over {
            c.triangles() as f64
        } else {
            quick_h(c)
        };
        (worst(&broken[i]), broken[i].len(), over, then)
    };
    let index = (0..candidates.len()).min_by(|&a, &b| {
        let (ra, rb) = (rank(a), rank(b));
        (ra.0, ra.1, ra.2)
            .cmp(&(rb.0, rb.1, rb.2))
            .then(ra.3.total_cmp(&rb.3))
    })?;
    let names: Vec<&str> = broken[index].iter().map(|p| p.name()).collect();
    let warning = format!(
        "no candidate kept every promise; the level ({}) breaks: {}",
        candidates[index].label(),
        names.join(", ")
    );
    Some((index, Some(warning)))
}

/// Step 4: candidates that broke a promise but measure closer than the level's `chosen_h`.
fn closer_but_broken(
    candidates: &mut [Candidate],
    broken: &[Vec<Promise>],
    chosen: usize,
    chosen_h: f64,
    measure: &Measure,
) -> Vec<RuledOut> {
    let mut out = Vec::new();
    for (i, c) in candidates.iter_mut().enumerate() {
        if i == chosen || broken[i].is_empty() || broken[i].contains(&Promise::Budget) {
            continue;
        }
        if c.quick.is_none() {
            c.quick = measure.distance(&c.mesh, Care::Quick, chosen_h);
        }
        let Some(d) = c.quick else { continue };
        if d.shape < chosen_h {
            out.push(RuledOut {
                candidate: c.label(),
                broken: broken[i].clone(),
                shape: d.shape,
                cost: if d.shape > 0.0 {
                    chosen_h / d.shape
                } else {
                    f64::INFINITY
                },
            });
        }
    }
    out
}

fn careful(candidate: &mut Candidate, measure: &Measure) -> Option<Distance> {
    if candidate.careful.is_none() {
        candidate.careful = measure.distance(&candidate.mesh, Care::Careful, f64::INFINITY);
    }
    candidate.careful
}

/// The quick shape distance: what ranks candidates (module docs).
fn quick_h(c: &Candidate) -> f64 {
    c.quick.map_or(f64::INFINITY, |d| d.shape)
}

fn careful_d(c: &Candidate) -> Distance {
    c.careful.unwrap_or(Distance {
        hausdorff: f64::INFINITY,
        shape: f64::INFINITY,
        mean: f64::INFINITY,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use voxlod_core::glam::DVec3;
    use voxlod_testkit::shapes::icosphere;

    /// A candidate of `method` (of a voxel level where `resolution` is given) measured quickly
    /// at `shape`.
    fn measured(method: Method, resolution: Option<usize>, shape: f64) -> Candidate {
        let mut c = Candidate::new(method, icosphere(1));
        c.resolution = resolution;
        c.quick = Some(Distance {
            hausdorff: shape,
            shape,
            mean: shape / 4.0,
        });
        c
    }

    #[test]
    fn fit_sources_are_the_closest_voxel_level_and_the_closest_of_another_grid_near_it() {
        let voxel = |resolution, shape| measured(Method::Voxel, Some(resolution), shape);
        let sources = |candidates: &[Candidate]| -> Vec<(Option<usize>, f64)> {
            let broken = vec![Vec::new(); candidates.len()];
            (fit_sources(candidates, &broken).iter())
                .map(|(c, h)| (c.resolution, *h))
                .collect()
        };
        // Grid 20's second level is passed over for grid 14's; the collapse is not a voxel
        // level, and grid 10 comes third.
        let near = [
            voxel(10, 0.20),
            voxel(20, 0.11),
            measured(Method::Collapse, None, 0.05),
            voxel(14, 0.12),
            voxel(20, 0.10),
        ];
        assert_eq!(sources(&near), [(Some(20), 0.10), (Some(14), 0.12)]);
        // Grid 14's level beyond 1.25 times the closest: the closest alone.
        let far = [voxel(20, 0.10), voxel(14, 0.13)];
        assert_eq!(sources(&far), [(Some(20), 0.10)]);
    }

    #[test]
    fn a_level_off_its_budget_has_fewer_triangles_rather_than_many_more() {
        let input = Input::prepare(&icosphere(2)).unwrap();
        let measure = Measure::new(&input, 500, 1_000).unwrap();
        // Budget 40, nothing within 10 %: far above and close, under and farther.
        let mut candidates = vec![
            measured(Method::Voxel, Some(40), 0.01),
            measured(Method::Voxel, Some(20), 0.5),
            measured(Method::Voxel, Some(10), 0.3),
            measured(Method::Voxel, Some(80), 0.02),
        ];
        let counts = [2_000, 20, 10, 1_000];
        for (c, n) in candidates.iter_mut().zip(counts) {
            c.mesh = icosphere(4);
            c.mesh.triangles.truncate(n);
        }
        let broken = vec![vec![Promise::Budget]; 4];
        let (index, warning) = relaxed(&mut candidates, &broken, &measure, 40).unwrap();
        assert_eq!(index, 2);
        assert!(warning.unwrap().contains("budget"));
        // With none under the budget, the fewest triangles above it.
        let (index, _) = relaxed(&mut candidates[..1], &broken[..1], &measure, 40).unwrap();
        assert_eq!(index, 0);
        candidates.swap(1, 3);
        let (index, _) = relaxed(&mut candidates[..2], &broken[..2], &measure, 40).unwrap();
        assert_eq!(index, 1);
    }

    #[test]
    fn the_runner_up_is_the_closest_of_the_other_lineage_and_the_mean_reference_a_collapse() {
        let mut candidates = vec![
            measured(Method::CollapseKept, None, 0.1),
            measured(Method::Collapse, None, 0.2),
            measured(Method::Voxel, Some(40), 0.9),
            measured(Method::Voxel, Some(40), 0.5),
            measured(Method::Voxel, Some(80), 0.3),
            measured(Method::Above, Some(80), 0.4),
        ];
        let mut broken = vec![Vec::new(); candidates.len()];
        // The closest voxel level crosses itself, the next breaks a cheap promise.
        candidates[4].crossings = Some(2);
        broken[5].push(Promise::Closed);
        assert_eq!(runner_up(&candidates, &broken, 0), Some(3));
        // Where the level is a voxel level, the runner-up is the closest collapse.
        assert_eq!(runner_up(&candidates, &broken, 3), Some(0));
        // None of the other lineage left: no runner-up.
        assert_eq!(runner_up(&candidates[..2], &broken[..2], 0), None);

        // The mean's reference: the plain collapse's, else the checked one's, else none.
        for c in candidates.iter_mut() {
            c.careful = c.quick.map(|d| Distance {
                mean: 2.0 * d.mean,
                ..d
            });
        }
        assert_eq!(mean_reference(&candidates, &[3, 1, 0]), Some(0.1));
        assert_eq!(mean_reference(&candidates, &[3, 0]), Some(0.05));
        assert_eq!(mean_reference(&candidates, &[3, 4]), None);

        let (level, runner) = take_two(candidates, 0, Some(3));
        assert_eq!(level.method, Method::CollapseKept);
        assert_eq!(runner.map(|r| quick_h(&r)), Some(0.5));
    }

    #[test]
    fn a_collapse_level_is_fitted_where_that_measures_no_farther() {
        // A fine sphere collapsed to 200 triangles: the quadric error puts the vertices on
        // the input's planes, not at the least distance from its surface.
        let sphere = icosphere(4);
        let input = Input::prepare(&sphere).unwrap();
        let measure = Measure::new(&input, 1_000, 10_000).unwrap();
        let promises = Promises {
            budget: 200,
            closed: true,
            max_handles: Some(0),
            remesh: false,
        };
        let collapsed = voxlod_quadric::simplify_unchecked(&sphere, 200, false).unwrap();
        let mut level = Candidate::new(Method::Collapse, collapsed.0);
        let before = careful(&mut level, &measure).unwrap();
        let fitted = fitted_level(level, &promises, &input, &measure, &FitOptions::quick());
        assert!(fitted.fitted, "the fit was not kept");
        assert_eq!(fitted.method, Method::Collapse);
        let after = fitted.careful.unwrap();
        assert!(after.hausdorff <= before.hausdorff, "{before:?} {after:?}");
        assert!(after.mean < 0.9 * before.mean, "{before:?} {after:?}");
        // Fitted already: left as it is.
        let again = fitted_level(fitted, &promises, &input, &measure, &FitOptions::quick());
        assert_eq!(again.careful, Some(after));
    }

    /// The unit cube's surface as a filter leaves it at resolution 10: its faces split 4³
    /// times, moved onto the rounded cube `Σ |x_i − ½|⁸ = ½⁸`.
    fn rounded_cube() -> TriangleMesh {
        let cube = voxlod_testkit::shapes::unit_cube();
        let points = cube.positions.iter().map(|p| p.as_dvec3()).collect();
        let centre = DVec3::splat(0.5);
        let round = |p: DVec3| {
            let d = p - centre;
            let norm = d.abs().to_array().iter().map(|x| x.powi(8)).sum::<f64>();
            centre + d * 0.5 / norm.powf(1.0 / 8.0)
        };
        let mut mesh = voxlod_testkit::shapes::subdivided(points, cube.triangles, 3, round);
        mesh.positions
            .iter_mut()
            .for_each(|p| *p = round(p.as_dvec3()).as_vec3());
        mesh
    }

    /// A proxy's promises for `budget`: closed, genus 0.
    fn proxy_promises(budget: usize) -> Promises {
        Promises {
            budget,
            closed: true,
            max_handles: Some(0),
            remesh: true,
        }
    }

    #[test]
    fn a_proxy_level_gets_its_edges_back_where_that_lowers_mean_times_shape() {
        let input = Input::prepare(&voxlod_testkit::shapes::unit_cube()).unwrap();
        let measure = Measure::new(&input, 2_000, 10_000).unwrap();
        let promises = proxy_promises(768);
        let mut level = Candidate::new(Method::Voxel, rounded_cube());
        level.resolution = Some(10);
        let before = careful(&mut level, &measure).unwrap();
        let snapped = sharpened_level(level, &promises, &input, &measure);
        assert!(snapped.fitted, "the snap was not kept");
        let after = snapped.careful.unwrap();
        let product = |d: Distance| d.mean * d.shape;
        assert!(
            product(after) < 0.5 * product(before),
            "{before:?} {after:?}"
        );
        assert!(after.mean < 0.5 * before.mean, "{before:?} {after:?}");
    }

    #[test]
    fn a_proxy_level_with_nothing_to_snap_is_kept_as_it_is() {
        // The level is the input itself, a sphere: no sharp feature, no vertex moves.
        let input = Input::prepare(&icosphere(2)).unwrap();
        let measure = Measure::new(&input, 500, 1_000).unwrap();
        let promises = proxy_promises(320);
        let mut level = Candidate::new(Method::Voxel, icosphere(2));
        level.resolution = Some(10);
        careful(&mut level, &measure);
        let kept = sharpened_level(level, &promises, &input, &measure);
        assert!(!kept.fitted);
        assert_eq!(kept.mesh.positions, icosphere(2).positions);
    }
}
