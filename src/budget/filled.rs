//! Cavities filled (our addition; issue 12, items 3 and 4): when the input mesh has closed
//! shells that bound voids inside its material ([`voxlod_core::cavities`]: a hollow part's
//! inner wall, the marrow spaces of a CT bone surface), each budget's search runs a second time
//! on the input with those cavities filled, and the closer of the two levels is kept.
//!
//! Why: a budget that cannot afford a thin wall's two sides makes the voxel levels lose the
//! wall, and the part perforates or vanishes, since a wall thinner than the filter's radius
//! cannot survive filtering (He et al. 1995, §2). Filled, the part closes up and turns solid as
//! seen from outside, the outcome the monotone chain gives a hollow part too; no silhouette
//! changes, and the two-sided distance pays only the cavity's depth behind the wall, which the
//! search weighs against the other level's loss. Where the budget affords the input's own
//! topology (step 0), the input's collapse stands and the second search is not run.
//!
//! Cost: one pass to find the cavities (O(F log F) plus a ray per cavity), and, for inputs
//! that have some, a second search per budget (the same steps 1 to 4 on the filled input).

use voxlod_core::cavities::{fill_cavities, FilledCavities};

use super::candidate::{beats, Standing};
use super::context::BudgetContext;
use super::search::budget_level;
use super::{BudgetLevel, Stage};
use crate::error::Error;
use crate::lod::LodLevel;

/// The input mesh with its cavities filled, when it has any.
pub(super) fn filled_input(ctx: &BudgetContext) -> Option<FilledCavities> {
    ctx.welded
        .as_ref()
        .and_then(|(mesh, _)| fill_cavities(mesh))
}

/// The level for `budget` from the input as given (`given`) or, when one of `filled` (the
/// contexts of the input with its cavities filled, by this module or by module `enclosed`)
/// gives a closer one, from that; its report counts the cavities filled and the candidates of
/// all the searches. The searches, and the choice between them, hold the levels to
/// `genus_cap` (module `genus_cap`).
pub(super) fn budget_level_either(
    given: &BudgetContext,
    filled: &[(&BudgetContext, &FilledCavities)],
    budget: usize,
    error: Option<f64>,
    genus_cap: Option<i64>,
) -> Result<(LodLevel, BudgetLevel, Vec<String>), Error> {
    let mut best = budget_level(given, budget, error, genus_cap)?;
    if best.1.stage == Stage::InputQuadric {
        return Ok(best);
    }
    let mut candidates = best.1.candidates;
    for (ctx, cavities) in filled {
        let mut other = budget_level(ctx, budget, error, genus_cap)?;
        candidates += other.1.candidates;
        if closer(&other.1, &best.1, budget, genus_cap) {
            other.1.cavities_filled = cavities.cavities;
            best = other;
        }
    }
    best.1.candidates = candidates;
    Ok(best)
}

/// Whether level `a` beats level `b` for `budget`, by the rule of the search's candidates.
fn closer(a: &BudgetLevel, b: &BudgetLevel, budget: usize, genus_cap: Option<i64>) -> bool {
    beats(
        Standing::of(a, genus_cap),
        Standing::of(b, genus_cap),
        budget,
    )
}
