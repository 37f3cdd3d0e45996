//! The one error type of the envelope simplifier, each message one line naming the bad value.

use thiserror::Error;
use voxlod_core::CoreError;
use voxlod_metrics::MetricsError;

use super::manifold::ManifoldProblems;

/// Why the envelope simplifier refused to run.
#[derive(Debug, Error)]
pub enum EnvelopeError {
    #[error("ε must be a positive, finite distance or percentage of the bounding-box diagonal (got {0})")]
    InvalidEpsilon(String),
    #[error("the levels must have growing ε (level {level} has {epsilon}, not more than the level before)")]
    EpsilonNotGrowing { level: usize, epsilon: f64 },
    #[error("{what} must be {expected} (got {value})")]
    InvalidOption {
        what: &'static str,
        expected: &'static str,
        value: f64,
    },
    #[error("the mesh is not a consistently oriented manifold: {0}; repair it first (voxlod envelope --repair)")]
    NotManifold(ManifoldProblems),
    #[error("the mesh is too large: {0}")]
    TooLarge(String),
    #[error(transparent)]
    Core(#[from] CoreError),
    #[error(transparent)]
    Metrics(#[from] MetricsError),
}
