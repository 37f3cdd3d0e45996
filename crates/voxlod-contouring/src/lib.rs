//! Marching cubes for voxlod: from a filtered volume (or any scalar volume) to a closed,
//! consistently oriented triangle mesh with shared vertices and gradient normals.
//!
//! - [`tables`]: the 256-case lookup tables, generated from first principles.
//! - [`marching_cubes`]: the extraction, in bit-parallel passes in the manner of Flying Edges;
//!   [`marching_cubes_with_cells`] also gives each triangle's cell, and [`marching_cubes_multi`]
//!   several isosurfaces from one read of the volume (the multi-layer shells of paper §3).
//! - [`clean_mesh`]: short edges collapsed and caps flipped, so that a level has no sliver,
//!   needle or zero-area triangle and no self-intersection (beyond the paper).
//! - [`triangle_estimate`]: marching cubes' triangle count of a mesh's surface at a resolution,
//!   before sampling (beyond the paper), and the resolution for a triangle budget.

pub mod clean_mesh;
mod local_crossings;
pub mod marching_cubes;
pub mod tables;
pub mod triangle_estimate;

pub use clean_mesh::{clean_mesh, CleanError, CleanOptions, CleanReport};
pub use marching_cubes::{
    marching_cubes, marching_cubes_multi, marching_cubes_with_cells, CellMesh, ContourError,
    ContourOptions,
};
