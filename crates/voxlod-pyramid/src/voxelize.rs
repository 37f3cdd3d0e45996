//! One level's filtered density as a volume (paper §2, equations 1–3): the inside function of a
//! mesh, a thresholded scan or a solid, low-pass filtered and sampled on a grid of `resolution`
//! samples across the object's longest side, padded so that the density is zero on the
//! boundary; or, for a scan filtered directly, its own values filtered. The volume can be
//! contoured at any isodensity with [`crate::contour`]. Cost: O(N³) samples, each a sum over the
//! lattice lines within the filter radius.

use std::time::Instant;

use voxlod_core::{Volume, WorldTransform};
use voxlod_sampling::{DensityReport, Filter, LevelPlan, PyramidOptions};

use crate::error::{InvalidOption, PyramidError};
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

    fn check(&self) -> Result<(), PyramidError> {
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
    /// A scan's density keeps the scan's orientation and lies where the scan does, so that
    /// contouring it gives the surfaces [`crate::lod()`] gives.
    pub volume: Volume,
    /// Grid (in the source's axis-aligned grid space), voxel size and radius in world units.
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
/// # fn main() -> Result<(), voxlod_pyramid::PyramidError> {
/// use voxlod_sampling::{CsgSolid, Shape};
/// use voxlod_core::glam::DVec3;
/// let ball = CsgSolid::new(Shape::sphere(DVec3::ZERO, 1.0))?;
/// let v = voxlod_pyramid::voxelize(&voxlod_pyramid::Source::Solid(&ball), &voxlod_pyramid::VoxelizeOptions::at(12))?;
/// let (lo, hi) = v.volume.range().unwrap();
/// // Far outside the ball the density is 0 (to rounding); its centre is deep inside.
/// assert!(lo.abs() < 1e-9 && hi > 0.9, "{lo} {hi}");
/// assert!(v.warnings.is_empty());
/// # Ok(())
/// # }
/// ```
pub fn voxelize(source: &Source, options: &VoxelizeOptions) -> Result<Voxelized, PyramidError> {
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
    let volume = in_world(sampled.volume.into_dense()?, lod_source.world())?;
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

/// A volume sampled in a scan's axis-aligned grid space, placed in the scan's `world`
/// (unchanged without one; [`WorldTransform::place`]).
fn in_world(volume: Volume, world: Option<WorldTransform>) -> Result<Volume, PyramidError> {
    Ok(match world {
        Some(world) => world.place(volume)?,
        None => volume,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use voxlod_core::glam::{DMat3, DVec3};
    use voxlod_core::{Frame, Grid, Orientation};

    #[test]
    fn a_scan_density_lies_where_the_scan_does() {
        // A ball of radius 4 around index (8, 7, 6) of a rotated, flipped 16 × 14 × 12 scan.
        let grid = Grid::new([16, 14, 12], [0.8, 1.1, 1.5], [-20.0, 13.0, -7.0]).unwrap();
        let centre = DVec3::new(8.0, 7.0, 6.0);
        let mut values = Vec::with_capacity(grid.len());
        for k in 0..12 {
            for j in 0..14 {
                for i in 0..16 {
                    let d =
                        (DVec3::new(i as f64, j as f64, k as f64) - centre) * grid.spacing_vec();
                    values.push((4.0 - d.length()) as f32);
                }
            }
        }
        let orientation = Orientation {
            direction: DMat3::from_rotation_z(0.5)
                * DMat3::from_diagonal(DVec3::new(1.0, 1.0, -1.0)),
            frame: Frame::Ras,
        };
        let scan = Volume::from_vec(grid, values)
            .unwrap()
            .oriented(orientation);
        let source = Source::Threshold {
            volume: &scan,
            threshold: 0.0,
        };
        let density = voxelize(&source, &VoxelizeOptions::at(24)).unwrap().volume;
        assert_eq!(density.orientation, orientation);
        let options = voxlod_contouring::ContourOptions::geometry_only(0.5);
        let mut surface = voxlod_contouring::marching_cubes(&density, &options).unwrap();
        voxlod_core::Placement::of(&density.world(), None).apply(&mut surface);
        let n = surface.positions.len() as f64;
        let mean = (surface.positions.iter()).fold(DVec3::ZERO, |s, p| s + p.as_dvec3() / n);
        let expected = scan.world().index_to_world(centre);
        assert!((mean - expected).length() < 0.2, "{mean} {expected}");
    }
}
