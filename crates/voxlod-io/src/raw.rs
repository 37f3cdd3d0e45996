//! Headerless raw volumes: samples one after another, x fastest, then y, then z, as the CT
//! archives publish them (the Stanford CT head is 256×256×113 big-endian `u16`).
//!
//! Reading needs the layout the file does not carry ([`RawLayout`]). The file size must equal
//! `header_bytes + dims × sample size` exactly: anything else is a [`IoErrorKind::SizeMismatch`]
//! whose message names both sizes and suggests layouts that would fit (another depth, another
//! sample type, a header). Writing produces `f32` little-endian samples and nothing else; keep
//! the dimensions, spacing and origin yourself, or prefer NRRD.
//!
//! Samples are decoded to `f32` for a volume, or to exact `u32` labels for a label map
//! (`decode_target.rs`), block by block on all threads (`block_read.rs`).
//!
//! Cost: one read of the N samples in O(N) time; memory at the peak is the decoded samples (4N
//! bytes) plus a block of stored bytes per thread, checked against the budget first
//! (`samples::check_decoded_size`).

use std::fmt;
use std::io::Write;
use std::path::Path;
use std::str::FromStr;

use voxlod_core::{LabelVolume, Orientation, Volume};

use crate::atomic::{stage, TempFile};
use crate::block_read;
use crate::blockwise_volume::{BlockwiseVolume, DataStart, StoredSamples};
use crate::decode_target::{AsLabels, AsSamples, DecodeTarget};
use crate::samples::{self, Decoded, Endian, ParseNameError, SampleType};
use crate::{IoError, IoErrorKind};

/// Sample type of a headerless raw volume.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum RawType {
    /// Unsigned 8-bit integers.
    U8,
    /// Signed 8-bit integers.
    I8,
    /// Signed 16-bit integers (most CT scans).
    I16,
    /// Unsigned 16-bit integers (the Stanford CT head).
    U16,
    /// Signed 32-bit integers.
    I32,
    /// Unsigned 32-bit integers (label maps of connectomics).
    U32,
    /// 32-bit IEEE floats.
    F32,
    /// Signed 64-bit integers.
    I64,
    /// Unsigned 64-bit integers.
    U64,
    /// 64-bit IEEE floats.
    F64,
}

impl RawType {
    /// Every sample type, smallest first.
    pub const ALL: [RawType; 10] = [
        RawType::U8,
        RawType::I8,
        RawType::I16,
        RawType::U16,
        RawType::I32,
        RawType::U32,
        RawType::F32,
        RawType::I64,
        RawType::U64,
        RawType::F64,
    ];

    /// Bytes per sample.
    pub fn size(self) -> usize {
        self.sample_type().size()
    }

    /// The short name accepted by [`FromStr`] (`u8`, `i8`, `i16`, `u16`, `i32`, `u32`, `f32`,
    /// `i64`, `u64`, `f64`).
    pub fn name(self) -> &'static str {
        match self {
            RawType::U8 => "u8",
            RawType::I8 => "i8",
            RawType::I16 => "i16",
            RawType::U16 => "u16",
            RawType::I32 => "i32",
            RawType::U32 => "u32",
            RawType::F32 => "f32",
            RawType::I64 => "i64",
            RawType::U64 => "u64",
            RawType::F64 => "f64",
        }
    }

    pub(crate) fn sample_type(self) -> SampleType {
        match self {
            RawType::U8 => SampleType::U8,
            RawType::I8 => SampleType::I8,
            RawType::I16 => SampleType::I16,
            RawType::U16 => SampleType::U16,
            RawType::I32 => SampleType::I32,
            RawType::U32 => SampleType::U32,
            RawType::F32 => SampleType::F32,
            RawType::I64 => SampleType::I64,
            RawType::U64 => SampleType::U64,
            RawType::F64 => SampleType::F64,
        }
    }
}

impl fmt::Display for RawType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for RawType {
    type Err = ParseNameError;

    /// The short names of [`RawType::name`], case-insensitive; the long forms `uint8`, `int8`,
    /// `int16`, `uint16`, `int32`, `uint32`, `float32`, `float`, `int64`, `uint64`, `float64` and
    /// `double` are accepted too.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "u8" | "uint8" => Ok(RawType::U8),
            "i8" | "int8" => Ok(RawType::I8),
            "i16" | "int16" => Ok(RawType::I16),
            "u16" | "uint16" => Ok(RawType::U16),
            "i32" | "int32" => Ok(RawType::I32),
            "u32" | "uint32" => Ok(RawType::U32),
            "f32" | "float32" | "float" => Ok(RawType::F32),
            "i64" | "int64" => Ok(RawType::I64),
            "u64" | "uint64" => Ok(RawType::U64),
            "f64" | "float64" | "double" => Ok(RawType::F64),
            _ => Err(ParseNameError::new(
                "sample type",
                s,
                "u8, i8, i16, u16, i32, u32, f32, i64, u64, f64",
            )),
        }
    }
}

