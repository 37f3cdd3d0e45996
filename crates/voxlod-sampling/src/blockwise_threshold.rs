//! The threshold route of paper §4 for scans that need not fit in memory:
//! a level's filtered density computed block by block from windows of the scan read one at a
//! time (Zarr chunks, slabs of a raw file), into a [`BrickVolume`].
//!
//! The dense route ([`crate::ThresholdSolid`] then [`crate::filtered_density`]) needs the whole
//! scan as `f32` and the whole lattice. Here the level's grid is cut into cubic blocks of whole
//! bricks. For each block, the scan is read over the block's box grown by a halo of ⌈R⌉ + 1
//! samples of the level (R the support radius in the level's voxels) plus one scan sample for
//! the trilinear interpolation; the lattice lines of the grown box get their crossings from
//! [`ThresholdSolid::window`] on that window, with the whole scan's coordinates, so every
//! crossing a sample of the block can reach is the dense route's, bit for bit; the line ends the
//! window adds lie beyond the filter's reach. The block is then integrated as one box, each
//! lattice row once over the block's span of it (the same blend and rounding as the dense
//! sampler, the narrow band's [`crate::narrow_band`] box routine), and cut into bricks; a brick
//! whose samples are all equal (far from the surface: all 0 or all 1) is kept as one value. So
//! the level's samples are those of the dense route, but for one f64 residue: a row's running
//! sum starts at the block, so spans that ended before it leave no `full - full` rounding
//! (values of 0 in one route can be ~1e-16 in the other, far from any iso value;
//! `tests/blockwise_threshold.rs` bounds the difference by 1e-12). On generated gyroids
//! of 48³ and 256³ the meshes had the same triangle counts and bit-identical vertex sets.
//!
//! A block whose window holds no crossing of the threshold (all its samples below it, or all at
//! or above it away from the scan's edge: [`BlockwiseThreshold::uniform_value`]) skips the
//! density pass: its samples are exactly 0 or 1 there, as the pass would give them.
//!
//! Beyond the paper, which holds the whole volume. **Memory**: per block in flight, its window of
//! the scan as `f32` and its lattice (a few MB for blocks of 64³ samples); then 8 bytes per brick
//! of the level and `4 B³` per leaf brick (those the surface reaches), checked against the budget
//! as they accumulate. **Cost**: each block reads its window (the halos are read twice) and
//! integrates every sample of the block that can see the surface: O(N³) at worst like the dense
//! route, in memory O(surface).

use rayon::prelude::*;
use serde::Serialize;
use voxlod_core::bricks::{brick_samples, local_index};
use voxlod_core::{memory, Axis, BrickVolume, Grid, Volume};

use crate::density::{check_options, DensityOptions, DensityReport};
use crate::lattice::{LineCrossings, LineFamily};
use crate::line_kernel::LineKernel;
use crate::narrow_band::{BandReport, BoxLattice, BrickScratch, NarrowBandOptions};
use crate::solid::Solid;
use crate::threshold::ThresholdSolid;
use crate::SamplingError;

/// Scan samples per block side the route aims at: a window of about this side is read at once.
const WINDOW_SIDE: f64 = 128.0;

/// Why a blockwise level failed: reading a window of the scan, or sampling.
#[derive(Debug, thiserror::Error)]
pub enum BlockwiseError<E: std::error::Error + 'static> {
    /// Reading a window of the scan failed.
    #[error(transparent)]
    Read(E),
    /// An option or the memory limit.
    #[error(transparent)]
    Sampling(#[from] SamplingError),
}

/// A level of a thresholded scan, cut into blocks (see the module documentation).
#[derive(Clone, Debug, Serialize)]
pub struct BlockwiseThreshold {
    /// The whole scan's grid.
    pub scan: Grid,
    /// Inside where the trilinear interpolation of the scan is `>= threshold`.
    pub threshold: f32,
    /// The level's grid.
    pub grid: Grid,
    /// Side of a brick, samples of the level.
    pub brick_size: usize,
    /// Side of a block, samples of the level (a multiple of the brick side).
    pub block_side: usize,
    /// Lattice lines per voxel of the level.
    pub lines_per_voxel: usize,
    /// Halo of the level's samples around a block: ⌈R⌉ + 1.
    pub halo: usize,
    /// When the blocks' windows together hold more than this many times the scan's samples, the
    /// scan is read once, whole, if the budget allows ([`blockwise_threshold_density`]); 1.5.
    pub whole_scan_above: f64,
    #[serde(skip)]
    kernel: LineKernel,
}

