//! A budget's search (steps 0 to 4 of [`crate::budget`]): the input's own collapse when the
//! budget affords its topology, then the levels of the search plan (each isodensity's first
//! resolution, its neighbours, coarser ones while nothing fits) under the time cap, a bisection
//! while nothing fits, and [`super::Then::Auto`]'s envelopes where the quadric stage stalled.

use std::collections::HashMap;
use std::f64::consts::SQRT_2;
use std::time::Instant;

use voxlod_core::cpu_clock::CpuTimer;

use super::candidate::{better, fits, fits_capped, Candidate};
use super::context::BudgetContext;
use super::geometric::{envelope_candidate, stages};
use super::input::closer_than_voxels;
use super::report::{finish, report, Choice, Tally, Target};
use super::resolution::step_down;
use super::{BudgetLevel, Stage, Then, COARSEST, FINEST, HEADROOM};
use crate::error::PyramidError;
use crate::lod::LodLevel;

/// What a budget's search has found so far.
struct Search {
    /// The best candidate, the voxel level it came from, and the caps cut from that level.
    best: Option<(Candidate, LodLevel, usize)>,
    /// Seconds charged to each isodensity's search (by its bits) against the time cap: its
    /// neighbouring levels and the geometric stages, not the probes for its first resolution.
    charged: HashMap<u32, f64>,
    /// Candidates built and measured.
    tried: usize,
    /// Per resolution tried, the count of its best candidate (for the bisection).
    counts: Vec<(usize, usize)>,
    /// Isodensities (their bits) with a candidate within 10 % of the budget: each isodensity's
    /// coarser levels are tried while it has none, whatever the time.
    fitted_isos: Vec<u32>,
    /// At most this genus, in a chain of budgets (module `genus_cap`).
    genus_cap: Option<i64>,
    /// Isodensities (their bits) whose first resolution's candidates all stalled above the
    /// budget: their finer levels, with at least as much to keep, are not tried.
    stalled_isos: Vec<u32>,
}

/// The level for `budget` (see the module documentation), with an optional error bound for the
/// geometric stage, and the warnings of its search; candidates with more handles than
/// `genus_cap` lose to those within it (module `genus_cap`).
pub(crate) fn budget_level(
    ctx: &BudgetContext,
    budget: usize,
    error: Option<f64>,
    genus_cap: Option<i64>,
) -> Result<(LodLevel, BudgetLevel, Vec<String>), PyramidError> {
    let start = Instant::now();
    let mut best: Option<(Candidate, LodLevel, usize)> = None;
    if let Some((candidate, level, _)) = ctx.input_candidate(budget, error)? {
        if fits_capped(&candidate, budget, genus_cap) && closer_than_voxels(ctx, &candidate, budget)
        {
            let voxel_triangles = level.mesh.triangle_count();
            let choice = Choice {
                candidate,
                level,
                caps_cut: 0,
                voxel_triangles,
            };
            let tally = Tally {
                tried: 1,
                start,
                warnings: Vec::new(),
            };
            return Ok(finish(ctx, choice, Target { budget, error }, tally));
        }
        best = Some((candidate, level, 0));
    }
    let headroom = if ctx.then == Then::None {
        1.0
    } else {
        HEADROOM
    };
    let (first, _, mut warnings) = ctx.resolution_for(headroom * budget as f64)?;
    let tries = search_plan(ctx, first, headroom * budget as f64)?;
    let mut search = Search {
        tried: usize::from(best.is_some()),
        best,
        charged: HashMap::new(),
        counts: Vec::new(),
        fitted_isos: Vec::new(),
        genus_cap,
        stalled_isos: Vec::new(),
    };
    for one in &tries {
        try_level(ctx, one, budget, error, &mut search)?;
    }
    search.tried += bisect(ctx, &mut search, budget, error)?;
    search.tried += envelopes_where_stalled(ctx, &mut search.best, budget, error, genus_cap);
    let tried = search.tried;
    let Some(chosen) = search.best else {
        warnings.push(format!(
            "budget {budget}: every resolution tried vanished; the level is empty"
        ));
        let (level, _) = ctx.level(first)?;
        let report = report(ctx, &level, Some(budget), error, 0, tried, start);
        return Ok((level, report, warnings));
    };
    let (candidate, level, caps_cut) = chosen;
    let voxel_triangles = level.mesh.triangle_count();
    let choice = Choice {
        candidate,
        level,
        caps_cut,
        voxel_triangles,
    };
    let tally = Tally {
        tried,
        start,
        warnings,
    };
    Ok(finish(ctx, choice, Target { budget, error }, tally))
}

