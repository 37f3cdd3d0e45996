//! The genus kept from rising along a chain of budgets (our addition): in a
//! run of several budgets, no level has more handles than the level of the next larger budget.
//!
//! Why: each budget's search (steps 0 to 6) picks the level closest to the input, and two
//! budgets may find their closest levels at resolutions whose topology differs the other way
//! round: on a printed part with thin walls (Thingi10K 68247) the searches of 5 000 and 1 000
//! triangles gave genus 0 and 6. The paper's promise (He et al. 1995, §1 and §4: topology
//! simplifies as detail goes) holds along the default chain by its monotone step; here it is
//! kept the same way the search keeps a budget: as a rule of the competition.
//!
//! How: the budgets are searched from the largest down. Each search after the first gets the
//! genus of the level above it as a cap: a candidate within 10 % of the budget and within the
//! cap beats every candidate that is not (module `candidate`), and an isodensity's coarser
//! resolutions are tried while it has none such. Then one more candidate competes with the
//! search's level by the same rule: the level above, simplified to the budget by the quadric
//! collapse with its topology kept (so within the cap), where it lands within 10 % and the
//! geometric stage is the quadric one; the report names the budget it came from
//! ([`super::BudgetLevel::simplified_from`]). Where the level still has more handles than the
//! one above (no candidate within 10 % had fewer), it stands and a warning says so.
//!
//! The simplified level above is often the closer one, not only where the cap binds: measured
//! on the eleven shared meshes at 20 000, 5 000, 1 000 and 250 triangles, it won 18 of the 33 smaller
//! budgets, and no level measured farther than the same budget searched alone (at 250
//! on a printed part, Thingi10K 138207, 0.17 against 0.89 mesh units). A level simplified in
//! steps from a fine voxel level keeps planes and sharp edges that a collapse from a coarse
//! voxel level of about `4 B` triangles has lost in marching cubes' staircase. The cap has a
//! price where the closest level of a smaller budget needs a handle that the level above
//! closed: the sphereflake's chain of 4 000, 1 000 and 300 triangles holds 1 000 to genus 0
//! at 5.1 % of the diagonal, where alone it has genus 1 at 3.0 %.
//!
//! **Independence** (module docs of [`crate::budget`]) holds for one budget alone and with
//! [`crate::BudgetOptions::monotone`] off (no cap, no level above); in a chain, a level depends
//! on the larger budgets of its run through the cap and the level above. `evaluate` runs each
//! budget alone.
//!
//! Cost: the genus of each candidate compared under a cap, O(F) each; where the cap binds, one
//! quadric collapse of the level above and its distance measurement.

use std::time::Instant;

use voxlod_core::cavities::FilledCavities;
use voxlod_quadric::{simplify_to_budget, QuadricOptions};

use super::candidate::{beats, fits, Candidate, Standing};
use super::context::BudgetContext;
use super::filled::budget_level_either;
use super::geometric::without_degenerate;
use super::report::{finish, Choice, Tally, Target};
use super::{BudgetLevel, Stage, Then};
use crate::error::PyramidError;
use crate::lod::LodLevel;
use crate::progress::{Event, Tracker};

/// A budget's level, its report and warnings.
pub(super) type Found = (LodLevel, BudgetLevel, Vec<String>);

/// The levels of a chain of budgets in the order given, their reports, and the warnings.
pub(super) struct Chain {
    pub(super) levels: Vec<LodLevel>,
    pub(super) reports: Vec<BudgetLevel>,
    pub(super) warnings: Vec<String>,
}