impl BlockwiseThreshold {
    /// The blocks of `grid` (a level of a scan with grid `scan`) filtered with `options`; blocks
    /// are sized so that each reads about 128³ samples of the scan.
    pub fn new(
        scan: Grid,
        threshold: f32,
        grid: &Grid,
        options: &DensityOptions,
        band: &NarrowBandOptions,
    ) -> Result<BlockwiseThreshold, SamplingError> {
        if !threshold.is_finite() {
            return Err(SamplingError::InvalidOption(format!(
                "the threshold {threshold} is not a finite number"
            )));
        }
        let b = band.brick_size;
        if !BrickVolume::BRICK_SIZES.contains(&b) {
            return Err(SamplingError::InvalidOption(format!(
                "brick side {b}: must be one of {:?}",
                BrickVolume::BRICK_SIZES
            )));
        }
        let q = check_options(grid, options)?;
        let h = grid.spacing[0];
        let kernel = LineKernel::new(options.filter, options.radius / h, q);
        let finest = scan.spacing.iter().cloned().fold(f64::INFINITY, f64::min);
        let side = ((WINDOW_SIDE * finest / h) as usize / b * b).clamp(b, 16 * b);
        Ok(BlockwiseThreshold {
            scan,
            threshold,
            grid: *grid,
            brick_size: b,
            block_side: side,
            lines_per_voxel: q,
            halo: kernel.radius.ceil() as usize + 1,
            whole_scan_above: 1.5,
            kernel,
        })
    }

    /// Blocks along each axis.
    pub fn block_dims(&self) -> [usize; 3] {
        self.grid.dims.map(|d| d.div_ceil(self.block_side))
    }

    /// The level's samples of block `block`: first sample and extent.
    fn block_box(&self, block: [usize; 3]) -> ([usize; 3], [usize; 3]) {
        let first = block.map(|c| c * self.block_side);
        let extent = [0, 1, 2].map(|a| (self.grid.dims[a] - first[a]).min(self.block_side));
        (first, extent)
    }

    /// The level's samples whose lattice lines a block needs: its box grown by the halo, cut to
    /// the grid. First and last sample, per axis.
    fn lattice_box(&self, block: [usize; 3]) -> ([usize; 3], [usize; 3]) {
        let (first, extent) = self.block_box(block);
        let lo = first.map(|f| f.saturating_sub(self.halo));
        let hi =
            [0, 1, 2].map(|a| (first[a] + extent[a] - 1 + self.halo).min(self.grid.dims[a] - 1));
        (lo, hi)
    }

    /// The scan samples a block reads: first sample and extent (x, y, z), reaching one sample
    /// beyond the block's lattice box on every side (cut to the scan).
    pub fn scan_window(&self, block: [usize; 3]) -> ([usize; 3], [usize; 3]) {
        self.window_reach(block).0
    }

    /// [`BlockwiseThreshold::scan_window`], and whether it had to be cut to the scan or the
    /// lattice box to the level's grid (then the filter of a sample of the block may reach
    /// beyond the scan, where the solid is outside).
    fn window_reach(&self, block: [usize; 3]) -> (([usize; 3], [usize; 3]), bool) {
        let (lo, hi) = self.lattice_box(block);
        let (first_sample, extent) = self.block_box(block);
        let mut cut = (0..3).any(|a| {
            first_sample[a] < self.halo
                || first_sample[a] + extent[a] - 1 + self.halo > self.grid.dims[a] - 1
        });
        let mut start = [0; 3];
        let mut extent = [0; 3];
        for a in 0..3 {
            let n = self.scan.dims[a];
            let index = |sample: usize| {
                let world = self.grid.origin[a] + sample as f64 * self.grid.spacing[a];
                (world - self.scan.origin[a]) / self.scan.spacing[a]
            };
            let last = n as f64 - 1.0;
            let (low, high) = (index(lo[a]).floor() - 1.0, index(hi[a]).ceil() + 1.0);
            cut |= low < 0.0 || high > last;
            let first = low.clamp(0.0, last) as usize;
            let end = high.clamp(0.0, last) as usize;
            let first = first.min(end.saturating_sub(1));
            start[a] = first;
            extent[a] = end - first + 1;
        }
        ((start, extent), cut)
    }

