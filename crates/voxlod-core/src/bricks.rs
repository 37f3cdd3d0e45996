//! A sparse volume of bricks, in the manner of OpenVDB's leaf level: the grid is cut into cubes
//! of `B³` samples (B = 8 or 16), and each brick is either **uniform** (one value for all its
//! samples) or a **leaf** (its `B³` values stored densely, x fastest).
//!
//! This is the type between narrow-band sampling and sparse marching cubes:
//! far from the surface the filtered density of paper §2 is exactly 0 or 1, so those bricks
//! cost one value each, and only the band of bricks the surface reaches stores samples. The
//! paper itself samples a dense grid; the bricks are beyond it and give the same samples.
//!
//! **Cost.** 8 bytes per brick (its value and leaf slot) plus `4 B³` bytes per leaf; a read of
//! one sample is two shifts, one index and one load. Leaves at the grid's upper faces are
//! padded to `B³`; the padding is never read.

use crate::{memory, CoreError, Grid, Volume};

/// No leaf: the brick is uniform.
const NO_LEAF: u32 = u32::MAX;

/// One brick's samples, as [`BrickVolume::brick`] returns them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Brick<'a> {
    /// Every sample of the brick has this value.
    Uniform(f32),
    /// The brick's `B³` samples, x fastest (samples past the grid are padding).
    Leaf(&'a [f32]),
}

/// A grid's samples stored brick by brick (see the module documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct BrickVolume {
    /// The sample grid the bricks cut up.
    pub grid: Grid,
    /// log2 of the brick side.
    shift: u32,
    brick_dims: [usize; 3],
    /// Per brick, its uniform value (unused for leaves).
    values: Vec<f32>,
    /// Per brick, its leaf's slot in `leaves`, or `NO_LEAF`.
    slots: Vec<u32>,
    /// The leaves' samples, `B³` per leaf, in slot order.
    leaves: Vec<f32>,
    /// Brick index of each leaf, in slot order (increasing).
    leaf_bricks: Vec<u32>,
}

impl BrickVolume {
    /// The brick sides this type accepts.
    pub const BRICK_SIZES: [usize; 2] = [8, 16];
    /// OpenVDB's leaf size.
    pub const DEFAULT_BRICK_SIZE: usize = 8;

    /// Bytes a brick volume of `grid` with `leaves` leaves takes.
    pub fn estimated_bytes(grid: &Grid, brick_size: usize, leaves: usize) -> u64 {
        let bricks: u64 = grid
            .dims
            .iter()
            .map(|&d| d.div_ceil(brick_size.max(1)) as u64)
            .product();
        let per_leaf = memory::bytes_of::<f32>(brick_size.pow(3)) + 4;
        bricks
            .saturating_mul(8)
            .saturating_add(per_leaf.saturating_mul(leaves as u64))
    }

    /// A volume whose bricks listed in `leaf_mask` (one flag per brick, x fastest) are leaves
    /// filled with their brick's value, and the others uniform with `values[brick]`. The
    /// memory is checked first. Fill the leaves through [`BrickVolume::leaves_mut`].
    pub fn from_leaves(
        grid: Grid,
        brick_size: usize,
        values: Vec<f32>,
        leaf_mask: &[bool],
    ) -> Result<BrickVolume, CoreError> {
        let shift = brick_shift(brick_size)?;
        let brick_dims = grid.dims.map(|d| d.div_ceil(brick_size));
        let count = brick_dims.iter().product::<usize>();
        if values.len() != count || leaf_mask.len() != count {
            return Err(CoreError::InvalidGrid(format!(
                "{} brick values and {} leaf flags given for {count} bricks",
                values.len(),
                leaf_mask.len()
            )));
        }
        let leaf_count = leaf_mask.iter().filter(|&&l| l).count();
        if leaf_count >= NO_LEAF as usize {
            return Err(CoreError::InvalidGrid(format!("{leaf_count} leaves")));
        }
        memory::check_allocation(
            "the brick volume",
            Self::estimated_bytes(&grid, brick_size, leaf_count),
        )?;
        let volume = brick_size.pow(3);
        let mut slots = vec![NO_LEAF; count];
        let mut leaf_bricks = Vec::with_capacity(leaf_count);
        let mut leaves: Vec<f32> = memory::zeroed_vec(leaf_count * volume);
        for (b, _) in leaf_mask.iter().enumerate().filter(|(_, &l)| l) {
            slots[b] = leaf_bricks.len() as u32;
            let value = values[b];
            if value != 0.0 {
                leaves[leaf_bricks.len() * volume..][..volume].fill(value);
            }
            leaf_bricks.push(b as u32);
        }
        Ok(BrickVolume {
            grid,
            shift,
            brick_dims,
            values,
            slots,
            leaves,
            leaf_bricks,
        })
    }

