//! The direct route of paper §4 (the second route: "directly apply the reconstruction filters
//! with different radius supports on the original volumes", [`crate::direct`]) block by block,
//! for scans read window by window or filtered on a cluster (`voxlod.dask.lod_volume(...,
//! direct=True)` in the Python package).
//!
//! A level's grid is cut into boxes of samples (blocks). A sample's filtered value is the
//! filter-weighted mean of the data samples within the support radius R of its position, with
//! the scan's minimum (the background) outside the scan, or trilinear interpolation where no
//! data sample lies within R ([`crate::direct_density`]). So a block needs the data samples
//! within R of its box: its *window*, the box's span on the scan grid grown by the support's
//! reach ⌈R/h⌉ (h the data spacing) and one more sample on each side, cut to the scan.
//! [`BlockwiseDirect::fill_block`] evaluates each sample of the block with the very code of
//! [`crate::direct_density`] over that window, indexed by the whole scan's indices and with the
//! whole scan's minimum as the background, so every sample is the single-process value bit for
//! bit (the same data, weights and summation order; `tests` below check it on several scans).
//! Nothing else is shared between blocks: the filter is not separable (a radial profile cut at
//! R), so there is no boundary rule to reconcile, only the halo.
//!
//! Beyond the paper, which filters the whole volume in memory. **Cost**: each block reads its
//! window once and does the work of the dense route for its samples, O(samples × (2R/h)³); a
//! level reads the scan about once plus the halos (blocks are sized so that a window spans about
//! [`WINDOW_SIDE`] scan samples where the reach allows). At coarse levels, where the halos 2R
//! span more than that, a block's own span is made at least 2R: a window then spans at most
//! twice its block per axis, so a level reads the scan at most about 8 times (a block of one
//! sample with a window of 2R would read it (2R/h)³ times over in tiny tasks). **Memory**: a
//! window of the scan as `f32` per block in flight (at most about (4R/h)³ samples at coarse
//! levels), and the level's dense grid where the blocks are gathered
//! ([`BlockwiseDirect::place_block`]), as the dense route holds it.

use rayon::prelude::*;
use serde::Serialize;
use voxlod_core::{memory, Grid, Volume};

use crate::blockwise_threshold::BlockwiseError;
use crate::direct::{check_radius, DataView, Support};
use crate::{Filter, SamplingError};

/// Scan samples per side that a block's window aims at by default (64 MiB of `f32`).
pub const WINDOW_SIDE: usize = 256;

/// A level of a scan filtered directly, cut into blocks (see the module documentation).
#[derive(Clone, Debug, Serialize)]
pub struct BlockwiseDirect {
    /// The whole scan's grid.
    pub scan: Grid,
    /// The level's grid.
    pub grid: Grid,
    /// The reconstruction filter.
    pub filter: Filter,
    /// Its support radius, world units.
    pub radius: f64,
    /// The value outside the scan: the scan's smallest finite sample.
    pub background: f32,
    /// Samples of the level per block along x, y, z.
    pub block_side: [usize; 3],
    /// Scan samples the support reaches along x, y, z (saturated for absurd ratios).
    pub reach: [u64; 3],
}

impl BlockwiseDirect {
    /// The blocks of `grid` (a level of the scan with grid `scan`) filtered with `filter` of
    /// support `radius`, `background` outside the scan (its smallest finite sample). Blocks are
    /// sized so that a window spans about `window_side` scan samples ([`WINDOW_SIDE`] is a good
    /// default), a block's own span at least its two halos (so that coarse levels are not cut
    /// into windows mostly of halo), and at least one sample of the level.
    pub fn new(
        scan: Grid,
        grid: &Grid,
        filter: Filter,
        radius: f64,
        background: f32,
        window_side: usize,
    ) -> Result<BlockwiseDirect, SamplingError> {
        check_radius(radius)?;
        if !background.is_finite() {
            return Err(SamplingError::InvalidOption(format!(
                "the background {background} is not a finite number"
            )));
        }
        let reach = Support::new(filter, radius, scan.spacing)
            .reach
            .map(|r| r.max(0) as u64);
        let block_side = [0, 1, 2].map(|a| {
            // Scan samples per level sample along the axis, and what the window leaves for the
            // block's own span once the halo on both sides is counted; at least the two halos
            // themselves, so that a window reads at most twice its block's span per axis.
            let step = grid.spacing[a] / scan.spacing[a];
            let halos = 2.0 * (reach[a] as f64 + 1.0);
            let own = (window_side as f64 - halos).max(halos);
            ((own / step).floor().max(1.0) as usize).min(grid.dims[a])
        });
        Ok(BlockwiseDirect {
            scan,
            grid: *grid,
            filter,
            radius,
            background,
            block_side,
            reach,
        })
    }