    /// The value of every sample of `block` when its window (the samples
    /// [`BlockwiseThreshold::scan_window`] names) runs from `low` to `high` and holds no crossing
    /// of the threshold, so that the density pass can be skipped: 0 when every sample is below
    /// the threshold; 1 when every sample is at or above it and the window lies inside the scan
    /// with its whole margin (every lattice line the block's filter reaches is then inside from
    /// end to end, and the line kernel is normalised to give exactly 1, as the narrow band
    /// relies on). `None`: the block needs [`BlockwiseThreshold::fill_block`].
    pub fn uniform_value(&self, block: [usize; 3], low: f32, high: f32) -> Option<f32> {
        if high < self.threshold {
            Some(0.0)
        } else if low >= self.threshold && !self.window_reach(block).1 {
            Some(1.0)
        } else {
            None
        }
    }

    /// Block `block` from `window` (the samples [`BlockwiseThreshold::scan_window`] names): its
    /// one value when [`BlockwiseThreshold::uniform_value`] finds no surface in the window (one
    /// pass for its range), else its bricks ([`BlockwiseThreshold::fill_block`]).
    pub fn sample_block(&self, block: [usize; 3], window: &Volume) -> BlockSamples {
        match self.uniform_window(block, window) {
            Some(value) => BlockSamples::Uniform(value),
            None => {
                let (bricks, crossings) = self.fill_block(block, window);
                BlockSamples::Bricks(bricks, crossings)
            }
        }
    }

    /// [`BlockwiseThreshold::uniform_value`] of `window`'s range, found without the range: the
    /// finite samples are compared with the threshold until one on each side turns up (a block
    /// with surface in its window stops at the first such pair, not at the window's end).
    fn uniform_window(&self, block: [usize; 3], window: &Volume) -> Option<f32> {
        let t = self.threshold;
        let (mut below, mut above) = (false, false);
        for chunk in window.as_slice().chunks(4096) {
            for &v in chunk.iter().filter(|v| v.is_finite()) {
                below |= v < t;
                above |= v >= t;
            }
            if below && above {
                return None;
            }
        }
        match (below, above) {
            (true, false) => Some(0.0),
            (false, true) => self.uniform_value(block, t, t),
            _ => None,
        }
    }

    /// The bricks of `block`, every one of them the single value `value` (a block
    /// [`BlockwiseThreshold::uniform_value`] answered), in increasing brick index.
    pub fn uniform_block(&self, block: [usize; 3], value: f32) -> Vec<BlockBrick> {
        self.bricks_of(block)
            .into_iter()
            .map(|(index, _)| BlockBrick {
                index: index as u32,
                value,
                leaf: None,
            })
            .collect()
    }

    /// The bricks of `block`: index in the level's brick grid and brick coordinates, in
    /// increasing index.
    fn bricks_of(&self, block: [usize; 3]) -> Vec<(usize, [usize; 3])> {
        let b = self.brick_size;
        let brick_dims = self.grid.dims.map(|d| d.div_ceil(b));
        let (first, extent) = self.block_box(block);
        let bricks_in = [0, 1, 2].map(|a| extent[a].div_ceil(b));
        let mut out = Vec::with_capacity(bricks_in.iter().product());
        for bz in 0..bricks_in[2] {
            for by in 0..bricks_in[1] {
                for bx in 0..bricks_in[0] {
                    let brick = [first[0] / b + bx, first[1] / b + by, first[2] / b + bz];
                    let index = brick[0] + brick_dims[0] * (brick[1] + brick_dims[1] * brick[2]);
                    out.push((index, brick));
                }
            }
        }
        out
    }

    /// The bricks of one block, from `window` (the samples [`BlockwiseThreshold::scan_window`]
    /// names, read from the scan), in increasing brick index. Also the crossings found.
    pub fn fill_block(&self, block: [usize; 3], window: &Volume) -> (Vec<BlockBrick>, u64) {
        let (start, _) = self.scan_window(block);
        let solid = ThresholdSolid::window(window, self.scan, start, self.threshold);
        let (lo, hi) = self.lattice_box(block);
        let q = self.lines_per_voxel;
        let crossings: [LineCrossings; 3] = [Axis::X, Axis::Y, Axis::Z].map(|axis| {
            let family = LineFamily::new(axis, self.grid, q);
            let dims = [0, 1, 2].map(|a| hi[a] - lo[a] + 1);
            let window_grid = Grid { dims, ..self.grid };
            let window_family = LineFamily::new(axis, window_grid, q);
            let (u, v) = axis.others();
            let first_line = (lo[u.index()] * q, lo[v.index()] * q);
            solid.window_crossings(&family, &window_family, first_line)
        });
        let found = crossings.iter().map(|c| c.len() as u64).sum();
        (self.integrate_block(block, &crossings, lo), found)
    }

