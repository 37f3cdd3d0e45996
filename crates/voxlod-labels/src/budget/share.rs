//! A label's budget shared among its patches: each patch gets the same fraction of its
//! triangles, except that none gets fewer than its floor (what its locked vertices hold), the
//! others then taking a smaller fraction so that the shares still add up to the budget
//! (water filling). Where the floors alone exceed the budget, every patch gets its floor.
//!
//! Cost: O(P log P) for a label's P patches.

/// Each patch's share of `budget`, given its triangles and floor (`(triangles, floor)`, the
/// floor at most the triangles): `max(floor, ⌊r · triangles⌋)` with the one fraction `r` in
/// [0, 1] that brings the sum to the budget, or every patch's triangles when the budget covers
/// them all. The shares add up to at most the budget unless the floors do not.
pub(crate) fn shares(patches: &[(usize, usize)], budget: usize) -> Vec<usize> {
    let total: usize = patches.iter().map(|p| p.0).sum();
    if budget >= total {
        return patches.iter().map(|p| p.0).collect();
    }
    // Patches by the fraction below which their floor holds them, most held first.
    let mut order: Vec<usize> = (0..patches.len()).collect();
    let held = |p: &(usize, usize)| p.1 as f64 / p.0.max(1) as f64;
    order.sort_by(|&a, &b| held(&patches[b]).total_cmp(&held(&patches[a])));
    // Hold the first k at their floors while the fraction the rest would get is below theirs.
    let (mut floors, mut rest) = (0usize, total);
    let mut fraction = budget as f64 / total as f64;
    for &p in &order {
        if held(&patches[p]) <= fraction {
            break;
        }
        floors += patches[p].1;
        rest -= patches[p].0;
        fraction = if rest == 0 {
            0.0
        } else {
            budget.saturating_sub(floors) as f64 / rest as f64
        };
    }
    patches
        .iter()
        .map(|&(n, floor)| floor.max((fraction * n as f64).floor() as usize).min(n))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::shares;

    #[test]
    fn shares_are_even_fractions_above_the_floors() {
        // No floor binds: 10 % of each.
        assert_eq!(shares(&[(1000, 10), (500, 0)], 150), [100, 50]);
        // The second's floor (200) holds it: the first takes what is left, 300 − 200.
        assert_eq!(shares(&[(1000, 10), (500, 200)], 300), [100, 200]);
        // The floors exceed the budget: each at its floor.
        assert_eq!(shares(&[(1000, 400), (500, 200)], 300), [400, 200]);
        // A budget covering everything keeps everything.
        assert_eq!(shares(&[(10, 2), (5, 5)], 15), [10, 5]);
    }
}
