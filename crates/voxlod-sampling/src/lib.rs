//! Volume sampling for voxlod (He, Hong, Kaufman, Varshney, Wang 1995, §2): the inside function
//! of a solid, low-pass filtered into a pyramid of volumes.
//!
//! - What can be sampled: [`Solid`], implemented by [`MeshSolid`] (a triangle mesh through an
//!   obvhs BVH, watertight, with a [`majority`] vote for meshes with holes), [`ThresholdSolid`]
//!   (a scanned volume thresholded with trilinear interpolation) and [`CsgSolid`] (spheres,
//!   boxes, cylinders and half-spaces under union, intersection and difference; the
//!   [`sphereflake()`] is one).
//! - The filters: [`Filter`]: the [`hypercone`] of equation 3 and the truncated [`gaussian`],
//!   with their analytic half-space profiles (equation 5).
//! - Equation 1: [`filtered_density`] integrates the filter along lattice lines exactly
//!   ([`line_kernel`]) and blends the three axis families ([`density`]).
//! - [`narrow_band_density`]: the same density computed only in the bricks the surface reaches,
//!   as a [`voxlod_core::BrickVolume`]; memory grows with the surface.
//! - The [`pyramid`]: every level filtered from the original object with its own radius.
//! - Topology that only simplifies along the pyramid (beyond the paper): [`monotone_level`]
//!   keeps each level's genus at most its finer neighbour's, using the exact
//!   [`digital_topology()`] of the samples marching cubes will contour.
//! - Levels that vanish (a sheet thinner than the filter): [`level_is_empty`] and
//!   [`find_surface_resolution`], the coarsest finer resolution that still has a surface.
//! - Scanned volumes filtered directly, without thresholding: [`direct_density`], or block by
//!   block from windows of the scan, [`blockwise_direct_density`]; and the
//!   separable [`gaussian::gaussian_blur`] of a whole volume, and
//!   [`gaussian_filter::gaussian_filter`] with SciPy's border modes.
//!
//! Cost: each level is dominated by [`filtered_density`], linear in the grid's samples plus the
//! crossings of the lattice lines, after an O(F log F) BVH build for a mesh.
//!
//! A two-level pyramid of a block with a hole drilled through it (genus 1), each level filtered
//! from the solid itself with a support radius of one of its voxels:
//!
//! ```
//! use voxlod_core::{glam::DVec3, Axis};
//! use voxlod_sampling::{
//!     filtered_density, plan_levels, CsgSolid, Filter, PyramidOptions, Shape, Solid,
//! };
//!
//! let block = Shape::cuboid(DVec3::splat(-1.0), DVec3::splat(1.0))
//!     .minus(Shape::cylinder(DVec3::ZERO, Axis::Z, 0.5, 2.0));
//! let solid = CsgSolid::new(block)?;
//! let options = PyramidOptions::for_resolutions(vec![16, 2], Filter::Hypercone);
//! let levels = plan_levels(&solid.bounds(), &options)?;
//! assert_eq!(levels[0].voxel_size, 2.0 / 16.0);
//! assert_eq!(levels[1].radius, 2.0 / 2.0); // one voxel of the coarser level
//! // Padded by the radius and two voxels on each side: 16 cells + 1 + 2·3 samples.
//! assert_eq!(levels[0].grid.dims, [23, 23, 23]);
//! assert_eq!(levels[1].grid.dims, [9, 9, 9]);
//!
//! let fine = &levels[0];
//! let (density, _) = filtered_density(&solid, &fine.grid, &fine.density_options(&options))?;
//! assert_eq!(density.get(11, 11, 11), 0.0); // the middle of the hole
//! assert_eq!(density.get(17, 11, 11), 1.0); // x = 0.75, inside the wall
//!
//! // At the coarse level the support (radius 1) reaches into the wall from the middle of the
//! // hole: the hole is filling in. Exactly, 0.448 of the hyper-cone's weight lies farther than
//! // 0.5 from the hole's axis. Four quadrature lines per radius (the default) keep a plane
//! // within 0.01 of equation 5; a surface curved as tightly as this hole (radius R/2) needs
//! // more lines for that accuracy.
//! let coarse = &levels[1];
//! let dense = PyramidOptions { lines_per_radius: 32, ..options.clone() };
//! let (density, _) = filtered_density(&solid, &coarse.grid, &coarse.density_options(&dense))?;
//! assert!((density.get(4, 4, 4) - 0.448).abs() < 0.005);
//! # Ok::<(), voxlod_sampling::SamplingError>(())
//! ```

#![warn(missing_docs)]

pub mod band_cover;
pub mod blockwise_direct;
pub mod blockwise_threshold;
mod cell_columns;
pub mod closing;
pub mod csg;
pub mod density;
pub mod digital_topology;
pub mod direct;
pub mod error;
pub mod filter;
pub mod gaussian;
pub mod gaussian_filter;
pub mod hypercone;
pub mod lattice;
pub mod line_kernel;
pub mod majority;
pub mod mesh_solid;
pub mod monotone_topology;
pub mod narrow_band;
pub mod pyramid;
pub mod run_components;
pub mod solid;
pub mod sphereflake;
pub mod threshold;
pub mod vanishing;

pub use blockwise_direct::{blockwise_direct_density, BlockwiseDirect};
pub use blockwise_threshold::{
    blockwise_threshold_density, BlockBrick, BlockSamples, BlockwiseError, BlockwiseThreshold,
    BrickAssembly,
};
pub use csg::{CsgSolid, Shape};
pub use density::{filtered_density, DensityOptions, DensityReport};
pub use digital_topology::{digital_topology, DigitalTopology};
pub use direct::direct_density;
pub use error::SamplingError;
pub use filter::Filter;
pub use gaussian_filter::{gaussian_filter, BoundaryMode, GaussianFilterOptions};
pub use mesh_solid::{MeshPreparation, MeshSolid, MeshSolidOptions};
pub use monotone_topology::{
    monotone_level, LevelShape, MonotoneChain, MonotoneError, MonotoneLevel, MonotoneOptions,
    TopologyRecord,
};
pub use narrow_band::{
    band_estimate, narrow_band_density, BandEstimate, BandReport, NarrowBandOptions,
};
pub use pyramid::{
    level_grid, plan_levels, plan_levels_with, LevelEstimate, LevelPlan, PyramidOptions,
};
pub use solid::Solid;
pub use sphereflake::{sphereflake, sphereflake_spheres};
pub use threshold::ThresholdSolid;
pub use vanishing::{find_surface_resolution, level_is_empty, Vanishing};