/// Everything a headerless raw file does not say about itself.
#[derive(Clone, Debug, PartialEq)]
pub struct RawLayout {
    /// Samples along x, y, z (x varies fastest in the file).
    pub dims: [usize; 3],
    /// The type of every sample.
    pub dtype: RawType,
    /// The byte order of multi-byte samples (ignored for `u8`).
    pub endian: Endian,
    /// Distance between neighbouring samples, in millimetres for a scan.
    pub spacing: [f64; 3],
    /// World position of the first sample.
    pub origin: [f64; 3],
    /// Bytes to skip at the start of the file.
    pub header_bytes: u64,
}

impl RawLayout {
    /// A layout with unit spacing, the origin at zero and no header.
    pub fn new(dims: [usize; 3], dtype: RawType, endian: Endian) -> RawLayout {
        RawLayout {
            dims,
            dtype,
            endian,
            spacing: [1.0; 3],
            origin: [0.0; 3],
            header_bytes: 0,
        }
    }
}

/// Reads a headerless raw volume laid out as `layout` says.
pub(crate) fn read(path: &Path, layout: &RawLayout) -> Result<Volume, IoError> {
    let values = read_as(path, layout, &AsSamples, "volume")?;
    samples::make_volume(path, layout.dims, layout.spacing, layout.origin, values)
}

/// Reads a headerless raw label map laid out as `layout` says (exact `u32` labels).
pub(crate) fn read_labels(path: &Path, layout: &RawLayout) -> Result<LabelVolume, IoError> {
    let values = read_as(path, layout, &AsLabels::default(), "label map")?;
    let decoded = Decoded {
        dims: layout.dims,
        spacing: layout.spacing,
        origin: layout.origin,
        orientation: Orientation::default(),
        values,
    };
    decoded.into_labels(path)
}

/// The samples of the file decoded by `target`, after the file's size is checked against the
/// layout and the decoded size against the budget (`noun` names what is read).
fn read_as<T: DecodeTarget>(
    path: &Path,
    layout: &RawLayout,
    target: &T,
    noun: &str,
) -> Result<Vec<T::Item>, IoError> {
    let ty = layout.dtype.sample_type();
    let (_, data_bytes) = samples::check_decoded_size(path, layout.dims, ty, noun)?;
    let file = std::fs::File::open(path).map_err(|e| IoError::access(path, "cannot open", &e))?;
    let file_len = file
        .metadata()
        .map_err(|e| IoError::access(path, "cannot read", &e))?
        .len();
    let expected = layout.header_bytes.saturating_add(data_bytes as u64);
    if file_len != expected {
        return Err(size_mismatch(path, layout, file_len, expected));
    }
    let stored = (ty, layout.endian);
    let (offset, what) = (layout.header_bytes, "raw sample data");
    block_read::read_decoded(path, &file, offset, layout.dims, stored, target, what)
}

/// A headerless raw volume laid out as `layout` says, for reading window by window
/// ([`BlockwiseVolume`]): the file's size is checked as [`read`] checks it, nothing more is read.
pub(crate) fn open_blockwise(path: &Path, layout: &RawLayout) -> Result<BlockwiseVolume, IoError> {
    let ty = layout.dtype.sample_type();
    let len = std::fs::metadata(path)
        .map_err(|e| IoError::access(path, "cannot open", &e))?
        .len();
    let data_bytes = layout
        .dims
        .iter()
        .try_fold(ty.size() as u64, |acc, &d| acc.checked_mul(d as u64));
    let expected = data_bytes.map(|b| b.saturating_add(layout.header_bytes));
    if let Some(expected) = expected.filter(|&e| e != len) {
        return Err(size_mismatch(path, layout, len, expected));
    }
    let stored = StoredSamples {
        dims: layout.dims,
        sample: ty,
        endian: layout.endian,
        spacing: layout.spacing,
        origin: layout.origin,
        orientation: Orientation::default(),
    };
    BlockwiseVolume::open(path, path, DataStart::At(layout.header_bytes), &stored)
}

