use std::path::{Path, PathBuf};

use thiserror::Error;

/// What went wrong with a file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IoErrorKind {
    /// The file could not be opened, read, written or renamed.
    Access,
    /// The file is empty.
    Empty,
    /// The file ends before the data its header promises.
    Truncated,
    /// The content does not follow the format.
    Malformed,
    /// A coordinate or sample is NaN or infinite.
    NonFinite,
    /// The extension or a feature of the file is not supported.
    Unsupported,
    /// Raw dimensions and the file size disagree.
    SizeMismatch,
    /// Reading it would not fit in memory.
    TooLarge,
}

/// An error about one file: its path and a one-line description of the problem.
#[derive(Debug, Error)]
#[error("{}: {message}", path.display())]
pub struct IoError {
    pub path: PathBuf,
    pub kind: IoErrorKind,
    pub message: String,
}

impl IoError {
    pub fn new(path: &Path, kind: IoErrorKind, message: impl Into<String>) -> IoError {
        IoError {
            path: path.to_path_buf(),
            kind,
            message: message.into(),
        }
    }
}
