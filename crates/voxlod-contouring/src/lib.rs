//! Marching cubes for voxlod: from a filtered volume (or any scalar volume) to a closed,
//! consistently oriented triangle mesh with shared vertices and gradient normals.
//!
//! - [`tables`]: the 256-case lookup tables, generated from first principles.
//! - [`marching_cubes`]: the extraction, in bit-parallel passes in the manner of Flying Edges;
//!   [`marching_cubes_with_cells`] also gives each triangle's cell, and [`marching_cubes_multi`]
//!   several isosurfaces from one read of the volume (the multi-layer shells of paper §3).
//! - [`sparse_marching_cubes`]: the same triangles from a [`voxlod_core::BrickVolume`], visiting
//!   only the bricks the surface touches.

mod edge_vertex;
pub mod marching_cubes;
pub mod sparse_marching_cubes;
pub mod tables;

pub use marching_cubes::{
    marching_cubes, marching_cubes_multi, marching_cubes_with_cells, CellMesh, ContourError,
    ContourOptions,
};
pub use sparse_marching_cubes::sparse_marching_cubes;
