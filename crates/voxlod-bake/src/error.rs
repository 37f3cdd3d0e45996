//! The one error type of voxlod-bake.

use thiserror::Error;

/// Why an atlas or a bake failed.
#[derive(Debug, Error)]
pub enum BakeError {
    /// The level, the source or the options cannot be used; the text says which and why.
    #[error("{0}")]
    Invalid(String),
    /// xatlas could not make an atlas; the text says what it reported.
    #[error("the UV atlas failed: {0}")]
    Atlas(String),
    /// A texture could not be encoded.
    #[error("the {what} texture could not be encoded: {why}")]
    Encode {
        /// Which texture (`base colour`, `normal`, …).
        what: &'static str,
        /// The encoder's message.
        why: String,
    },
    /// A failure of the source asset (an invariant broken, an image that cannot be read).
    #[error(transparent)]
    Asset(#[from] voxlod_asset::AssetError),
    /// The source cannot be searched (empty, or too large for the memory available).
    #[error(transparent)]
    Metrics(#[from] voxlod_metrics::MetricsError),
    /// A core failure (a memory refusal among them).
    #[error(transparent)]
    Core(#[from] voxlod_core::CoreError),
}
