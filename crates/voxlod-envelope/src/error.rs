//! The one error type of the envelope simplifier, each message one line naming the bad value,
//! and [`ManifoldProblems`], what it says of a mesh that is not a manifold.

use std::fmt;

use serde::Serialize;
use thiserror::Error;
use voxlod_core::CoreError;
use voxlod_metrics::MetricsError;

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
    /// The memory limit's refusal, or another core error.
    #[error(transparent)]
    Core(#[from] CoreError),
    /// Measuring the distance to the input failed.
    #[error(transparent)]
    Metrics(#[from] MetricsError),
}

/// Why a mesh is not a consistently oriented 2-manifold, with examples.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct ManifoldProblems {
    /// Triangles with a repeated vertex index.
    pub degenerate_triangles: usize,
    /// Edges used by three or more triangles.
    pub non_manifold_edges: usize,
    /// Edges used twice in the same direction (neighbours disagree about the outside).
    pub inconsistent_edges: usize,
    /// Vertices whose triangles form more than one fan.
    pub non_manifold_vertices: usize,
    /// Up to a few named examples, e.g. "edge 12–40 (3 triangles)".
    pub examples: Vec<String>,
}

impl ManifoldProblems {
    /// Whether nothing is wrong.
    pub fn is_empty(&self) -> bool {
        self.degenerate_triangles == 0
            && self.non_manifold_edges == 0
            && self.inconsistent_edges == 0
            && self.non_manifold_vertices == 0
    }
}

impl fmt::Display for ManifoldProblems {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut parts = Vec::new();
        for (n, what) in [
            (
                self.non_manifold_edges,
                "edges used by more than two triangles",
            ),
            (
                self.inconsistent_edges,
                "edges used twice in the same direction",
            ),
            (
                self.non_manifold_vertices,
                "vertices where separate fans meet",
            ),
            (self.degenerate_triangles, "triangles that repeat a vertex"),
        ] {
            if n > 0 {
                parts.push(format!("{n} {what}"));
            }
        }
        write!(f, "{}", parts.join(", "))?;
        if !self.examples.is_empty() {
            write!(f, " ({})", self.examples.join("; "))?;
        }
        Ok(())
    }
}
