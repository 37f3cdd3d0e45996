//! The pyramid of levels (paper §2): every level is filtered **from the original object** with
//! its own support radius, never from the level above, so the errors of a non-ideal filter do
//! not accumulate from level to level.
//!
//! Defaults follow the paper's tables: level k has resolution `N / 2^k` samples across the
//! longest side of the object's box, and a support radius of one voxel of that level (Table 1:
//! 200³ with radius 1, 100³ with radius 2, …, in units of the finest voxel). An explicit list of
//! resolutions (`200,100,50,30,15,5`) reproduces the tables exactly.
//!
//! Each level's grid is the object's box, padded by the support radius plus two voxels on every
//! side, so that the filtered density is zero on the grid's boundary and marching cubes closes
//! every surface. The padding is why a level of "resolution 200" has a few more samples.
//!
//! Cost: planning is O(levels), and checks every level against the memory limit before any
//! work starts; each level then costs one [`crate::filtered_density`], so the finest level
//! dominates (halving the resolution divides the samples by eight).

use serde::Serialize;
use voxlod_core::{Bounds, Grid};

use crate::density::{estimated_bytes, DensityOptions};
use crate::{Filter, SamplingError};

/// How to build the pyramid.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PyramidOptions {
    /// Samples across the longest side of the object's box, one entry per level.
    pub resolutions: Vec<usize>,
    /// Support radius in voxels of each level (the paper uses 1).
    pub radius_voxels: f64,
    /// The low-pass filter of every level.
    pub filter: Filter,
    /// Quadrature lines per support radius (see [`DensityOptions`]).
    pub lines_per_radius: usize,
}

impl Default for PyramidOptions {
    /// Six levels from 256, hyper-cone filter, radius one voxel.
    fn default() -> Self {
        PyramidOptions::halving(256, 6, Filter::Hypercone)
    }
}

impl PyramidOptions {
    /// `levels` levels from `resolution`, halving each time (never below 2).
    pub fn halving(resolution: usize, levels: usize, filter: Filter) -> Self {
        let resolutions = (0..levels)
            .map(|k| (resolution >> k).max(2))
            .collect::<Vec<_>>();
        PyramidOptions {
            resolutions,
            radius_voxels: 1.0,
            filter,
            lines_per_radius: DensityOptions::DEFAULT_LINES_PER_RADIUS,
        }
    }

    /// The paper's Table 1: the sphereflake at 200, 100, 50, 30, 15 and 5 with the Gaussian.
    pub fn paper_table1() -> Self {
        PyramidOptions {
            resolutions: vec![200, 100, 50, 30, 15, 5],
            ..PyramidOptions::halving(200, 1, Filter::GAUSSIAN)
        }
    }

    /// Explicit resolutions.
    pub fn for_resolutions(resolutions: Vec<usize>, filter: Filter) -> Self {
        PyramidOptions {
            resolutions,
            ..PyramidOptions::halving(2, 1, filter)
        }
    }
}

/// One level: its nominal resolution, voxel size, support radius (world units) and grid.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct LevelPlan {
    /// 0 for the finest level, counting up as the levels coarsen.
    pub level: usize,
    /// Samples across the longest side of the object's box (before padding).
    pub resolution: usize,
    /// Sample spacing, world units.
    pub voxel_size: f64,
    /// Support radius R of the filter, world units.
    pub radius: f64,
    /// The padded grid the level is sampled on.
    pub grid: Grid,
    /// Bytes the plan expects the level to need at its peak (checked against the budget).
    pub estimated_bytes: u64,
}

/// What a level is expected to need: bytes, and what they are for when a refusal should say
/// more than the level's resolution (the narrow band's bricks).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LevelEstimate {
    /// Bytes at the level's peak.
    pub bytes: u64,
    /// What needs them, e.g. "the narrow band of ~120,000 bricks of 8³ samples …".
    pub what: Option<String>,
}

impl From<u64> for LevelEstimate {
    fn from(bytes: u64) -> Self {
        LevelEstimate { bytes, what: None }
    }
}

impl LevelPlan {
    /// The filtering options of this level.
    pub fn density_options(&self, options: &PyramidOptions) -> DensityOptions {
        DensityOptions {
            filter: options.filter,
            radius: self.radius,
            lines_per_radius: options.lines_per_radius,
        }
    }
}

/// The padded grid of `resolution` samples across the longest side of `bounds`.
pub fn level_grid(bounds: &Bounds, resolution: usize, radius: f64) -> Result<Grid, SamplingError> {
    if resolution == 0 {
        return Err(SamplingError::InvalidOption(
            "a resolution must be at least 1".into(),
        ));
    }
    let extent = bounds.longest_extent();
    if bounds.is_empty() || !(extent.is_finite() && extent > 0.0) {
        return Err(SamplingError::EmptyBounds);
    }
    let h = extent / resolution as f64;
    let pad = (radius / h).ceil() as usize + 2;
    let size = bounds.size();
    let centre = bounds.center();
    let mut dims = [0usize; 3];
    let mut origin = [0.0; 3];
    for a in 0..3 {
        let cells = (size[a] / h).ceil() as usize;
        dims[a] = cells + 1 + 2 * pad;
        origin[a] = centre[a] - (dims[a] - 1) as f64 * h / 2.0;
    }
    Ok(Grid::new(dims, [h; 3], origin)?)
}