/// One level of the search plan, unless the time cap or a fitting candidate skips it: its
/// geometric stages' candidates compete with `search.best`, and its time is charged to its
/// isodensity (not the building of an isodensity's first resolution, charged to the probes).
fn try_level(
    ctx: &BudgetContext,
    &Try {
        resolution,
        iso,
        base,
        finer,
    }: &Try,
    budget: usize,
    error: Option<f64>,
    search: &mut Search,
) -> Result<(), PyramidError> {
    let is_first = resolution == base;
    let input_fits = (search.best.as_ref()).is_some_and(|b| {
        b.0.stage == Stage::InputQuadric && fits_capped(&b.0, budget, search.genus_cap)
    });
    let fitted = search.fitted_isos.contains(&iso.to_bits()) || input_fits;
    if finer && input_fits {
        return Ok(());
    }
    let over_time = !is_first
        && search
            .charged
            .get(&iso.to_bits())
            .is_some_and(|&c| c >= ctx.time_cap);
    if !is_first && fitted && (over_time || resolution < step_down(base)) {
        return Ok(());
    }
    let stalled = search.stalled_isos.contains(&iso.to_bits());
    if (over_time || stalled) && resolution > base {
        return Ok(());
    }
    let (level, cut, seconds) = ctx.uncapped_at(resolution, iso)?;
    // Timed after the level is at hand: its building is charged once, below, as `seconds` (the
    // time it first took, also when it was built for another budget).
    let stage_timer = CpuTimer::start();
    if level.mesh.is_empty() {
        return Ok(());
    }
    let (mut built_any, mut all_over) = (false, true);
    for candidate in stages(ctx, &level, iso, budget, error) {
        search.tried += 1;
        built_any = true;
        all_over &= candidate.mesh.triangle_count() > budget && !fits(&candidate, budget);
        if iso == ctx.level_options.iso {
            search
                .counts
                .push((resolution, candidate.mesh.triangle_count()));
        }
        if fits_capped(&candidate, budget, search.genus_cap) {
            search.fitted_isos.push(iso.to_bits());
        }
        let best = search.best.as_ref().map(|b| &b.0);
        if better(&candidate, best, budget, search.genus_cap) {
            search.best = Some((candidate, level.clone(), cut));
        }
    }
    if is_first && built_any && all_over {
        search.stalled_isos.push(iso.to_bits());
    }
    let built = if is_first { 0.0 } else { seconds };
    *search.charged.entry(iso.to_bits()).or_default() += built + stage_timer.seconds();
    Ok(())
}

/// [`Then::Auto`]'s envelopes, where the quadric stage stalled above the budget on every level
/// (module docs, step 3): the envelope stage on the best candidate's level, kept if better. The
/// candidates built (zero or one).
fn envelopes_where_stalled(
    ctx: &BudgetContext,
    best: &mut Option<(Candidate, LodLevel, usize)>,
    budget: usize,
    error: Option<f64>,
    genus_cap: Option<i64>,
) -> usize {
    let mut tried = 0;
    if let Some((stalled, level, cut)) = best.as_ref().filter(|b| !fits(&b.0, budget)) {
        if ctx.then == Then::Auto && ctx.input.is_some() {
            let (level, iso) = (level.clone(), stalled.iso);
            if let Some(candidate) = envelope_candidate(ctx, &level, iso, budget, error) {
                tried += 1;
                if better(&candidate, Some(stalled), budget, genus_cap) {
                    *best = Some((candidate, level, *cut));
                }
            }
        }
    }
    tried
}

/// One level of a budget's search: its resolution and isodensity, and the first resolution of
/// that isodensity's search (module docs, steps 1 and 4).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Try {
    resolution: usize,
    iso: f32,
    base: usize,
    /// One of the finer steps, tried only while the input's own collapse does not fit.
    finer: bool,
}

