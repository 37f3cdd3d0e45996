//! Marching cubes for voxlod: from a filtered volume (or any scalar volume) to a closed,
//! consistently oriented triangle mesh with shared vertices and gradient normals.
//!
//! - [`tables`]: the 256-case lookup tables, generated from first principles.
//! - [`marching_cubes()`]: the extraction (paper §2), in bit-parallel passes in the manner of
//!   Flying Edges (module [`mod@marching_cubes`]); [`marching_cubes_with_cells`] also gives each
//!   triangle's cell, and [`marching_cubes_multi`] several isosurfaces from one read of the
//!   volume (the multi-layer shells of paper §3).
//! - [`block_marching_cubes()`]: the same extraction block by block, with global edge keys, and
//!   [`stitch_blocks`], the stitching of the pieces into the whole-volume mesh (module
//!   [`mod@block_marching_cubes`]).
//! - [`clean_mesh()`] (module [`mod@clean_mesh`]): short edges collapsed and caps flipped, so
//!   that a level has no sliver, needle or zero-area triangle and no self-intersection (beyond
//!   the paper).
//! - [`triangle_estimate`]: marching cubes' triangle count of a mesh's surface at a resolution,
//!   before sampling (beyond the paper), and the resolution for a triangle budget.
//! - [`sparse_marching_cubes()`]: the same triangles from a [`voxlod_core::BrickVolume`],
//!   visiting only the bricks the surface touches (module [`mod@sparse_marching_cubes`]).
//!
//! Cost: one read of the volume, then O(N³/64) word operations and work proportional to the
//! surface.
//!
//! One sample inside a 3×3×3 grid of outside samples comes out as an octahedron, one triangle
//! in each of the eight cells around it, closed and outward-facing:
//!
//! ```
//! use voxlod_contouring::{marching_cubes, ContourOptions};
//! use voxlod_core::{mesh_topology, Grid, Volume};
//!
//! let mut values = vec![0.0f32; 27];
//! values[13] = 1.0; // sample (1, 1, 1)
//! let volume = Volume::from_vec(Grid::unit([3, 3, 3])?, values)?;
//! let mesh = marching_cubes(&volume, &ContourOptions::default())?; // iso 0.5, with normals
//! assert_eq!((mesh.vertex_count(), mesh.triangle_count()), (6, 8));
//! let topology = mesh_topology(&mesh);
//! assert!(topology.is_closed_manifold() && topology.is_consistently_oriented());
//! assert_eq!(topology.genus, Some(0));
//! # Ok::<(), voxlod_contouring::ContourError>(())
//! ```

#![warn(missing_docs)]

pub mod block_marching_cubes;
mod bucket_index;
pub mod clean_mesh;
mod edge_vertex;
mod local_crossings;
pub mod marching_cubes;
pub mod sparse_marching_cubes;
pub mod tables;
pub mod triangle_estimate;

pub use block_marching_cubes::{
    block_marching_cubes, stitch_blocks, Block, BlockError, BlockPiece,
};
pub use clean_mesh::{clean_mesh, CleanError, CleanOptions, CleanReport};
pub use marching_cubes::{
    marching_cubes, marching_cubes_multi, marching_cubes_with_cells, CellMesh, ContourError,
    ContourOptions, PLAIN_CLAMP,
};
pub use sparse_marching_cubes::sparse_marching_cubes;
/// The whole-mesh count of crossing triangles, whose pair test the cleaning's guard shares; it
/// lives in voxlod-core so that the quadric stage can refuse folds with it too.
pub use voxlod_core::crossing_pairs;