    /// Blocks along each axis.
    pub fn block_dims(&self) -> [usize; 3] {
        [0, 1, 2].map(|a| self.grid.dims[a].div_ceil(self.block_side[a]))
    }

    /// How many blocks the level has.
    pub fn block_count(&self) -> usize {
        self.block_dims().iter().product()
    }

    /// Block number `n` (x fastest) as block coordinates.
    pub fn block_at(&self, n: usize) -> [usize; 3] {
        let [bx, by, _] = self.block_dims();
        [n % bx, (n / bx) % by, n / (bx * by)]
    }

    /// The level's samples of `block`: first sample and extent (x, y, z).
    pub fn block_box(&self, block: [usize; 3]) -> ([usize; 3], [usize; 3]) {
        let first = [0, 1, 2].map(|a| block[a] * self.block_side[a]);
        let extent =
            [0, 1, 2].map(|a| self.block_side[a].min(self.grid.dims[a].saturating_sub(first[a])));
        (first, extent)
    }

    /// The scan samples `block` reads: first sample and extent (x, y, z). Every data sample
    /// within the support of a sample of the block, and the two on either side of its position
    /// (for the trilinear fallback), lie in it.
    pub fn scan_window(&self, block: [usize; 3]) -> ([usize; 3], [usize; 3]) {
        let (first, extent) = self.block_box(block);
        let mut start = [0; 3];
        let mut window = [0; 3];
        for a in 0..3 {
            let at = |sample: usize| {
                let p = self.grid.origin[a] + sample as f64 * self.grid.spacing[a];
                (p - self.scan.origin[a]) / self.scan.spacing[a]
            };
            let margin = self.reach[a] as f64 + 1.0;
            let last = (self.scan.dims[a] - 1) as f64;
            let low = (at(first[a]).floor() - margin).clamp(0.0, last) as usize;
            let high = (at(first[a] + extent[a] - 1).ceil() + margin).clamp(0.0, last) as usize;
            let low = low.min(high);
            start[a] = low;
            window[a] = high - low + 1;
        }
        (start, window)
    }

    /// The filtered samples of `block` (x fastest over its box, [`BlockwiseDirect::block_box`])
    /// from `window`, the scan samples [`BlockwiseDirect::scan_window`] names.
    pub fn fill_block(
        &self,
        block: [usize; 3],
        window: &Volume,
    ) -> Result<Vec<f32>, SamplingError> {
        let blocks = self.block_dims();
        if (0..3).any(|a| block[a] >= blocks[a]) {
            return Err(SamplingError::InvalidOption(format!(
                "block {block:?} of a level of {blocks:?} blocks"
            )));
        }
        let (start, expected) = self.scan_window(block);
        if window.grid.dims != expected {
            return Err(SamplingError::InvalidOption(format!(
                "the window of block {block:?} has {:?} samples (x, y, z), not {expected:?}",
                window.grid.dims
            )));
        }
        let (first, extent) = self.block_box(block);
        let count: usize = extent.iter().product();
        memory::check_allocation("a block's samples", memory::bytes_of::<f32>(count))?;
        let support = Support::new(self.filter, self.radius, self.scan.spacing);
        let data = DataView {
            samples: window,
            start,
            scan: self.scan,
        };
        let [ex, ey, _] = extent;
        let mut out: Vec<f32> = memory::zeroed_vec(count);
        out.par_chunks_mut(ex * ey)
            .enumerate()
            .for_each(|(dk, slice)| {
                for dj in 0..ey {
                    for di in 0..ex {
                        let sample = [first[0] + di, first[1] + dj, first[2] + dk];
                        slice[dj * ex + di] =
                            support.level_sample(&data, self.background, &self.grid, sample);
                    }
                }
            });
        Ok(out)
    }

    /// An empty level (every sample 0) to gather the blocks into, after a memory check.
    pub fn empty_level(&self) -> Result<Volume, SamplingError> {
        Ok(Volume::filled(self.grid, 0.0, "the level's density")?)
    }

