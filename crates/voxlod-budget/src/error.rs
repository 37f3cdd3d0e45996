//! [`BudgetError`]: why a run of budgets could not start or could not give a level.

use voxlod_core::CoreError;
use voxlod_metrics::MetricsError;
use voxlod_sampling::SamplingError;

/// Why [`crate::levels`] gave no levels.
#[derive(Debug, thiserror::Error)]
pub enum BudgetError {
    /// A mesh with bad coordinates or indices, or work that would not fit the memory budget.
    #[error(transparent)]
    Core(#[from] CoreError),
    /// The input has no triangle with area once coincident vertices are merged.
    #[error("the mesh has no triangle with area ({triangles} triangles, all degenerate or none)")]
    EmptyMesh {
        /// Triangles given.
        triangles: usize,
    },
    /// A budget list that no closed surface can meet (empty, or a budget under 4).
    #[error("--triangles: {0}")]
    InvalidBudgets(String),
    /// An option out of its range.
    #[error("{name}: {problem}")]
    InvalidOption {
        /// The option's name.
        name: &'static str,
        /// What is wrong with its value.
        problem: String,
    },
    /// Sampling the input failed (the memory budget, a degenerate box).
    #[error(transparent)]
    Sampling(#[from] SamplingError),
    /// Measuring failed (the memory budget).
    #[error(transparent)]
    Metrics(#[from] MetricsError),
    /// Drawing the input's views to find what is seen failed (the memory budget).
    #[error(transparent)]
    Render(#[from] voxlod_render::RenderError),
    /// Every method failed on a budget: no candidate at all.
    #[error("no level for {budget} triangles: {why}")]
    NoLevel {
        /// The budget.
        budget: usize,
        /// What each method said.
        why: String,
    },
    /// The progress callback asked to stop.
    #[error("stopped on request")]
    Cancelled,
}
