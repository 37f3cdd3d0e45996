//! Why a level chain could not be written or read.

use voxlod_core::CoreError;
use voxlod_io::IoError;

/// The errors of this crate.
#[derive(Debug, thiserror::Error)]
pub enum GltfError {
    /// The levels given cannot make a chain (none, empty, mismatched normals, bad sizes).
    #[error("invalid level chain: {0}")]
    InvalidChain(String),
    /// A coverage parameter is not a positive finite number.
    #[error("{what} must be a positive finite number, got {value}")]
    InvalidParameter { what: &'static str, value: f64 },
    /// The glTF JSON or binary container could not be encoded.
    #[error("cannot encode the glTF file: {0}")]
    Encode(String),
    /// A file given to read is not a usable glTF binary.
    #[error("invalid glTF file: {0}")]
    Invalid(String),
    /// A well-formed file whose scene holds no triangle to mesh.
    #[error("the scene has no triangles (it has no mesh, or only points and lines)")]
    NoTriangles,
    /// meshoptimizer refused a stream.
    #[error("meshopt: {0}")]
    Meshopt(String),
    #[error(transparent)]
    Core(#[from] CoreError),
    #[error(transparent)]
    Io(#[from] IoError),
}
