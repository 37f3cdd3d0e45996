//! Reading a glTF file's bytes, for both readers (`read` and `scene`): the size checked
//! against the memory limit first, and errors that name the file.

use std::path::Path;

use crate::GltfError;

/// A glTF file's bytes, its size checked against the memory limit first; a file that cannot be
/// read is [`GltfError::Io`] of kind `Access`, naming it.
pub(crate) fn file_bytes(path: &Path) -> Result<Vec<u8>, GltfError> {
    let cannot_read = |e: std::io::Error| {
        voxlod_io::IoError::new(
            path,
            voxlod_io::IoErrorKind::Access,
            format!("cannot read: {e}"),
        )
    };
    let len = std::fs::metadata(path).map_err(cannot_read)?.len();
    voxlod_core::memory::check_allocation(&format!("reading {}", path.display()), len)?;
    Ok(std::fs::read(path).map_err(cannot_read)?)
}

/// `e` with the file's name in front of an [`GltfError::Invalid`] message.
pub(crate) fn named(path: &Path, e: GltfError) -> GltfError {
    match e {
        GltfError::Invalid(m) => GltfError::Invalid(format!("{}: {m}", path.display())),
        other => other,
    }
}