    /// Integrates `block` from the block's lattice window as one box (each row once over the
    /// block's span of it, rather than once per brick), then cuts it into bricks.
    fn integrate_block(
        &self,
        block: [usize; 3],
        crossings: &[LineCrossings; 3],
        first_line: [usize; 3],
    ) -> Vec<BlockBrick> {
        let b = self.brick_size;
        let (first, extent) = self.block_box(block);
        let mut samples = vec![0.0f32; extent.iter().product()];
        let lattice = BoxLattice {
            crossings,
            kernel: &self.kernel,
            first_line,
        };
        BrickScratch::new(b).fill_box(&lattice, first, extent, extent, &mut samples);
        let mut leaf = vec![0.0f32; b * b * b];
        let bricks = self.bricks_of(block);
        let mut out = Vec::with_capacity(bricks.len());
        for (index, brick) in bricks {
            // The brick's samples within the grid, from the block's; zero beyond.
            leaf.fill(0.0);
            let local = [0, 1, 2].map(|a| brick[a] * b - first[a]);
            let ext = [0, 1, 2].map(|a| (extent[a] - local[a]).min(b));
            for k in 0..ext[2] {
                for j in 0..ext[1] {
                    let from = local[0] + extent[0] * (local[1] + j + extent[1] * (local[2] + k));
                    let to = b * (j + b * k);
                    leaf[to..to + ext[0]].copy_from_slice(&samples[from..from + ext[0]]);
                }
            }
            out.push(BlockBrick::new(index as u32, &leaf, &self.grid, b, brick));
        }
        out
    }
}

/// What [`BlockwiseThreshold::sample_block`] found for a block.
#[derive(Clone, Debug)]
pub enum BlockSamples {
    /// Every sample of the block has this value (its window holds no surface).
    Uniform(f32),
    /// The block's bricks and the crossings found.
    Bricks(Vec<BlockBrick>, u64),
}

/// One brick of a block: uniform, or a leaf.
#[derive(Clone, Debug)]
pub struct BlockBrick {
    /// Index of the brick in the level's brick grid (x fastest).
    pub index: u32,
    /// Its value when uniform; its first sample when a leaf.
    pub value: f32,
    /// Its `B³` samples, unless every sample has the same bits.
    pub leaf: Option<Vec<f32>>,
}

impl BlockBrick {
    fn new(index: u32, samples: &[f32], grid: &Grid, b: usize, brick: [usize; 3]) -> BlockBrick {
        let mut valid = brick_samples(grid, b, brick).map(|p| {
            let local = [0, 1, 2].map(|a| p[a] - brick[a] * b);
            samples[local_index(b, local)]
        });
        let value = valid.next().unwrap_or(0.0);
        let uniform = valid.all(|v| v.to_bits() == value.to_bits());
        BlockBrick {
            index,
            value,
            leaf: (!uniform).then(|| samples.to_vec()),
        }
    }
}

/// A level's bricks gathered from its blocks into one [`BrickVolume`], checked against the memory
/// budget as they accumulate: what [`blockwise_threshold_density`] does with the blocks it fills,
/// and what a caller that fills the blocks elsewhere (on a cluster) does with their answers.
pub struct BrickAssembly {
    grid: Grid,
    brick_size: usize,
    lines_per_voxel: usize,
    values: Vec<f32>,
    leaf_bricks: Vec<u32>,
    leaves: Vec<f32>,
    crossings: u64,
}

impl BrickAssembly {
    /// An empty level (every brick 0), after checking its brick index against the budget.
    pub fn new(level: &BlockwiseThreshold) -> Result<BrickAssembly, SamplingError> {
        let b = level.brick_size;
        let bricks: usize = level.grid.dims.map(|d| d.div_ceil(b)).iter().product();
        memory::check_allocation("the brick index", memory::bytes_of::<u64>(bricks))?;
        Ok(BrickAssembly {
            grid: level.grid,
            brick_size: b,
            lines_per_voxel: level.lines_per_voxel,
            values: vec![0.0; bricks],
            leaf_bricks: Vec::new(),
            leaves: Vec::new(),
            crossings: 0,
        })
    }