/// Plans every level, checking that the largest fits in memory before any work starts.
pub fn plan_levels(
    bounds: &Bounds,
    options: &PyramidOptions,
) -> Result<Vec<LevelPlan>, SamplingError> {
    plan_levels_with(bounds, options, &|grid, q| estimated_bytes(grid, q).into())
}

/// As [`plan_levels`], with the bytes a level needs given by `estimate(grid, lines_per_voxel)`
/// (the dense sampler's [`estimated_bytes`], or the narrow band's).
pub fn plan_levels_with(
    bounds: &Bounds,
    options: &PyramidOptions,
    estimate: &dyn Fn(&Grid, usize) -> LevelEstimate,
) -> Result<Vec<LevelPlan>, SamplingError> {
    if options.resolutions.is_empty() {
        return Err(SamplingError::InvalidOption("no levels requested".into()));
    }
    if !(options.radius_voxels.is_finite() && options.radius_voxels > 0.0) {
        return Err(SamplingError::InvalidOption(format!(
            "the radius must be a positive number of voxels, got {}",
            options.radius_voxels
        )));
    }
    let extent = bounds.longest_extent();
    options
        .resolutions
        .iter()
        .enumerate()
        .map(|(level, &resolution)| {
            if resolution == 0 {
                return Err(SamplingError::InvalidOption(format!(
                    "level {level} has resolution 0; resolutions must be at least 1"
                )));
            }
            let voxel_size = extent / resolution as f64;
            let radius = options.radius_voxels * voxel_size;
            // Refuse absurd sizes before even forming the grid.
            let approx_side = resolution as f64 + 2.0 * options.radius_voxels + 6.0;
            let approx_bytes = match Grid::unit([approx_side as usize; 3]) {
                Ok(cube) if approx_side < (1u64 << 40) as f64 => estimate(&cube, 1).bytes,
                _ => u64::MAX,
            };
            voxlod_core::memory::check_allocation(
                &format!("level {level} at resolution {resolution}"),
                approx_bytes,
            )?;
            let grid = level_grid(bounds, resolution, radius)?;
            let mut plan = LevelPlan {
                level,
                resolution,
                voxel_size,
                radius,
                grid,
                estimated_bytes: 0,
            };
            let q = plan.density_options(options).lines_per_voxel(voxel_size);
            let need = estimate(&grid, q);
            let what = match &need.what {
                Some(what) => format!("level {level} at resolution {resolution}: {what}"),
                None => format!("level {level} at resolution {resolution}"),
            };
            voxlod_core::memory::check_allocation(&what, need.bytes)?;
            plan.estimated_bytes = need.bytes;
            Ok(plan)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn halving_levels_follow_the_paper() {
        let o = PyramidOptions::halving(256, 6, Filter::Hypercone);
        assert_eq!(o.resolutions, vec![256, 128, 64, 32, 16, 8]);
        let b = Bounds::new(DVec3::ZERO, DVec3::new(2.0, 1.0, 0.5));
        let plans = plan_levels(&b, &o).unwrap();
        assert_eq!(plans[1].voxel_size, 2.0 / 128.0);
        assert_eq!(plans[1].radius, plans[1].voxel_size);
        // Padded by ceil(R/h) + 2 = 3 voxels each side: 128 + 1 + 6 along x.
        assert_eq!(plans[1].grid.dims[0], 135);
        // The object's box lies inside the grid with at least R + h to spare.
        let gb = plans[1].grid.bounds();
        let margin = plans[1].radius + plans[1].voxel_size;
        assert!(gb.min.cmple(b.min - DVec3::splat(margin)).all());
        assert!(gb.max.cmpge(b.max + DVec3::splat(margin)).all());
    }

    #[test]
    fn refuses_zero_and_absurd_resolutions() {
        let b = Bounds::new(DVec3::ZERO, DVec3::ONE);
        let zero = PyramidOptions::for_resolutions(vec![64, 0], Filter::Hypercone);
        assert!(plan_levels(&b, &zero)
            .unwrap_err()
            .to_string()
            .contains("resolution 0"));
        let huge = PyramidOptions::for_resolutions(vec![1_000_000], Filter::Hypercone);
        let err = plan_levels(&b, &huge).unwrap_err().to_string();
        assert!(err.contains("would need") && err.contains("bytes"), "{err}");
    }
}