/// The size mismatch error, with the layouts that would fit when some are obvious.
fn size_mismatch(path: &Path, layout: &RawLayout, file_len: u64, expected: u64) -> IoError {
    let [nx, ny, nz] = layout.dims;
    let size = layout.dtype.size() as u64;
    let mut message = format!(
        "file has {file_len} bytes but a {nx}x{ny}x{nz} {} volume needs {expected} bytes",
        layout.dtype
    );
    if layout.header_bytes > 0 {
        message.push_str(&format!(" (with {} header bytes)", layout.header_bytes));
    }
    let mut hints = Vec::new();
    let payload = file_len.checked_sub(layout.header_bytes);
    if let Some(payload) = payload.filter(|p| p.is_multiple_of(size) && *p > 0) {
        let count = payload / size;
        let slice = (nx * ny) as u64;
        if count.is_multiple_of(slice) && count / slice != nz as u64 {
            hints.push(format!("dims {nx} {ny} {}", count / slice));
        }
        let side = (count as f64).cbrt().round() as u64;
        if side * side * side == count && [side; 3] != [nx as u64, ny as u64, nz as u64] {
            hints.push(format!("dims {side} {side} {side}"));
        }
    }
    let samples = (nx * ny * nz) as u64;
    for other in RawType::ALL {
        if other != layout.dtype && layout.header_bytes + samples * other.size() as u64 == file_len
        {
            hints.push(format!("type {other}"));
        }
    }
    if file_len > expected {
        hints.push(format!(
            "a header of {} bytes",
            file_len - expected + layout.header_bytes
        ));
    }
    if !hints.is_empty() {
        message.push_str(&format!("; would fit: {}", hints.join(", or ")));
    }
    IoError::new(path, IoErrorKind::SizeMismatch, message)
}

/// Writes the samples as `f32` little-endian, with no header.
pub(crate) fn write(path: &Path, volume: &Volume) -> Result<TempFile, IoError> {
    stage(path, |w| write_samples_f32_le(w, volume.as_slice()))
}

/// Streams samples as little-endian `f32`, in blocks so no second copy of the volume is made.
pub(crate) fn write_samples_f32_le(
    w: &mut (impl Write + ?Sized),
    values: &[f32],
) -> std::io::Result<()> {
    write_le(w, values, f32::to_le_bytes)
}

/// Streams labels as little-endian `u32`, in blocks so no second copy of the map is made.
pub(crate) fn write_labels_le(
    w: &mut (impl Write + ?Sized),
    values: &[u32],
) -> std::io::Result<()> {
    write_le(w, values, u32::to_le_bytes)
}

/// Streams values as the bytes `le` gives each, 16 Ki values per write.
fn write_le<T: Copy, const N: usize>(
    w: &mut (impl Write + ?Sized),
    values: &[T],
    le: impl Fn(T) -> [u8; N],
) -> std::io::Result<()> {
    let mut block = Vec::with_capacity(16 * 1024 * N);
    for chunk in values.chunks(16 * 1024) {
        block.clear();
        for &v in chunk {
            block.extend_from_slice(&le(v));
        }
        w.write_all(&block)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_parse_both_ways() {
        for t in RawType::ALL {
            assert_eq!(t.name().parse::<RawType>().unwrap(), t);
            assert_eq!(t.to_string().to_uppercase().parse::<RawType>().unwrap(), t);
        }
        assert_eq!("BIG".parse::<Endian>().unwrap(), Endian::Big);
        assert_eq!("little".parse::<Endian>().unwrap(), Endian::Little);
        let err = "u128".parse::<RawType>().unwrap_err().to_string();
        assert!(err.contains("u128") && err.contains("u16"), "{err}");
        assert!("middle".parse::<Endian>().is_err());
    }

    #[test]
    fn mismatch_suggests_fitting_layouts() {
        let layout = RawLayout::new([256, 256, 113], RawType::U16, Endian::Big);
        // The engine: 256x256x128 bytes.
        let err = size_mismatch(Path::new("engine.raw"), &layout, 8388608, 14811136);
        assert_eq!(err.kind, IoErrorKind::SizeMismatch);
        let text = err.to_string();
        assert!(
            text.contains("8388608") && text.contains("14811136"),
            "{text}"
        );
        assert!(text.contains("dims 256 256 64"), "{text}");
        let layout = RawLayout::new([256, 256, 128], RawType::U16, Endian::Big);
        let err = size_mismatch(Path::new("engine.raw"), &layout, 8388608, 16777216);
        assert!(err.to_string().contains("type u8"), "{err}");
        let layout = RawLayout::new([10, 10, 10], RawType::U8, Endian::Big);
        let err = size_mismatch(Path::new("h.raw"), &layout, 1512, 1000);
        assert!(err.to_string().contains("a header of 512 bytes"), "{err}");
    }
}
