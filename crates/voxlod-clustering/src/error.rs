//! The one error type of the crate: what is wrong with the input or the options, in one line.

use thiserror::Error;
use voxlod_core::CoreError;

/// Why a baseline refused to run. Every message is one line and names the offending value.
#[derive(Debug, Error)]
pub enum ClusteringError {
    /// Zero cells asked for.
    #[error("the number of cells per axis must be at least 1 (got 0)")]
    ZeroCells,
    /// More cells per axis than cell keys can name.
    #[error("{cells} cells per axis is too many (at most {max})")]
    TooManyCells {
        /// Cells asked for.
        cells: u32,
        /// The most allowed ([`crate::grid::MAX_CELLS`]).
        max: u32,
    },
    /// Zero levels asked for.
    #[error("the number of levels must be at least 1 (got 0)")]
    ZeroLevels,
    /// More levels than halving the cells allows.
    #[error("{levels} levels starting from {cells} cells per axis: at most {max} (the coarsest level has a single cell along the longest axis)")]
    TooManyLevels {
        /// Levels asked for.
        levels: u32,
        /// Cells of the finest level.
        cells: u32,
        /// The most levels from that many cells.
        max: u32,
    },
    /// More vertices or triangles than 32-bit ids can name (what, and the limit).
    #[error("the mesh is too large: {what}")]
    TooLarge {
        /// The count and its limit, in words.
        what: String,
    },
    /// A clustering box that is empty or not finite.
    #[error("the clustering box must be finite and not empty (got min {min:?}, max {max:?})")]
    InvalidBounds {
        /// Its lower corner.
        min: [f64; 3],
        /// Its upper corner.
        max: [f64; 3],
    },
    /// A size or factor that must be positive and finite (which, and its value).
    #[error("{what} must be positive and finite (got {value})")]
    InvalidParameter {
        /// What the parameter is.
        what: &'static str,
        /// The value given.
        value: f64,
    },
    /// The memory limit's refusal, or another core error.
    #[error(transparent)]
    Core(#[from] CoreError),
}
