//! The one error type of every reader and writer: the file, what kind of problem, and a
//! one-line message saying what was expected and what was found.
//!
//! Messages are plain words about the file, never a parser's internals: the failures of the
//! third-party parsers (vtkio, quick-xml, ply-rs-bw, stl_io, nifti) reach an [`IoError`] only
//! through the constructors of [`foreign`], which translate each kind of failure rather than
//! print the parser's `Debug` or `Display` text (both of which quote its own types). Nothing
//! in this crate formats a foreign error with `{:?}`; a test scans the sources for it.
//!
//! Cost: O(message length) to build an error; nothing on the paths that succeed.

use std::path::{Path, PathBuf};

use thiserror::Error;
use voxlod_core::CoreError;

pub(crate) mod foreign;

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
    /// Writing it would replace an input, or another output of the same command.
    Conflict,
}

/// An error about one file: its path and a one-line description of the problem.
#[derive(Debug, Error)]
#[error("{}: {message}", path.display())]
pub struct IoError {
    /// The file the problem is about (for a detached header, the data file when that is the
    /// one that is short or missing).
    pub path: PathBuf,
    /// The kind of problem, for callers that act on it.
    pub kind: IoErrorKind,
    /// One line of plain words: what was expected and what was found.
    pub message: String,
}

impl IoError {
    /// An error of `kind` about `path`; the message is folded onto one line.
    pub fn new(path: &Path, kind: IoErrorKind, message: impl Into<String>) -> IoError {
        IoError {
            path: path.to_path_buf(),
            kind,
            message: one_line(&message.into()),
        }
    }

    /// An [`IoErrorKind::Access`] error: `doing` says what failed ("cannot open", ...).
    pub(crate) fn access(path: &Path, doing: &str, err: &std::io::Error) -> IoError {
        IoError::new(path, IoErrorKind::Access, format!("{doing}: {err}"))
    }

    pub(crate) fn malformed(path: &Path, message: impl Into<String>) -> IoError {
        IoError::new(path, IoErrorKind::Malformed, message)
    }

    pub(crate) fn unsupported(path: &Path, message: impl Into<String>) -> IoError {
        IoError::new(path, IoErrorKind::Unsupported, message)
    }

    pub(crate) fn truncated(path: &Path, message: impl Into<String>) -> IoError {
        IoError::new(path, IoErrorKind::Truncated, message)
    }

    /// Maps an error of the core types: running out of memory becomes
    /// [`IoErrorKind::TooLarge`], an invalid grid or mesh [`IoErrorKind::Malformed`].
    pub(crate) fn from_core(path: &Path, err: CoreError) -> IoError {
        let kind = match err {
            CoreError::OutOfMemory { .. } | CoreError::BadMemoryLimit { .. } => {
                IoErrorKind::TooLarge
            }
            CoreError::Mesh(defect) if defect.is_non_finite() => IoErrorKind::NonFinite,
            CoreError::InvalidGrid(_) | CoreError::InvalidMesh(_) | CoreError::Mesh(_) => {
                IoErrorKind::Malformed
            }
        };
        IoError::new(path, kind, err.to_string())
    }
}

/// Squeezes a message from a parser (which may span lines and quote whole input lines) into one
/// short line, so that every error prints as `path: message`.
pub(crate) fn one_line(message: &str) -> String {
    const LIMIT: usize = 300;
    let mut out = String::with_capacity(message.len().min(LIMIT + 3));
    for word in message.split_whitespace() {
        if !out.is_empty() {
            out.push(' ');
        }
        out.push_str(word);
        if out.len() > LIMIT {
            let mut cut = LIMIT;
            while !out.is_char_boundary(cut) {
                cut -= 1;
            }
            out.truncate(cut);
            out.push_str("...");
            break;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_are_one_short_line() {
        let e = IoError::new(
            Path::new("dir/a.ply"),
            IoErrorKind::Malformed,
            "Line 3:\n\tString: 'x'\n\tError: bad",
        );
        assert_eq!(e.to_string(), "dir/a.ply: Line 3: String: 'x' Error: bad");
        let long = "word ".repeat(200);
        let e = IoError::malformed(Path::new("b"), long);
        assert!(e.message.len() <= 303 && e.message.ends_with("..."));
        assert!(!e.to_string().contains('\n'));
    }
}
