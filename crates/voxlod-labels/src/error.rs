//! The one error type of the segmentation stage.

use voxlod_core::CoreError;

/// Why a label map cannot be meshed.
#[derive(Debug, thiserror::Error)]
pub enum LabelsError {
    /// Only background.
    #[error("the map holds no label other than 0")]
    NoLabels,
    /// A label asked for is not in the map.
    #[error("the map has no label {0} (it holds {1})")]
    Missing(u32, String),
    /// A mesh whose coordinates leave 32-bit floats (a map placed too far out).
    #[error("label {0}: {1} (the map's extent is too large for 32-bit coordinates)")]
    BeyondRange(u32, String),
    /// An option out of its range (a usage error: the caller asked for something meaningless).
    #[error("{option} = {value}: {problem}")]
    InvalidOption {
        /// The option's name as the options struct spells it (e.g. `smoothing.lambda`).
        option: &'static str,
        /// The value given.
        value: String,
        /// What the option must be.
        problem: String,
    },
    /// Memory or grid trouble from the core.
    #[error(transparent)]
    Core(#[from] CoreError),
}
