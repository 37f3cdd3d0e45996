//! The budget search: for each triangle budget, the parameter of a method whose level comes
//! nearest it.
//!
//! Triangle counts grow about as a power of the parameter ([`SearchSpace::exponent`]), so the
//! search works in log–log space: with nothing known it tries [`SearchSpace::first`] (the budget
//! itself where the parameter is the count, [`SearchSpace::first_at_budget`]); with trials
//! on one side of the budget only it extrapolates along the power law; with trials on both sides
//! it interpolates between the nearest below and above. A guess already tried moves one step of
//! the parameter's grid towards the budget, never across a tried step on the far side. The search
//! of a budget ends when a trial lands within [`EvaluateOptions::tolerance`] of it, when no
//! untried step can do better, or after [`EvaluateOptions::max_trials`] runs.
//!
//! **A budget's result depends on that budget alone**, not on the other budgets of the run: each
//! budget's search starts from nothing and sees only its own trials, so it takes the same steps
//! in any run. Runs are deterministic, so every run of a method is cached by its step and a step
//! that another budget already ran is taken from the cache instead of run again. (Before, each
//! budget's search started from the trials of the budgets before it and stopped at the first
//! one within the tolerance, so `--budgets 5022,627` and the default series kept different levels
//! for 627.)
//!
//! The trial kept for a budget is the one nearest it in ratio among its own search's; it is
//! measured ([`super::measure`]) unless it misses the budget by more than
//! [`EvaluateOptions::max_miss_factor`] or has no area. A level already measured for another
//! budget is not measured again: its point is repeated for this budget. Cost: that of the runs
//! and measurements; the search's own bookkeeping is negligible.

use std::time::Instant;

use voxlod::metrics::MetricsError;

use super::error::{parameter_text, EvaluateError};
use super::measure::Measurer;
use super::options::EvaluateOptions;
use super::results::{Curve, CurvePoint};
use super::trial::{run_trial, Trial};
use crate::methods::{Method, MethodInput, SearchSpace};

/// The runs of one method so far (a cache by step), and the steps the current budget's search
/// has seen.
struct Trials {
    list: Vec<Trial>,
    seen: Vec<i64>,
}

impl Trials {
    /// The current search's trial at `step`.
    fn get(&self, step: i64) -> Option<&Trial> {
        self.seen().find(|t| t.step == step)
    }

    /// The current search's trials.
    fn seen(&self) -> impl Iterator<Item = &Trial> {
        self.list.iter().filter(|t| self.seen.contains(&t.step))
    }

    /// Starts the search of another budget, with the cache kept.
    fn new_search(&mut self) {
        self.seen.clear();
    }

    /// The parameter step to try next for `budget`, or `None` when no untried step can do
    /// better than the trials so far.
    fn next_guess(&self, budget: usize, space: &SearchSpace) -> Option<i64> {
        let count = |t: &Trial| t.triangles();
        // The nearest trials with fewer triangles than the budget and with at least as many.
        let below = self
            .seen()
            .filter(|t| count(t) < budget)
            .max_by_key(|t| (count(t), std::cmp::Reverse(t.step)));
        let above = self
            .seen()
            .filter(|t| count(t) >= budget)
            .min_by_key(|t| (count(t), t.step));
        let mut guess = space.step_of(guess_value(below, above, budget, space));
        if let Some(tried) = self.get(guess) {
            // Move one step from the tried parameter towards the budget.
            let towards_more = count(tried) < budget;
            guess += if towards_more == (space.exponent > 0.0) {
                1
            } else {
                -1
            };
            // Never cross a tried parameter on the far side of the budget.
            let crosses = match (below, above) {
                (Some(b), Some(a)) => guess <= b.step.min(a.step) || guess >= b.step.max(a.step),
                _ => false,
            };
            if !space.contains(guess) || self.get(guess).is_some() || crosses {
                return None;
            }
        }
        Some(guess)
    }

    /// The trial nearest `budget` in ratio (ties: fewer triangles), among those with triangles.
    fn nearest(&self, budget: usize) -> Option<&Trial> {
        let miss = |t: &Trial| ((t.triangles() as f64) / budget as f64).ln().abs();
        self.seen().filter(|t| t.triangles() > 0).min_by(|a, b| {
            miss(a)
                .total_cmp(&miss(b))
                .then(a.triangles().cmp(&b.triangles()))
        })
    }
}

/// The parameter value aimed at for `budget`, from the nearest trials below and above it: the
/// first value, a power-law extrapolation from one side, or a log–log interpolation between
/// both.
fn guess_value(
    below: Option<&Trial>,
    above: Option<&Trial>,
    budget: usize,
    space: &SearchSpace,
) -> f64 {
    let target = (budget as f64).ln();
    let count = |t: &Trial| t.triangles();
    match (below, above) {
        (None, None) if space.first_at_budget => budget as f64,
        (None, None) => space.first,
        (Some(b), Some(a)) if count(b) > 0 => {
            let (xb, xa) = (b.parameter.ln(), a.parameter.ln());
            let (tb, ta) = ((count(b) as f64).ln(), (count(a) as f64).ln());
            if ta > tb {
                (xb + (target - tb) * (xa - xb) / (ta - tb)).exp()
            } else {
                (b.parameter * a.parameter).sqrt()
            }
        }
        (Some(b), Some(a)) => (b.parameter + a.parameter) / 2.0,
        (Some(near), None) | (None, Some(near)) => {
            if count(near) == 0 {
                near.parameter * 2f64.powf(space.exponent.signum())
            } else {
                let ratio = budget as f64 / count(near) as f64;
                near.parameter * ratio.powf(1.0 / space.exponent)
            }
        }
    }
}

