//! Vertex clustering: the classic simplifiers that voxlod is compared with, on the same inputs.
//!
//! - [`rossignac_borrel()`]: vertex clustering on a uniform grid, with weighted synthesis and the
//!   §3.5 elimination into triangles, dangling edges and isolated points, and a series of levels
//!   from an octree (Rossignac and Borrel, "Multi-resolution 3D approximations for rendering
//!   complex scenes", 1993).
//! - [`low_tan()`]: weight-controlled clustering in floating cells centred on the heaviest vertices,
//!   with thick edges (Low and Tan's patent, "Multi-resolution graphic representation generated
//!   by weight-controlled vertex clustering").
//!
//! Which level to draw for the object-space size of a pixel is the facade's `voxlod::select`;
//! simplification envelopes are the crate `voxlod-envelope`.
//!
//! One algorithm per module: [`grading`], [`grid`], [`elimination`], [`rossignac_borrel`](mod@rossignac_borrel),
//! [`floating_cell`], [`thick_edges`]; results are [`Level`]s with a
//! serialisable [`LevelReport`]. Every entry point
//! checks its input and returns a [`ClusteringError`]: zero cells or levels, an empty mesh,
//! non-finite coordinates, indices out of range.
//!
//! Vertices that no triangle uses are ignored throughout. Speed: see the workspace's
//! `BENCHMARKS.md` (beside the peers), and `examples/cluster_timing.rs` for a stage-by-stage
//! timing.

pub mod elimination;
pub mod error;
pub mod floating_cell;
pub mod grading;
pub mod grid;
mod input;
pub mod level;
pub mod rossignac_borrel;
mod sort;
pub mod thick_edges;

pub use elimination::{eliminate, Simplices};
pub use error::ClusteringError;
pub use floating_cell::{low_tan, FloatingCellOptions};
pub use grading::{grade, Grading};
pub use grid::ClusterGrid;
pub use level::{reports, Level, LevelReport, Method};
pub use rossignac_borrel::{rossignac_borrel, ClusterOptions, Synthesis};
