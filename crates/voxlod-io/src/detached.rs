//! Detached data files of the header formats (NRRD `.nhdr`, MetaImage `.mhd`): how a header
//! names its data file when the volume is written.
//!
//! Cost: O(1) per name (string work on the path).

use std::path::Path;

use crate::IoError;

/// The name of a detached data file as its header records it: a file in the header's folder,
/// without whitespace (which the header's field cannot hold).
pub(crate) fn name_in_header(header: &Path, data: &Path) -> Result<String, IoError> {
    let name = data
        .file_name()
        .and_then(|n| n.to_str())
        .filter(|n| !n.chars().any(char::is_whitespace) && header.with_file_name(n) == data);
    name.map(str::to_string).ok_or_else(|| {
        IoError::unsupported(
            header,
            format!(
                "cannot name {} as the data file: it must be a name without spaces in the header's folder",
                data.display()
            ),
        )
    })
}
