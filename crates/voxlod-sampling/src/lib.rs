//! Volume sampling for voxlod (He, Hong, Kaufman, Varshney, Wang 1995, §2): the inside function
//! of a solid, low-pass filtered into a pyramid of volumes.
//!
//! - What can be sampled: [`Solid`], implemented by [`MeshSolid`] (a triangle mesh through an
//!   obvhs BVH, watertight, with a [`majority`] vote for meshes with holes), [`ThresholdSolid`]
//!   (a scanned volume thresholded with trilinear interpolation) and [`CsgSolid`] (spheres,
//!   boxes, cylinders and half-spaces under union, intersection and difference; the
//!   [`sphereflake`] is one).
//! - The filters: [`Filter`]: the [`hypercone`] of equation 3 and the truncated [`gaussian`],
//!   with their analytic half-space profiles (equation 5).
//! - Equation 1: [`filtered_density`] integrates the filter along lattice lines exactly
//!   ([`line_kernel`]) and blends the three axis families ([`density`]).
//! - [`narrow_band_density`]: the same density computed only in the bricks the surface reaches,
//!   as a [`voxlod_core::BrickVolume`]; memory grows with the surface.
//! - The [`pyramid`]: every level filtered from the original object with its own radius.
//! - Scanned volumes filtered directly, without thresholding: [`direct_density`]; and the
//!   separable [`gaussian::gaussian_blur`] of a whole volume.

pub mod csg;
pub mod density;
pub mod direct;
pub mod error;
pub mod filter;
pub mod gaussian;
pub mod hypercone;
pub mod lattice;
pub mod line_kernel;
pub mod majority;
pub mod mesh_solid;
pub mod narrow_band;
pub mod pyramid;
pub mod solid;
pub mod sphereflake;
pub mod threshold;

pub use csg::{CsgSolid, Shape};
pub use density::{filtered_density, DensityOptions, DensityReport};
pub use direct::direct_density;
pub use error::SamplingError;
pub use filter::Filter;
pub use mesh_solid::{MeshPreparation, MeshSolid, MeshSolidOptions};
pub use narrow_band::{narrow_band_density, BandReport, NarrowBandOptions};
pub use pyramid::{level_grid, plan_levels, plan_levels_with, LevelPlan, PyramidOptions};
pub use solid::Solid;
pub use sphereflake::{sphereflake, sphereflake_spheres};
pub use threshold::ThresholdSolid;
