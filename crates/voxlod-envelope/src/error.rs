//! The one error type of the envelope simplifier, each message one line naming the bad value.

use thiserror::Error;
use voxlod_core::CoreError;
use voxlod_metrics::MetricsError;

use super::manifold::ManifoldProblems;

/// Why the envelope simplifier refused to run.
#[derive(Debug, Error)]
pub enum EnvelopeError {
    /// An ε that is zero, negative or not finite (as written).
    #[error("ε must be a positive, finite distance or percentage of the bounding-box diagonal (got {0})")]
    InvalidEpsilon(String),
    /// A series whose ε shrinks from one level to the next.
    #[error("the levels must have growing ε (level {level} has {epsilon}, not more than the level before)")]
    EpsilonNotGrowing {
        /// The level whose ε is smaller than the one before.
        level: usize,
        /// Its ε, in the mesh's units.
        epsilon: f64,
    },
    /// An option out of its range.
    #[error("{what} must be {expected} (got {value})")]
    InvalidOption {
        /// The option, in words.
        what: &'static str,
        /// Its range, in words.
        expected: &'static str,
        /// The value given.
        value: f64,
    },
    /// A mesh that is not a consistently oriented manifold (what is wrong, with examples).
    #[error("the mesh is not a consistently oriented manifold: {0}; repair it first (voxlod envelope --repair)")]
    NotManifold(ManifoldProblems),
    /// More vertices or triangles than the ids can name (the counts and the limit, in words).
    #[error("the mesh is too large: {0}")]
    TooLarge(String),
    /// The memory budget's refusal, or another core error.
    #[error(transparent)]
    Core(#[from] CoreError),
    /// Measuring the distance to the input failed.
    #[error(transparent)]
    Metrics(#[from] MetricsError),
}