    /// Copies the samples of `block` ([`BlockwiseDirect::fill_block`]) into `level`.
    pub fn place_block(
        &self,
        level: &mut Volume,
        block: [usize; 3],
        samples: &[f32],
    ) -> Result<(), SamplingError> {
        let (first, extent) = self.block_box(block);
        if level.grid.dims != self.grid.dims || samples.len() != extent.iter().product() {
            return Err(SamplingError::InvalidOption(format!(
                "{} samples for block {block:?} of {extent:?} samples",
                samples.len()
            )));
        }
        let [nx, ny, _] = self.grid.dims;
        let [ex, ey, ez] = extent;
        let out = level.as_slice_mut();
        for dk in 0..ez {
            for dj in 0..ey {
                let to = first[0] + nx * (first[1] + dj + ny * (first[2] + dk));
                let from = ex * (dj + ey * dk);
                out[to..to + ex].copy_from_slice(&samples[from..from + ex]);
            }
        }
        Ok(())
    }
}

/// A level of a scan filtered directly, block by block: `read(start, extent)` reads a window of
/// the scan (x, y, z sample indices) as a volume. The blocks are filled one after another (each
/// in parallel over its slices) and gathered into the level's dense grid, which is
/// [`crate::direct_density`]'s bit for bit.
pub fn blockwise_direct_density<E>(
    level: &BlockwiseDirect,
    read: &dyn Fn([usize; 3], [usize; 3]) -> Result<Volume, E>,
) -> Result<Volume, BlockwiseError<E>>
where
    E: std::error::Error + 'static,
{
    let mut out = level.empty_level()?;
    for n in 0..level.block_count() {
        let block = level.block_at(n);
        let (start, extent) = level.scan_window(block);
        let window = read(start, extent).map_err(BlockwiseError::Read)?;
        let samples = level.fill_block(block, &window)?;
        level.place_block(&mut out, block, &samples)?;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::direct_density;

    /// The window `start .. start + extent` of `volume`, placed where it lies in the scan.
    fn cut(volume: &Volume, start: [usize; 3], extent: [usize; 3]) -> Volume {
        let mut values = Vec::with_capacity(extent.iter().product());
        for k in start[2]..start[2] + extent[2] {
            for j in start[1]..start[1] + extent[1] {
                values.extend((start[0]..start[0] + extent[0]).map(|i| volume.get(i, j, k)));
            }
        }
        let g = &volume.grid;
        let origin = [0, 1, 2].map(|a| g.origin[a] + start[a] as f64 * g.spacing[a]);
        let grid = Grid::new(extent, g.spacing, origin).unwrap();
        Volume::from_vec(grid, values).unwrap()
    }

    /// A scan of `dims` with a smooth field plus a ramp (no two samples alike).
    fn scan(dims: [usize; 3], spacing: [f64; 3], origin: [f64; 3]) -> Volume {
        let grid = Grid::new(dims, spacing, origin).unwrap();
        let mut values = Vec::with_capacity(grid.len());
        for k in 0..dims[2] {
            for j in 0..dims[1] {
                for i in 0..dims[0] {
                    let (x, y, z) = (i as f64 * 0.37, j as f64 * 0.29, k as f64 * 0.41);
                    let v = 500.0 * (x.sin() * y.cos() + z.sin()) + (i + 3 * j + 7 * k) as f64;
                    values.push(v as f32);
                }
            }
        }
        Volume::from_vec(grid, values).unwrap()
    }

    /// The blocked level and the dense one, bit for bit; returns the block count.
    fn assert_same(volume: &Volume, grid: &Grid, filter: Filter, radius: f64) -> usize {
        let (background, _) = volume.range().unwrap();
        // Small blocks, so that every case has blocks at the edges and inside.
        let level =
            BlockwiseDirect::new(volume.grid, grid, filter, radius, background, 12).unwrap();
        let read = |start, extent| Ok::<_, SamplingError>(cut(volume, start, extent));
        let blocked = blockwise_direct_density(&level, &read).unwrap();
        let dense = direct_density(volume, grid, filter, radius).unwrap();
        let bits = |v: &Volume| v.as_slice().iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&blocked), bits(&dense), "{filter:?} radius {radius}");
        level.block_count()
    }

    #[test]
    fn blocks_give_the_dense_levels_bit_for_bit() {
        let volume = scan([46, 38, 30], [1.0, 1.0, 1.5], [-3.0, 2.5, 10.0]);
        let bounds = volume.grid.bounds();
        for filter in [Filter::Hypercone, Filter::GAUSSIAN] {
            // A fine level (supports of a few samples), a coarse one reaching beyond the scan
            // on every side, and a level finer than the data with a support below its spacing,
            // where samples fall back to trilinear interpolation.
            for (resolution, radius_voxels) in [(16, 1.0), (4, 1.0), (40, 0.3)] {
                let voxel = bounds.longest_extent() / resolution as f64;
                let radius = radius_voxels * voxel;
                let grid = crate::level_grid(&bounds, resolution, radius).unwrap();
                let blocks = assert_same(&volume, &grid, filter, radius);
                assert!(blocks > 1, "{blocks} blocks");
            }
        }
    }

    #[test]
    fn strong_anisotropy_integrates_the_dense_axes_the_same_way() {
        // Spacing 1:1:100: the support spans more than EXACT_REACH samples along x and y.
        let volume = scan([12, 10, 4], [1.0, 1.0, 100.0], [0.0; 3]);
        let grid = Grid::new([3, 3, 3], [150.0; 3], [-50.0, -60.0, -20.0]).unwrap();
        assert_same(&volume, &grid, Filter::Hypercone, 150.0);
        assert_same(&volume, &grid, Filter::GAUSSIAN, 150.0);
    }

    #[test]
    fn windows_cover_the_support_and_blocks_cover_the_level() {
        let volume = scan([40, 30, 20], [0.5, 0.5, 1.0], [0.0; 3]);
        let grid = Grid::new([20, 16, 11], [1.0; 3], [-0.5, -0.5, -0.5]).unwrap();
        let level =
            BlockwiseDirect::new(volume.grid, &grid, Filter::Hypercone, 2.0, 0.0, WINDOW_SIDE)
                .unwrap();
        // Reach: 4 scan samples along x and y, 2 along z.
        assert_eq!(level.reach, [4, 4, 2]);
        let mut covered = 0;
        for n in 0..level.block_count() {
            let block = level.block_at(n);
            let (first, extent) = level.block_box(block);
            covered += extent.iter().product::<usize>();
            let (start, window) = level.scan_window(block);
            for a in 0..3 {
                let at = |s: usize| (grid.origin[a] + s as f64) / volume.grid.spacing[a];
                let lo = (at(first[a]) - level.reach[a] as f64).max(0.0) as usize;
                let hi = ((at(first[a] + extent[a] - 1) + level.reach[a] as f64).ceil() as usize)
                    .min(volume.grid.dims[a] - 1);
                assert!(start[a] <= lo && start[a] + window[a] > hi, "axis {a}");
            }
        }
        assert_eq!(covered, grid.len());
    }

    #[test]
    fn coarse_levels_read_the_scan_a_bounded_number_of_times() {
        // Level spacing 8, support radius 8: halos of 9 scan samples each side exceed the
        // 16-sample window asked for, and blocks of one sample (windows of 19³) would read the
        // scan 13 times over.
        let scan = Grid::new([64; 3], [1.0; 3], [0.0; 3]).unwrap();
        let grid = Grid::new([8; 3], [8.0; 3], [0.0; 3]).unwrap();
        let level = BlockwiseDirect::new(scan, &grid, Filter::Hypercone, 8.0, 0.0, 16).unwrap();
        assert_eq!(level.block_side, [2, 2, 2]);
        let read: usize = (0..level.block_count())
            .map(|n| {
                level
                    .scan_window(level.block_at(n))
                    .1
                    .iter()
                    .product::<usize>()
            })
            .sum();
        assert!(
            read <= 8 * scan.len(),
            "{read} samples read for {}",
            scan.len()
        );
    }

    #[test]
    fn a_window_of_the_wrong_size_is_refused() {
        let volume = scan([8, 8, 8], [1.0; 3], [0.0; 3]);
        let grid = Grid::new([4, 4, 4], [2.0; 3], [0.0; 3]).unwrap();
        let level =
            BlockwiseDirect::new(volume.grid, &grid, Filter::Hypercone, 2.0, 0.0, WINDOW_SIDE)
                .unwrap();
        let wrong = cut(&volume, [0; 3], [3, 3, 3]);
        let e = level.fill_block([0, 0, 0], &wrong).unwrap_err();
        assert!(e.to_string().contains("not [8, 8, 8]"), "{e}");
        assert!(level.fill_block([5, 0, 0], &volume).is_err());
        assert!(BlockwiseDirect::new(volume.grid, &grid, Filter::Hypercone, 0.0, 0.0, 64).is_err());
        assert!(
            BlockwiseDirect::new(volume.grid, &grid, Filter::Hypercone, 1.0, f32::NAN, 64).is_err()
        );
    }
}
