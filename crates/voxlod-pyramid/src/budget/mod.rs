//! Levels by triangle budget or by error target: the voxel method first, then a geometric
//! simplifier, as the paper proposes (He et al. 1995, §5: the voxel method removes the small
//! features and holes, a geometric method then spends the triangles where the shape needs them).
//!
//! For each budget `B` of [`crate::BudgetOptions::triangles`], on its own:
//!
//! 0. **What the budget affords.** The marching-cubes level with about `B` triangles shows what
//!    topology `B` triangles can carry. When it has no fewer handles and components than the
//!    input mesh, the voxel stage has nothing to remove, and the geometric stage runs on the
//!    input itself (quadric collapse, topology kept, [`Stage::InputQuadric`]): a filtered level
//!    would only add the filter's smoothing to the error (measured on the bunny, rocker arm and
//!    fandisk: the input's collapse is two to ten times closer than any voxel level's). If that
//!    collapse reaches the budget, it is the level; if not (it stalls above it), it stays a
//!    candidate of the search below. This shortcut is our addition to §5, which always filters.
//! 1. **Resolution.** The finest voxel resolution whose marching-cubes level has about
//!    `4 B` triangles: what the budget cannot afford (handles, thin parts, small pieces below a
//!    voxel) is filtered away there, and the geometric stage gets room to choose. Found by
//!    probing: from the resolution that [`voxlod_contouring::triangle_estimate`] predicts from
//!    the input mesh (32 for a volume), each try scales the resolution by `√(wanted / got)`
//!    (marching cubes' count grows as the resolution squared), until the count is within 25 %,
//!    at most five tries. A level that vanished (a sheet thinner than a voxel) sends the search
//!    to twice the resolution, with a warning. **Dilated levels** (our addition to §4, which
//!    contours at 0.5): with a mesh input and the default isodensity, the same search runs on
//!    levels contoured at 0.25 and 0.15 ([`DILATED_ISO_FRACTIONS`] of 0.5), each finding its
//!    own resolution, where a part thinner than the filter still leaves a surface: the thin
//!    skull of a CT bone surface, which 0.5 erases at the coarse resolutions a small budget
//!    affords, closes up into a thicker shell instead of vanishing (a slab of thickness `t`
//!    under the hyper-cone of radius `R` peaks at a density of about `t / R`, so 0.25 keeps
//!    slabs half as thick as 0.5 does, 0.15 slabs a third as thick). The price is one-sided: a
//!    flat surface moves outwards by 0.27 `R` at 0.25 and 0.40 `R` at 0.15 (where the density
//!    of a half-space under the hyper-cone falls that low), which the measured distances of
//!    step 4 weigh against what the 0.5 level lost: the candidates of all three compete there.
//! 2. **Openings.** An open mesh input keeps its openings: the caps that sampling put over its
//!    holes are cut away from the level ([`crate::caps`]), unless
//!    [`crate::BudgetOptions::closed`] asks for watertight levels.
//! 3. **Geometric stage** ([`Then`]): meshoptimizer's quadric collapse with the topology kept
//!    (voxlod-quadric); where it stalls more than 10 % above the budget because the level has
//!    more components than the budget can carry, the smallest components (by bounding-box
//!    diagonal) are dropped until it fits ([`voxlod_quadric::simplify_dropping_parts`], reported
//!    as [`BudgetLevel::parts_dropped`]): the paper's point that the voxel method may drop small
//!    parts, carried into the geometric stage (our addition), so that a finer level that still
//!    holds the large parts' shape can compete with a coarser one that filtered everything;
//!    or simplification envelopes (voxlod-envelope, `tight` preset, ε searched for the count),
//!    or none. [`Then::Auto`] runs the quadric stage, and the envelopes only on
//!    a level where the quadric stage stalls above the budget: measured on the bunny's chain,
//!    the envelopes cost 10 to 300 times the quadric stage's time and were closer to the input
//!    only once, at the largest budget, where the input's own collapse (step 0) is closer
//!    still.
//! 4. **Search.** Within [`crate::BudgetOptions::time_cap`] CPU seconds per budget and
//!    isodensity (counted after the probes for its first resolution, on the process's CPU
//!    clock, [`voxlod_core::cpu_clock`], so that other programs' load does not cut the search
//!    short and change the level), the finer neighbour (about `8 B`
//!    triangles) is tried too, then finer ones while the time allows (about `11 B`, `16 B` and
//!    `5.7 B`, finest first: the finest level whose topology the budget affords is usually the
//!    closest, and a thin part survives only in narrow windows of resolution; not once the
//!    input's own collapse fits, nor for an isodensity whose first level stalled above the
//!    budget), then the coarser neighbour (about `2 B`), and the candidate within 10 % of the budget
//!    with the smallest measured two-sided Hausdorff distance to the input is kept (without a
//!    mesh input, the first within 10 %). A candidate none of whose triangles cross
//!    ([`voxlod_contouring::crossing_pairs`]) beats one with crossings (the quadric stage
//!    itself refuses a pass that folds one sheet through another, so its candidates cross
//!    only where their input did), and an isodensity's coarser resolutions are tried while it
//!    has no such candidate (our addition); where every candidate has some,
//!    the report counts them and a warning says so. Distances are sampled (10 000 points a
//!    side) against the input's closest-point structure, built once per run.
//!
//! 5. **Cavities filled** (our addition, module `filled`): when the input mesh has closed
//!    shells bounding voids inside its material, steps 1 to 4 run again on the input with
//!    those cavities filled ([`voxlod_core::cavities`]), and the closer level is kept: a hollow
//!    part whose wall the budget cannot afford then turns solid instead of perforating.
//!    **Nearly enclosed cavities** (module `enclosed`): with the dilated levels on, steps 1
//!    to 4 also run on the input with the hollows filled that a morphological closing of
//!    its solid (radius 1/16 of its longest side) encloses, such as the cranial cavity of a
//!    CT bone surface, open only through the skull's foramina and orbits, and on the input
//!    with those hollows lined (filled only within that radius of the material). On that
//!    surface at 300 triangles the skull's dome then stays whole instead of perforating
//!    (lined: Hausdorff 13.7 → 8.5 %, silhouette difference 0.174 → 0.069; BENCHMARKS.md).
//!    **Between the solids** (module `silhouettes`): the levels that tie on step 4's tiers are
//!    rendered from 14 views, and the one whose Hausdorff distance and silhouette difference
//!    are both nearest the best of their kind is kept, since the distance counts a buried inner
//!    surface in full and a perforated dome hardly at all, where a viewer sees the opposite.
//!    At 1 000 triangles the skull's lined level (8.4 %, silhouette 0.034) then wins over the
//!    given one (6.8 %, 0.085).
//! 6. **Detached parts restored** (our addition, module `detached`): input parts (closed,
//!    genus 0) that lie outside a quadric candidate, clear of its triangles' boxes, come back
//!    beside it as their own collapse to a few triangles, within a quarter of the budget (the
//!    nearest giving way where the level, re-simplified to make room, stalls above its share),
//!    in twin candidates of step 3 that compete like the others (step 4); distances give every
//!    input part a point of its own, so that a tiny lost part counts.
//! 7. **Fitted to the input** (our addition, module `fit`; the inner problem of Hoppe et al.
//!    1993's mesh optimization, §4.1, in [`voxlod_fit`]): once every budget's level is chosen,
//!    its vertices are moved by least squares towards points sampled on the input and onto
//!    it, its triangles kept, and the result is kept only where its measured distances are no
//!    larger, no new triangle pairs cross and its topology (and silhouette difference, where
//!    measured) is unchanged or better: the filter's smoothing, which no collapse of the voxel
//!    level can undo, is then taken back where the input shows it (the sphereflake at 1 000
//!    triangles: 3.11 % → 2.84 % of the diagonal, `evaluate`'s samples).
//!    [`crate::BudgetOptions::fit`] `None` leaves the levels as step 3 made them.
//!
//! **Independence.** A budget's level depends on that budget and the options alone, never on
//! the other budgets of the run: each search starts from nothing, and levels built for one
//! budget are reused by another only because building them again would give the same level.
//! The time cap charges a reused level its original building time, so it stops a search at the
//! same candidate whatever ran before (up to the timing noise of the CPU clock, a few per cent,
//! which decides only where a search ends near the cap).
//!
//! **Genus along a chain** (module `genus_cap`, our addition): with
//! [`crate::BudgetOptions::monotone`] on, several budgets are searched from the largest down and
//! no level may have more handles than the level above it; a level whose own search would add
//! handles is the one exception to independence.
//!
//! **Error target.** With [`crate::BudgetOptions::error`] and no budgets, one level: the resolution
//! whose voxel is the error, then the quadric stage within the error; with budgets too, the
//! error bounds every geometric stage.
//!
//! Every level is within 10 % of its budget or its report says why not
//! ([`BudgetLevel::note`]). Cost: per budget and isodensity (three with the dilated levels),
//! one to five samplings (the finest dominates, O(N³)), marching cubes, one to four geometric
//! stages (each up to four quadric runs when parts are dropped) and a distance measurement
//! each; when the budget affords the input's topology, one small sampling and one collapse of
//! the input, O(F log F).
//!
//! **Files.** This module holds the public types and the entry points; one concern a file:
//! `context` (what the budgets share, the levels built once), `resolution` (step 1's probes),
//! `openings` (step 2), `input` (step 0), `geometric` (step 3), `candidate` and `measure`
//! (step 4's comparison and distances), `search` (a budget's search, the time cap, the
//! bisection), `filled`, `enclosed` and `silhouettes` (step 5), `detached` and `parts`
//! (step 6), `fit` (step 7), `genus_cap` (the genus along a chain of budgets), `error_target`
//! (the error target alone, without step 5) and `report`.

