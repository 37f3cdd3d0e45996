//! NIfTI-1 volumes, `.nii` and `.nii.gz` (gzip is recognised by its magic bytes, whatever the
//! name): read only.
//!
//! The `nifti` crate parses the 348-byte header (both byte orders); the samples are then read
//! here, from `vox_offset` on, with the same exact-length check and conversion as the other
//! formats. (Doing it here rather than through `nifti`'s volume reader also honours a
//! `vox_offset` beyond 352 in files without extensions, and keeps the crate's `ndarray`
//! feature, with its second copy of the data, out of the build.)
//!
//! - Types: 8-, 16-, 32- and 64-bit integers, `float32`, `float64`; `scl_slope`/`scl_inter` are
//!   applied when the slope is non-zero. RGB and complex data are refused.
//! - Label maps ([`read_labels`]) are decoded straight to exact `u32` labels; a scaling other
//!   than the identity is applied in `f64` and the map accepted only when every scaled sample
//!   is a whole number from 0 to 2³²−1.
//! - Geometry: the full index-to-world transform in RAS and millimetres, chosen as nibabel
//!   chooses it (sform, else qform, else the `pixdim` base affine; `affine.rs`).
//! - Only 3-D data: a 4-D series with more than one volume is refused rather than cut short.
//! - Header/image pairs (`.hdr`/`.img`, magic `ni1`) and NIfTI-2 are not supported.
//!
//! Cost: O(1) for the header, then one streaming read of the N samples (decompressed on the fly
//! when gzipped, decoded block by block, `stream_read.rs`), O(N); memory the decoded samples
//! (4N bytes) plus one block of stored bytes, checked against the budget from the header's
//! dimensions before reading.

mod affine;
pub(crate) mod write;

use std::fs::File;
use std::io::{BufRead, BufReader, Read};
use std::path::Path;

use ::nifti::NiftiHeader;
use voxlod_core::{LabelVolume, Volume};

use crate::decode_target::{AsLabels, AsSamples, DecodeTarget};
use crate::samples::{self, Decoded, SampleType};
use crate::stream_read::read_stream;
use crate::{guard, Endian, IoError};

/// The file's bytes, decompressed if they are gzip.
fn open(path: &Path) -> Result<Box<dyn Read>, IoError> {
    let file = File::open(path).map_err(|e| IoError::access(path, "cannot open", &e))?;
    let mut reader = BufReader::with_capacity(1 << 20, file);
    let is_gzip = reader
        .fill_buf()
        .map_err(|e| IoError::access(path, "cannot read", &e))?
        .starts_with(&[0x1f, 0x8b]);
    Ok(if is_gzip {
        Box::new(flate2::bufread::MultiGzDecoder::new(reader))
    } else {
        Box::new(reader)
    })
}

/// The sample type of a `datatype` code (NIfTI-1 `nifti1.h`).
fn sample_type(path: &Path, code: i16) -> Result<SampleType, IoError> {
    Ok(match code {
        2 => SampleType::U8,
        256 => SampleType::I8,
        4 => SampleType::I16,
        512 => SampleType::U16,
        8 => SampleType::I32,
        768 => SampleType::U32,
        1024 => SampleType::I64,
        1280 => SampleType::U64,
        16 => SampleType::F32,
        64 => SampleType::F64,
        other => {
            let name = match other {
                32 => "complex64",
                128 => "RGB24",
                1536 => "float128",
                1792 => "complex128",
                2048 => "complex256",
                2304 => "RGBA32",
                _ => {
                    return Err(IoError::malformed(
                        path,
                        format!("datatype code {other} is not a NIfTI-1 type"),
                    ))
                }
            };
            return Err(IoError::unsupported(
                path,
                format!("datatype {name} (code {other}) is not supported: only scalar 8- to 64-bit integer and 32- and 64-bit float data are read"),
            ));
        }
    })
}

/// The grid size from `dim`, read as the signed shorts NIfTI stores: `dim[0]` axes (1 to 7),
/// each of size at least 1, and nothing but ones beyond the third.
fn dimensions(path: &Path, raw: &[u16; 8]) -> Result<[usize; 3], IoError> {
    let dim = raw.map(|d| d as i16);
    let axes = dim[0];
    if !(1..=7).contains(&axes) {
        return Err(IoError::malformed(
            path,
            format!("dim[0] = {axes}: the number of dimensions must be 1 to 7"),
        ));
    }
    let axes = axes as usize;
    if let Some(i) = (1..=axes).find(|&i| dim[i] < 1) {
        return Err(IoError::malformed(
            path,
            format!(
                "dim[{i}] = {}: the size along axis {i} must be at least 1",
                dim[i]
            ),
        ));
    }
    let mut dims = [1usize; 3];
    for (axis, size) in dims.iter_mut().enumerate().take(axes) {
        *size = dim[axis + 1] as usize;
    }
    let volumes: u64 = (4..=axes).map(|i| dim[i] as u64).product();
    if let Some(axis) = (4..=axes).find(|&i| dim[i] > 1) {
        let sizes: Vec<String> = (1..=axes).map(|i| dim[i].to_string()).collect();
        return Err(IoError::unsupported(
            path,
            format!(
                "a series of {volumes} volumes (sizes {}; axis {axis} holds {}): only single 3-D volumes are read",
                sizes.join(" x "),
                dim[axis]
            ),
        ));
    }
    Ok(dims)
}

