//! An upper bound on the narrow band of a triangle mesh, known before sampling it: the bricks
//! that hold a sample within `margin` samples (per axis) of some triangle's bounding box.
//!
//! The narrow band ([`crate::narrow_band`]) keeps every brick within `R + 2` samples of a lattice
//! crossing; every crossing lies on a triangle, so inside that triangle's box, and the bricks
//! this marks are a superset of the band's. It is what lets the plan ([`crate::pyramid`]) state
//! the band's memory before the lattice is cast, instead of only the lattice's.
//!
//! A triangle longer than a brick is split at its edges' midpoints until its pieces are not, so
//! that the boxes of a large slanted triangle follow its plane instead of filling its box.
//!
//! Beyond the paper (which samples a dense grid). **Cost.** O(T · b) for T triangles, b the
//! bricks each piece's box covers (one to eight for pieces smaller than a brick), plus the
//! pieces of large triangles (about their area in bricks); memory one bit per brick of the grid,
//! checked against the budget.

use glam::DVec3;
use voxlod_core::{memory, Grid};

/// How many bricks of side `brick_size` of `grid` hold a sample within `margin` samples of the
/// bounding box of one of `triangles`; `None` when the bitmap of the grid's bricks would not
/// fit in memory.
pub fn triangle_band_bricks(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    grid: &Grid,
    brick_size: usize,
    margin: f64,
) -> Option<usize> {
    let b = brick_size.max(1);
    let brick_dims = grid.dims.map(|d| d.div_ceil(b));
    let bricks = brick_dims
        .iter()
        .try_fold(1usize, |acc, &n| acc.checked_mul(n))?;
    let words = bricks.div_ceil(64);
    memory::check_allocation("the band's estimate", memory::bytes_of::<u64>(words)).ok()?;
    let mut flags = vec![0u64; words];
    let to_samples = |p: DVec3| (p - DVec3::from(grid.origin)) / DVec3::from(grid.spacing);
    let mut pieces: Vec<[DVec3; 3]> = Vec::new();
    for t in triangles {
        pieces.push(t.map(|v| to_samples(positions[v as usize])));
        // A triangle longer than a brick is split at its edges' midpoints until its pieces
        // are not: the boxes of a large slanted triangle's pieces follow its plane.
        while let Some(c) = pieces.pop() {
            let lo = c[0].min(c[1]).min(c[2]);
            let hi = c[0].max(c[1]).max(c[2]);
            let outside = (0..3)
                .any(|a| !(hi[a] + margin >= 0.0 && lo[a] - margin <= (grid.dims[a] - 1) as f64));
            if outside {
                continue;
            }
            if (hi - lo).max_element() > b as f64 {
                let m = [
                    (c[0] + c[1]) / 2.0,
                    (c[1] + c[2]) / 2.0,
                    (c[2] + c[0]) / 2.0,
                ];
                pieces.extend([
                    [c[0], m[0], m[2]],
                    [m[0], c[1], m[1]],
                    [m[2], m[1], c[2]],
                    m,
                ]);
                continue;
            }
            mark_box(&mut flags, grid.dims, brick_dims, b, lo, hi, margin);
        }
    }
    Some(flags.iter().map(|w| w.count_ones() as usize).sum())
}

/// Flags the bricks holding a sample within `margin` of the box `lo ..= hi` (sample units).
fn mark_box(
    flags: &mut [u64],
    dims: [usize; 3],
    brick_dims: [usize; 3],
    b: usize,
    lo: DVec3,
    hi: DVec3,
    margin: f64,
) {
    let range = |a: usize| {
        let last = (dims[a] - 1) as f64;
        let (lo, hi) = (lo[a] - margin, hi[a] + margin);
        if !(hi >= 0.0 && lo <= last) {
            return None;
        }
        let first = lo.ceil().clamp(0.0, last) as usize;
        let end = hi.floor().clamp(0.0, last) as usize;
        Some((first / b)..=(end / b))
    };
    let (Some(x), Some(y), Some(z)) = (range(0), range(1), range(2)) else {
        return;
    };
    for k in z {
        for j in y.clone() {
            for i in x.clone() {
                let index = i + brick_dims[0] * (j + brick_dims[1] * k);
                flags[index / 64] |= 1 << (index % 64);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_small_triangle_marks_the_bricks_its_widened_box_reaches() {
        let grid = Grid::new([32, 32, 32], [1.0; 3], [0.0; 3]).unwrap();
        let positions = [
            DVec3::new(10.0, 10.0, 10.0),
            DVec3::new(12.0, 10.0, 10.0),
            DVec3::new(10.0, 12.0, 10.0),
        ];
        let t = [[0, 1, 2]];
        // Samples 10..12 (+-0): brick 1 (8..16) on every axis.
        assert_eq!(triangle_band_bricks(&positions, &t, &grid, 8, 0.0), Some(1));
        // Widened by 3: samples 7..15 on x and y, 7..13 on z: bricks 0 and 1 on each axis.
        assert_eq!(triangle_band_bricks(&positions, &t, &grid, 8, 3.0), Some(8));
        // Outside the grid: nothing.
        let far = positions.map(|p| p + DVec3::splat(100.0));
        assert_eq!(triangle_band_bricks(&far, &t, &grid, 8, 3.0), Some(0));
    }
}