    /// Adds the bricks of some blocks (in any order) and the crossings their filling found.
    /// Every brick of a call must come after (in brick index) those of the calls before it,
    /// as whole slabs of blocks along z do.
    pub fn add(
        &mut self,
        mut bricks: Vec<BlockBrick>,
        crossings: u64,
    ) -> Result<(), SamplingError> {
        let b = self.brick_size;
        self.crossings += crossings;
        bricks.sort_unstable_by_key(|brick| brick.index);
        let new_leaves = bricks.iter().filter(|x| x.leaf.is_some()).count();
        let total = self.leaf_bricks.len() + new_leaves;
        memory::check_allocation(
            &format!(
                "the band of bricks ({total} of {} bricks of {b}³ samples so far)",
                self.values.len()
            ),
            BrickVolume::estimated_bytes(&self.grid, b, total),
        )?;
        self.leaves.reserve_exact(new_leaves * b * b * b);
        self.leaf_bricks.reserve_exact(new_leaves);
        for brick in bricks {
            self.values[brick.index as usize] = brick.value;
            if let Some(leaf) = brick.leaf {
                self.leaf_bricks.push(brick.index);
                self.leaves.extend_from_slice(&leaf);
            }
        }
        Ok(())
    }

    /// The level as bricks, with the sampling's figures and the band's.
    pub fn finish(self) -> Result<(BrickVolume, DensityReport, BandReport), SamplingError> {
        let (grid, b) = (self.grid, self.brick_size);
        let bricks = self.values.len();
        let band_bricks = self.leaf_bricks.len();
        let volume = BrickVolume::from_parts(grid, b, self.values, self.leaf_bricks, self.leaves)?;
        let q = self.lines_per_voxel;
        let families = [Axis::X, Axis::Y, Axis::Z].map(|a| LineFamily::new(a, grid, q));
        let report = DensityReport {
            lines_per_voxel: q,
            lattice_lines: families.iter().map(|f| f.line_count() as u64).sum(),
            crossings: self.crossings,
            majority: None,
        };
        let band = BandReport {
            bricks,
            band_bricks,
            bytes: BrickVolume::estimated_bytes(&grid, b, band_bricks),
        };
        Ok((volume, report, band))
    }
}

/// Samples a level of a thresholded scan block by block (see the module documentation):
/// `read(start, extent)` reads a window of the scan (x, y, z sample indices) as a volume. Blocks
/// go in slabs along z, each slab's blocks in parallel; the level is returned as bricks, with
/// the sampling's figures and the band's.
///
/// A coarse level's blocks are few samples wide and their halos long, in the scan's samples:
/// their windows overlap, and together hold the scan several times over. When they would hold it
/// more than one and a half times and the scan as `f32` (plus a byte per sample) fits the
/// budget, the scan is read once, whole, and the level's lattice cast on it as the dense route
/// casts it; each block is then integrated from that lattice. The crossings a block's rows reach
/// are those of its window, bit for bit, so the bricks are the same.
pub fn blockwise_threshold_density<E>(
    level: &BlockwiseThreshold,
    read: &(dyn Fn([usize; 3], [usize; 3]) -> Result<Volume, E> + Sync),
) -> Result<(BrickVolume, DensityReport, BandReport), BlockwiseError<E>>
where
    E: std::error::Error + Send + 'static,
{
    if level.reads_scan_over() {
        let scan = read([0; 3], level.scan.dims).map_err(BlockwiseError::Read)?;
        return Ok(level.sample_from_whole_scan(&scan)?);
    }
    let mut assembly = BrickAssembly::new(level)?;
    let [bx, by, bz] = level.block_dims();
    for z in 0..bz {
        let slab: Vec<[usize; 3]> = (0..bx * by).map(|i| [i % bx, i / bx, z]).collect();
        let filled: Result<Vec<(Vec<BlockBrick>, u64)>, E> = slab
            .par_iter()
            .map(|&block| {
                let (start, extent) = level.scan_window(block);
                let window = read(start, extent)?;
                Ok(match level.sample_block(block, &window) {
                    BlockSamples::Uniform(value) => (level.uniform_block(block, value), 0),
                    BlockSamples::Bricks(bricks, crossings) => (bricks, crossings),
                })
            })
            .collect();
        let mut slab_bricks: Vec<BlockBrick> = Vec::new();
        let mut crossings = 0;
        for (block_bricks, found) in filled.map_err(BlockwiseError::Read)? {
            crossings += found;
            slab_bricks.extend(block_bricks);
        }
        assembly.add(slab_bricks, crossings)?;
    }
    Ok(assembly.finish()?)
}

