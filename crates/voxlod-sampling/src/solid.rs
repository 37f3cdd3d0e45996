//! What can be sampled: any solid that answers "where does this line enter and leave you?".
//!
//! The voxel paper's §2 accepts "polygonal meshes, volume datasets, objects derived from
//! range-scanners, and algebraic mathematical functions". Each kind implements [`Solid`]:
//! [`crate::MeshSolid`] (a triangle mesh through a BVH), [`crate::ThresholdSolid`] (a scanned
//! volume thresholded with trilinear interpolation) and [`crate::CsgSolid`] (primitives combined
//! by union, intersection and difference, such as the sphereflake and the mechanical part).
//! The sampler asks for the crossings of whole families of lattice lines at once, tile by tile
//! in parallel ([`crossings_per_tile`]); the cost of a family is each solid's own (see its
//! module).

use rayon::prelude::*;
use voxlod_core::{Bounds, Grid, WorldTransform};

use crate::lattice::{LineCrossings, LineFamily, TILE};
use crate::SamplingError;

/// A solid: the inside function S of the paper's equation 2, queried along lines.
pub trait Solid: Sync {
    /// A box that contains the solid.
    fn bounds(&self) -> Bounds;

    /// The sorted crossings of every line of `family` with the solid's boundary, in index units
    /// along the family's axis; inside is where an odd number of crossings lie before.
    fn crossings(&self, family: &LineFamily) -> Result<LineCrossings, SamplingError>;

    /// Work that the three families' [`Solid::crossings`] share, done before they are cast side
    /// by side: made lazily by the first of them instead, it would run on one thread while the
    /// others wait for it (a thresholded scan's cell classification). The default does nothing.
    fn prepare(&self) {}

    /// True when the crossings are exact (a closed mesh, an implicit solid, a thresholded
    /// volume). When false, the sampler corrects them by a majority vote of the three axis
    /// families ([`crate::majority`]).
    fn is_exact(&self) -> bool;

    /// Where the solid's grid space lies in the world, for a solid made from an oriented scan
    /// (`voxlod_core::world`): its meshes are moved there after contouring. `None` (the
    /// default): grid space is the world.
    fn world(&self) -> Option<WorldTransform> {
        None
    }

    /// An upper bound on the bricks of side `brick_size` of `grid` that hold a sample within
    /// `margin` samples of the solid's boundary (the narrow band, [`crate::narrow_band`]), when
    /// the solid can tell without casting the lattice; `None` (the default) when it cannot.
    fn band_bricks_bound(&self, grid: &Grid, brick_size: usize, margin: f64) -> Option<usize> {
        let _ = (grid, brick_size, margin);
        None
    }

    /// Bytes the process holds for this solid while a level is sampled (the solid, its search
    /// structure, the input the caller keeps), for the plan's estimate; 0 when unknown.
    fn resident_bytes(&self) -> u64 {
        0
    }
}

/// Fills a [`LineCrossings`] by calling `line(u, v, out)` for each line in parallel over tiles.
/// `line` appends the world coordinates (along the axis) of the crossings of the line at world
/// cross-coordinates `(u, v)`, in any order; they are sorted and converted here.
pub fn crossings_per_line<F>(family: &LineFamily, line: F) -> LineCrossings
where
    F: Fn(f64, f64, &mut Vec<f64>) + Sync,
{
    crossings_per_tile(family, |tile_m, tile_n, out| {
        let mut world = Vec::new();
        for (row, n) in tile_n.clone().enumerate() {
            for (col, m) in tile_m.clone().enumerate() {
                world.clear();
                let (u, v) = family.line_position(m, n);
                line(u, v, &mut world);
                let local = (row * TILE + col) as u16;
                out.extend(world.iter().map(|&w| (local, family.index_t(w) as f32)));
            }
        }
    })
}

/// Fills a [`LineCrossings`] tile by tile in parallel: `tile(m_range, n_range, out)` appends
/// `(local line, t)` pairs, `local = (n - n0) * TILE + (m - m0)`, `t` in index units.
pub fn crossings_per_tile<F>(family: &LineFamily, tile: F) -> LineCrossings
where
    F: Fn(std::ops::Range<usize>, std::ops::Range<usize>, &mut Vec<(u16, f32)>) + Sync,
{
    let (tiles_u, tiles_v) = family.tile_counts();
    let lists: Vec<Vec<(u16, f32)>> = (0..tiles_u * tiles_v)
        .into_par_iter()
        .map(|id| {
            let (m, n) = family.tile_lines(id % tiles_u, id / tiles_u);
            let mut out = Vec::new();
            tile(m, n, &mut out);
            sorted_by_line(out)
        })
        .collect();
    LineCrossings::from_tiles(*family, lists)
}

/// A tile's crossings sorted by line, then along the line (`f32::total_cmp`): counted into
/// their lines (at most `TILE²`), then each line's few crossings sorted. Crossings equal in
/// this order are equal bit for bit, so the result is the one any sort by the same order gives.
/// Cost: O(k + TILE²) for k crossings, plus a small sort per line; O(k) for a solid that walks
/// its lines in order (a thresholded scan), whose crossings come sorted.
fn sorted_by_line(out: Vec<(u16, f32)>) -> Vec<(u16, f32)> {
    if out.is_sorted_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)).is_le()) {
        return out;
    }
    let mut start = vec![0u32; TILE * TILE + 1];
    for &(line, _) in &out {
        start[line as usize + 1] += 1;
    }
    for l in 0..TILE * TILE {
        start[l + 1] += start[l];
    }
    let mut sorted = vec![(0u16, 0f32); out.len()];
    let mut next = start.clone();
    for &crossing in &out {
        let slot = &mut next[crossing.0 as usize];
        sorted[*slot as usize] = crossing;
        *slot += 1;
    }
    for line in start.windows(2) {
        sorted[line[0] as usize..line[1] as usize].sort_unstable_by(|a, b| a.1.total_cmp(&b.1));
    }
    sorted
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// Random tiles (repeated positions, both zeros, lines left empty) come out of
    /// `sorted_by_line` as out of the comparison sort, bit for bit.
    #[test]
    fn lines_counted_then_sorted_are_the_comparison_sort() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(16);
        for size in [0, 1, 7, 300, 5000] {
            let crossings: Vec<(u16, f32)> = (0..size)
                .map(|_| {
                    let line = rng.random_range(0..(TILE * TILE) as u16 / 3) * 3;
                    let t = match rng.random_range(0..4) {
                        0 => 0.0,
                        1 => -0.0,
                        2 => rng.random_range(-4..4) as f32 * 0.5,
                        _ => rng.random_range(-100.0..100.0),
                    };
                    (line, t)
                })
                .collect();
            let mut expected = crossings.clone();
            expected.sort_unstable_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
            let bits = |v: &[(u16, f32)]| -> Vec<(u16, u32)> {
                v.iter().map(|&(l, t)| (l, t.to_bits())).collect()
            };
            assert_eq!(bits(&sorted_by_line(crossings)), bits(&expected), "{size}");
        }
    }
}
