//! The crate's one error type.

use std::path::PathBuf;

use voxlod_core::CoreError;

/// What can go wrong writing or reading a precomputed layer. Messages name the file, the label
/// or the option at fault.
#[derive(Debug, thiserror::Error)]
pub enum PrecomputedError {
    /// A file or folder could not be written, read, renamed or removed.
    #[error("{path}: {source}")]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// What the system said.
        source: std::io::Error,
    },
    /// An option out of its range, or options that contradict each other.
    #[error("invalid option: {0}")]
    Options(String),
    /// The label map cannot be stored as a precomputed volume (oblique orientation, a label that
    /// does not fit the data type, ...).
    #[error("label map: {0}")]
    LabelMap(String),
    /// A label's mesh cannot be written (non-finite positions, indices out of range, a label
    /// given twice, outside the octree's reach, ...).
    #[error("mesh of label {label}: {reason}")]
    Mesh {
        /// The segment id.
        label: u64,
        /// What is wrong.
        reason: String,
    },
    /// The Draco encoder or decoder refused a fragment.
    #[error("draco: {0}")]
    Draco(String),
    /// A manifest, shard or fragment does not follow the format.
    #[error("{path}: {reason}")]
    Format {
        /// The file (or `file#segment`) read.
        path: PathBuf,
        /// What is wrong with it.
        reason: String,
    },
    /// The memory limit refused an allocation, or another core check failed.
    #[error(transparent)]
    Core(#[from] CoreError),
}

impl PrecomputedError {
    /// The error for an I/O failure on `path`.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> PrecomputedError {
        PrecomputedError::Io {
            path: path.into(),
            source,
        }
    }
}
