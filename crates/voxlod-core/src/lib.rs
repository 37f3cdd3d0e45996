//! Core types shared by every stage of voxlod.
//!
//! - [`TriangleMesh`] and [`PolyMesh`]: indexed triangle meshes with optional normals, and the
//!   richer output of clustering and layering (dangling edges, isolated points, attributes).
//! - [`Grid`] and [`Volume`]: a regular lattice of samples with spacing and origin in world units
//!   (millimetres for a CT), and a scalar field on it.
//! - [`world`]: where a volume sits in the patient: direction cosines, LPS or RAS, and the
//!   map of finished meshes from grid space to the world.
//! - [`topology`]: edge-based manifold checks, Euler characteristic and genus.
//! - [`weld`]: merging coincident vertices, as STL triangle soups need.
//! - [`memory`]: refusing allocations that cannot fit, with the size they would need.

pub mod bounds;
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
pub mod world;

pub use bounds::Bounds;
pub use error::CoreError;
pub use grid::{Axis, Grid};
pub use mesh::{Attribute, PolyMesh, TriangleMesh};
pub use topology::{mesh_topology, Topology};
pub use volume::Volume;
pub use world::{Frame, Orientation, Placement, WorldTransform};

pub use glam;
pub use ndarray;
