//! The general form of [`crate::lod()`]: a prepared solid or a scanned volume in, one closed
//! triangle mesh per level of the pyramid out (paper §2), one level at a time.
//!
//! Each level is sampled from the **original** source with its own filter radius
//! ([`voxlod_sampling::pyramid`]) and contoured by marching cubes; nothing is derived from the
//! level above. [`plan`] sizes every level first (and refuses what would not fit in memory),
//! then [`build_level`] makes one level at a time, so a caller can write and drop each mesh
//! before the next. [`crate::lod()`] does all of it in one call, with the source's preparation,
//! the iso value's check, warnings, progress and the optional envelope step; use this module
//! when levels must be handled one by one. Cost per level: the sampling (O(N³) samples, each a
//! sum over the lattice lines within the radius) and marching cubes (O(N³)).
//!
//! **Large levels of solids** (beyond the paper): when the dense sampling of a solid's level
//! would need more than [`BAND_ABOVE_BYTES`], the level is sampled only in the narrow band of
//! bricks the surface reaches ([`voxlod_sampling::narrow_band`]) and contoured by
//! [`sparse_marching_cubes`]: the same surface as the dense path, with memory and time that grow
//! with the surface's area instead of the grid's volume, so `--resolution 2048` fits.

use std::time::Instant;

use serde::Serialize;
use voxlod_contouring::clean_mesh::has_defects;
use voxlod_contouring::clean_mesh::CLEAN_BYTES_PER_TRIANGLE;
use voxlod_contouring::{
    clean_mesh, marching_cubes, sparse_marching_cubes, CleanError, CleanOptions, ContourError,
    ContourOptions, PLAIN_CLAMP,
};
use voxlod_core::{
    mesh_topology, Bounds, BrickVolume, Grid, Placement, Topology, TriangleMesh, Volume,
    WorldTransform,
};
use voxlod_sampling::density::estimated_bytes;
use voxlod_sampling::narrow_band::{
    band_estimate, narrow_band_density, BandReport, NarrowBandOptions,
};

use crate::blockwise::BlockwiseSource;
use crate::then_envelope::EnvelopeStep;
use voxlod_sampling::{
    direct_density, filtered_density, plan_levels_with, BlockwiseError, BlockwiseThreshold,
    DensityReport, LevelEstimate, LevelPlan, MonotoneChain, MonotoneError, PyramidOptions,
    SamplingError, Solid, TopologyRecord,
};

/// Levels of solids whose dense sampling would need more bytes than this go through the narrow
/// band and sparse marching cubes (the dense path stays for smaller grids, where it is as fast).
pub const BAND_ABOVE_BYTES: u64 = 1 << 30;

/// The largest mesh of a level through the narrow band that is cleaned
/// ([`voxlod_contouring::clean_mesh()`]). Cleaning holds about 130 bytes per triangle at its
/// peak beyond the mesh itself (measured on a 326 k-triangle sphereflake level). Larger meshes are kept as marching cubes made them
/// (closed and oriented still, contoured for cleaning so without its defects but by rounding),
/// and the level's report says so if cleaning's scan finds any. The limit keeps the 1024³ Zarr
/// ball's 7.3 M-triangle level within its memory target (667 MiB uncleaned; cleaned it would
/// need about 1 GB more, BENCHMARKS.md): raise it only with that run measured again.
pub const CLEAN_BAND_AT_MOST_TRIANGLES: usize = 4_000_000;

/// The largest dense level (by the plan's estimate) that is sampled on another task while the
/// level above it is finished ([`sample_ahead`]).
pub const SAMPLE_AHEAD_AT_MOST_BYTES: u64 = 256 << 20;