impl BlockwiseThreshold {
    /// True when the blocks' windows together hold the scan more than `whole_scan_above` times
    /// over and the whole scan (as `f32`, and a byte per sample for its classification) fits
    /// the memory limit.
    fn reads_scan_over(&self) -> bool {
        let [bx, by, bz] = self.block_dims();
        let windows: u64 = (0..bx * by * bz)
            .map(|n| {
                let (_, extent) = self.scan_window([n % bx, (n / bx) % by, n / (bx * by)]);
                extent.iter().map(|&e| e as u64).product::<u64>()
            })
            .sum();
        let scan: u64 = self.scan.dims.iter().map(|&d| d as u64).product();
        windows as f64 > self.whole_scan_above * scan as f64
            && memory::check_allocation("the whole scan", scan.saturating_mul(5)).is_ok()
    }

    /// The level from the whole scan `scan` held in memory: its lattice cast once, then every
    /// block integrated from it (see [`blockwise_threshold_density`]).
    pub fn sample_from_whole_scan(
        &self,
        scan: &Volume,
    ) -> Result<(BrickVolume, DensityReport, BandReport), SamplingError> {
        let solid = ThresholdSolid::window(scan, self.scan, [0; 3], self.threshold);
        let q = self.lines_per_voxel;
        let crossings: [LineCrossings; 3] = [Axis::X, Axis::Y, Axis::Z]
            .map(|axis| solid.crossings(&LineFamily::new(axis, self.grid, q)))
            .into_iter()
            .collect::<Result<Vec<_>, _>>()?
            .try_into()
            .expect("three families");
        let found = crossings.iter().map(|c| c.len() as u64).sum();
        let mut assembly = BrickAssembly::new(self)?;
        let [bx, by, bz] = self.block_dims();
        for z in 0..bz {
            let slab: Vec<BlockBrick> = (0..bx * by)
                .into_par_iter()
                .flat_map_iter(|i| self.integrate_block([i % bx, i / bx, z], &crossings, [0; 3]))
                .collect();
            assembly.add(slab, if z == 0 { found } else { 0 })?;
        }
        assembly.finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{level_grid, Filter};

    #[test]
    fn the_early_stopping_test_answers_as_the_range_does() {
        let scan = Grid::new([40, 40, 40], [1.0; 3], [0.0; 3]).unwrap();
        let grid = level_grid(&scan.bounds(), 12, 3.25).unwrap();
        let options = DensityOptions::new(Filter::Hypercone, 3.25);
        let band = NarrowBandOptions::default();
        let mut level = BlockwiseThreshold::new(scan, 10.0, &grid, &options, &band).unwrap();
        // Block (2, 2, 2) has its window inside the scan, block (0, 0, 0) is cut by its edge.
        level.block_side = 4;
        assert!(!level.window_reach([2, 2, 2]).1 && level.window_reach([0, 0, 0]).1);
        let n = scan.len();
        let windows: [Vec<f32>; 6] = [
            vec![3.0; n],
            vec![12.0; n],
            (0..n)
                .map(|i| if i == n - 1 { 10.0 } else { 2.0 })
                .collect(),
            (0..n)
                .map(|i| if i % 2 == 0 { f32::NAN } else { 11.0 })
                .collect(),
            (0..n)
                .map(|i| if i < 5 { f32::INFINITY } else { 1.0 })
                .collect(),
            vec![f32::NAN; n],
        ];
        for values in windows {
            let window = Volume::from_vec(scan, values).unwrap();
            let (low, high) = window.range().unwrap_or((f32::NAN, f32::NAN));
            for block in [[0, 0, 0], [2, 2, 2]] {
                assert_eq!(
                    level.uniform_window(block, &window),
                    level.uniform_value(block, low, high)
                );
            }
        }
    }
}
