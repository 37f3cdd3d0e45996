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
//! - The [`pyramid`]: every level filtered from the original object with its own radius.
//! - Topology that only simplifies along the pyramid (beyond the paper): [`monotone_level`]
//!   keeps each level's genus at most its finer neighbour's, using the exact
//!   [`digital_topology`] of the samples marching cubes will contour.
//! - Levels that vanish (a sheet thinner than the filter): [`level_is_empty`] and
//!   [`find_surface_resolution`], the coarsest finer resolution that still has a surface.
//! - Scanned volumes filtered directly, without thresholding: [`direct_density`]; and the
//!   separable [`gaussian::gaussian_blur`] of a whole volume.

pub mod csg;
pub mod density;
pub mod digital_topology;
pub mod direct;
pub mod error;
pub mod filter;
pub mod gaussian;
pub mod hypercone;
pub mod lattice;
pub mod line_kernel;
pub mod majority;
pub mod mesh_solid;
pub mod monotone_topology;
pub mod pyramid;
pub mod solid;
pub mod sphereflake;
pub mod threshold;
pub mod vanishing;

pub use csg::{CsgSolid, Shape};
pub use density::{filtered_density, DensityOptions, DensityReport};
pub use digital_topology::{digital_topology, DigitalTopology};
pub use direct::direct_density;
pub use error::SamplingError;
pub use filter::Filter;
pub use mesh_solid::{MeshPreparation, MeshSolid, MeshSolidOptions};
pub use monotone_topology::{
    monotone_level, LevelShape, MonotoneError, MonotoneLevel, MonotoneOptions, TopologyRecord,
};
pub use pyramid::{level_grid, plan_levels, LevelPlan, PyramidOptions};
pub use solid::Solid;
pub use sphereflake::{sphereflake, sphereflake_spheres};
pub use threshold::ThresholdSolid;
pub use vanishing::{find_surface_resolution, level_is_empty, Vanishing};