    /// A volume from its parts, as a builder that made the leaves itself assembles them (the
    /// blockwise threshold route, brick by brick): `values` one per brick (used for the bricks
    /// not in `leaf_bricks`), `leaf_bricks` the leaves' brick indices, strictly increasing, and
    /// `leaves` their `B³` samples each, in that order.
    pub fn from_parts(
        grid: Grid,
        brick_size: usize,
        values: Vec<f32>,
        leaf_bricks: Vec<u32>,
        leaves: Vec<f32>,
    ) -> Result<BrickVolume, CoreError> {
        let shift = brick_shift(brick_size)?;
        let brick_dims = grid.dims.map(|d| d.div_ceil(brick_size));
        let count = brick_dims.iter().product::<usize>();
        let increasing = leaf_bricks.windows(2).all(|w| w[0] < w[1]);
        let in_range = leaf_bricks.last().is_none_or(|&b| (b as usize) < count);
        if values.len() != count
            || !increasing
            || !in_range
            || leaves.len() != leaf_bricks.len() * brick_size.pow(3)
            || leaf_bricks.len() >= NO_LEAF as usize
        {
            return Err(CoreError::InvalidGrid(format!(
                "{} brick values, {} leaves ({} samples) do not make a brick volume of {count} bricks",
                values.len(),
                leaf_bricks.len(),
                leaves.len()
            )));
        }
        let mut slots = vec![NO_LEAF; count];
        for (slot, &b) in leaf_bricks.iter().enumerate() {
            slots[b as usize] = slot as u32;
        }
        Ok(BrickVolume {
            grid,
            shift,
            brick_dims,
            values,
            slots,
            leaves,
            leaf_bricks,
        })
    }

    /// Every brick uniform with `value`.
    pub fn uniform(grid: Grid, brick_size: usize, value: f32) -> Result<BrickVolume, CoreError> {
        let count: usize = grid
            .dims
            .map(|d| d.div_ceil(brick_size.max(1)))
            .iter()
            .product();
        memory::check_allocation(
            "the brick volume",
            Self::estimated_bytes(&grid, brick_size, 0),
        )?;
        Self::from_leaves(grid, brick_size, vec![value; count], &vec![false; count])
    }

    /// The samples of a dense volume, a brick uniform where all its samples are bitwise equal.
    pub fn from_volume(volume: &Volume, brick_size: usize) -> Result<BrickVolume, CoreError> {
        let grid = volume.grid;
        let b = brick_size;
        brick_shift(b)?;
        let brick_dims = grid.dims.map(|d| d.div_ceil(b));
        let mut values = Vec::with_capacity(brick_dims.iter().product());
        let mut mask = Vec::with_capacity(values.capacity());
        for [bx, by, bz] in brick_coords(brick_dims) {
            let first = volume.get(bx * b, by * b, bz * b);
            let uniform = brick_samples(&grid, b, [bx, by, bz])
                .all(|[i, j, k]| volume.get(i, j, k).to_bits() == first.to_bits());
            values.push(first);
            mask.push(!uniform);
        }
        let mut bricks = Self::from_leaves(grid, b, values, &mask)?;
        let leaf_bricks = bricks.leaf_bricks.clone();
        for (leaf, &brick) in bricks.leaves_mut().chunks_mut(b * b * b).zip(&leaf_bricks) {
            let origin = brick_origin(brick_dims, b, brick as usize);
            for [i, j, k] in brick_samples(&grid, b, origin.map(|o| o / b)) {
                leaf[local_index(b, [i, j, k])] = volume.get(i, j, k);
            }
        }
        Ok(bricks)
    }

    /// The samples as one dense volume (for small grids and tests).
    pub fn to_volume(&self) -> Result<Volume, CoreError> {
        let mut volume = Volume::filled(self.grid, 0.0, "the dense copy of a brick volume")?;
        let [nx, ny, _] = self.grid.dims;
        for (index, value) in volume.as_slice_mut().iter_mut().enumerate() {
            let (i, j, k) = (index % nx, (index / nx) % ny, index / (nx * ny));
            *value = self.get(i, j, k);
        }
        Ok(volume)
    }

    /// The side B of a brick.
    pub fn brick_size(&self) -> usize {
        1 << self.shift
    }

    /// Bricks along each axis.
    pub fn brick_dims(&self) -> [usize; 3] {
        self.brick_dims
    }

    /// Bricks in all.
    pub fn brick_count(&self) -> usize {
        self.slots.len()
    }

    /// Bricks stored densely.
    pub fn leaf_count(&self) -> usize {
        self.leaf_bricks.len()
    }

    /// Brick index of each leaf, increasing; the leaves of [`BrickVolume::leaves_mut`] follow
    /// this order.
    pub fn leaf_bricks(&self) -> &[u32] {
        &self.leaf_bricks
    }

    /// The leaves' samples, `B³` per leaf in the order of [`BrickVolume::leaf_bricks`].
    pub fn leaves_mut(&mut self) -> &mut [f32] {
        &mut self.leaves
    }

    /// Linear index of brick (bx, by, bz), x fastest.
    #[inline]
    pub fn brick_index(&self, b: [usize; 3]) -> usize {
        b[0] + self.brick_dims[0] * (b[1] + self.brick_dims[1] * b[2])
    }

