//! Plain words for the failures of `zarrs` (see `error/foreign.rs` for the rule: a foreign
//! error's `Debug` is never printed, and its `Display` only where it is known to be plain words).
//!
//! zarrs says which codec, data type or chunk grid it lacks in a plain sentence ("codec
//! numcodecs.foo is not supported"), which is quoted; everything else is told by its kind.
//!
//! Cost: O(1) per translation.

use std::path::Path;

use zarrs::array::codec::CodecError;
use zarrs::array::{ArrayCreateError, ArrayError};
use zarrs::plugin::PluginCreateError;
use zarrs::storage::StorageError;

use crate::{IoError, IoErrorKind};

/// A failure to open the array at `array` (a path inside the store).
pub(crate) fn opening(path: &Path, array: &str, e: ArrayCreateError) -> IoError {
    let plugin = |what: &str, p: &PluginCreateError| match p {
        PluginCreateError::Unsupported(u) => IoError::unsupported(
            path,
            format!("the array {array} needs {u} by voxlod's Zarr reader"),
        ),
        _ => IoError::malformed(
            path,
            format!("the {what} of the array {array} has invalid metadata"),
        ),
    };
    match &e {
        ArrayCreateError::CodecsCreateError(p) => plugin("compressor or codec", p),
        ArrayCreateError::DataTypeCreateError(p) => plugin("data type", p),
        ArrayCreateError::ChunkGridCreateError(p) => plugin("chunk grid", p),
        ArrayCreateError::ChunkKeyEncodingCreateError(p) => plugin("chunk key encoding", p),
        ArrayCreateError::StorageTransformersCreateError(p) => plugin("storage transformer", p),
        ArrayCreateError::InvalidFillValue(_) | ArrayCreateError::InvalidFillValueMetadata(_) => {
            IoError::malformed(
                path,
                format!("the fill value of the array {array} does not fit its data type"),
            )
        }
        ArrayCreateError::MissingMetadata => IoError::malformed(
            path,
            format!("the array {array} has no metadata (zarr.json or .zarray)"),
        ),
        ArrayCreateError::StorageError(s) => storage(path, s),
        _ => IoError::malformed(
            path,
            format!("the metadata of the array {array} is not valid Zarr"),
        ),
    }
}

/// A failure while reading samples of the array at `array`.
pub(crate) fn reading(path: &Path, array: &str, e: ArrayError) -> IoError {
    match &e {
        ArrayError::StorageError(s) => storage(path, s),
        ArrayError::CodecError(c) => codec(path, array, c),
        _ => IoError::malformed(
            path,
            format!("a chunk of the array {array} does not match the array's shape or type"),
        ),
    }
}

fn codec(path: &Path, array: &str, e: &CodecError) -> IoError {
    match e {
        CodecError::StorageError(s) => storage(path, s),
        CodecError::IOError(io) => IoError::reading(path, "Zarr chunk", io),
        CodecError::InvalidChecksum => IoError::malformed(
            path,
            format!("a chunk of the array {array} fails its checksum"),
        ),
        _ => IoError::malformed(
            path,
            format!("a chunk of the array {array} is corrupt: it does not decode to its shape"),
        ),
    }
}

fn storage(path: &Path, e: &StorageError) -> IoError {
    match e {
        // A chunk file shorter than the byte range read from it (an uncompressed chunk cut
        // short): the store is readable, the chunk is truncated.
        StorageError::IOError(io) if io.kind() == std::io::ErrorKind::UnexpectedEof => {
            IoError::reading(path, "Zarr chunk", io)
        }
        StorageError::IOError(io) => IoError::access(path, "cannot read the Zarr store", io),
        StorageError::InvalidMetadata(key, _) => {
            IoError::malformed(path, format!("the Zarr metadata {key} is not valid"))
        }
        StorageError::MissingMetadata(_) => {
            IoError::malformed(path, "the Zarr store has no array or group metadata")
        }
        _ => IoError::new(path, IoErrorKind::Access, "cannot read the Zarr store"),
    }
}
