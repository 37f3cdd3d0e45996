//! The product's main job as a library call: a solid or a scanned volume in, a chain of closed
//! triangle meshes out, one per level of the pyramid (paper §2).
//!
//! Each level is sampled from the **original** source with its own filter radius
//! ([`voxlod_sampling::pyramid`]) and contoured by marching cubes; nothing is derived from the
//! level above. [`plan`] sizes every level first (and refuses what would not fit in memory),
//! then [`build_level`] makes one level at a time, so a caller can write and drop each mesh
//! before the next.

use std::time::Instant;

use serde::Serialize;
use voxlod_contouring::{
    clean_mesh, marching_cubes, CleanError, CleanOptions, ContourError, ContourOptions,
};
use voxlod_core::{mesh_topology, Bounds, Topology, TriangleMesh, Volume};
use voxlod_sampling::{
    direct_density, filtered_density, plan_levels, DensityReport, LevelPlan, PyramidOptions,
    SamplingError, Solid,
};

/// What a level is made from.
pub enum LodSource<'a> {
    /// A solid (mesh, thresholded volume, CSG): its inside function is filtered, and the level's
    /// density runs from 0 to 1.
    Solid(&'a dyn Solid),
    /// A scanned volume filtered directly: the density stays in the data's units.
    Direct(&'a Volume),
}

impl LodSource<'_> {
    /// The box the levels cover.
    pub fn bounds(&self) -> Bounds {
        match self {
            LodSource::Solid(s) => s.bounds(),
            LodSource::Direct(v) => v.grid.bounds(),
        }
    }
}

/// How to build the levels.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LodOptions {
    pub pyramid: PyramidOptions,
    /// The isodensity of the surfaces (0.5 for solids; data units for direct filtering).
    pub iso: f32,
    /// Gradient normals on the output meshes.
    pub normals: bool,
    /// Clean each level (no sliver, needle or zero-area triangle, no self-intersection; beyond
    /// the paper, see [`voxlod_contouring::clean_mesh`]); `None` keeps raw marching cubes.
    pub clean: Option<CleanOptions>,
}

impl Default for LodOptions {
    /// Six levels from 256, hyper-cone filter of one voxel, isodensity 0.5, with normals,
    /// cleaned.
    fn default() -> Self {
        LodOptions {
            pyramid: PyramidOptions::default(),
            iso: 0.5,
            normals: true,
            clean: Some(CleanOptions::default()),
        }
    }
}

impl LodOptions {
    /// The paper's Table 1 setting: the Gaussian at 200, 100, 50, 30, 15 and 5, isodensity 0.5.
    pub fn paper_table1() -> Self {
        LodOptions {
            pyramid: PyramidOptions::paper_table1(),
            ..Default::default()
        }
    }
}

/// One level of detail.
#[derive(Clone, Debug)]
pub struct LodLevel {
    pub plan: LevelPlan,
    pub mesh: TriangleMesh,
    pub topology: Topology,
    /// Present for solids.
    pub density: Option<DensityReport>,
    pub sample_seconds: f64,
    pub contour_seconds: f64,
}

/// Why the levels could not be built.
#[derive(Debug, thiserror::Error)]
pub enum LodError {
    #[error(transparent)]
    Sampling(#[from] SamplingError),
    #[error(transparent)]
    Contour(#[from] ContourError),
    #[error(transparent)]
    Clean(#[from] CleanError),
}

/// Plans every level: grids, radii, and a memory check of the largest.
pub fn plan(source: &LodSource, options: &LodOptions) -> Result<Vec<LevelPlan>, LodError> {
    Ok(plan_levels(&source.bounds(), &options.pyramid)?)
}

/// Samples and contours one planned level.
pub fn build_level(
    source: &LodSource,
    plan: &LevelPlan,
    options: &LodOptions,
) -> Result<LodLevel, LodError> {
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
    let sample_seconds = start.elapsed().as_secs_f64();
    let start = Instant::now();
    let contour = ContourOptions {
        iso: options.iso,
        normals: options.normals,
    };
    let mut mesh = marching_cubes(&volume, &contour)?;
    if let Some(clean) = &options.clean {
        mesh = clean_mesh(&mesh, plan.voxel_size, clean)?.0;
    }
    let contour_seconds = start.elapsed().as_secs_f64();
    let topology = mesh_topology(&mesh);
    Ok(LodLevel {
        plan: *plan,
        mesh,
        topology,
        density,
        sample_seconds,
        contour_seconds,
    })
}

/// Builds every level, handing each to `each` as soon as it is made.
pub fn build_lod(
    source: &LodSource,
    options: &LodOptions,
    mut each: impl FnMut(LodLevel) -> Result<(), LodError>,
) -> Result<(), LodError> {
    for level in plan(source, options)? {
        each(build_level(source, &level, options)?)?;
    }
    Ok(())
}
