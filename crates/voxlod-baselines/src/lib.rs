//! Classic simplifiers that voxlod is compared with, on the same inputs.
//!
//! - [`rossignac_borrel()`]: vertex clustering on a uniform grid, with weighted synthesis and the
//!   §3.5 elimination into triangles, dangling edges and isolated points, and a series of levels
//!   from an octree (Rossignac and Borrel, "Multi-resolution 3D approximations for rendering
//!   complex scenes", 1993).
//! - [`low_tan()`]: weight-controlled clustering in floating cells centred on the heaviest vertices,
//!   with thick edges (Low and Tan's patent, "Multi-resolution graphic representation generated
//!   by weight-controlled vertex clustering").
//! - [`select`]: which level to draw for the object-space size of a pixel.
//! - [`envelope`]: simplification envelopes, ε-bounded and topology-preserving vertex removal
//!   between two offset surfaces (Varshney, Agarwal, Brooks, Wright and Weber, "Generating
//!   levels of detail for large-scale polygonal models", 1995), with its own [`EnvelopeError`].
//!
//! One algorithm per module: [`grading`], [`grid`], [`elimination`], [`rossignac_borrel`](mod@rossignac_borrel),
//! [`floating_cell`], [`thick_edges`], [`select`], [`envelope`]; results are [`Level`]s with a
//! serialisable [`LevelReport`] (the envelope's: [`EnvelopeLevel`]). Every entry point
//! checks its input and returns a [`BaselineError`]: zero cells or levels, an empty mesh,
//! non-finite coordinates, indices out of range.
//!
//! Vertices that no triangle uses are ignored throughout. Speed: see the workspace's
//! `BENCHMARKS.md` (beside the peers), and `examples/cluster_timing.rs` for a stage-by-stage
//! timing.

pub mod elimination;
pub mod envelope;
pub mod error;
pub mod floating_cell;
pub mod grading;
pub mod grid;
mod input;
pub mod level;
pub mod rossignac_borrel;
pub mod select;
mod sort;
pub mod thick_edges;

pub use elimination::{eliminate, Simplices};
pub use envelope::{
    envelope_series, simplify_envelope, EnvelopeError, EnvelopeLevel, EnvelopeOptions, Epsilon,
};
pub use error::BaselineError;
pub use floating_cell::{low_tan, FloatingCellOptions};
pub use grading::{grade, Grading};
pub use grid::ClusterGrid;
pub use level::{reports, Level, LevelReport, Method};
pub use rossignac_borrel::{rossignac_borrel, ClusterOptions, Synthesis};
pub use select::{pixel_size, select_from_reports, select_level, SelectOptions, Selection};