/// Whether level `next` may be sampled on another task while `current` (the level above it)
/// is kept monotone, contoured, cleaned and handed over: both are dense levels of a solid or of
/// a scan filtered directly (not a blockwise scan, not through the narrow band), `next` is
/// expected to need at most [`SAMPLE_AHEAD_AT_MOST_BYTES`], and both together fit the memory
/// budget. Sampling reads only the source, so the level is the one sampled in its turn.
pub(crate) fn sample_ahead(
    source: &LodSource,
    current: &LevelPlan,
    next: &LevelPlan,
    pyramid: &PyramidOptions,
) -> bool {
    let dense = |plan: &LevelPlan| {
        let q = plan
            .density_options(pyramid)
            .lines_per_voxel(plan.voxel_size);
        !uses_band(source, &plan.grid, q)
    };
    let both = current.estimated_bytes.saturating_add(next.estimated_bytes);
    matches!(source, LodSource::Solid(_) | LodSource::Direct(_))
        && next.estimated_bytes <= SAMPLE_AHEAD_AT_MOST_BYTES
        && dense(current)
        && dense(next)
        && voxlod_core::memory::available_bytes().is_ok_and(|budget| both <= budget)
}

/// Whether a level of `source` on `grid` with `lines_per_voxel` goes through the narrow band.
fn uses_band(source: &LodSource, grid: &Grid, lines_per_voxel: usize) -> bool {
    matches!(source, LodSource::Solid(_))
        && estimated_bytes(grid, lines_per_voxel) > BAND_ABOVE_BYTES
}

/// What a level is made from: a prepared source ([`crate::Prepared::lod_source`]).
pub enum LodSource<'a> {
    /// A solid (mesh, thresholded volume, CSG): its inside function is filtered, and the level's
    /// density runs from 0 to 1.
    Solid(&'a dyn Solid),
    /// A scanned volume filtered directly: the density stays in the data's units.
    Direct(&'a Volume),
    /// A scan thresholded and read window by window ([`crate::blockwise`]): as `Solid` of its
    /// [`voxlod_sampling::ThresholdSolid`], level by level through bricks.
    Blockwise(&'a BlockwiseSource<'a>),
}

impl LodSource<'_> {
    /// The map of finished meshes from grid space to the source's world: the scan's own
    /// transform for a thresholded or directly filtered volume, the identity otherwise.
    pub fn placement(&self) -> Placement {
        self.world()
            .map_or(Placement::IDENTITY, |w| Placement::of(&w, None))
    }

    /// The index-to-world transform of the scan the source comes from (`None` for a mesh or a
    /// solid whose grid space is the world).
    pub fn world(&self) -> Option<WorldTransform> {
        match self {
            LodSource::Solid(s) => s.world(),
            LodSource::Direct(v) => Some(v.world()),
            // The scan's own transform (the identity for a Zarr array's spacing and origin).
            LodSource::Blockwise(c) => Some(c.world()),
        }
    }

    /// The box the levels cover.
    pub fn bounds(&self) -> Bounds {
        match self {
            LodSource::Solid(s) => s.bounds(),
            LodSource::Direct(v) => v.grid.bounds(),
            LodSource::Blockwise(c) => c.bounds(),
        }
    }
}

/// How to build the levels, one at a time: the pyramid and a checked iso value (the options
/// of [`crate::lod()`] are [`crate::LodOptions`]).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LevelOptions {
    /// Resolutions, filter, radius and quadrature of the levels.
    pub pyramid: PyramidOptions,
    /// The isodensity of the surfaces (0.5 for solids; data units for direct filtering).
    pub iso: f32,
    /// Gradient normals on the output meshes.
    pub normals: bool,
    /// Clean each level (no sliver, needle or zero-area triangle, no self-intersection; beyond
    /// the paper, see [`voxlod_contouring::clean_mesh()`]); `None` keeps raw marching cubes.
    pub clean: Option<CleanOptions>,
    /// Levels that are cleaned are contoured with the clamp that leaves cleaning nothing to
    /// fix ([`CleanOptions::contour_clamp`]: vertices kept 0.072 cell from the samples, fast,
    /// the mean distance to the input about 1 % larger on the bunny); `false` contours them
    /// plainly and lets cleaning collapse the slivers (the budget pipeline, whose search
    /// weighs distances and whose levels are simplified again).
    pub snap: bool,
}

impl Default for LevelOptions {
    /// Six levels from 256, hyper-cone filter of one voxel, isodensity 0.5, with normals,
    /// cleaned.
    fn default() -> Self {
        LevelOptions {
            pyramid: PyramidOptions::default(),
            iso: 0.5,
            normals: true,
            clean: Some(CleanOptions::default()),
            snap: true,
        }
    }
}

