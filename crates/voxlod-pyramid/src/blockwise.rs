//! Scans read blockwise, window by window, for the threshold route (paper §4, first route): a
//! [`BlockwiseScan`] is a volume that is never read whole (a Zarr array, or a raw, NRRD or
//! MetaImage file with uncompressed samples, [`voxlod_io::BlockwiseVolume`], read blockwise with
//! positioned reads), and [`crate::Source::BlockwiseThreshold`] samples each level from it block by
//! block ([`voxlod_sampling::blockwise_threshold`]) into bricks for sparse marching cubes. The
//! levels are those of [`crate::Source::Threshold`] on the same data (same triangles, same
//! vertices, placed in the same world: the scan's [`BlockwiseScan::orientation`] moves the meshes
//! as a volume's own does); peak memory is a few windows of the scan, the band of bricks the
//! surface reaches, and the mesh.
//!
//! Beyond the paper (which holds the whole volume). Cost per level: each window is read once
//! (the halos twice), every sample of the level is integrated as the dense route does.

use voxlod_core::{Bounds, BrickVolume, Grid, Orientation, Volume, WorldTransform};
use voxlod_io::{BlockwiseVolume, IoError, ZarrVolume};
use voxlod_sampling::narrow_band::{BandReport, NarrowBandOptions};
use voxlod_sampling::{
    blockwise_threshold_density, BlockwiseError, BlockwiseThreshold, DensityOptions, DensityReport,
    SamplingError,
};

/// A scanned volume read window by window.
pub trait BlockwiseScan: Sync {
    /// The whole scan's grid.
    fn grid(&self) -> Grid;
    /// The direction cosines and anatomical frame of the scan's index axes, through which its
    /// meshes leave grid space as those of a volume held whole do (`voxlod_core::world`). By
    /// default axis-aligned in an unknown frame: a Zarr array has spacing and origin only.
    fn orientation(&self) -> Orientation {
        Orientation::default()
    }
    /// Samples `start .. start + extent` (x, y, z indices) as a volume.
    fn read_window(&self, start: [usize; 3], extent: [usize; 3]) -> Result<Volume, IoError>;

    /// One level's samples as bricks: by default every block of `level` read
    /// ([`BlockwiseScan::read_window`]) and filled here ([`blockwise_threshold_density`]). A scan
    /// whose blocks are filled elsewhere (the Python package's Dask route runs
    /// [`BlockwiseThreshold::fill_block`] on a cluster) gathers their bricks with
    /// [`voxlod_sampling::BrickAssembly`] instead; the levels are then the same.
    fn sample_level(
        &self,
        level: &BlockwiseThreshold,
    ) -> Result<(BrickVolume, DensityReport, BandReport), BlockwiseError<IoError>> {
        blockwise_threshold_density(level, &|start, extent| self.read_window(start, extent))
    }
}

impl BlockwiseScan for ZarrVolume {
    fn grid(&self) -> Grid {
        ZarrVolume::grid(self)
    }

    fn read_window(&self, start: [usize; 3], extent: [usize; 3]) -> Result<Volume, IoError> {
        self.read_region(start, extent)
    }
}

impl BlockwiseScan for BlockwiseVolume {
    fn grid(&self) -> Grid {
        BlockwiseVolume::grid(self)
    }

    fn orientation(&self) -> Orientation {
        BlockwiseVolume::orientation(self)
    }

    fn read_window(&self, start: [usize; 3], extent: [usize; 3]) -> Result<Volume, IoError> {
        BlockwiseVolume::read_window(self, start, extent)
    }
}

/// A blockwise scan and its threshold, as [`crate::lod::LodSource::Blockwise`] samples it.
pub struct BlockwiseSource<'a> {
    /// The scan.
    pub scan: &'a dyn BlockwiseScan,
    /// Inside where the trilinear interpolation of the scan is `>= threshold`.
    pub threshold: f32,
}

impl BlockwiseSource<'_> {
    /// The box the levels cover: the scan's.
    pub fn bounds(&self) -> Bounds {
        self.scan.grid().bounds()
    }

    /// The scan's index-to-world transform: its grid's spacing and origin, its orientation.
    pub fn world(&self) -> WorldTransform {
        WorldTransform::of(&self.scan.grid(), &self.scan.orientation())
    }

    /// How one level of `grid` is cut into blocks (every level's:
    /// [`BlockwiseSource::level_blocks`]).
    pub fn blocks(
        &self,
        grid: &Grid,
        options: &DensityOptions,
    ) -> Result<BlockwiseThreshold, SamplingError> {
        BlockwiseThreshold::new(
            self.scan.grid(),
            self.threshold,
            grid,
            options,
            &NarrowBandOptions::default(),
        )
    }

    /// Bytes a level needs before its band is known: the brick index and a window of the scan
    /// and its lattice per block in flight (two, one per core of this machine's kind).
    pub fn estimated_bytes(&self, grid: &Grid, lines_per_voxel: usize) -> u64 {
        let b = NarrowBandOptions::default().brick_size;
        let q = lines_per_voxel as u64;
        let block = (128 * q + 16 * q).pow(2) * 3 * 8 + 140u64.pow(3) * 4 * 2;
        BrickVolume::estimated_bytes(grid, b, 0).saturating_add(2 * block)
    }

    /// The level's samples as bricks, with the sampling's and the band's figures.
    pub(crate) fn sample(
        &self,
        grid: &Grid,
        options: &DensityOptions,
    ) -> Result<(BrickVolume, DensityReport, BandReport), BlockwiseError<IoError>> {
        let blocks = self
            .blocks(grid, options)
            .map_err(BlockwiseError::Sampling)?;
        self.scan.sample_level(&blocks)
    }
}
