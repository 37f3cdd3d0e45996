//! The one error type of voxlod-asset.

use thiserror::Error;

/// Why an asset or one of its stages failed.
#[derive(Debug, Error)]
pub enum AssetError {
    /// The asset breaks an invariant of [`crate::Asset`] (an attribute of the wrong length, an
    /// index out of range, a value that is not finite); the text says which and where.
    #[error("{0}")]
    Invalid(String),
    /// A core failure (a memory refusal among them).
    #[error(transparent)]
    Core(#[from] voxlod_core::CoreError),
}