impl LevelOptions {
    /// The paper's Table 1 setting: the Gaussian at 200, 100, 50, 30, 15 and 5, isodensity 0.5.
    pub fn paper_table1() -> Self {
        LevelOptions {
            pyramid: PyramidOptions::paper_table1(),
            // The paper's counts are of plain marching cubes.
            clean: None,
            ..Default::default()
        }
    }
}

/// One level of detail.
#[derive(Clone, Debug)]
pub struct LodLevel {
    /// Samples across the longest side of the source's box (the plan's).
    pub resolution: usize,
    /// Grid, voxel size and filter radius of the level.
    pub plan: LevelPlan,
    /// The closed, consistently oriented surface (empty when the filter removed the object).
    pub mesh: TriangleMesh,
    /// Components, Euler characteristic, genus, manifoldness of `mesh`.
    pub topology: Topology,
    /// The sampling's figures; present for solids.
    pub density: Option<DensityReport>,
    /// Wall time of the filtered sampling.
    pub sample_seconds: f64,
    /// Wall time of marching cubes.
    pub contour_seconds: f64,
    /// Present when the level went through the narrow band: its bricks.
    pub band: Option<BandReport>,
    /// What the envelope step did ([`crate::LodOptions::then_envelope`]), when asked.
    pub envelope: Option<EnvelopeStep>,
    /// What keeping the chain's genus from rising changed at this level
    /// ([`crate::LodOptions::monotone`]): handles removed since the level above, components
    /// gained or lost, perforations prevented. `None` when not asked, or for a level sampled in
    /// the narrow band (the chain then starts again at the next level).
    pub monotone: Option<TopologyRecord>,
    /// Wall time of keeping the genus from rising (zero when not asked).
    pub monotone_seconds: f64,
    /// True when cleaning was asked but skipped: a level through the narrow band whose mesh
    /// has more than [`CLEAN_BAND_AT_MOST_TRIANGLES`] triangles and an edge or triangle that
    /// cleaning would fix (contoured for cleaning, it has none but by rounding).
    pub clean_skipped: bool,
}

impl LodLevel {
    /// Handles fewer (none where the genus rose) and surfaces (pieces and cavities) more (> 0)
    /// or fewer (< 0) than `above`, the level before it: as the genus chain recorded them
    /// ([`LodLevel::monotone`]), else from the two meshes' topology; none for the first level.
    pub fn change_from(&self, above: Option<&LodLevel>) -> (u64, i64) {
        match (&self.monotone, above) {
            (Some(record), _) => (record.handles_removed, record.surfaces_gained),
            (None, Some(above)) => {
                let (t, a) = (&self.topology, &above.topology);
                let handles = a.genus.unwrap_or(0) - t.genus.unwrap_or(0);
                (
                    handles.max(0) as u64,
                    t.components as i64 - a.components as i64,
                )
            }
            (None, None) => (0, 0),
        }
    }
}

