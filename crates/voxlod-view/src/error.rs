//! Why a page could not be made: a file that cannot be read or is not a usable `.glb` (an
//! [`IoError`] naming it, of kind `Access` or `Malformed`), a glTF failure, the memory limit,
//! or nothing to show. Each is a stage error the facade's `voxlod::Error` takes as it is, so a
//! caller keeps its class; [`ViewError::NoInput`] is the caller's mistake.

use voxlod_core::CoreError;
use voxlod_gltf::GltfError;
use voxlod_io::IoError;

/// The errors of this crate; a file's error names the file.
#[derive(Debug, thiserror::Error)]
pub enum ViewError {
    /// No model was given.
    #[error("no input to show")]
    NoInput,
    /// A glTF failure.
    #[error(transparent)]
    Gltf(#[from] GltfError),
    /// Work beyond the memory limit.
    #[error(transparent)]
    Core(#[from] CoreError),
    /// A file that cannot be read, written, or is not a usable `.glb`.
    #[error(transparent)]
    Io(#[from] IoError),
}
