//! Uncompressed samples read and converted to `f32` block by block on all threads, straight
//! from the file into the volume's buffer.
//!
//! A raw NRRD or a headerless scan used to be read whole into a byte buffer on one thread and
//! then converted into a second buffer: for a 512×512×361 int16 CT that is 189 MB read and
//! 378 MB written on one thread before any level starts, and the byte buffer's pages are
//! faulted in and cleared for nothing. Here each block of [`BLOCK`] samples is read with a
//! positioned read (no shared cursor) into a small per-thread buffer and converted into its
//! place in the output, so the reads, the conversion and the output's page faults are spread
//! over the threads and the stored bytes are never held whole. The values are those of
//! [`crate::samples::decode`] of the whole data (a test compares them bit for bit).
//!
//! Cost: O(N) for N samples, on all threads; memory: the `f32` output plus one block of stored
//! bytes per thread.

use std::fs::File;
use std::path::Path;

use rayon::prelude::*;

use crate::blockwise_volume::read_exact_at;
use crate::samples::{decode_into, SampleType};
use crate::{Endian, IoError};

/// Samples per block: 256 Ki (512 KiB of 16-bit samples, 1 MiB of output).
pub(crate) const BLOCK: usize = 1 << 18;

/// The `count` samples of type `ty` stored from byte `offset` of `file` (at `path`, for
/// messages), as `f32`. A file shorter than the samples gives [`crate::IoErrorKind::Truncated`] with
/// both byte counts, as [`crate::samples::read_data`] words it (`what` names the data).
pub(crate) fn read_decoded(
    path: &Path,
    file: &File,
    offset: u64,
    count: usize,
    (ty, endian): (SampleType, Endian),
    what: &str,
) -> Result<Vec<f32>, IoError> {
    let expected = count.saturating_mul(ty.size());
    let len = file
        .metadata()
        .map_err(|e| IoError::access(path, &format!("cannot read the {what}"), &e))?
        .len();
    let found = len.saturating_sub(offset);
    if found < expected as u64 {
        return Err(truncated(path, what, expected, found));
    }
    // Zeroed by the allocator (fresh pages, not written here), so that each page is first
    // touched by its block's thread; the sizes were checked against the memory budget.
    let mut values = vec![0.0f32; count];
    let size = ty.size();
    (values.par_chunks_mut(BLOCK).enumerate()).try_for_each_init(Vec::new, |bytes, (b, out)| {
        bytes.resize(out.len() * size, 0u8);
        let at = offset + (b * BLOCK * size) as u64;
        read_exact_at(file, bytes, at).map_err(|e| match e.kind() {
            std::io::ErrorKind::UnexpectedEof => truncated(path, what, expected, at - offset),
            _ => IoError::access(path, &format!("cannot read the {what}"), &e),
        })?;
        decode_into(bytes, ty, endian, out);
        Ok(())
    })?;
    Ok(values)
}

/// The truncation error: `expected` bytes of `what` wanted, at most `found` there.
fn truncated(path: &Path, what: &str, expected: usize, found: u64) -> IoError {
    IoError::truncated(
        path,
        format!("the {what} is truncated: expected {expected} bytes, found {found}"),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::samples::decode;
    use crate::IoErrorKind;
    use std::io::Write;

    /// A file of `header` bytes then `data`.
    fn file_with(header: usize, data: &[u8]) -> tempfile::NamedTempFile {
        let mut f = tempfile::NamedTempFile::new().unwrap();
        f.write_all(&vec![7u8; header]).unwrap();
        f.write_all(data).unwrap();
        f.flush().unwrap();
        f
    }

    /// Every type and byte order, over two whole blocks and part of a third, read from an
    /// offset: bit for bit the one-pass conversion of the same bytes.
    #[test]
    fn blocks_read_from_the_file_are_the_whole_data_decoded() {
        let types = [
            SampleType::U8,
            SampleType::I8,
            SampleType::U16,
            SampleType::I16,
            SampleType::U32,
            SampleType::I32,
            SampleType::F32,
            SampleType::F64,
        ];
        let count = 2 * BLOCK + 1234;
        for ty in types {
            let bytes: Vec<u8> = (0..count * ty.size())
                .map(|i| (i.wrapping_mul(2654435761) >> 7) as u8)
                .collect();
            for endian in [Endian::Little, Endian::Big] {
                let f = file_with(13, &bytes);
                let file = File::open(f.path()).unwrap();
                let read = read_decoded(f.path(), &file, 13, count, (ty, endian), "data").unwrap();
                let whole = decode(&bytes, ty, endian);
                let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&read), bits(&whole), "{ty:?} {endian:?}");
            }
        }
    }

    #[test]
    fn a_short_file_is_truncated_with_both_counts() {
        let f = file_with(4, &[1u8; 10]);
        let file = File::open(f.path()).unwrap();
        let ty = (SampleType::I16, Endian::Little);
        let err = read_decoded(f.path(), &file, 4, 6, ty, "raw data").unwrap_err();
        assert_eq!(err.kind, IoErrorKind::Truncated);
        assert!(err.message.contains("expected 12 bytes, found 10"), "{err}");
        assert_eq!(
            read_decoded(f.path(), &file, 4, 5, ty, "raw data")
                .unwrap()
                .len(),
            5
        );
    }
}
