//! Decoding the binary data of one VTK XML data array: the header of `UInt32` or `UInt64`
//! integers, raw or base64, and the zlib, LZ4 or LZMA blocks of compressed files, every
//! header value checked against the data present and every size against the memory budget.
//! Cost: linear in the array's bytes.

use std::io::Read;
use std::path::Path;

use base64::engine::{DecodePaddingMode, GeneralPurpose, GeneralPurposeConfig};
use base64::Engine;

use crate::{budget, IoError};

/// Lenient base64, as VTK's own reader: padding optional, trailing bits allowed.
pub(super) const BASE64: GeneralPurpose = GeneralPurpose::new(
    &base64::alphabet::STANDARD,
    GeneralPurposeConfig::new()
        .with_decode_allow_trailing_bits(true)
        .with_decode_padding_mode(DecodePaddingMode::Indifferent),
);

#[derive(Clone, Copy, PartialEq, Debug)]
pub(super) enum Compressor {
    None,
    Zlib,
    Lz4,
    Lzma,
}

/// How the binary data of the file is laid out (attributes of `<VTKFile>`).
#[derive(Clone, Copy, Debug)]
pub(super) struct Layout {
    pub(super) big_endian: bool,
    /// Bytes per header integer: 4 or 8.
    pub(super) header: usize,
    pub(super) compressor: Compressor,
}

impl Layout {
    fn number(&self, bytes: &[u8]) -> u64 {
        let mut b = [0u8; 8];
        let h = self.header;
        if self.big_endian {
            b[8 - h..].copy_from_slice(&bytes[..h]);
            u64::from_be_bytes(b)
        } else {
            b[..h].copy_from_slice(&bytes[..h]);
            u64::from_le_bytes(b)
        }
    }

    pub(super) fn encode_number(&self, n: u64) -> [u8; 8] {
        if self.big_endian {
            n.to_be_bytes()
        } else {
            n.to_le_bytes()
        }
    }
}