mod candidate;
mod context;
mod detached;
mod enclosed;
mod error_target;
mod filled;
mod fit;
mod genus_cap;
mod geometric;
mod input;
mod measure;
mod openings;
mod parts;
mod report;
mod resolution;
mod search;
mod silhouettes;

use std::time::Instant;
use voxlod_core::cavities::FilledCavities;

use crate::budget_options::BudgetOptions;
use crate::error::PyramidError;
use crate::lod::LevelOptions;
use crate::lod_options::Lod;
use crate::progress::{Event, ProgressFn, Tracker};
use crate::source::Source;

pub use crate::budget_terms::{BudgetLevel, ErrorTarget, Stage, Then, BUDGET_TOLERANCE};
pub(crate) use context::BudgetContext;
pub(crate) use error_target::error_level;
/// The marching-cubes level aimed at has this many times the budget's triangles.
const HEADROOM: f64 = 4.0;
/// Resolutions searched: at most this fine (memory is checked as well), at least this coarse.
const FINEST: usize = 512;
const COARSEST: usize = 4;
/// The resolution search stops once a level's count is within this fraction of the wanted one.
const PROBE_TOLERANCE: f64 = 0.25;
/// With a mesh input and the solid's default isodensity, the search also runs on levels
/// contoured at these fractions of it (0.25 and 0.15 for 0.5): module docs, step 1.
const DILATED_ISO_FRACTIONS: [f32; 2] = [0.5, 0.3];
/// Samples per side of the distances measured during the search.
const SEARCH_SAMPLES: usize = 10_000;