/// Reads a NIfTI-1 volume (`f32` samples, `scl_slope`/`scl_inter` applied when the slope is
/// non-zero).
pub(crate) fn read(path: &Path) -> Result<Volume, IoError> {
    let header = read_header(path)?;
    let mut decoded = read_as(path, &header, &AsSamples, "volume")?;
    if let Some((slope, inter)) = scaling(&header) {
        let (slope, inter) = (slope as f32, inter as f32);
        for v in &mut decoded.values {
            *v = *v * slope + inter;
        }
    }
    decoded.into_volume(path)
}

/// Reads a NIfTI-1 label map (exact `u32` labels, `decode_target.rs`). A `scl_slope` and
/// `scl_inter` other than the identity are applied in `f64`, and the map is read only when
/// every scaled sample is a whole number from 0 to 2³²−1 (else the first that is not is
/// named, with its stored value and the scaling).
pub(crate) fn read_labels(path: &Path) -> Result<LabelVolume, IoError> {
    let header = read_header(path)?;
    let target = AsLabels {
        scale: scaling(&header),
    };
    read_as(path, &header, &target, "label map")?.into_labels(path)
}

/// The header, parsed by the `nifti` crate under the panic guard; single-file NIfTI-1 only.
fn read_header(path: &Path) -> Result<NiftiHeader, IoError> {
    let header = guard::quietly(|| {
        NiftiHeader::from_reader(open(path)?).map_err(|e| IoError::from_nifti(path, &e))
    })
    .ok_or_else(|| IoError::malformed(path, "the NIfTI-1 header cannot be decoded"))??;
    if &header.magic != b"n+1\0" {
        return Err(IoError::unsupported(
            path,
            "not a single-file NIfTI-1 image (header/image pairs .hdr/.img are not supported)",
        ));
    }
    Ok(header)
}

/// `(scl_slope, scl_inter)` when they change the samples: a finite non-zero slope and a finite
/// intercept that are not 1 and 0 (a zero or NaN slope means unscaled, as nibabel writes it).
fn scaling(header: &NiftiHeader) -> Option<(f64, f64)> {
    let (slope, inter) = (header.scl_slope, header.scl_inter);
    let applies =
        slope != 0.0 && slope.is_finite() && inter.is_finite() && !(slope == 1.0 && inter == 0.0);
    applies.then_some((f64::from(slope), f64::from(inter)))
}

/// The samples decoded by `target` (a `noun` for the budget's message) as they are read (and
/// inflated), with the geometry of the header.
fn read_as<T: DecodeTarget>(
    path: &Path,
    header: &NiftiHeader,
    target: &T,
    noun: &str,
) -> Result<Decoded<Vec<T::Item>>, IoError> {
    let dims = dimensions(path, &header.dim)?;
    let sample = sample_type(path, header.datatype)?;
    samples::check_decoded_size(path, dims, sample, noun)?;

    // Skip to the data: the header and any extensions come first.
    let offset = header.vox_offset;
    if !(offset.is_finite() && offset >= 348.0) {
        return Err(IoError::malformed(
            path,
            format!("vox_offset {offset} is before the end of the header"),
        ));
    }
    let mut reader = open(path)?;
    let skipped = std::io::copy(
        &mut reader.by_ref().take(offset as u64),
        &mut std::io::sink(),
    )
    .map_err(|e| {
        IoError::truncated(path, format!("cannot reach the data at byte {offset}: {e}"))
    })?;
    if skipped < offset as u64 {
        return Err(IoError::truncated(
            path,
            format!("the file ends at byte {skipped}, before the data at vox_offset {offset}"),
        ));
    }
    let endian = match header.endianness {
        ::nifti::Endianness::Little => Endian::Little,
        ::nifti::Endianness::Big => Endian::Big,
    };
    let values = read_stream(path, reader, dims, (sample, endian), target, "image data")?;

    // Geometry in millimetres and RAS, as nibabel chooses it (`affine.rs`).
    let world = affine::world_of(path, header, dims)?;
    let (grid, orientation) = world
        .split(dims)
        .map_err(|e| IoError::malformed(path, e.to_string()))?;
    Ok(Decoded {
        dims,
        spacing: grid.spacing,
        origin: grid.origin,
        orientation,
        values,
    })
}
