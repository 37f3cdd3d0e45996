//! Core types shared by every stage of voxlod.
//!
//! - [`TriangleMesh`] and [`PolyMesh`]: indexed triangle meshes with optional normals, and the
//!   richer output of clustering and layering (dangling edges, isolated points, attributes).
//! - [`Grid`] and [`Volume`]: a regular lattice of samples with spacing and origin in world units
//!   (millimetres for a CT), and a scalar field on it.
//! - [`BrickVolume`]: the same samples stored sparsely, dense leaf bricks near the surface and
//!   one value per brick elsewhere.
//! - [`topology`]: edge-based manifold checks, Euler characteristic and genus.
//! - [`weld`]: merging coincident vertices, as STL triangle soups need.
//! - [`memory`]: refusing allocations that cannot fit, with the size they would need.

pub mod bounds;
pub mod bricks;
pub mod disjoint;
pub mod error;
pub mod grid;
pub mod memory;
pub mod mesh;
pub mod repair;
#[cfg(test)]
mod test_shapes;
pub mod topology;
pub mod volume;
pub mod weld;

pub use bounds::Bounds;
pub use bricks::{Brick, BrickVolume};
pub use error::CoreError;
pub use grid::{Axis, Grid};
pub use mesh::{Attribute, PolyMesh, TriangleMesh};
pub use topology::{mesh_topology, Topology};
pub use volume::Volume;

pub use glam;
pub use ndarray;
