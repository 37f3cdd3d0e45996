//! Core types shared by every stage of voxlod.
//!
//! - [`TriangleMesh`] and [`PolyMesh`]: indexed triangle meshes with optional normals, and the
//!   richer output of clustering and layering (dangling edges, isolated points, attributes).
//! - [`Grid`] and [`Volume`]: a regular lattice of samples with spacing and origin in world units
//!   (millimetres for a CT), and a scalar field on it.
//! - [`world`]: where a volume sits in the patient: direction cosines, LPS or RAS, and the
//!   map of finished meshes from grid space to the world.
//! - [`BrickVolume`]: the same samples stored sparsely, dense leaf bricks near the surface and
//!   one value per brick elsewhere.
//! - [`topology`]: edge-based manifold checks, Euler characteristic and genus.
//! - [`cavities`]: a solid as seen from outside, its enclosed voids filled; [`components`]:
//!   a mesh's connected parts; [`parity`]: inside a closed surface or not.
//! - [`crossings`]: whether two triangles cross (exact orientation signs), and
//!   [`crossing_pairs`]: every pair of a mesh's triangles that does.
//! - [`weld`]: merging coincident vertices, as STL triangle soups need.
//! - [`memory`]: refusing allocations that cannot fit, with the size they would need.
//! - [`repair`]: dropping degenerate and duplicate triangles, closing holes for the inside test;
//!   [`split`]: refining a mesh to a triangle count without changing its surface.
//! - [`Bounds`], [`CoreError`], and [`disjoint`] writes from several threads.
//!
//! The types are the data of the voxel paper's pipeline (He et al. 1995): the object and its
//! levels are triangle meshes, the filtered buffers of §2 are volumes on grids, and the genus
//! the paper simplifies (§1, §4) is computed by [`topology`]. Cost: the types are plain arrays
//! (12 bytes a vertex, 12 a triangle, 4 a sample); each module gives the cost of its functions.
//!
//! A closed mesh and what its topology says of it (a tetrahedron: a sphere, genus 0):
//!
//! ```
//! use voxlod_core::{glam::Vec3, mesh_topology, TriangleMesh};
//!
//! let tetrahedron = TriangleMesh::new(
//!     vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z],
//!     vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
//! );
//! tetrahedron.validate()?;
//! let topology = mesh_topology(&tetrahedron);
//! assert_eq!((topology.vertices, topology.edges, topology.triangles), (4, 6, 4));
//! assert_eq!(topology.euler_characteristic, 2);
//! assert_eq!(topology.genus, Some(0));
//! assert!(topology.is_closed_manifold() && topology.is_consistently_oriented());
//! // Outward winding encloses a positive volume: 1/6 of the unit cube's corner.
//! assert!((tetrahedron.signed_volume() - 1.0 / 6.0).abs() < 1e-12);
//! # Ok::<(), voxlod_core::CoreError>(())
//! ```

#![warn(missing_docs)]

pub mod bounds;
pub mod bricks;
pub mod cavities;
pub mod components;
pub mod cpu_clock;
pub mod crossing_pairs;
pub mod crossings;
pub mod disjoint;
pub mod error;
pub mod grid;
pub mod label_volume;
pub mod manifold;
pub mod memory;
pub mod mesh;
pub mod parity;
pub mod repair;
pub mod rounding;
pub mod rows;
pub mod split;
#[cfg(test)]
mod test_shapes;
pub mod topology;
pub mod uncross;
pub mod validate;
pub mod volume;
pub mod weld;
pub mod world;

pub use bounds::Bounds;
pub use bricks::{Brick, BrickVolume};
pub use crossing_pairs::crossing_pairs;
pub use error::CoreError;
pub use grid::{Axis, Grid};
pub use label_volume::LabelVolume;
pub use mesh::{Attribute, PolyMesh, TriangleMesh};
pub use topology::{mesh_topology, Topology};
pub use volume::Volume;
pub use world::{Frame, Orientation, Placement, WorldTransform};

pub use glam;
pub use ndarray;