fn within(triangles: usize, budget: usize, tolerance: f64) -> bool {
    (triangles as f64 / budget as f64 - 1.0).abs() <= tolerance
}

/// What every method's curve is made for: the budgets, the options, and what measures a level.
pub(super) struct CurveJob<'a> {
    pub measurer: &'a Measurer<'a>,
    pub budgets: &'a [usize],
    pub options: &'a EvaluateOptions,
}

/// Searches each of the job's budgets in turn, then measures the level kept for it: the curve
/// of `method`. `on_point` hears of each measured level.
pub(super) fn method_curve(
    method: Method,
    input: &MethodInput,
    job: &CurveJob,
    on_point: &mut impl FnMut(Method, &CurvePoint),
) -> Result<Curve, EvaluateError> {
    let start = Instant::now();
    let CurveJob {
        measurer,
        budgets,
        options,
    } = *job;
    let space = method.simplifier().search_space(&options.search_limits());
    let mut trials = Trials {
        list: Vec::new(),
        seen: Vec::new(),
    };
    let mut points: Vec<CurvePoint> = Vec::new();
    let mut misses = Vec::new();
    for &budget in budgets {
        search_budget(method, input, &space, &mut trials, budget, options)?;
        let best = match kept_trial(method, &trials, budget, options) {
            Ok(best) => best,
            Err(miss) => {
                misses.push(miss);
                continue;
            }
        };
        if let Some(same) = points.iter().find(|p| p.parameter == best.parameter) {
            let point = CurvePoint {
                budget,
                ..same.clone()
            };
            on_point(method, &point);
            points.push(point);
            continue;
        }
        match measurer.measure(method, best, budget) {
            Ok(point) => {
                on_point(method, &point);
                points.push(point);
            }
            Err(e) => misses.push(unmeasurable(e, method, best, budget)?),
        }
    }
    Ok(Curve {
        method,
        parameter: method.parameter_name(),
        points,
        misses,
        trials: trials.list.len(),
        seconds: start.elapsed().as_secs_f64(),
        notes: Vec::new(),
    })
}

/// Runs `method` until a trial lands within the tolerance of `budget`, no untried step can do
/// better, or the budget's runs are spent.
fn search_budget(
    method: Method,
    input: &MethodInput,
    space: &SearchSpace,
    trials: &mut Trials,
    budget: usize,
    options: &EvaluateOptions,
) -> Result<(), EvaluateError> {
    trials.new_search();
    for _ in 0..options.max_trials.max(1) {
        if trials
            .nearest(budget)
            .is_some_and(|t| within(t.triangles(), budget, options.tolerance))
        {
            break;
        }
        let Some(step) = trials.next_guess(budget, space) else {
            break;
        };
        if !trials.list.iter().any(|t| t.step == step) {
            let trial = run_trial(method, input, step, space.value_of(step))?;
            trials.list.push(trial);
        }
        trials.seen.push(step);
    }
    Ok(())
}

/// The trial to measure for `budget`, or why none is kept (the report's miss).
fn kept_trial<'t>(
    method: Method,
    trials: &'t Trials,
    budget: usize,
    options: &EvaluateOptions,
) -> Result<&'t Trial, String> {
    let Some(best) = trials.nearest(budget) else {
        return Err(format!(
            "budget {budget}: no {} gave any triangles",
            method.parameter_name()
        ));
    };
    match out_of_reach(method, best, budget, options) {
        Some(miss) => Err(miss),
        None => Ok(best),
    }
}

/// The miss of `budget` when `level` is further from it than
/// [`EvaluateOptions::max_miss_factor`] either way; `None` when it is kept.
pub(super) fn out_of_reach(
    method: Method,
    level: &Trial,
    budget: usize,
    options: &EvaluateOptions,
) -> Option<String> {
    let ratio = level.triangles() as f64 / budget as f64;
    (ratio.ln().abs() > options.max_miss_factor.ln()).then(|| {
        format!(
            "budget {budget}: out of reach; the nearest level has {} triangles ({} {})",
            level.triangles(),
            method.parameter_name(),
            parameter_text(level.parameter)
        )
    })
}

/// The miss for a level that could not be measured because its triangles all collapsed to zero
/// area (nothing to sample); any other failure is passed on.
pub(super) fn unmeasurable(
    error: EvaluateError,
    method: Method,
    best: &Trial,
    budget: usize,
) -> Result<String, EvaluateError> {
    match error {
        EvaluateError::Distance {
            source:
                MetricsError::InMesh {
                    which: "second",
                    source,
                },
            ..
        } if matches!(*source, MetricsError::NoArea { .. }) => Ok(format!(
            "budget {budget}: the nearest level ({} {}) has {} triangles but no area",
            method.parameter_name(),
            parameter_text(best.parameter),
            best.triangles()
        )),
        e => Err(e),
    }
}
