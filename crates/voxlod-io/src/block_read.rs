//! Uncompressed samples read and decoded block by block on all threads, straight from the file
//! into the buffer of the volume (`f32`) or the label map (`u32`) being read.
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
//! Label maps are decoded by the same blocks ([`DecodeTarget`]); a sample that is not a label
//! stops the read with an error naming its voxel (when several blocks hold one, whichever
//! thread finds one first).
//!
//! Cost: O(N) for N samples, on all threads; memory: the output plus one block of stored bytes
//! per thread.

use std::fs::File;
use std::path::Path;

use rayon::prelude::*;

use crate::blockwise_volume::read_exact_at;
use crate::decode_target::DecodeTarget;
use crate::samples::{SampleType, BLOCK};
use crate::{Endian, IoError};

/// The samples of a grid of `dims` (x fastest), of type `ty`, stored from byte `offset` of
/// `file` (at `path`, for messages), decoded by `target`. A file shorter than the samples gives
/// [`crate::IoErrorKind::Truncated`] with both byte counts (`what` names the data); a sample the
/// target refuses, an error naming its voxel. The sizes must have been checked against the
/// memory budget (`samples::check_decoded_size`).
pub(crate) fn read_decoded<T: DecodeTarget>(
    path: &Path,
    file: &File,
    offset: u64,
    dims: [usize; 3],
    (ty, endian): (SampleType, Endian),
    target: &T,
    what: &str,
) -> Result<Vec<T::Item>, IoError> {
    let count = dims.iter().product::<usize>();
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
    let mut values = vec![T::Item::default(); count];
    let size = ty.size();
    (values.par_chunks_mut(BLOCK).enumerate()).try_for_each_init(Vec::new, |bytes, (b, out)| {
        bytes.resize(out.len() * size, 0u8);
        let at = offset + (b * BLOCK * size) as u64;
        read_exact_at(file, bytes, at).map_err(|e| match e.kind() {
            std::io::ErrorKind::UnexpectedEof => truncated(path, what, expected, at - offset),
            _ => IoError::access(path, &format!("cannot read the {what}"), &e),
        })?;
        target
            .decode(bytes, ty, endian, out)
            .map_err(|bad| bad.error(path, dims, b * BLOCK))
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
    use crate::decode_target::{AsLabels, AsSamples};
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
            SampleType::U64,
            SampleType::I64,
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
                let (dims, stored) = ([count, 1, 1], (ty, endian));
                let read = read_decoded(f.path(), &file, 13, dims, stored, &AsSamples, "data");
                let read = read.unwrap();
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
        let err = read_decoded(f.path(), &file, 4, [6, 1, 1], ty, &AsSamples, "raw data");
        let err = err.unwrap_err();
        assert_eq!(err.kind, IoErrorKind::Truncated);
        assert!(err.message.contains("expected 12 bytes, found 10"), "{err}");
        assert_eq!(
            read_decoded(f.path(), &file, 4, [5, 1, 1], ty, &AsSamples, "raw data")
                .unwrap()
                .len(),
            5
        );
    }

    /// Labels over several blocks: exact above 2²⁴, and a negative one in the last block named
    /// by its voxel.
    #[test]
    fn labels_are_read_exactly_and_refused_by_voxel() {
        let dims = [BLOCK / 2, 2, 3];
        let count = BLOCK * 3;
        let labels: Vec<i32> = (0..count as i32).map(|v| v * 97 + (1 << 24)).collect();
        let bytes: Vec<u8> = labels.iter().flat_map(|v| v.to_le_bytes()).collect();
        let f = file_with(3, &bytes);
        let file = File::open(f.path()).unwrap();
        let stored = (SampleType::I32, Endian::Little);
        let read = read_decoded(f.path(), &file, 3, dims, stored, &AsLabels::default(), "d");
        let expected: Vec<u32> = labels.iter().map(|&v| v as u32).collect();
        assert_eq!(read.unwrap(), expected);
        let mut bad = bytes;
        let n = (2 * 2 + 1) * dims[0] + 9;
        bad[4 * n..4 * n + 4].copy_from_slice(&(-3i32).to_le_bytes());
        let f = file_with(3, &bad);
        let file = File::open(f.path()).unwrap();
        let err = read_decoded(f.path(), &file, 3, dims, stored, &AsLabels::default(), "d");
        let message = err.unwrap_err().message;
        assert_eq!(
            message,
            "label -3 at (9, 1, 2): labels are whole numbers from 0 to 4294967295"
        );
    }
}
