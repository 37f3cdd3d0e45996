//! Z-order (Morton) sorting of query points, so that consecutive queries are near each other.
//!
//! Points are quantised to 21 bits per axis inside their bounding box and sorted by the
//! interleaved bits (ties by index, so the order is deterministic). Queries taken in this
//! order walk the BVH coherently: the nodes they touch stay in cache and each query can start
//! from the previous one's answer. Cost: O(n) for the keys, O(n log n) for the parallel sort,
//! 16 bytes per point while sorting.

use glam::DVec3;
use rayon::prelude::*;

/// Indices of `points` in Z-order.
pub fn z_order(points: &[DVec3]) -> Vec<u32> {
    debug_assert!(points.len() <= u32::MAX as usize);
    let (min, max) = points
        .par_iter()
        .fold(
            || (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(lo, hi), &p| (lo.min(p), hi.max(p)),
        )
        .reduce(
            || (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(a, b), (c, d)| (a.min(c), b.max(d)),
        );
    let cells = ((1u32 << 21) - 1) as f64;
    let extent = (max - min).max(DVec3::splat(f64::MIN_POSITIVE));
    let scale = DVec3::splat(cells) / extent;
    let mut keyed: Vec<(u64, u32)> = points
        .par_iter()
        .enumerate()
        .map(|(i, &p)| {
            // Non-finite points get clamped; they sort somewhere, which is all that matters.
            let q = ((p - min) * scale).clamp(DVec3::ZERO, DVec3::splat(cells));
            let key = spread_bits(q.x as u64)
                | spread_bits(q.y as u64) << 1
                | spread_bits(q.z as u64) << 2;
            (key, i as u32)
        })
        .collect();
    keyed.par_sort_unstable();
    keyed.into_iter().map(|(_, i)| i).collect()
}

/// Spreads the low 21 bits of `x` to every third bit.
fn spread_bits(x: u64) -> u64 {
    let mut x = x & 0x1f_ffff;
    x = (x | x << 32) & 0x001f_0000_0000_ffff;
    x = (x | x << 16) & 0x001f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spreads_bits_and_orders_along_the_curve() {
        assert_eq!(spread_bits(0b111), 0b1001001);
        assert_eq!(spread_bits(0x1f_ffff), 0x1249_2492_4924_9249);
        let points = [
            DVec3::new(1.0, 1.0, 1.0),
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(0.0, 0.0, 1.0),
            DVec3::new(1.0, 0.0, 0.0),
        ];
        assert_eq!(z_order(&points), vec![1, 3, 2, 0]);
        let empty: [DVec3; 0] = [];
        assert!(z_order(&empty).is_empty());
    }
}
