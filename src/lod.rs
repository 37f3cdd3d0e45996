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

use std::time::Instant;

use serde::Serialize;
use voxlod_contouring::{marching_cubes, ContourError, ContourOptions};
use voxlod_core::{mesh_topology, Bounds, Placement, Topology, TriangleMesh, Volume};

use crate::then_envelope::EnvelopeStep;
use voxlod_sampling::{
    direct_density, filtered_density, plan_levels, DensityReport, LevelPlan, PyramidOptions,
    SamplingError, Solid,
};

/// What a level is made from: a prepared source ([`crate::Prepared::lod_source`]).
pub enum LodSource<'a> {
    /// A solid (mesh, thresholded volume, CSG): its inside function is filtered, and the level's
    /// density runs from 0 to 1.
    Solid(&'a dyn Solid),
    /// A scanned volume filtered directly: the density stays in the data's units.
    Direct(&'a Volume),
}

impl LodSource<'_> {
    /// The map of finished meshes from grid space to the source's world: the scan's own
    /// transform for a thresholded or directly filtered volume, the identity otherwise.
    pub fn placement(&self) -> Placement {
        let world = match self {
            LodSource::Solid(s) => s.world(),
            LodSource::Direct(v) => Some(v.world()),
        };
        world.map_or(Placement::IDENTITY, |w| Placement::of(&w, None))
    }

    /// The box the levels cover.
    pub fn bounds(&self) -> Bounds {
        match self {
            LodSource::Solid(s) => s.bounds(),
            LodSource::Direct(v) => v.grid.bounds(),
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
}

/// The former name of [`LevelOptions`], kept while `voxlod-eval` still uses it. Not to be
/// confused with [`crate::LodOptions`], the options of [`crate::lod()`].
pub type LodOptions = LevelOptions;

impl Default for LevelOptions {
    /// Six levels from 256, hyper-cone filter of one voxel, isodensity 0.5, with normals.
    fn default() -> Self {
        LevelOptions {
            pyramid: PyramidOptions::default(),
            iso: 0.5,
            normals: true,
        }
    }
}

impl LevelOptions {
    /// The paper's Table 1 setting: the Gaussian at 200, 100, 50, 30, 15 and 5, isodensity 0.5.
    pub fn paper_table1() -> Self {
        LevelOptions {
            pyramid: PyramidOptions::paper_table1(),
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
    /// What the envelope step did ([`crate::LodOptions::then_envelope`]), when asked.
    pub envelope: Option<EnvelopeStep>,
}

/// Why a level could not be built.
#[derive(Debug, thiserror::Error)]
pub enum LodError {
    /// The sampling failed (an option, the memory budget).
    #[error(transparent)]
    Sampling(#[from] SamplingError),
    /// Marching cubes failed (32-bit limits, the memory budget).
    #[error(transparent)]
    Contour(#[from] ContourError),
}

/// Plans every level: grids, radii, and a memory check of the largest.
pub fn plan(source: &LodSource, options: &LevelOptions) -> Result<Vec<LevelPlan>, LodError> {
    Ok(plan_levels(&source.bounds(), &options.pyramid)?)
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
    pub(crate) volume: Volume,
    /// Grid space to the world of an oriented scan (`voxlod_core::world`), applied to the mesh.
    pub(crate) placement: Placement,
    pub(crate) density: Option<DensityReport>,
    pub(crate) sample_seconds: f64,
}

/// The filtered density of one planned level: the source's inside function filtered, or the
/// scan's data filtered directly.
pub(crate) fn sample_level(
    source: &LodSource,
    plan: &LevelPlan,
    options: &LevelOptions,
) -> Result<SampledLevel, LodError> {
    let start = Instant::now();
    let (volume, density) = match source {
        LodSource::Solid(solid) => {
            let (v, report) =
                filtered_density(*solid, &plan.grid, &plan.density_options(&options.pyramid))?;
            (v, Some(report))
        }
        LodSource::Direct(volume) => (
            direct_density(volume, &plan.grid, options.pyramid.filter, plan.radius)?,
            None,
        ),
    };
    Ok(SampledLevel {
        plan: *plan,
        volume,
        placement: source.placement(),
        density,
        sample_seconds: start.elapsed().as_secs_f64(),
    })
}

impl SampledLevel {
    /// Marching cubes at the options' iso value (the second half of [`build_level`]).
    pub(crate) fn contour(self, options: &LevelOptions) -> Result<LodLevel, LodError> {
        let start = Instant::now();
        let contour = ContourOptions {
            iso: options.iso,
            normals: options.normals,
        };
        let mut mesh = marching_cubes(&self.volume, &contour)?;
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
            envelope: None,
        })
    }
}

/// Builds every level, handing each to `each` as soon as it is made.
pub fn build_lod(
    source: &LodSource,
    options: &LevelOptions,
    mut each: impl FnMut(LodLevel) -> Result<(), LodError>,
) -> Result<(), LodError> {
    for level in plan(source, options)? {
        each(build_level(source, &level, options)?)?;
    }
    Ok(())
}