/// The levels of `budgets`, searched from the largest down, each held to the genus of the one
/// above when `capped` (module docs), and returned in the order given, with their reports and
/// warnings.
pub(super) fn budget_chain(
    given: &BudgetContext,
    filled: &[(&BudgetContext, &FilledCavities)],
    budgets: &[usize],
    error: Option<f64>,
    capped: bool,
    tracker: &mut Tracker,
) -> Result<Chain, PyramidError> {
    let mut order: Vec<usize> = (0..budgets.len()).collect();
    order.sort_by_key(|&i| std::cmp::Reverse(budgets[i]));
    let mut slots: Vec<Option<(LodLevel, BudgetLevel)>> = vec![None; budgets.len()];
    let mut warnings = Vec::new();
    let mut above: Option<usize> = None;
    for (k, &i) in order.iter().enumerate() {
        let budget = budgets[i];
        let held = above
            .filter(|_| capped)
            .and_then(|j| slots[j].as_ref().map(|(l, r)| (l, r)));
        let (level, report, more) = budget_level_below(given, filled, budget, error, held)
            .map_err(|e| e.context(format!("budget {budget} (level {i})")))?;
        warnings.extend(more);
        tracker.step(k, "budget level")?;
        tracker.ask(Event::LodLevel(&level))?;
        slots[i] = Some((level, report));
        above = Some(i);
    }
    let (levels, reports) = slots.into_iter().flatten().unzip();
    Ok(Chain {
        levels,
        reports,
        warnings,
    })
}

/// The level for `budget` (module `filled`), held to the genus of `above` (the level of the
/// next larger budget of the run and its report) when given: module docs.
pub(super) fn budget_level_below(
    given: &BudgetContext,
    filled: &[(&BudgetContext, &FilledCavities)],
    budget: usize,
    error: Option<f64>,
    above: Option<(&LodLevel, &BudgetLevel)>,
) -> Result<Found, PyramidError> {
    let start = Instant::now();
    let cap = above.and_then(|(_, report)| report.genus);
    let (level, report, mut warnings) = budget_level_either(given, filled, budget, error, cap)?;
    let Some((above_level, above_report)) = above else {
        return Ok((level, report, warnings));
    };
    let simplified = simplified_above(given, above_level, above_report, budget, error);
    if let Some(simplified) = simplified.filter(|s| {
        let theirs = Standing {
            triangles: s.mesh.triangle_count(),
            hausdorff: s.distance.map(|d| d.hausdorff),
            within_cap: true,
            clean: s.crossings() == 0,
        };
        beats(theirs, Standing::of(&report, cap), budget)
    }) {
        let candidates = report.candidates + 1;
        let choice = Choice {
            candidate: simplified,
            level: above_level.clone(),
            caps_cut: above_report.caps_cut,
            voxel_triangles: above_report.voxel_triangles,
        };
        let tally = Tally {
            tried: candidates,
            start,
            warnings,
        };
        let mut found = finish(given, choice, Target { budget, error }, tally);
        found.1.resolution = above_report.resolution;
        found.1.cavities_filled = above_report.cavities_filled;
        found.1.simplified_from = above_report.budget;
        return Ok(found);
    }
    if let (Some(cap), Some(genus)) = (cap, report.genus.filter(|&g| cap.is_some_and(|c| g > c))) {
        warnings.push(format!(
            "budget {budget}: genus {genus}, more than the {cap} of the level above it: no \
             candidate within 10 % of the budget had fewer handles, and the level above does \
             not simplify to the budget"
        ));
    }
    Ok((level, report, warnings))
}

/// The level above simplified to `budget` (quadric collapse, topology kept), measured, when it
/// lands within 10 % of the budget and the geometric stage asked for is the quadric one.
fn simplified_above(
    ctx: &BudgetContext,
    above: &LodLevel,
    above_report: &BudgetLevel,
    budget: usize,
    error: Option<f64>,
) -> Option<Candidate> {
    if !matches!(ctx.then, Then::Auto | Then::Quadric) {
        return None;
    }
    let options = QuadricOptions::budget(error.unwrap_or(f64::INFINITY));
    let done = simplify_to_budget(&above.mesh, budget, &options).ok()?;
    let mesh = without_degenerate(done.mesh, above.plan.voxel_size);
    let candidate = Candidate {
        distance: ctx.measure(&mesh),
        mesh,
        stage: Stage::Quadric,
        error_bound: done.error_bound + above_report.error_bound,
        parts_dropped: 0,
        parts_restored: above_report.parts_restored,
        iso: above_report.iso,
        facts: Default::default(),
    };
    fits(&candidate, budget).then_some(candidate)
}
