//! One level's filtered density as a volume (paper §2, equations 1–3): the inside function of a
//! mesh, a thresholded scan or a solid, low-pass filtered and sampled on a grid of `resolution`
//! samples across the object's longest side, padded so that the density is zero on the
//! boundary; or, for a scan filtered directly, its own values filtered. The volume can be
//! contoured at any isodensity with [`crate::contour`]. Cost: O(N³) samples, each a sum over the
//! lattice lines within the filter radius.

use std::time::Instant;

use voxlod_core::Volume;
use voxlod_sampling::{DensityReport, Filter, LevelPlan, PyramidOptions};

use crate::error::{Error, InvalidOption};
use crate::lod::{plan, sample_level, LevelOptions};
use crate::source::Source;

/// Options of [`voxelize`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VoxelizeOptions {
    /// Samples across the longest side of the object's box.
    pub resolution: usize,
    /// The low-pass filter.
    pub filter: Filter,
    /// Filter support radius, in voxels.
    pub radius_voxels: f64,
    /// Quadrature lines per filter radius.
    pub lines_per_radius: usize,
}

impl Default for VoxelizeOptions {
    /// 128 samples, hyper-cone of one voxel, four lines per radius.
    fn default() -> Self {
        VoxelizeOptions::at(128)
    }
}

impl VoxelizeOptions {
    /// `resolution` samples, hyper-cone of one voxel.
    pub fn at(resolution: usize) -> Self {
        let pyramid = PyramidOptions::halving(resolution, 1, Filter::Hypercone);
        VoxelizeOptions {
            resolution,
            filter: pyramid.filter,
            radius_voxels: pyramid.radius_voxels,
            lines_per_radius: pyramid.lines_per_radius,
        }
    }

    /// `resolution` samples, the paper's Gaussian of one voxel.
    pub fn gaussian(resolution: usize) -> Self {
        VoxelizeOptions {
            filter: Filter::GAUSSIAN,
            ..VoxelizeOptions::at(resolution)
        }
    }

    fn check(&self) -> Result<(), Error> {
        if self.resolution == 0 {
            return Err(InvalidOption::new("resolution", 0, "must be at least 1").into());
        }
        if !(self.radius_voxels.is_finite() && self.radius_voxels > 0.0) {
            let problem = "must be a positive number of voxels";
            return Err(InvalidOption::new("radius_voxels", self.radius_voxels, problem).into());
        }
        Ok(())
    }
}

/// The filtered density of a source.
#[derive(Clone, Debug)]
pub struct Voxelized {
    /// The density: 0 outside to 1 inside for solids; the data's units when filtered directly.
    pub volume: Volume,
    /// Grid, voxel size and radius in world units.
    pub plan: LevelPlan,
    /// The sampling's figures (solids).
    pub density: Option<DensityReport>,
    /// An object the filter removed, a threshold at or below every sample.
    pub warnings: Vec<String>,
    /// Wall time of the sampling (without the source's preparation).
    pub seconds: f64,
}

/// Samples `source` into its filtered density.
///
/// ```
/// # fn main() -> Result<(), voxlod::Error> {
/// use voxlod::sampling::{CsgSolid, Shape};
/// use voxlod::core::glam::DVec3;
/// let ball = CsgSolid::new(Shape::sphere(DVec3::ZERO, 1.0))?;
/// let v = voxlod::voxelize(&voxlod::Source::Solid(&ball), &voxlod::VoxelizeOptions::at(12))?;
/// let (lo, hi) = v.volume.range().unwrap();
/// // Far outside the ball the density is 0 (to rounding); its centre is deep inside.
/// assert!(lo.abs() < 1e-9 && hi > 0.9, "{lo} {hi}");
/// assert!(v.warnings.is_empty());
/// # Ok(())
/// # }
/// ```
pub fn voxelize(source: &Source, options: &VoxelizeOptions) -> Result<Voxelized, Error> {
    options.check()?;
    let prepared = source.prepare()?;
    let level_options = LevelOptions {
        pyramid: PyramidOptions {
            resolutions: vec![options.resolution],
            radius_voxels: options.radius_voxels,
            filter: options.filter,
            lines_per_radius: options.lines_per_radius,
        },
        iso: 0.5,
        normals: false,
        clean: None,
        snap: false,
    };
    let lod_source = prepared.lod_source();
    let level_plan = plan(&lod_source, &level_options)?[0];
    let start = Instant::now();
    let sampled = sample_level(&lod_source, &level_plan, &level_options)?;
    let volume = sampled.volume.into_dense()?;
    let seconds = start.elapsed().as_secs_f64();
    let mut warnings = prepared.warnings().to_vec();
    let solid = prepared.solid().is_some();
    if solid && volume.range().is_none_or(|(_, hi)| hi < 0.5) {
        warnings.push(format!(
            "the filter of radius {:.4} removed the whole object: no sample reaches the density \
             0.5 of its surface (the object is thinner than the filter; use a higher \
             `resolution`)",
            level_plan.radius
        ));
    }
    Ok(Voxelized {
        volume,
        plan: level_plan,
        density: sampled.density,
        warnings,
        seconds,
    })
}