/// Why a level could not be built.
#[derive(Debug, thiserror::Error)]
pub enum LodError {
    /// The sampling failed (an option, the memory limit).
    #[error(transparent)]
    Sampling(#[from] SamplingError),
    /// Marching cubes failed (32-bit limits, the memory limit).
    #[error(transparent)]
    Contour(#[from] ContourError),
    /// Cleaning the level failed (the memory limit).
    #[error(transparent)]
    Clean(#[from] CleanError),
    /// Keeping the chain's genus from rising failed (the memory limit).
    #[error(transparent)]
    Monotone(#[from] MonotoneError),
    /// Reading a window of a blockwise scan failed.
    #[error(transparent)]
    Read(voxlod_io::IoError),
}

impl From<BlockwiseError<voxlod_io::IoError>> for LodError {
    fn from(e: BlockwiseError<voxlod_io::IoError>) -> Self {
        match e {
            BlockwiseError::Read(e) => LodError::Read(e),
            BlockwiseError::Sampling(e) => LodError::Sampling(e),
        }
    }
}

impl BlockwiseSource<'_> {
    /// The blocks of every level [`crate::lod::plan`] plans for this scan with `options`, finest
    /// first: what a caller that fills blocks elsewhere needs to know of each level.
    pub fn level_blocks(
        &self,
        options: &LevelOptions,
    ) -> Result<Vec<BlockwiseThreshold>, LodError> {
        let plans = plan(&LodSource::Blockwise(self), options)?;
        let blocks = plans
            .iter()
            .map(|p| self.blocks(&p.grid, &p.density_options(&options.pyramid)))
            .collect::<Result<_, _>>()?;
        Ok(blocks)
    }
}

/// Plans every level: grids, radii, and a memory check of the largest.
pub fn plan(source: &LodSource, options: &LevelOptions) -> Result<Vec<LevelPlan>, LodError> {
    let estimate = |grid: &Grid, q: usize| -> LevelEstimate {
        match source {
            LodSource::Blockwise(c) => {
                // A level small enough for the dense route is made dense for the genus step.
                let dense = estimated_bytes(grid, q);
                let dense = if dense > BAND_ABOVE_BYTES { 0 } else { dense };
                c.estimated_bytes(grid, q).max(dense).into()
            }
            LodSource::Solid(solid) if uses_band(source, grid, q) => {
                let band = NarrowBandOptions::default();
                let radius = options.pyramid.radius_voxels;
                let mut need = band_estimate(*solid, grid, q, radius, &band);
                // Cleaning runs below the limit: counted unless the mesh is expected well above
                // it (the expectation is an upper bound, about 1.1 times the mesh on scans).
                let limit = CLEAN_BAND_AT_MOST_TRIANGLES as u64;
                if options.clean.is_some() && need.triangles <= limit * 3 / 2 {
                    let cleaned = need.triangles.min(limit);
                    let cleaning = CLEAN_BYTES_PER_TRIANGLE * cleaned;
                    need.estimate.bytes = need.estimate.bytes.saturating_add(cleaning);
                }
                need.estimate
            }
            _ => estimated_bytes(grid, q).into(),
        }
    };
    Ok(plan_levels_with(
        &source.bounds(),
        &options.pyramid,
        &estimate,
    )?)
}

/// Samples and contours one planned level.
pub fn build_level(
    source: &LodSource,
    plan: &LevelPlan,
    options: &LevelOptions,
) -> Result<LodLevel, LodError> {
    sample_level(source, plan, options)?.contour(options)
}

/// A level sampled but not yet contoured (the first half of [`build_level`]).
pub(crate) struct SampledLevel {
    pub(crate) plan: LevelPlan,
    pub(crate) volume: LevelVolume,
    /// Grid space to the world of an oriented scan (`voxlod_core::world`), applied to the mesh.
    pub(crate) placement: Placement,
    pub(crate) density: Option<DensityReport>,
    pub(crate) band: Option<BandReport>,
    pub(crate) sample_seconds: f64,
}

/// The samples of a level: dense, or bricks from the narrow band.
pub(crate) enum LevelVolume {
    Dense(Volume),
    Bricks(BrickVolume),
}

impl LevelVolume {
    /// The samples as one dense volume (checked against the memory limit).
    pub(crate) fn into_dense(self) -> Result<Volume, LodError> {
        match self {
            LevelVolume::Dense(volume) => Ok(volume),
            LevelVolume::Bricks(bricks) => Ok(bricks.to_volume().map_err(SamplingError::from)?),
        }
    }
}

/// The filtered density of one planned level: the source's inside function filtered, or the
/// scan's data filtered directly.
pub(crate) fn sample_level(
    source: &LodSource,
    plan: &LevelPlan,
    options: &LevelOptions,
) -> Result<SampledLevel, LodError> {
    let start = Instant::now();
    let density_options = plan.density_options(&options.pyramid);
    let q = density_options.lines_per_voxel(plan.voxel_size);
    let (volume, density, band) = match source {
        LodSource::Solid(solid) if uses_band(source, &plan.grid, q) => {
            let band = NarrowBandOptions::default();
            let (bricks, report, band) =
                narrow_band_density(*solid, &plan.grid, &density_options, &band)?;
            (LevelVolume::Bricks(bricks), Some(report), Some(band))
        }
        LodSource::Solid(solid) => {
            let (v, report) = filtered_density(*solid, &plan.grid, &density_options)?;
            (LevelVolume::Dense(v), Some(report), None)
        }
        LodSource::Blockwise(scan) => {
            let (bricks, report, band) = scan.sample(&plan.grid, &density_options)?;
            (LevelVolume::Bricks(bricks), Some(report), Some(band))
        }
        LodSource::Direct(volume) => (
            LevelVolume::Dense(direct_density(
                volume,
                &plan.grid,
                options.pyramid.filter,
                plan.radius,
            )?),
            None,
            None,
        ),
    };
    Ok(SampledLevel {
        plan: *plan,
        volume,
        placement: source.placement(),
        density,
        band,
        sample_seconds: start.elapsed().as_secs_f64(),
    })
}

impl SampledLevel {
    /// Marching cubes at the options' iso value (the second half of [`build_level`]).
    pub(crate) fn contour(self, options: &LevelOptions) -> Result<LodLevel, LodError> {
        let start = Instant::now();
        // Levels that are cleaned are contoured with vertices snapped away from the samples,
        // so that cleaning finds (next to) nothing to do.
        let clamp = (options.clean)
            .filter(|_| options.snap)
            .map_or(PLAIN_CLAMP, |c| c.contour_clamp());
        let contour = ContourOptions {
            iso: options.iso,
            normals: options.normals,
            clamp,
        };
        let mut mesh = match &self.volume {
            LevelVolume::Dense(volume) => marching_cubes(volume, &contour)?,
            LevelVolume::Bricks(bricks) => sparse_marching_cubes(bricks, &contour)?,
        };
        let band = matches!(self.volume, LevelVolume::Bricks(_));
        drop(self.volume);
        // A band level too large for cleaning's memory is left as it is; skipped only if
        // cleaning would have found something to fix.
        let too_large = band && mesh.triangles.len() > CLEAN_BAND_AT_MOST_TRIANGLES;
        let cell = self.plan.voxel_size;
        let clean_skipped =
            too_large && options.clean.is_some_and(|c| has_defects(&mesh, cell, &c));
        if let Some(clean) = options.clean.as_ref().filter(|_| !too_large) {
            mesh = clean_mesh(&mesh, self.plan.voxel_size, clean)?.0;
        }
        // The one place where levels leave grid space: an oblique or flipped scan's mesh moves
        // to its world here, rewound when the transform flips handedness.
        self.placement.apply(&mut mesh);
        let contour_seconds = start.elapsed().as_secs_f64();
        let topology = mesh_topology(&mesh);
        Ok(LodLevel {
            resolution: self.plan.resolution,
            plan: self.plan,
            mesh,
            topology,
            density: self.density,
            sample_seconds: self.sample_seconds,
            contour_seconds,
            band: self.band,
            envelope: None,
            monotone: None,
            monotone_seconds: 0.0,
            clean_skipped,
        })
    }

    /// Adjusts the level's density so that its surface has no more handles than the chain's
    /// previous level ([`voxlod_sampling::monotone_topology`]), and returns what changed. A level
    /// sampled in the narrow band is left as it is (the rules need the dense volume, which is
    /// what the band avoids) and starts the chain again: `None`. A level of a blockwise scan small
    /// enough for the dense route ([`BAND_ABOVE_BYTES`]) is made dense first, so that its chain
    /// is the in-memory threshold route's. The level's density goes through the chain by value
    /// (no copy of the dense volume).
    pub(crate) fn keep_monotone(
        mut self,
        chain: &mut MonotoneChain,
        options: &LevelOptions,
    ) -> Result<(SampledLevel, Option<TopologyRecord>), LodError> {
        let filter = self.plan.density_options(&options.pyramid);
        let q = filter.lines_per_voxel(self.plan.voxel_size);
        if let LevelVolume::Bricks(bricks) = &self.volume {
            if estimated_bytes(&self.plan.grid, q) <= BAND_ABOVE_BYTES {
                let dense = bricks.to_volume().map_err(SamplingError::from)?;
                self.volume = LevelVolume::Dense(dense);
            }
        }
        let volume = match self.volume {
            LevelVolume::Dense(volume) => volume,
            bricks => {
                *chain = MonotoneChain::new(chain.options);
                self.volume = bricks;
                return Ok((self, None));
            }
        };
        let (adjusted, record) = chain.next_owned(volume, options.iso, &filter)?;
        self.volume = LevelVolume::Dense(adjusted);
        Ok((self, Some(record)))
    }
}
