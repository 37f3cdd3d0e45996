//! Why a page could not be made.

use std::path::PathBuf;

use voxlod_core::CoreError;
use voxlod_gltf::GltfError;
use voxlod_io::IoError;

/// The errors of this crate; each names the file it is about.
#[derive(Debug, thiserror::Error)]
pub enum ViewError {
    #[error("{}: cannot read: {source}", path.display())]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{}: {reason}", path.display())]
    Invalid { path: PathBuf, reason: String },
    #[error("no input to show")]
    NoInput,
    #[error(transparent)]
    Gltf(#[from] GltfError),
    #[error(transparent)]
    Core(#[from] CoreError),
    #[error(transparent)]
    Io(#[from] IoError),
}
