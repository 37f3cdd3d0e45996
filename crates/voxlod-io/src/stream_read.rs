//! Samples read from a stream (a decompressor, or a file read from its current position) and
//! decoded block by block into the buffer the reader returns, so that the stored bytes are never
//! held whole: the peak is the decoded samples plus one block of stored bytes.
//!
//! Used for gzip NRRD, MetaImage and NIfTI (plain or gzipped), whose data has no random access
//! (uncompressed files with it go through `block_read.rs`, on all threads). The decoding is the
//! target's ([`DecodeTarget`]): `f32` samples, or checked labels whose first refusal names the
//! voxel.
//!
//! Cost: O(N) for N samples, one thread; memory: the output plus one block of
//! [`BLOCK`] stored samples.

use std::io::Read;
use std::path::Path;

use crate::decode_target::DecodeTarget;
use crate::samples::BLOCK;
use crate::samples::{read_error, short_data, SampleType};
use crate::{Endian, IoError};

/// The samples of a grid of `dims`, stored as `ty` in `endian` order, read from `reader` and
/// decoded by `target`. Exactly the samples' bytes are read; fewer give
/// [`crate::IoErrorKind::Truncated`] naming both counts, a corrupt compressed stream
/// [`crate::IoErrorKind::Malformed`], a sample the target refuses an error naming its voxel
/// (all about `path`, with `what` naming the data). The sizes must have been checked against
/// the memory budget (`samples::check_decoded_size`).
pub(crate) fn read_stream<T: DecodeTarget>(
    path: &Path,
    mut reader: impl Read,
    dims: [usize; 3],
    (ty, endian): (SampleType, Endian),
    target: &T,
    what: &str,
) -> Result<Vec<T::Item>, IoError> {
    let count = dims.iter().product::<usize>();
    let size = ty.size();
    let expected = count * size;
    let mut values = vec![T::Item::default(); count];
    let mut bytes = vec![0u8; count.min(BLOCK) * size];
    for (b, out) in values.chunks_mut(BLOCK).enumerate() {
        let first = b * BLOCK;
        let block = &mut bytes[..out.len() * size];
        let filled = fill(&mut reader, block)
            .map_err(|(found, e)| read_error(path, what, expected, first * size + found, &e))?;
        if filled < block.len() {
            return Err(short_data(path, what, expected, first * size + filled));
        }
        target
            .decode(block, ty, endian, out)
            .map_err(|bad| bad.error(path, dims, first))?;
    }
    Ok(values)
}

/// Fills `buf` from `reader` as far as it goes: the bytes read (fewer at the end of the
/// stream), or the error with the bytes read before it.
fn fill(reader: &mut impl Read, buf: &mut [u8]) -> Result<usize, (usize, std::io::Error)> {
    let mut filled = 0;
    while filled < buf.len() {
        match reader.read(&mut buf[filled..]) {
            Ok(0) => break,
            Ok(n) => filled += n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err((filled, e)),
        }
    }
    Ok(filled)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::decode_target::{AsLabels, AsSamples};
    use crate::samples::decode;
    use crate::IoErrorKind;

    #[test]
    fn blocks_of_a_stream_are_the_whole_data_decoded() {
        let count = 2 * BLOCK + 77;
        let bytes: Vec<u8> = (0..count * 2).map(|i| (i * 7 % 251) as u8).collect();
        let ty = (SampleType::I16, Endian::Big);
        let read = read_stream(
            Path::new("s"),
            &bytes[..],
            [count, 1, 1],
            ty,
            &AsSamples,
            "data",
        );
        assert_eq!(read.unwrap(), decode(&bytes, ty.0, ty.1));
    }

    #[test]
    fn short_data_names_both_counts() {
        let ty = (SampleType::U8, Endian::Little);
        let err = read_stream(
            Path::new("t.mha"),
            &[1u8, 2, 3][..],
            [10, 1, 1],
            ty,
            &AsSamples,
            "image data",
        )
        .unwrap_err();
        assert_eq!(err.kind, IoErrorKind::Truncated);
        assert!(err.message.contains("expected 10 bytes, found 3"), "{err}");
    }

    #[test]
    fn a_refused_label_in_a_later_block_names_its_voxel() {
        let nx = BLOCK / 4;
        let dims = [nx, 4, 3];
        let count = nx * 12;
        let mut bytes = vec![0u8; count * 2];
        // Voxel (5, 2, 1): index (1 * 4 + 2) * nx + 5, in the second block.
        let n = 6 * nx + 5;
        bytes[2 * n..2 * n + 2].copy_from_slice(&(-3i16).to_le_bytes());
        let ty = (SampleType::I16, Endian::Little);
        let err = read_stream(
            Path::new("m.nii"),
            &bytes[..],
            dims,
            ty,
            &AsLabels::default(),
            "d",
        )
        .unwrap_err();
        assert_eq!(
            err.message,
            "label -3 at (5, 2, 1): labels are whole numbers from 0 to 4294967295"
        );
    }
}