/// The levels a budget's search tries, in order: each isodensity's first resolution (about
/// `wanted` triangles at that isodensity; `first` for the surface's), then their finer
/// neighbours (about twice `wanted`); then, while the time cap allows, the geometric stage is
/// the quadric collapse and the input's own collapse (step 0) does not fit, finer levels beyond
/// and between (about 2.8, 4 and 1.4 times `wanted`: finest first, since the finest level whose
/// topology the budget affords is usually the closest, and the time cap may stop the rest);
/// then the coarser neighbours (about half `wanted`) and, only while nothing fits the budget,
/// coarser levels still (about a quarter and an eighth), with less to keep.
/// A thin part survives filtering only in windows of resolution that depend on how it meets
/// the lattice (a ring of tori 0.1 thick, at isodensity 0.15, keeps its shape at 19, 20, 22
/// to 30, and breaks up or vanishes at 18, 21 and 25), so the finer steps are closer together
/// than a factor of two in the count: the finest level whose topology the budget affords is
/// usually the closest to the input.
fn search_plan(ctx: &BudgetContext, first: usize, wanted: f64) -> Result<Vec<Try>, PyramidError> {
    let mut bases = vec![(ctx.level_options.iso, first)];
    for iso in ctx.isos().into_iter().skip(1) {
        bases.push((iso, ctx.resolution_for_at(wanted, iso)?.0));
    }
    let mut tries: Vec<Try> = bases
        .iter()
        .map(|&(iso, base)| Try {
            resolution: base,
            iso,
            base,
            finer: false,
        })
        .collect();
    if ctx.then == Then::None {
        return Ok(tries);
    }
    // The finer steps only where the geometric stage is the quadric collapse: simplification
    // envelopes cost 10 to 300 times as much per level (module docs, step 3).
    let finer: &[f64] = match ctx.then {
        Then::Envelope => &[],
        _ => &[2.0 * SQRT_2, 4.0, SQRT_2],
    };
    let finer_steps = std::iter::once((2f64, false)).chain(finer.iter().map(|&f| (f, true)));
    let coarser_steps = [0.5, 0.25, 0.125].map(|f| (f, false));
    for (f, finer) in finer_steps.chain(coarser_steps) {
        for &(iso, base) in &bases {
            let resolution = ((base as f64 * f.sqrt()).round() as usize).clamp(COARSEST, FINEST);
            let next = Try {
                resolution,
                iso,
                base,
                finer,
            };
            if !tries
                .iter()
                .any(|t| t.resolution == resolution && t.iso == iso)
            {
                tries.push(next);
            }
        }
    }
    Ok(tries)
}

/// While nothing fits the budget: bisects between the finest resolution whose candidate stayed
/// under the budget and the coarsest whose candidate stalled over it (at most four tries: a
/// level's topology, and so where the quadric stage stalls, can change quickly with the
/// resolution). The candidates built.
fn bisect(
    ctx: &BudgetContext,
    search: &mut Search,
    budget: usize,
    error: Option<f64>,
) -> Result<usize, PyramidError> {
    let (best, counts) = (&mut search.best, &mut search.counts);
    let mut tried = 0;
    for _ in 0..4 {
        if best.as_ref().is_none_or(|b| fits(&b.0, budget)) {
            break;
        }
        let under = counts.iter().filter(|c| c.1 < budget).map(|c| c.0).max();
        let over = counts.iter().filter(|c| c.1 > budget).map(|c| c.0).min();
        let (Some(low), Some(high)) = (under, over) else {
            break;
        };
        if high <= low + 1 {
            break;
        }
        let resolution = (low + high) / 2;
        let (level, cut, _) = ctx.uncapped(resolution)?;
        counts.push((resolution, level.mesh.triangle_count()));
        let iso = ctx.level_options.iso;
        for candidate in stages(ctx, &level, iso, budget, error) {
            tried += 1;
            counts.push((resolution, candidate.mesh.triangle_count()));
            if better(
                &candidate,
                best.as_ref().map(|b| &b.0),
                budget,
                search.genus_cap,
            ) {
                *best = Some((candidate, level.clone(), cut));
            }
        }
    }
    Ok(tried)
}