    /// The brick with linear index `index`.
    #[inline]
    pub fn brick(&self, index: usize) -> Brick<'_> {
        match self.slots[index] {
            NO_LEAF => Brick::Uniform(self.values[index]),
            slot => {
                let n = 1usize << (3 * self.shift);
                Brick::Leaf(&self.leaves[slot as usize * n..][..n])
            }
        }
    }

    /// Sample (i, j, k).
    #[inline]
    pub fn get(&self, i: usize, j: usize, k: usize) -> f32 {
        debug_assert!(i < self.grid.dims[0] && j < self.grid.dims[1] && k < self.grid.dims[2]);
        let s = self.shift;
        let brick = self.brick_index([i >> s, j >> s, k >> s]);
        match self.slots[brick] {
            NO_LEAF => self.values[brick],
            slot => {
                let m = (1usize << s) - 1;
                let local = (i & m) | ((j & m) << s) | ((k & m) << (2 * s));
                self.leaves[((slot as usize) << (3 * s)) + local]
            }
        }
    }
}

/// log2 of an accepted brick side.
fn brick_shift(brick_size: usize) -> Result<u32, CoreError> {
    if BrickVolume::BRICK_SIZES.contains(&brick_size) {
        Ok(brick_size.trailing_zeros())
    } else {
        Err(CoreError::InvalidGrid(format!(
            "brick side {brick_size}: must be one of {:?}",
            BrickVolume::BRICK_SIZES
        )))
    }
}

/// Every brick's coordinates, x fastest.
pub fn brick_coords(brick_dims: [usize; 3]) -> impl Iterator<Item = [usize; 3]> {
    let [bx, by, bz] = brick_dims;
    (0..bz).flat_map(move |k| (0..by).flat_map(move |j| (0..bx).map(move |i| [i, j, k])))
}

/// First sample of the brick with linear index `brick`.
pub fn brick_origin(brick_dims: [usize; 3], brick_size: usize, brick: usize) -> [usize; 3] {
    let [bx, by, _] = brick_dims;
    [brick % bx, (brick / bx) % by, brick / (bx * by)].map(|c| c * brick_size)
}

/// The grid samples of brick `b` (clipped to the grid), x fastest.
pub fn brick_samples(
    grid: &Grid,
    brick_size: usize,
    b: [usize; 3],
) -> impl Iterator<Item = [usize; 3]> {
    let range = |a: usize| b[a] * brick_size..((b[a] + 1) * brick_size).min(grid.dims[a]);
    let (rx, ry, rz) = (range(0), range(1), range(2));
    rz.flat_map(move |k| {
        let rx = rx.clone();
        ry.clone()
            .flat_map(move |j| rx.clone().map(move |i| [i, j, k]))
    })
}

/// Index of global sample `p` inside its brick's leaf.
#[inline]
pub fn local_index(brick_size: usize, p: [usize; 3]) -> usize {
    let m = brick_size - 1;
    (p[0] & m) + brick_size * ((p[1] & m) + brick_size * (p[2] & m))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp(dims: [usize; 3]) -> Volume {
        let grid = Grid::new(dims, [0.5; 3], [1.0, 2.0, 3.0]).unwrap();
        let values = (0..grid.len())
            .map(|n| {
                let (i, j, k) = (
                    n % dims[0],
                    (n / dims[0]) % dims[1],
                    n / (dims[0] * dims[1]),
                );
                // Constant (and so uniform bricks) below z = 8, distinct values above.
                if k < 8 {
                    -1.0
                } else {
                    (i + 100 * j + 10_000 * k) as f32
                }
            })
            .collect();
        Volume::from_vec(grid, values).unwrap()
    }

    #[test]
    fn round_trips_a_dense_volume_with_partial_edge_bricks() {
        let dense = ramp([19, 10, 21]);
        for b in [8, 16] {
            let bricks = BrickVolume::from_volume(&dense, b).unwrap();
            assert_eq!(
                bricks.brick_dims(),
                [19, 10, 21].map(|d: usize| d.div_ceil(b))
            );
            assert_eq!(bricks.to_volume().unwrap(), dense, "brick side {b}");
            // The bricks below z = 8 are uniform, all others leaves.
            let [bx, by, bz] = bricks.brick_dims();
            let uniform_layers = 8 / b;
            assert_eq!(bricks.leaf_count(), bx * by * (bz - uniform_layers));
            let first_is_uniform = matches!(bricks.brick(0), Brick::Uniform(v) if v == -1.0);
            assert_eq!(first_is_uniform, b == 8, "brick side {b}");
        }
    }

    #[test]
    fn rejects_bad_brick_sizes_and_counts() {
        let grid = Grid::unit([4, 4, 4]).unwrap();
        assert!(BrickVolume::uniform(grid, 4, 0.0).is_err());
        assert!(BrickVolume::from_leaves(grid, 8, vec![0.0; 2], &[false; 2]).is_err());
        let u = BrickVolume::uniform(grid, 8, 2.5).unwrap();
        assert_eq!(
            (u.brick_count(), u.leaf_count(), u.get(3, 2, 1)),
            (1, 0, 2.5)
        );
    }
}
