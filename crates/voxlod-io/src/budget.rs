//! The one place where sizes read from files meet the memory budget.
//!
//! Every count a reader takes from a file (PLY element counts, OFF and STL counts, VTK point
//! numbers, extents and binary block sizes, volume dimensions, the file itself) passes through
//! [`check_count`] or [`check_bytes`] before anything of that size is allocated, so an absurd
//! header ends as an [`IoErrorKind::TooLarge`](crate::IoErrorKind::TooLarge) error naming the
//! bytes it would take, never as an abort. The budget itself is
//! [`voxlod_core::memory::available_bytes`].
//!
//! Cost: O(1) per check.

use std::path::Path;

use voxlod_core::memory;

use crate::{IoError, IoErrorKind};

/// Fails unless `bytes` (described by `what`, e.g. "the 'vertex' elements") fit in memory.
pub(crate) fn check_bytes(path: &Path, what: &str, bytes: u64) -> Result<(), IoError> {
    memory::check_allocation(what, bytes).map_err(|e| IoError::from_core(path, e))
}

/// `count` items of `bytes_each` bytes in memory: fails if the product overflows or does not
/// fit, else returns `count` as a `usize`.
pub(crate) fn check_count(
    path: &Path,
    what: &str,
    count: u64,
    bytes_each: u64,
) -> Result<usize, IoError> {
    let too_large = || {
        IoError::new(
            path,
            IoErrorKind::TooLarge,
            format!("{what}: {count} of them is more than memory can address"),
        )
    };
    let bytes = count.checked_mul(bytes_each).ok_or_else(too_large)?;
    check_bytes(path, &format!("{what} ({count})"), bytes)?;
    usize::try_from(count).map_err(|_| too_large())
}

/// Fails with [`IoErrorKind::Truncated`] when `count` items of at least `min_bytes_each` bytes
/// cannot be in a file of `file_bytes`: a header that promises more than its file holds is
/// refused before the parser tries (and before the budget is asked about a size the file
/// could never fill).
pub(crate) fn check_fits_file(
    path: &Path,
    what: &str,
    count: u64,
    min_bytes_each: u64,
    file_bytes: u64,
) -> Result<(), IoError> {
    let needed = count.saturating_mul(min_bytes_each.max(1));
    if needed > file_bytes {
        return Err(IoError::truncated(
            path,
            format!(
                "the header declares {count} {what}, which need at least {needed} bytes, but the file has {file_bytes}"
            ),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn absurd_counts_are_too_large_and_plausible_ones_pass() {
        let p = Path::new("a.ply");
        let err = check_count(p, "the 'vertex' elements", u64::MAX, 12).unwrap_err();
        assert_eq!(err.kind, IoErrorKind::TooLarge);
        let err = check_count(p, "the 'vertex' elements", 1 << 50, 12).unwrap_err();
        assert_eq!(err.kind, IoErrorKind::TooLarge);
        assert!(err.message.contains("'vertex' elements"), "{err}");
        assert_eq!(check_count(p, "faces", 1000, 12).unwrap(), 1000);
        let err = check_fits_file(p, "'face' elements", 1000, 13, 12000).unwrap_err();
        assert_eq!(err.kind, IoErrorKind::Truncated);
        assert!(err.message.contains("13000"), "{err}");
        check_fits_file(p, "'face' elements", 1000, 12, 12000).unwrap();
    }
}
