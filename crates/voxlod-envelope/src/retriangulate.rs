//! Filling the hole a removed vertex leaves: the triangulation of a polygon of `k` corners that
//! uses only allowed triangles and allowed diagonals and whose worst triangle is best.
//!
//! Paper §6.3 asks whether the hole "can be triangulated" with the candidate among its triangles;
//! a polygon has Catalan-many triangulations, but the best one under a max–min criterion falls out
//! of the classic interval dynamic programme: `best(i, j)` for the sub-polygon `i..=j` is the best
//! over `m` of `min(quality(i, m, j), best(i, m), best(m, j))`. A triangle is forbidden by giving
//! it quality ≤ 0; the caller forbids triangles the envelope refuses and re-runs, so only the
//! triangles of the triangulations actually proposed are ever tested against the envelope.
//!
//! Cost: O(k³) time and O(k²) memory; k is a vertex's valence (6 on average).

/// The best triangulation of the polygon `0, 1, …, k − 1` (in order around the hole), written
/// to `out` as corner-index triples `(i, m, j)` with `i < m < j` (the polygon's orientation), or
/// `None` when every triangulation uses a forbidden triangle or diagonal. Returns the quality of
/// its worst triangle.
///
/// `quality[(i * k + m) * k + j]` is the quality of triangle `(i, m, j)`, `i < m < j` (≤ 0 or NaN
/// forbids it); `diagonal_free[i * k + j]` (for `i < j`) says whether `i–j` may become an edge
/// (sides of the polygon need not be free).
pub(crate) fn best_triangulation(
    k: usize,
    quality: &[f64],
    diagonal_free: &[bool],
    out: &mut Vec<[usize; 3]>,
) -> Option<f64> {
    debug_assert!(k >= 3);
    debug_assert!(quality.len() >= k * k * k && diagonal_free.len() >= k * k);
    out.clear();
    let mut best = vec![f64::NEG_INFINITY; k * k];
    let mut choice = vec![0u8; k * k];
    for i in 0..k - 1 {
        best[i * k + i + 1] = f64::INFINITY;
    }
    for len in 2..k {
        for i in 0..k - len {
            let j = i + len;
            let outer_side = i == 0 && j == k - 1;
            if !outer_side && !diagonal_free[i * k + j] {
                continue;
            }
            let mut top = f64::NEG_INFINITY;
            let mut arg = 0;
            for m in i + 1..j {
                let q = quality[(i * k + m) * k + j];
                // NaN and non-positive qualities forbid the triangle.
                if q.is_nan() || q <= 0.0 {
                    continue;
                }
                let worst = q.min(best[i * k + m]).min(best[m * k + j]);
                if worst > top {
                    top = worst;
                    arg = m;
                }
            }
            best[i * k + j] = top;
            choice[i * k + j] = arg as u8;
        }
    }
    let total = best[k - 1];
    if total.is_nan() || total <= 0.0 {
        return None;
    }
    let mut pending = vec![(0usize, k - 1)];
    while let Some((i, j)) = pending.pop() {
        if j - i < 2 {
            continue;
        }
        let m = choice[i * k + j] as usize;
        out.push([i, m, j]);
        pending.push((i, m));
        pending.push((m, j));
    }
    debug_assert_eq!(out.len(), k - 2);
    Some(total)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Quality of every triangle of a convex polygon: its smallest index gap (a stand-in).
    fn table(k: usize, f: impl Fn(usize, usize, usize) -> f64) -> Vec<f64> {
        let mut q = vec![f64::NAN; k * k * k];
        for i in 0..k {
            for m in i + 1..k {
                for j in m + 1..k {
                    q[(i * k + m) * k + j] = f(i, m, j);
                }
            }
        }
        q
    }

    #[test]
    fn picks_the_max_min_triangulation() {
        // Square 0-1-2-3: diagonal 0–2 gives (0,1,2), (0,2,3); diagonal 1–3 gives (0,1,3), (1,2,3).
        let q = table(4, |i, m, j| match (i, m, j) {
            (0, 1, 2) => 0.9,
            (0, 2, 3) => 0.2,
            (0, 1, 3) => 0.5,
            (1, 2, 3) => 0.6,
            _ => unreachable!(),
        });
        let free = vec![true; 16];
        let mut out = Vec::new();
        assert_eq!(best_triangulation(4, &q, &free, &mut out), Some(0.5));
        out.sort_unstable();
        assert_eq!(out, vec![[0, 1, 3], [1, 2, 3]]);
        // Forbid diagonal 1–3: the other one is the only choice left.
        let mut free = free;
        free[4 + 3] = false;
        assert_eq!(best_triangulation(4, &q, &free, &mut out), Some(0.2));
        // Forbid triangle (0,2,3) too: nothing is left.
        let mut q = q;
        // Triangle (0, 2, 3) sits at (0·4 + 2)·4 + 3.
        q[2 * 4 + 3] = -1.0;
        assert_eq!(best_triangulation(4, &q, &free, &mut out), None);
    }

    #[test]
    fn every_size_gives_k_minus_2_triangles_covering_the_sides() {
        for k in 3..=20 {
            let q = table(k, |i, m, j| {
                1.0 / (1.0 + ((j - m) as f64 - (m - i) as f64).abs())
            });
            let mut out = Vec::new();
            assert!(best_triangulation(k, &q, &vec![true; k * k], &mut out).is_some());
            assert_eq!(out.len(), k - 2);
            // Every side of the polygon is used exactly once; every diagonal twice.
            let mut uses = std::collections::HashMap::new();
            for &[i, m, j] in &out {
                assert!(i < m && m < j);
                for e in [(i, m), (m, j), (i, j)] {
                    *uses.entry(e).or_insert(0) += 1;
                }
            }
            for (&(a, b), &n) in &uses {
                let side = b == a + 1 || (a == 0 && b == k - 1);
                assert_eq!(n, if side { 1 } else { 2 }, "k {k} edge {a}-{b}");
            }
        }
    }
}
