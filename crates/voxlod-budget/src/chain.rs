//! The run of budgets (crate docs): candidates for every budget made at once, on all cores,
//! then the levels chosen from the largest budget down, each with the level above as one more
//! candidate and its handles as the next level's cap.

use std::time::Instant;

use rayon::prelude::*;
use voxlod_core::TriangleMesh;

use crate::below;
use crate::candidate::{Candidate, Fill, Method};
use crate::collapse;
use crate::collapse_fits::{apply_fits, fitted_ahead, Ahead};
use crate::grids::{with_solids, Grids};
use crate::input::Input;
use crate::measure::{Care, Measure};
use crate::plate::Plate;
use crate::promises::{crosses_no_more, within_budget, Promise, Promises};
use crate::report::{BudgetLevel, CandidateReport, InputReport, Outline};
use crate::restore::StandIns;
use crate::select::{choose, measure_ahead, Chosen};
use crate::shell::shell_candidates;
use crate::voxel::{planned_grids, voxel_candidates, COARSEST, FINEST, HEADROOM};
use crate::{BudgetError, Budgeted, Level, PortfolioOptions, Timings};
use voxlod_contouring::triangle_estimate::resolution_for_triangles;

/// The input's collapse is kept without a voxel search where it is measured closer than this
/// fraction of the voxel that the budget affords: a voxel level places its surface no closer
/// than about that, before its own collapse adds to it.
pub const VOXEL_WORTH: f64 = 0.5;

/// Budgets up to this many triangles search with voxels unless the input's collapse is within
/// [`VOXEL_WORTH_SMALL`] of the voxel: on their coarse grids the search is cheap, and the voxel
/// level fitted to the input (crate `voxlod-fit`) places its vertices on the surface, often
/// closer than half a voxel (a bumpy cube at 312 triangles: its collapse at 1.87 % of the
/// diagonal, under half the voxel, its fitted voxel level at 1.05 %).
pub const SMALL_BUDGET: usize = 1_000;

/// [`VOXEL_WORTH`] for budgets up to [`SMALL_BUDGET`].
pub const VOXEL_WORTH_SMALL: f64 = 0.25;

/// Budgets whose voxel level would have more triangles than this ([`HEADROOM`] times the
/// budget) are not searched with voxels where the input's collapse only came out cut open:
/// the collapse, at the budget, is the level, with a warning.
pub const LARGE_VOXEL: usize = 150_000;

/// Called with (steps done, steps in all) after each step; `false` stops the run.
pub type ProgressFn<'f> = dyn Fn(usize, usize) -> bool + Sync + 'f;