/// The voxel-first levels of [`crate::lod_by_budget`] (module docs; the options are checked by
/// the caller): one level per budget, in the order given, or one for the error target alone.
pub(crate) fn voxel_first(
    source: &Source,
    options: &BudgetOptions,
    progress: &ProgressFn,
) -> Result<Lod, PyramidError> {
    let start = Instant::now();
    let prepared = source.prepare()?;
    let iso = prepared.iso(options.iso)?;
    let level_options = LevelOptions {
        pyramid: options.pyramid(),
        iso,
        normals: options.normals,
        clean: Some(voxlod_contouring::CleanOptions::default()),
        // Plain marching cubes, cleaned: the search weighs distances, and snapping the
        // vertices cost the thin shell's level 3 % of its Hausdorff distance.
        snap: false,
    };
    let lod_source = prepared.lod_source();
    let input = match source {
        Source::Mesh(mesh) => Some(*mesh),
        _ => None,
    };
    let mut ctx = BudgetContext::new(
        &lod_source,
        level_options,
        input,
        options.then,
        options.closed,
        options.time_cap,
    )?;
    ctx.dilated = input.is_some() && options.iso.is_none() && options.then != Then::None;
    // The input with its cavities filled (module `filled`), and with its nearly enclosed
    // cavities filled (module `enclosed`), each with the context of its search.
    // An optional search: where its grid does not fit (the memory limit), the run goes on
    // without it and says so.
    let mut skipped = None;
    let enclosed = match (&ctx.welded, ctx.dilated) {
        (Some((welded, _)), true) => enclosed::enclosed_filled(welded).unwrap_or_else(|e| {
            skipped = Some(format!("nearly enclosed cavities not searched: {e}"));
            Vec::new()
        }),
        _ => Vec::new(),
    };
    let fills: Vec<FilledCavities> = filled::filled_input(&ctx)
        .into_iter()
        .chain(enclosed)
        .collect();
    let fill_prepared = (fills.iter())
        .map(|f| Source::Mesh(&f.mesh).prepare())
        .collect::<Result<Vec<_>, _>>()?;
    let fill_sources: Vec<_> = fill_prepared.iter().map(|p| p.lod_source()).collect();
    let fill_ctxs: Vec<_> = (fill_sources.iter().zip(&fills))
        .map(|(source, f)| ctx.filled(source, &f.mesh))
        .collect();
    let filled: Vec<_> = fill_ctxs.iter().zip(&fills).collect();
    let error = options.error.map(|e| e.distance(ctx.diagonal));
    let budgets = options.triangles.clone();
    let mut tracker = Tracker::start(progress, budgets.len().max(1))?;
    let mut warnings = prepared.warnings().to_vec();
    warnings.extend(skipped);
    if input.is_some() && ctx.measure.is_none() {
        warnings.push(
            "distances to the input not measured (its samples or closest-point structure could not be \
             built: the memory limit, or a mesh without area): each budget's first level within \
             10 % is kept"
                .to_string(),
        );
    }
    let (levels, budgets) = if budgets.is_empty() {
        let (level, report, more) = error_level(&ctx, error.unwrap_or(f64::INFINITY))?;
        tracker.step(0, "budget level")?;
        tracker.ask(Event::LodLevel(&level))?;
        warnings.extend(more);
        (vec![level], vec![report])
    } else {
        let capped = options.monotone;
        let chain = genus_cap::budget_chain(&ctx, &filled, &budgets, error, capped, &mut tracker)?;
        warnings.extend(chain.warnings);
        (chain.levels, chain.reports)
    };
    let (mut levels, mut budgets) = (levels, budgets);
    if let Some(fit_options) = &options.fit {
        fit::fit_levels(&ctx, fit_options, &mut levels, &mut budgets);
    }
    Ok(Lod {
        levels,
        route: prepared.route(),
        preparation: prepared.preparation().copied(),
        iso,
        warnings,
        budgets,
        finest: None,
        seconds: start.elapsed().as_secs_f64(),
    })
}
