//! A level's vertices moved to fit the input surface, its triangles kept: the last geometric
//! stage of voxlod's budget levels (beyond He et al. 1995, whose §5 leaves the geometric stage
//! open).
//!
//! A voxel level, simplified or not, inherits the filter's smoothing: a concave crease between
//! two merged spheres fills in, a sharp edge rounds off, and no later collapse of that level
//! gets them back, because it only ever looks at the level. Fitting looks at the input again.
//! With the connectivity fixed, the vertex positions that minimise
//!
//! ```text
//! Σ_s |s − φ(b_s)|²  +  w Σ_v |v − c_v|²  +  κ Σ_(i,j) |v_i − v_j|²
//! ```
//!
//! are found by linear least squares, where `s` runs over points sampled on the input surface,
//! `φ(b_s)` is the point of the level nearest to `s` (its triangle and barycentric coordinates
//! held fixed), `c_v` is the point of the input nearest to vertex `v`, and the last sum is a
//! spring over the level's edges that keeps the system well posed where few samples fall. This
//! is the inner problem of Hoppe, DeRose, Duchamp, McDonald and Stuetzle's mesh optimization
//! (SIGGRAPH 1993, §4.1: projections, then a sparse least-squares solve, repeated), without
//! their connectivity changes; the vertex term (the level's side of the two-sided distance) is
//! our addition, so that a level is pulled towards the input from both sides, as the two-sided
//! Hausdorff distance that judges it measures.
//!
//! The normal equations are sparse (a vertex couples only to its neighbours) and positive
//! definite (the vertex term puts weight on every diagonal entry); they are solved by conjugate
//! gradients with a Jacobi preconditioner ([`normal_equations`]). A step that would turn any
//! triangle's normal by 60° or more (a fold, or a triangle squeezed to nothing) is halved, twice
//! at most; where even the quarter step turns some, the corners of those triangles stay where
//! they were and the other vertices take the full step, so that a sliver folding in one place
//! does not stop the whole level's fitting; the fitting stops where that would hold every
//! vertex. Where two sheets of the level that lie close were moved through each other, the
//! corners of the crossing triangles go back to where they were (module `untangle`). The
//! caller judges the result (the budget pipeline keeps it only when its measured distances to
//! the input are lower).
//!
//! Cost per iteration: one BVH of the level, `S` closest-point queries on it and `V` on the
//! input, O((S + F) log) for F triangles and V vertices, and the solve, O(F) per CG step.
//!
//! ```
//! use voxlod_core::glam::Vec3;
//! use voxlod_fit::{fit_to_surface, FitOptions};
//!
//! // A unit cube's surface, and the same cube shrunk by 10 % as the level to fit.
//! let cube = voxlod_testkit::shapes::unit_cube();
//! let mut level = cube.clone();
//! for p in &mut level.positions {
//!     *p = Vec3::splat(0.5) + (*p - Vec3::splat(0.5)) * 0.9;
//! }
//! let fitted = fit_to_surface(&level, &cube, &FitOptions::default())?;
//! let gap = |m: &voxlod_core::TriangleMesh| {
//!     (m.positions.iter().map(|p| (*p - Vec3::splat(0.5)).abs().max_element()))
//!         .fold(0.0f32, f32::max)
//! };
//! assert!((gap(&fitted.mesh) - 0.5).abs() < 0.01, "{}", gap(&fitted.mesh));
//! # Ok::<(), voxlod_fit::FitError>(())
//! ```

mod features;
mod normal_equations;
mod untangle;
mod vertex_fit;

pub use features::{snap_to_features, FeatureOptions};
pub use vertex_fit::{fit_to_surface, fit_with, FitOptions, Fitted};

use voxlod_metrics::MetricsError;

/// Why a mesh could not be fitted.
#[derive(Debug, thiserror::Error)]
pub enum FitError {
    /// The level or the input cannot be measured (no triangles with area, the memory limit).
    #[error(transparent)]
    Metrics(#[from] MetricsError),
}