/// [`crate::levels`] with a progress callback.
pub fn levels_with(
    mesh: &TriangleMesh,
    options: &PortfolioOptions,
    progress: &ProgressFn,
) -> Result<Budgeted, BudgetError> {
    let start = Instant::now();
    let mut timings = Timings::default();
    let mut phase = Instant::now();
    let mut lap = |slot: &mut f64| {
        *slot = phase.elapsed().as_secs_f64();
        phase = Instant::now();
    };
    options.check()?;
    let mut input = Input::prepare(mesh)?;
    if options.drop_hidden {
        input = crate::visible::without_hidden(input)?;
    }
    let given = input.changed_by_preparation().then_some(mesh);
    lap(&mut timings.prepare);
    let mut budgets = options.triangles.clone();
    budgets.sort_unstable_by(|a, b| b.cmp(a));
    budgets.dedup();
    let total = 2 * budgets.len() + 1;
    let step = |done: usize| {
        if progress(done, total) {
            Ok(())
        } else {
            Err(BudgetError::Cancelled)
        }
    };
    step(0)?;
    // The input's side of the measure beside its collapses, which need none of it.
    let (measure, made) = rayon::join(
        || Measure::new(&input, options.quick_samples, options.careful_samples),
        || all_collapses(&input, given, options, &budgets),
    );
    let measure = measure?;
    let searched: Vec<Searched> = (budgets.par_iter().zip(made))
        .map(|(&b, made)| search(&input, &measure, options, b, made))
        .collect::<Result<_, _>>()?;
    lap(&mut timings.collapses);
    step(budgets.len())?;
    let mut searched = searched;
    if options.monotone {
        share_near_searches(&mut searched);
    }
    match searched.iter().any(|s| s.needs_voxels) {
        true => add_all_voxels(&mut searched, &input, &measure, options)?,
        false => add_kept(&mut searched, &input, options),
    }
    searched.par_iter_mut().for_each(|s| {
        let promises = first_promises(&input, options, s.budget);
        measure_ahead(&mut s.candidates, &promises, &measure);
    });
    lap(&mut timings.voxels);
    step(2 * budgets.len())?;
    let stand_ins = StandIns::default();
    let chain = choose_down(searched, &input, &measure, options, &stand_ins)?;
    let (mut chosen, mut warnings) = refined_and_fitted(chain, &input, &measure, options);
    if options.remesh {
        warnings.extend(crossed_levels(&mut chosen));
    }
    lap(&mut timings.choice);
    step(total)?;
    let levels = options
        .triangles
        .iter()
        .map(|b| chosen.iter().find(|l| l.report.budget == *b).cloned())
        .collect::<Option<Vec<Level>>>()
        .ok_or_else(|| BudgetError::NoLevel {
            budget: 0,
            why: "a budget was lost between search and choice".into(),
        })?;
    if let Some(hidden) = input
        .seen
        .as_ref()
        .map(|s| s.hidden_parts)
        .filter(|&h| h > 0)
    {
        let views = crate::visible::VIEWS;
        warnings.push(format!(
            "{hidden} parts seen from none of {views} views around the input were dropped"
        ));
    }
    warnings.extend(voxlod_core::rounding::rounding_warning(mesh));
    if input.preparation.turned_right_side_out {
        warnings
            .push("the input was inside out (negative volume): its levels face outwards".into());
    }
    Ok(Budgeted {
        levels,
        input: InputReport::of(&input),
        warnings,
        timings,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// Each of `levels` that crosses itself, in words, its report's count of crossing pairs made
/// exact. For new surfaces (a proxy's levels): a scene whose parts pass through each other
/// licenses as many crossings in its levels as it has, but a remeshed level's crossings are
/// the collapse's own, not the scene's. Cost: one crossing search per level.
fn crossed_levels(levels: &mut [Level]) -> Vec<String> {
    let mut warnings = Vec::new();
    for level in levels {
        let pairs = voxlod_core::crossing_pairs(&level.mesh).len();
        level.report.self_intersections = pairs;
        if pairs > 0 {
            warnings.push(format!(
                "{} triangles: the level crosses itself in {pairs} triangle pairs",
                level.report.budget
            ));
        }
    }
    warnings
}

/// One budget's candidates before the choice.
struct Searched {
    budget: usize,
    candidates: Vec<Candidate>,
    needs_voxels: bool,
    /// The plain collapse broke a promise.
    plain_broke: bool,
    /// The plain collapse broke no promise but the crossings: its topology held.
    plain_crossed: bool,
    /// ... and it measured within [`VOXEL_WORTH`] of the voxel (at small budgets
    /// [`VOXEL_WORTH_SMALL`]): its checked or uncrossed form, where one keeps every promise,
    /// makes the voxel search needless ([`add_all_voxels`]).
    crossed_close: bool,
    /// A plate candidate (module `plate`) keeps every promise within the distance that makes
    /// a voxel search pointless: no checked collapse is made either (on a plate it stalls).
    plate_stands_in: bool,
    seconds: f64,
    notes: Vec<String>,
}

/// The input's own collapses for one budget, made before anything is measured (and the plate
/// candidates, where the input is a plate).
struct Collapses {
    /// meshoptimizer's plain collapse ([`collapse::plain`]), its crossing pairs counted where
    /// it keeps the cheap promises.
    plain: Option<Candidate>,
    /// The collapse of the input as given, the sloppy collapse and the plate candidates.
    others: Vec<Candidate>,
    /// The time they took.
    seconds: f64,
}

/// Every budget's [`Collapses`] (none for a proxy) on all cores, and the input's crossing pairs
/// where a plain collapse crosses: counted once on all cores here, not by the first search to
/// ask while the others wait (a waiting rayon thread could be handed a task that asks again).
/// An input of several parts, whose collapses often cross where parts touch, has them counted
/// beside the collapses.
fn all_collapses(
    input: &Input,
    given: Option<&TriangleMesh>,
    options: &PortfolioOptions,
    budgets: &[usize],
) -> Vec<Collapses> {
    let ahead = input.parts.len() > 1 && !options.remesh;
    // A plate's mid-surface, found once (O(F) where the input is no plate: module `plate`).
    let plate = match options.remesh {
        true => None,
        false => Plate::detect_parts(&input.mesh, &input.parts),
    };
    let (made, ()) = rayon::join(
        || {
            (budgets.par_iter())
                .map(|&b| collapses(input, given, options, b, plate.as_ref()))
                .collect::<Vec<_>>()
        },
        || {
            if ahead {
                input.crossings();
            }
        },
    );
    let crossed = |c: &Collapses| c.plain.as_ref().is_some_and(|p| p.crossings > Some(0));
    if made.iter().any(crossed) {
        input.crossings();
    }
    made
}

/// The input's own collapses for `budget` (module docs of `collapse`), and the plate
/// candidates where the input is a plate (module `plate`).
fn collapses(
    input: &Input,
    given: Option<&TriangleMesh>,
    options: &PortfolioOptions,
    budget: usize,
    plate: Option<&Plate>,
) -> Collapses {
    let start = Instant::now();
    if options.remesh {
        let (plain, others) = (None, Vec::new());
        return Collapses {
            plain,
            others,
            seconds: 0.0,
        };
    }
    let plain = collapse::plain(input, budget, options.max_error).map(|mut plain| {
        let promises = first_promises(input, options, budget);
        if promises.broken_cheap(&plain).is_empty() {
            Promises::crossings(&mut plain);
        }
        plain
    });
    let mut others: Vec<Candidate> = (given.into_iter())
        .flat_map(|g| collapse::as_given(g, budget, input))
        .collect();
    others.extend(collapse::sloppy(input, budget));
    others.extend(plate.map_or_else(Vec::new, |p| crate::plate::candidates(p, input, budget)));
    let seconds = start.elapsed().as_secs_f64();
    Collapses {
        plain,
        others,
        seconds,
    }
}

/// Whether a voxel search can do better than the input's collapses for `budget` (the plain
/// collapse breaks a promise, misses the budget, or is farther than [`VOXEL_WORTH`] voxels),
/// where no plate candidate (module `plate`) keeps every promise within that distance either.
fn search(
    input: &Input,
    measure: &Measure,
    options: &PortfolioOptions,
    budget: usize,
    made: Collapses,
) -> Result<Searched, BudgetError> {
    let start = Instant::now();
    let promises = first_promises(input, options, budget);
    let mut candidates = Vec::new();
    let (mut close_enough, mut plain_broke, mut large_and_opened) = (false, false, false);
    let (mut plain_crossed, mut crossed_close) = (false, false);
    if let Some(mut plain) = made.plain {
        let broken = promises.broken_cheap(&plain);
        let keeps = broken.is_empty() && crosses_no_more(input, &mut plain);
        plain_crossed = broken.is_empty() && !keeps;
        // A large budget whose collapse only came out cut open (or with more handles): its
        // voxel level would cost seconds and rarely keep the promises at this size either.
        let only_opened = broken
            .iter()
            .all(|p| matches!(p, Promise::Closed | Promise::Genus));
        large_and_opened = !keeps && only_opened && HEADROOM * budget as f64 > LARGE_VOXEL as f64;
        if keeps {
            close_enough = is_close_enough(input, measure, &mut plain, budget);
        }
        if plain_crossed {
            crossed_close = is_close_enough(input, measure, &mut plain, budget);
        }
        plain_broke = !keeps;
        candidates.push(plain);
    }
    let mut others = made.others;
    // A plate candidate that keeps every promise stands in for the plain collapse there.
    let mut plate_stands_in = false;
    for plate in (others.iter_mut()).filter(|c| c.method == Method::Plate) {
        if !close_enough && promises.broken_cheap(plate).is_empty() && crosses_no_more(input, plate)
        {
            close_enough = is_close_enough(input, measure, plate, budget);
            plate_stands_in = close_enough;
        }
    }
    candidates.extend(others);
    Ok(Searched {
        budget,
        candidates,
        needs_voxels: options.remesh || (!close_enough && !large_and_opened),
        plain_broke,
        plain_crossed,
        crossed_close,
        plate_stands_in,
        seconds: made.seconds + start.elapsed().as_secs_f64(),
        notes: Vec::new(),
    })
}

/// A budget at least this fraction of the next larger one shares its voxel search
/// ([`share_near_searches`]).
pub const NEAR_BUDGET: f64 = 0.95;

/// A budget within [`NEAR_BUDGET`] of the next larger one (sorted largest first), which
/// searches with voxels, gets no voxel search of its own: the larger budget's grids and
/// isodensities are its, and the level chosen among them, collapsed by at most a twentieth,
/// comes to it as the level above (the chain's candidate), beside the input's collapses
/// (1/128 of a 38 000-triangle input and 300: a quarter of a second for nearly the same level).
fn share_near_searches(searched: &mut [Searched]) {
    for k in 1..searched.len() {
        let (larger, this) = (&searched[k - 1], &searched[k]);
        if larger.needs_voxels && this.budget as f64 >= NEAR_BUDGET * larger.budget as f64 {
            searched[k].needs_voxels = false;
        }
    }
}

/// Whether `c`, measured quickly here, is within [`VOXEL_WORTH`] (at small budgets
/// [`VOXEL_WORTH_SMALL`]) of the voxel `budget` affords: no voxel level would come closer, so
/// none is searched.
fn is_close_enough(input: &Input, measure: &Measure, c: &mut Candidate, budget: usize) -> bool {
    c.quick = measure.distance(&c.mesh, Care::Quick, f64::INFINITY);
    let voxel = voxel_at(input, budget);
    let worth = match budget <= SMALL_BUDGET {
        true => VOXEL_WORTH_SMALL,
        false => VOXEL_WORTH,
    };
    c.quick.is_some_and(|d| d.shape <= worth * voxel)
}

/// A checked collapse ([`collapse::kept`]) for every budget whose plain collapse broke a
/// promise, made from the nearest larger budget's plain collapse that kept them all, or the
/// checked collapse made for it (a fraction of the cost of collapsing the input), and from the
/// input (within [`collapse::KEPT_AT_MOST`] triangles, or at any size where the plain one only
/// crossed and nothing larger was there to start from; an input pinched at a few vertices or
/// edges cut there first, its surface unchanged) where there is none or a plain one stalled
/// it; while they reach their budgets. The voxel searches go on beside them: a voxel level
/// that loses to a checked collapse at a large budget often collapses closer at the small ones
/// (the chain's runner-up, [`crate::select::Chosen::runner_up`]). Where the plain collapse only
/// crossed and no larger budget's collapse was there to start from, the plain collapse made in
/// two steps as well ([`collapse::in_two_steps`]). None where a plate candidate stands in
/// for the plain collapse ([`Searched::plate_stands_in`]).
fn add_kept(searched: &mut [Searched], input: &Input, options: &PortfolioOptions) {
    // The input as the checked collapse takes it, cut only where it is needed.
    let cut = std::cell::OnceCell::new();
    let whole = || match input.topology.is_manifold() {
        true => &input.mesh,
        false => cut.get_or_init(|| cut_into_manifold(&input.mesh)),
    };
    // The mesh to collapse next, and whether it is a checked collapse itself.
    let mut from: Option<(TriangleMesh, bool)> = None;
    for s in searched.iter_mut() {
        if !s.plain_broke {
            let plain = s.candidates.iter().find(|c| c.method == Method::Collapse);
            from = plain.map(|c| (c.mesh.clone(), false)).or(from);
            continue;
        }
        if s.plate_stands_in {
            continue;
        }
        let start = Instant::now();
        let reached = |c: &Candidate| within_budget(c.triangles(), s.budget);
        let mut made: Vec<Candidate> = (from.as_ref())
            .and_then(|(mesh, _)| collapse::kept(mesh, s.budget, input, options.max_error))
            .into_iter()
            .collect();
        // From the input where there is nothing to start from, or the plain collapse it started
        // from stalled it (a checked collapse from the input would only repeat a checked one).
        let allowed = input.mesh.triangle_count() <= collapse::KEPT_AT_MOST
            || (s.plain_crossed && from.is_none());
        let repeats = from.as_ref().is_some_and(|(_, checked)| *checked);
        if allowed && !repeats && !made.iter().any(reached) {
            made.extend(collapse::kept(whole(), s.budget, input, options.max_error));
        }
        // The plain collapse only crossed: its crossings flipped apart.
        if s.plain_crossed {
            let plain = s.candidates.iter().find(|c| c.method == Method::Collapse);
            let uncrossed = plain.and_then(|p| collapse::uncrossed(input, p));
            s.candidates.extend(uncrossed);
        }
        // Nothing larger to start from and the plain collapse only crossed: the input's
        // collapse in two steps too, beside the checked one (not a start for the next budgets:
        // its second step is not checked).
        if from.is_none() && s.plain_crossed {
            let promises = first_promises(input, options, 2 * s.budget);
            let keeps = |c: &mut Candidate| {
                promises.broken_cheap(c).is_empty() && crosses_no_more(input, c)
            };
            s.candidates.extend(collapse::in_two_steps(
                input,
                s.budget,
                options.max_error,
                keeps,
            ));
        }
        from = made
            .iter()
            .find(|c| reached(c))
            .map(|c| (c.mesh.clone(), true));
        s.candidates.extend(made);
        s.seconds += start.elapsed().as_secs_f64();
        if from.is_none() {
            return;
        }
    }
}

/// `mesh` cut into a manifold where it is not, as every candidate is ([`Candidate::new`]:
/// vertices split where fans meet, the copies moved a hair apart into their own fans so that
/// the sheets no longer touch). Cost: O(F log F).
fn cut_into_manifold(mesh: &TriangleMesh) -> TriangleMesh {
    Candidate::new(Method::Collapse, mesh.clone()).mesh
}

/// The checked collapse ([`add_kept`]) beside the voxel and shell candidates of every budget
/// that needs them: the solids built, the grids the budgets ask for first made at once
/// (module `grids`), then each budget's search, all on the cores. A budget whose plain
/// collapse only crossed itself and measured close enough ([`Searched::crossed_close`]) is
/// searched only where none of its checked, uncrossed or two-step collapses keeps every
/// promise (its grids made then, not planned with the others): they move little from the
/// plain one (on the 93 inputs of the budget bench, no level changed, and the chains of a
/// tower with holes, a falcon statue, a hammer and the generated scan with holes took
/// 22–36 % less time).
fn add_all_voxels(
    searched: &mut [Searched],
    input: &Input,
    measure: &Measure,
    options: &PortfolioOptions,
) -> Result<(), BudgetError> {
    with_solids(input, options.remesh, |solids| {
        let plan: Vec<(usize, usize)> = (searched.iter())
            .filter(|s| s.needs_voxels && !s.crossed_close)
            .flat_map(|s| planned_grids(input, options, solids.len(), s.budget))
            .collect();
        let (grids, ()) = rayon::join(
            || Grids::new(input, solids, options, &plan),
            || add_kept(searched, input, options),
        );
        let grids = grids?;
        for s in searched.iter_mut().filter(|s| s.crossed_close) {
            let promises = first_promises(input, options, s.budget);
            let fixed = [
                Method::CollapseKept,
                Method::CollapseUncrossed,
                Method::CollapseInTwoSteps,
            ];
            s.needs_voxels &= !(s.candidates.iter_mut())
                .filter(|c| fixed.contains(&c.method))
                .any(|c| promises.broken_cheap(c).is_empty() && crosses_no_more(input, c));
        }
        searched
            .par_iter_mut()
            .filter(|s| s.needs_voxels)
            .try_for_each(|s| add_voxels(s, input, measure, &grids, options))
    })
}

/// The voxel (and, for a surface that is not closed, shell) candidates of `searched`'s budget.
fn add_voxels(
    searched: &mut Searched,
    input: &Input,
    measure: &Measure,
    grids: &Grids,
    options: &PortfolioOptions,
) -> Result<(), BudgetError> {
    let start = Instant::now();
    let budget = searched.budget;
    // The input's collapse, measured by `search`, bounds the levels worth collapsing
    // (`voxel::within_reach`) where it keeps every promise: not where it crossed itself.
    let crossed = |c: &Candidate| searched.plain_crossed && c.method == Method::Collapse;
    let closest = (searched.candidates.iter())
        .filter(|c| !crossed(c))
        .filter_map(|c| c.quick.map(|d| d.shape))
        .fold(f64::INFINITY, f64::min);
    // The solids' searches side by side (each is a chain of grids, one after another).
    let founds = (0..grids.solids().len())
        .into_par_iter()
        .map(|solid| voxel_candidates(input, measure, grids, (solid, closest), options, budget))
        .collect::<Result<Vec<_>, BudgetError>>()?;
    for (found, sampled) in founds.into_iter().zip(grids.solids()) {
        if found.vanished && sampled.fill == Fill::None {
            searched.notes.push(format!(
                "the voxel level at resolution {} vanished (parts thinner than a voxel)",
                found.resolution
            ));
        }
        searched.candidates.extend(found.candidates);
    }
    if !input.is_closed()
        || searched
            .candidates
            .iter()
            .all(|c| c.method != Method::Voxel)
    {
        let max_error = options.max_error;
        let shell = shell_candidates(input, measure.input_closest(), budget, max_error)?;
        searched.candidates.extend(shell);
    }
    searched.seconds += start.elapsed().as_secs_f64();
    Ok(())
}

/// The levels chosen from the largest budget down (module docs), and each level's fit
/// (module `collapse_fits`), made while the next budget is chosen.
fn choose_down(
    searched: Vec<Searched>,
    input: &Input,
    measure: &Measure,
    options: &PortfolioOptions,
    stand_ins: &StandIns,
) -> Result<ChosenChain, BudgetError> {
    let mut levels: Vec<Level> = Vec::new();
    let mut promised: Vec<Promises> = Vec::new();
    let mut ahead: Vec<Ahead> = Vec::new();
    let mut warnings = Vec::new();
    let mut runner_up: Option<Candidate> = None;
    let count = searched.len();
    let fit =
        |level: &Level, promises: &Promises| fitted_ahead(level, promises, input, measure, options);
    for (k, s) in searched.into_iter().enumerate() {
        let start = Instant::now();
        let promises = chained_promises(input, options, s.budget, levels.last());
        let runner = runner_up.take();
        let next = options.monotone && k + 1 < count;
        let (budget, seconds, notes) = (s.budget, s.seconds, s.notes.join("; "));
        let (fitted, chosen) = rayon::join(
            || levels.last().zip(promised.last()).map(|(l, p)| fit(l, p)),
            || {
                let above = levels.last();
                let candidates = with_above(s.candidates, above, runner, input, options, budget);
                let fit = options.fit.as_ref();
                choose(candidates, &promises, input, measure, fit, stand_ins, next)
            },
        );
        ahead.extend(fitted);
        let mut chosen = chosen.ok_or(BudgetError::NoLevel { budget, why: notes })?;
        if promises.budget < budget {
            warnings.push(format!(
                "{budget} triangles: the input has only {}, its level is the input's own",
                promises.budget
            ));
        }
        runner_up = chosen.runner_up.take();
        let from = levels.last().map(|l| l.report.budget);
        let seconds = seconds + start.elapsed().as_secs_f64();
        levels.push(level_of(
            chosen,
            input,
            budget,
            from,
            seconds,
            &mut warnings,
        ));
        promised.push(promises);
    }
    ahead.extend(levels.last().zip(promised.last()).map(|(l, p)| fit(l, p)));
    Ok(ChosenChain {
        levels,
        warnings,
        ahead,
    })
}

/// The chain refined from below, then its collapses fitted (module `collapse_fits`): the
/// levels and the warnings.
fn refined_and_fitted(
    chain: ChosenChain,
    input: &Input,
    measure: &Measure,
    options: &PortfolioOptions,
) -> (Vec<Level>, Vec<String>) {
    let ChosenChain {
        mut levels,
        mut warnings,
        ahead,
    } = chain;
    let replaced = refine_from_below(&mut levels, &mut warnings, input, measure, options);
    let now: Vec<Promises> = (0..levels.len())
        .map(|k| {
            let above = k.checked_sub(1).map(|a| &levels[a]);
            chained_promises(input, options, levels[k].report.budget, above)
        })
        .collect();
    apply_fits(
        &mut levels,
        ahead,
        (&replaced, &now),
        (input, measure, options),
    );
    (levels, warnings)
}

/// What [`choose_down`] chose: the levels from the largest budget down, the warnings so far,
/// and each level's fit made ahead (module `collapse_fits`).
struct ChosenChain {
    levels: Vec<Level>,
    warnings: Vec<String>,
    ahead: Vec<Ahead>,
}

/// `candidates` of `budget` with, in the monotone chain, the level above (`above`) and its
/// runner-up collapsed to the budget.
fn with_above(
    mut candidates: Vec<Candidate>,
    above: Option<&Level>,
    runner_up: Option<Candidate>,
    input: &Input,
    options: &PortfolioOptions,
    budget: usize,
) -> Vec<Candidate> {
    let (true, Some(above)) = (options.monotone, above) else {
        return candidates;
    };
    let collapse =
        |mesh, lineage| collapsed_above(mesh, lineage, budget, input.cell(), options.max_error);
    let r = &above.report;
    let lineage = (r.resolution, r.iso, r.fitted_to_input, r.fill);
    candidates.extend(collapse(above.mesh.clone(), lineage));
    if let Some(r) = runner_up {
        candidates.extend(collapse(r.mesh, (r.resolution, r.iso, r.fitted, r.fill)));
    }
    candidates
}

/// Each level replaced by the next smaller budget's level refined to its budget (module
/// `below`), where that keeps every promise and is closer, tried wherever the smaller level is
/// at most [`below::REACH`] times as far from the input; from the smallest budget up, so that
/// a refined level can serve the one above it. Not for a proxy, nor without the monotone
/// chain. `levels` run from the largest budget down; which of them were replaced.
fn refine_from_below(
    levels: &mut [Level],
    warnings: &mut Vec<String>,
    input: &Input,
    measure: &Measure,
    options: &PortfolioOptions,
) -> Vec<bool> {
    let mut replaced = vec![false; levels.len()];
    if options.remesh || !options.monotone {
        return replaced;
    }
    for k in (0..levels.len().saturating_sub(1)).rev() {
        let start = Instant::now();
        let (larger, smaller) = (&levels[k].report, &levels[k + 1].report);
        if !(smaller.hausdorff <= below::REACH * larger.hausdorff && larger.budget > smaller.budget)
        {
            continue;
        }
        let above = k.checked_sub(1).map(|a| &levels[a]);
        let promises = chained_promises(input, options, larger.budget, above);
        // Closer by Hausdorff distance, the mean within what the choice allows (module
        // `select`): the larger level's, or the input's collapse's times `MEAN_SLACK` (the
        // plain one's, else the checked one's, as reported among the larger level's
        // candidates).
        let reference = [Method::Collapse, Method::CollapseKept]
            .iter()
            .find_map(|m| {
                (larger.candidates.iter())
                    .find(|c| c.candidate == m.name())
                    .and_then(|c| c.careful_mean)
            });
        let allowed_mean = reference.map_or(larger.mean_distance, |m| {
            larger.mean_distance.max(crate::MEAN_SLACK * m)
        });
        let farther = (larger.hausdorff, allowed_mean);
        let fit = options.fit.as_ref();
        let Some(below) =
            below::refined_below(&levels[k + 1], &promises, input, measure, fit, farther)
        else {
            continue;
        };
        // A level chosen for its outline is replaced only by one whose outline also beats
        // the plain collapse's (module `outline`).
        let outline = match levels[k].report.outline {
            Some(o) => match measure.silhouette(&below.mesh) {
                Some(s) if s < o.collapse_silhouette_difference => Some(Outline {
                    silhouette_difference: s,
                    ..o
                }),
                _ => continue,
            },
            None => None,
        };
        let old = &levels[k].report;
        if let Some(note) = &old.note {
            let text = format!("{} triangles: {note}", old.budget);
            warnings.retain(|w| *w != text);
        }
        let mut candidates = old.candidates.clone();
        candidates.push(CandidateReport::of(&below, &[]));
        let chosen = Chosen {
            level: below,
            candidates,
            ruled_out: old.ruled_out.clone(),
            warning: None,
            outline,
            runner_up: None,
        };
        let seconds = old.seconds + start.elapsed().as_secs_f64();
        let above = k.checked_sub(1).map(|a| levels[a].report.budget);
        levels[k] = level_of(chosen, input, old.budget, above, seconds, warnings);
        replaced[k] = true;
    }
    replaced
}

/// A level of the budget above (the level, or its runner-up,
/// [`crate::select::Chosen::runner_up`]) collapsed to `budget` as a [`Method::Above`]
/// candidate, keeping its lineage: the resolution, isodensity, fit and fill it came from.
fn collapsed_above(
    mesh: TriangleMesh,
    (resolution, iso, fitted, fill): (Option<usize>, Option<f32>, bool, Fill),
    budget: usize,
    cell: f64,
    max_error: Option<f64>,
) -> Vec<Candidate> {
    let mut c = crate::voxel::collapsed(Method::Above, mesh, budget, cell, max_error);
    for c in c.iter_mut() {
        (c.resolution, c.iso, c.fitted, c.fill) = (resolution, iso, fitted, fill);
    }
    c
}

/// The promises of `budget` before the chain adds the level above's cap. A budget above the
/// input's triangles asks for the input's count (every candidate made of the input's own
/// triangles has at most that many, and none with more is any closer than the input itself),
/// but a proxy's, whose surface is new.
fn first_promises(input: &Input, options: &PortfolioOptions, budget: usize) -> Promises {
    let budget = match options.remesh {
        true => budget,
        false => budget.min(input.mesh.triangle_count()),
    };
    Promises {
        budget,
        closed: options.closed || input.is_closed(),
        max_handles: input.topology.genus,
        remesh: options.remesh,
    }
}

/// The promises of `budget` in the chain below the level `above`: the budget's first, with no
/// more handles than `above` where the chain is monotone (the genus never rises).
pub(crate) fn chained_promises(
    input: &Input,
    options: &PortfolioOptions,
    budget: usize,
    above: Option<&Level>,
) -> Promises {
    let mut promises = first_promises(input, options, budget);
    if let (true, Some(above)) = (options.monotone, above) {
        promises.max_handles = above.report.genus.or(promises.max_handles);
    }
    promises
}

/// The voxel the budget affords: the longest side over the resolution whose marching-cubes
/// level would have [`HEADROOM`] times its triangles.
fn voxel_at(input: &Input, budget: usize) -> f64 {
    let want = (HEADROOM * budget as f64) as usize;
    let resolution = resolution_for_triangles(&input.mesh, want).unwrap_or(COARSEST);
    input.voxel(resolution.clamp(COARSEST, FINEST))
}

/// The level and its report.
fn level_of(
    chosen: Chosen,
    input: &Input,
    budget: usize,
    above: Option<usize>,
    seconds: f64,
    warnings: &mut Vec<String>,
) -> Level {
    let c = chosen.level;
    let careful = c.careful.unwrap_or(crate::measure::Distance {
        hausdorff: f64::NAN,
        shape: f64::NAN,
        mean: f64::NAN,
    });
    let t = &c.topology;
    if let Some(w) = &chosen.warning {
        warnings.push(format!("{budget} triangles: {w}"));
    }
    let report = BudgetLevel {
        budget,
        triangles: c.triangles(),
        method: c.method,
        resolution: c.resolution,
        iso: c.iso,
        staged: c.staged,
        fitted_to_input: c.fitted,
        parts_dropped: c.parts_dropped,
        parts_restored: c.parts_restored,
        fill: c.fill,
        hausdorff: careful.hausdorff,
        mean_distance: careful.mean,
        hausdorff_fraction: careful.hausdorff / input.diagonal,
        shape_distance: careful.shape,
        genus: t.genus,
        components: t.components,
        boundary_loops: t.boundary_loops,
        handles_removed: input.topology.genus.zip(t.genus).map(|(i, l)| i - l),
        self_intersections: c.crossings.unwrap_or(0),
        simplified_from: (c.method == Method::Above).then_some(above).flatten(),
        candidates: chosen.candidates,
        ruled_out: chosen.ruled_out,
        note: chosen.warning,
        outline: chosen.outline,
        seconds,
    };
    Level {
        mesh: c.mesh,
        topology: c.topology,
        report,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashSet;
    use voxlod_testkit::shapes::icosphere;

    fn searched(budget: usize, candidates: Vec<Candidate>, broke: bool) -> Searched {
        Searched {
            budget,
            candidates,
            needs_voxels: false,
            plain_broke: broke,
            plain_crossed: broke,
            crossed_close: false,
            plate_stands_in: false,
            seconds: 0.0,
            notes: Vec::new(),
        }
    }

    fn positions(mesh: &TriangleMesh) -> HashSet<[u32; 3]> {
        (mesh.positions.iter())
            .map(|p| p.to_array().map(f32::to_bits))
            .collect()
    }

    #[test]
    fn three_eighths_of_a_voxel_is_close_enough_only_at_large_budgets() {
        let input = Input::prepare(&icosphere(5)).unwrap();
        let measure = Measure::new(&input, 2_000, 10_000).unwrap();
        // A sphere grown by three eighths of the voxel a budget affords, as its collapse.
        let grown = |budget: usize| {
            let by = 1.0 + 0.375 * voxel_at(&input, budget) as f32;
            let mut mesh = icosphere(4);
            mesh.positions.iter_mut().for_each(|p| *p *= by);
            Candidate::new(Method::Collapse, mesh)
        };
        for (budget, close) in [(SMALL_BUDGET, false), (4 * SMALL_BUDGET, true)] {
            let mut c = grown(budget);
            assert_eq!(is_close_enough(&input, &measure, &mut c, budget), close);
            assert!(c.quick.is_some());
        }
    }

    #[test]
    fn a_budget_whose_collapse_broke_a_promise_gets_a_checked_collapse_of_the_larger_ones() {
        let input = Input::prepare(&icosphere(5)).unwrap();
        let options = PortfolioOptions::default();
        let plain = collapse::plain(&input, 2_000, None).unwrap();
        let plain_positions = positions(&plain.mesh);
        // The first budget's plain collapse kept the promises; the next two (taken to have
        // broken one) get checked collapses, the first made of that plain collapse (its
        // vertices are some of its vertices: a collapse moves none), the next of the first.
        let mut run = vec![
            searched(2_000, vec![plain], false),
            searched(500, Vec::new(), true),
            searched(100, Vec::new(), true),
        ];
        add_kept(&mut run, &input, &options);
        assert_eq!(run[0].candidates.len(), 1);
        let [kept_500, kept_100] = [&run[1], &run[2]].map(|s| {
            assert_eq!(s.candidates.len(), 1);
            let c = &s.candidates[0];
            assert_eq!(c.method, Method::CollapseKept);
            assert!(within_budget(c.triangles(), s.budget), "{}", c.triangles());
            assert!(c.topology.is_closed_manifold() && c.topology.genus == Some(0));
            positions(&c.mesh)
        });
        assert!(kept_500.is_subset(&plain_positions));
        assert!(kept_100.is_subset(&kept_500));
    }
}
