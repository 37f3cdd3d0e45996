//! Cavities filled (our addition): when the input mesh has closed
//! shells that bound voids inside its material ([`voxlod_core::cavities`]: a hollow part's
//! inner wall, the marrow spaces of a CT bone surface), each budget's search runs a second time
//! on the input with those cavities filled, and the better of the two levels is kept (by the
//! search's rule, and between levels that tie on its tiers by module `silhouettes`).
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

use super::candidate::{beats, tier, Standing};
use super::context::BudgetContext;
use super::genus_cap::Found;
use super::search::budget_level;
use super::silhouettes::balanced_choice;
use super::Stage;
use crate::error::PyramidError;

/// The input mesh with its cavities filled, when it has any.
pub(super) fn filled_input(ctx: &BudgetContext) -> Option<FilledCavities> {
    ctx.welded
        .as_ref()
        .and_then(|(mesh, _)| fill_cavities(mesh))
}

/// The level for `budget` from the input as given (`given`) or, when one of `filled` (the
/// contexts of the input with its cavities filled, by this module or by module `enclosed`)
/// gives a better one, from that; its report counts the cavities filled and the candidates of
/// all the searches. Better: the search's rule (module `candidate`), and between levels that
/// tie on its tiers, the balance of distance and silhouette of module `silhouettes`. The
/// searches, and the choice between them, hold the levels to `genus_cap` (module `genus_cap`).
pub(super) fn budget_level_either(
    given: &BudgetContext,
    filled: &[(&BudgetContext, &FilledCavities)],
    budget: usize,
    error: Option<f64>,
    genus_cap: Option<i64>,
) -> Result<Found, PyramidError> {
    let first = budget_level(given, budget, error, genus_cap)?;
    if first.1.stage == Stage::InputQuadric || filled.is_empty() {
        return Ok(first);
    }
    let mut levels = vec![first];
    for (ctx, cavities) in filled {
        let mut other = budget_level(ctx, budget, error, genus_cap)?;
        other.1.cavities_filled = cavities.cavities;
        levels.push(other);
    }
    let candidates = levels.iter().map(|l| l.1.candidates).sum();
    let mut best = choose(given, levels, budget, genus_cap);
    best.1.candidates = candidates;
    Ok(best)
}

/// The best of the solids' levels (see [`budget_level_either`]).
fn choose(
    given: &BudgetContext,
    mut levels: Vec<Found>,
    budget: usize,
    genus_cap: Option<i64>,
) -> Found {
    let standing = |l: &Found| Standing::of(&l.1, genus_cap);
    let mut leader = 0;
    for (i, level) in levels.iter().enumerate().skip(1) {
        if beats(standing(level), standing(&levels[leader]), budget) {
            leader = i;
        }
    }
    let top = tier(&standing(&levels[leader]), budget);
    let contenders: Vec<usize> = (0..levels.len())
        .filter(|&i| tier(&standing(&levels[i]), budget) == top && levels[i].1.hausdorff.is_some())
        .collect();
    if top == 3 || contenders.len() < 2 {
        return levels.swap_remove(leader);
    }
    let reference = match given.silhouettes() {
        Some(Ok(reference)) => reference,
        Some(Err(why)) => {
            let mut best = levels.swap_remove(leader);
            best.2.push(format!(
                "{why}: the levels of the filled input were compared by distance alone"
            ));
            return best;
        }
        None => return levels.swap_remove(leader),
    };
    let mut errors = Vec::with_capacity(contenders.len());
    for &i in &contenders {
        match reference.mesh_difference(&levels[i].0.mesh) {
            Ok(d) => {
                levels[i].1.silhouette_difference = Some(d.fraction);
                errors.push((levels[i].1.hausdorff.unwrap_or(f64::INFINITY), d.fraction));
            }
            Err(_) => errors.push((f64::INFINITY, f64::INFINITY)),
        }
    }
    let chosen = balanced_choice(&errors).map_or(leader, |k| contenders[k]);
    levels.swap_remove(chosen)
}