/// A run of binary data: raw bytes, or base64 text whose header and data may be separate
/// base64 streams (compressed data) or one stream (uncompressed data).
#[derive(Clone, Copy)]
pub(super) enum Stream<'a> {
    Raw(&'a [u8]),
    Base64(&'a [u8]),
}

impl<'a> Stream<'a> {
    /// Stream units (bytes or base64 characters) that `bytes` decoded bytes take.
    fn units(&self, bytes: u64) -> u64 {
        match self {
            Stream::Raw(_) => bytes,
            Stream::Base64(_) => bytes.div_ceil(3).saturating_mul(4),
        }
    }

    fn len(&self) -> u64 {
        match self {
            Stream::Raw(b) | Stream::Base64(b) => b.len() as u64,
        }
    }

    /// The first `bytes` decoded bytes from unit `at` on.
    fn read(&self, at: u64, bytes: u64) -> Result<Vec<u8>, String> {
        let end = at.saturating_add(self.units(bytes));
        if end > self.len() {
            return Err(format!(
                "is cut short: it needs {bytes} bytes at position {at} but the data ends after {} {}",
                self.len(),
                match self {
                    Stream::Raw(_) => "bytes",
                    Stream::Base64(_) => "base64 characters",
                }
            ));
        }
        let (at, end) = (at as usize, end as usize);
        match self {
            Stream::Raw(b) => Ok(b[at..end].to_vec()),
            Stream::Base64(text) => {
                let mut out = BASE64.decode(&text[at..end]).map_err(|_| {
                    format!("holds invalid base64 between characters {at} and {end}")
                })?;
                if (out.len() as u64) < bytes {
                    return Err(format!("holds fewer than {bytes} bytes of base64 at {at}"));
                }
                out.truncate(bytes as usize);
                Ok(out)
            }
        }
    }
}

/// Decodes one array's bytes (in the file's byte order) starting at unit `at` of `stream`;
/// `label` names the array in messages.
pub(super) fn decode_array(
    path: &Path,
    label: &str,
    stream: Stream<'_>,
    at: u64,
    layout: &Layout,
) -> Result<Vec<u8>, IoError> {
    let bad = |problem: String| IoError::malformed(path, format!("{label} {problem}"));
    let h = layout.header as u64;
    let first = stream.read(at, h).map_err(bad)?;
    let count = layout.number(&first);
    if layout.compressor == Compressor::None {
        // Header and data in one stream: re-read from the start.
        if count > stream.len().saturating_sub(at) {
            return Err(IoError::truncated(
                path,
                format!(
                    "{label} declares {count} bytes but the data ends {} units after it starts",
                    stream.len().saturating_sub(at)
                ),
            ));
        }
        budget::check_bytes(path, label, count.saturating_mul(3))?;
        let mut all = stream.read(at, h + count).map_err(bad)?;
        all.drain(..h as usize);
        return Ok(all);
    }
    // Compressed: [nb][nu][np][nc_1 .. nc_nb] as its own stream, then the blocks.
    let blocks = count;
    if blocks.saturating_mul(h) > stream.len() {
        return Err(IoError::truncated(
            path,
            format!("{label} declares {blocks} compressed blocks, more than the file can hold"),
        ));
    }
    let header_bytes = (3 + blocks) * h;
    let header = stream.read(at, header_bytes).map_err(bad)?;
    let numbers: Vec<u64> = header
        .chunks_exact(layout.header)
        .map(|c| layout.number(c))
        .collect();
    let (block_size, last_size, sizes) = (numbers[1], numbers[2], &numbers[3..]);
    let total = if blocks == 0 {
        0
    } else {
        let last = if last_size == 0 {
            block_size
        } else {
            last_size
        };
        (blocks - 1)
            .checked_mul(block_size)
            .and_then(|t| t.checked_add(last))
            .ok_or_else(|| bad("declares a size that overflows".to_string()))?
    };
    if last_size > block_size {
        return Err(bad(format!(
            "declares a last block of {last_size} bytes, larger than its blocks of {block_size}"
        )));
    }
    budget::check_bytes(path, label, total.saturating_mul(3))?;
    let compressed: u64 = sizes
        .iter()
        .try_fold(0u64, |s, &n| s.checked_add(n))
        .unwrap_or(u64::MAX);
    let data_at = at + stream.units(header_bytes);
    let packed = stream.read(data_at, compressed).map_err(bad)?;
    inflate_blocks(
        path,
        label,
        &packed,
        sizes,
        block_size,
        total,
        layout.compressor,
    )
}

/// Decompresses the blocks of one array into `total` bytes.
fn inflate_blocks(
    path: &Path,
    label: &str,
    packed: &[u8],
    sizes: &[u64],
    block_size: u64,
    total: u64,
    compressor: Compressor,
) -> Result<Vec<u8>, IoError> {
    let mut out = vec![0u8; total as usize];
    let mut from = 0usize;
    for (b, &size) in sizes.iter().enumerate() {
        let start = b as u64 * block_size;
        let end = (start + block_size).min(total);
        let target = &mut out[start as usize..end as usize];
        let block = &packed[from..from + size as usize];
        from += size as usize;
        let got = match compressor {
            Compressor::Zlib => fill(flate2::read::ZlibDecoder::new(block), target),
            Compressor::Lzma => fill(xz2::read::XzDecoder::new(block), target),
            Compressor::Lz4 => lz4_flex::block::decompress_into(block, target).ok(),
            Compressor::None => None,
        };
        // vtkio's own writer ends data of a whole number of blocks with an empty extra block
        // (and np = 0); VTK's reader accepts it, so do we.
        let vtkio_tail =
            b + 1 == sizes.len() && b > 0 && got == Some(0) && end - start == block_size;
        if vtkio_tail {
            out.truncate(start as usize);
            break;
        }
        if got != Some(target.len()) {
            return Err(IoError::malformed(
                path,
                format!(
                    "{label}: compressed block {b} of {} does not decompress to its {} bytes",
                    sizes.len(),
                    target.len()
                ),
            ));
        }
    }
    Ok(out)
}

/// Reads into `target` until it is full or the stream ends; `None` for a corrupt stream.
fn fill(mut reader: impl Read, target: &mut [u8]) -> Option<usize> {
    let mut filled = 0;
    while filled < target.len() {
        match reader.read(&mut target[filled..]) {
            Ok(0) => break,
            Ok(n) => filled += n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(_) => return None,
        }
    }
    Some(filled)
}
