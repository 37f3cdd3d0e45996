//! The one error type of the crate: what is wrong with the input or the options, in one line.

use thiserror::Error;
use voxlod_core::CoreError;

/// Why a baseline refused to run. Every message is one line and names the offending value.
#[derive(Debug, Error)]
pub enum ClusteringError {
    #[error("the number of cells per axis must be at least 1 (got 0)")]
    ZeroCells,
    #[error("{cells} cells per axis is too many (at most {max})")]
    TooManyCells { cells: u32, max: u32 },
    #[error("the number of levels must be at least 1 (got 0)")]
    ZeroLevels,
    #[error("{levels} levels starting from {cells} cells per axis: at most {max} (the coarsest level has a single cell along the longest axis)")]
    TooManyLevels { levels: u32, cells: u32, max: u32 },
    #[error("the mesh is too large: {what}")]
    TooLarge { what: String },
    #[error("the clustering box must be finite and not empty (got min {min:?}, max {max:?})")]
    InvalidBounds { min: [f64; 3], max: [f64; 3] },
    #[error("{what} must be positive and finite (got {value})")]
    InvalidParameter { what: &'static str, value: f64 },
    #[error(transparent)]
    Core(#[from] CoreError),
}
