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
//! Cost: O(V + T) per level for both methods (plus an O(V log V) sort for Low–Tan), parallel;
//! see each module.
//!
//! Vertices that no triangle uses are ignored throughout. Speed: see the workspace's
//! `BENCHMARKS.md` (beside the peers), and `examples/cluster_timing.rs` for a stage-by-stage
//! timing.
//!
//! # Example
//!
//! A flat 8 × 8 grid of quads on the unit square (81 vertices, 128 triangles) clustered on
//! 4 × 4 cells: the vertices at x, y = 1/8, 3/8, 5/8 and 7/8 fall in one cell with their right
//! and upper neighbours, so only the quads across the 3 × 3 inner cell borders keep three
//! clusters; the result is the 4 × 4 vertex grid in 2 · 3 · 3 = 18 triangles, every other
//! triangle an edge or point that bounds them.
//!
//! ```
//! use glam::Vec3;
//! use voxlod_clustering::{rossignac_borrel, ClusterOptions};
//! use voxlod_core::TriangleMesh;
//!
//! let n = 8u32;
//! let positions = (0..=n)
//!     .flat_map(|j| (0..=n).map(move |i| Vec3::new(i as f32, j as f32, 0.0) / n as f32))
//!     .collect();
//! let id = |i: u32, j: u32| j * (n + 1) + i;
//! let mut triangles = Vec::new();
//! for j in 0..n {
//!     for i in 0..n {
//!         let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
//!         triangles.extend([[a, b, c], [a, c, d]]);
//!     }
//! }
//! let plane = TriangleMesh::new(positions, triangles);
//!
//! let levels = rossignac_borrel(&plane, &ClusterOptions::smoothing(4))?;
//! let report = &levels[0].report;
//! assert_eq!((report.clusters, report.triangles), (16, 18));
//! assert_eq!((report.dangling_edges, report.isolated_points), (0, 0));
//! assert_eq!(report.cell_size, 0.25);
//! # Ok::<(), voxlod_clustering::ClusteringError>(())
//! ```

#![warn(missing_docs)]

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
