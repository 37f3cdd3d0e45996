//! What the volume readers share: sample types and byte orders ([`Endian`]) and their
//! conversion to `f32`, the words of a short or corrupt read of sample data, the memory check
//! before any large allocation, the decoded samples with their geometry ([`Decoded`]), and the
//! final checks on grid geometry.
//!
//! Cost: O(N) per conversion of N samples; the checks are O(1).

use std::fmt;
use std::fs::File;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::str::FromStr;

use voxlod_core::{memory, Grid, LabelVolume, Orientation, Volume};

use crate::{budget, IoError, IoErrorKind};

/// Byte order of multi-byte samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Endian {
    /// Least significant byte first (x86, ARM, most files today).
    Little,
    /// Most significant byte first (older scanners and workstations).
    Big,
}

impl fmt::Display for Endian {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Endian::Little => "little",
            Endian::Big => "big",
        })
    }
}

impl FromStr for Endian {
    type Err = ParseNameError;

    /// `little` or `big`, case-insensitive (`le` and `be` too).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "little" | "le" => Ok(Endian::Little),
            "big" | "be" => Ok(Endian::Big),
            _ => Err(ParseNameError::new("byte order", s, "little, big")),
        }
    }
}

/// A name that is not one of the accepted spellings of a [`RawType`](crate::RawType) or [`Endian`].
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("unknown {what} '{given}': expected one of {expected}")]
pub struct ParseNameError {
    what: &'static str,
    given: String,
    expected: &'static str,
}

impl ParseNameError {
    /// `given` is not a `what` (a sample type, a byte order); `expected` lists the names.
    pub(crate) fn new(what: &'static str, given: &str, expected: &'static str) -> Self {
        ParseNameError {
            what,
            given: given.to_string(),
            expected,
        }
    }
}

/// A stored sample type. Volumes convert everything to `f32` in memory (32- and 64-bit integers
/// and `f64` lose precision beyond 24 bits of mantissa, which no scanner comes near); label maps
/// to exact `u32` (`decode_target.rs`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum SampleType {
    U8,
    I8,
    U16,
    I16,
    U32,
    I32,
    U64,
    I64,
    F32,
    F64,
}

impl SampleType {
    pub(crate) fn size(self) -> usize {
        match self {
            SampleType::U8 | SampleType::I8 => 1,
            SampleType::U16 | SampleType::I16 => 2,
            SampleType::U32 | SampleType::I32 | SampleType::F32 => 4,
            SampleType::U64 | SampleType::I64 | SampleType::F64 => 8,
        }
    }

    pub(crate) fn name(self) -> &'static str {
        match self {
            SampleType::U8 => "uint8",
            SampleType::I8 => "int8",
            SampleType::U16 => "uint16",
            SampleType::I16 => "int16",
            SampleType::U32 => "uint32",
            SampleType::I32 => "int32",
            SampleType::U64 => "uint64",
            SampleType::I64 => "int64",
            SampleType::F32 => "float32",
            SampleType::F64 => "float64",
        }
    }
}

/// Converts stored samples to `f32`. `bytes.len()` must be a multiple of the sample size.
pub(crate) fn decode(bytes: &[u8], ty: SampleType, endian: Endian) -> Vec<f32> {
    debug_assert_eq!(bytes.len() % ty.size(), 0);
    let mut out = vec![0.0; bytes.len() / ty.size()];
    decode_into(bytes, ty, endian, &mut out);
    out
}

/// [`decode`] into `out`, one value per stored sample of `bytes` (as many as both hold).
pub(crate) fn decode_into(bytes: &[u8], ty: SampleType, endian: Endian, out: &mut [f32]) {
    macro_rules! convert {
        ($t:ty, $n:literal) => {
            for (value, c) in out.iter_mut().zip(bytes.chunks_exact($n)) {
                let raw: [u8; $n] = c.try_into().expect("chunks_exact gives whole samples");
                *value = (match endian {
                    Endian::Little => <$t>::from_le_bytes(raw),
                    Endian::Big => <$t>::from_be_bytes(raw),
                }) as f32;
            }
        };
    }
    match ty {
        SampleType::U8 => (out.iter_mut().zip(bytes)).for_each(|(v, &b)| *v = b as f32),
        SampleType::I8 => (out.iter_mut().zip(bytes)).for_each(|(v, &b)| *v = b as i8 as f32),
        SampleType::U16 => convert!(u16, 2),
        SampleType::I16 => convert!(i16, 2),
        SampleType::U32 => convert!(u32, 4),
        SampleType::I32 => convert!(i32, 4),
        SampleType::U64 => convert!(u64, 8),
        SampleType::I64 => convert!(i64, 8),
        SampleType::F32 => convert!(f32, 4),
        SampleType::F64 => convert!(f64, 8),
    }
}

/// A grid with no samples along some axis, refused as malformed, naming the file.
pub(crate) fn refuse_zero_dims(path: &Path, dims: [usize; 3]) -> Result<(), IoError> {
    if dims.contains(&0) {
        return Err(IoError::malformed(
            path,
            format!(
                "dimensions {}x{}x{} include a zero",
                dims[0], dims[1], dims[2]
            ),
        ));
    }
    Ok(())
}

/// The number of samples of a grid of `dims`, and the bytes they take on disk, after checking
/// that both the stored bytes and the `f32` copy fit in memory (for the readers that hold both:
/// VTK, Zarr, windows of a blockwise volume). An absurd header (sizes of 100000³) ends here with
/// [`IoErrorKind::TooLarge`] and the byte count, before any allocation.
pub(crate) fn check_volume_size(
    path: &Path,
    dims: [usize; 3],
    ty: SampleType,
) -> Result<(usize, usize), IoError> {
    check_size(path, dims, ty, "volume", |count| {
        memory::bytes_of::<u8>(count)
            .saturating_mul(ty.size() as u64)
            .saturating_add(memory::bytes_of::<f32>(count))
    })
}

/// Samples per block of the readers that decode block by block (`block_read.rs`,
/// `stream_read.rs`): 256 Ki (512 KiB of 16-bit samples, 1 MiB of output).
pub(crate) const BLOCK: usize = 1 << 18;

/// As [`check_volume_size`], for a reader that decodes block by block (`stream_read.rs`,
/// `block_read.rs`): the 4-byte samples or labels (`noun` says which, "volume" or "label
/// map") and the blocks of stored bytes in flight (one per thread, no more than the data).
pub(crate) fn check_decoded_size(
    path: &Path,
    dims: [usize; 3],
    ty: SampleType,
    noun: &str,
) -> Result<(usize, usize), IoError> {
    let in_flight = BLOCK.saturating_mul(rayon::current_num_threads());
    check_size(path, dims, ty, noun, |count| {
        let blocks = memory::bytes_of::<u8>(count.min(in_flight)).saturating_mul(ty.size() as u64);
        memory::bytes_of::<u32>(count).saturating_add(blocks)
    })
}

/// The count and stored bytes of a grid of `dims`, once `needed(count)` bytes fit in memory.
fn check_size(
    path: &Path,
    dims: [usize; 3],
    ty: SampleType,
    noun: &str,
    needed: impl Fn(usize) -> u64,
) -> Result<(usize, usize), IoError> {
    refuse_zero_dims(path, dims)?;
    let what = format!("a {}x{}x{} {} {noun}", dims[0], dims[1], dims[2], ty.name());
    let count = dims
        .iter()
        .try_fold(1usize, |acc, &d| acc.checked_mul(d))
        .filter(|n| n.checked_mul(8).is_some());
    let Some(count) = count else {
        return Err(IoError::new(
            path,
            IoErrorKind::TooLarge,
            format!("{what} has more samples than memory can address"),
        ));
    };
    budget::check_bytes(path, &what, needed(count))?;
    Ok((count, count * ty.size()))
}

/// The error of a read of `expected` bytes of the `what` that failed with `e` after `found`
/// bytes: [`IoErrorKind::Truncated`] naming both counts when the data (or its compressed stream)
/// ends early, [`IoErrorKind::Malformed`] for a corrupt compressed stream, else an access error.
pub(crate) fn read_error(
    path: &Path,
    what: &str,
    expected: usize,
    found: usize,
    e: &std::io::Error,
) -> IoError {
    match e.kind() {
        std::io::ErrorKind::UnexpectedEof => IoError::truncated(
            path,
            format!(
                "the {what} is truncated: expected {expected} bytes, found {found} before the compressed stream ended early"
            ),
        ),
        std::io::ErrorKind::InvalidInput | std::io::ErrorKind::InvalidData => IoError::malformed(
            path,
            format!("the {what} is corrupt after {found} bytes: {e}"),
        ),
        _ => IoError::access(path, &format!("cannot read the {what}"), e),
    }
}

/// The error of `what` ending after `found` of its `expected` bytes.
pub(crate) fn short_data(path: &Path, what: &str, expected: usize, found: usize) -> IoError {
    IoError::truncated(
        path,
        format!("the {what} is truncated: expected {expected} bytes, found {found}"),
    )
}

/// A decompressor for zlib or gzip data, told apart by the gzip magic bytes.
pub(crate) fn inflater<'a, R: std::io::BufRead + 'a>(mut reader: R) -> Box<dyn Read + 'a> {
    let is_gzip = matches!(reader.fill_buf(), Ok(b) if b.starts_with(&[0x1f, 0x8b]));
    if is_gzip {
        Box::new(flate2::bufread::MultiGzDecoder::new(reader))
    } else {
        Box::new(flate2::bufread::ZlibDecoder::new(reader))
    }
}

/// Builds the volume after checking the geometry: spacing finite and positive, origin finite.
pub(crate) fn make_volume(
    path: &Path,
    dims: [usize; 3],
    spacing: [f64; 3],
    origin: [f64; 3],
    values: Vec<f32>,
) -> Result<Volume, IoError> {
    check_geometry(path, spacing, origin)?;
    let grid = Grid::new(dims, spacing, origin).map_err(|e| IoError::from_core(path, e))?;
    Volume::from_vec(grid, values).map_err(|e| IoError::from_core(path, e))
}

/// Decoded samples (`f32` for a volume, `u32` for a label map) with the geometry their header
/// gave, before the checks that make them a [`Volume`] or a [`LabelVolume`].
pub(crate) struct Decoded<V> {
    pub(crate) dims: [usize; 3],
    pub(crate) spacing: [f64; 3],
    pub(crate) origin: [f64; 3],
    pub(crate) orientation: Orientation,
    pub(crate) values: V,
}

impl<V> Decoded<V> {
    /// The same geometry with `f` of the values (which fails naming the file).
    pub(crate) fn map<W>(
        self,
        f: impl FnOnce(V) -> Result<W, IoError>,
    ) -> Result<Decoded<W>, IoError> {
        Ok(Decoded {
            dims: self.dims,
            spacing: self.spacing,
            origin: self.origin,
            orientation: self.orientation,
            values: f(self.values)?,
        })
    }
}

impl Decoded<Vec<f32>> {
    /// The volume, its geometry checked ([`make_volume`]).
    pub(crate) fn into_volume(self, path: &Path) -> Result<Volume, IoError> {
        make_volume(path, self.dims, self.spacing, self.origin, self.values)
            .map(|v| v.oriented(self.orientation))
    }
}

impl Decoded<Vec<u32>> {
    /// The label map, its geometry checked as [`make_volume`] checks a volume's.
    pub(crate) fn into_labels(self, path: &Path) -> Result<LabelVolume, IoError> {
        check_geometry(path, self.spacing, self.origin)?;
        let grid = Grid::new(self.dims, self.spacing, self.origin)
            .map_err(|e| IoError::from_core(path, e))?;
        LabelVolume::from_vec(grid, self.values)
            .map(|v| v.oriented(self.orientation))
            .map_err(|e| IoError::from_core(path, e))
    }
}

/// Fails unless the spacing is finite and positive and the origin finite.
pub(crate) fn check_geometry(
    path: &Path,
    spacing: [f64; 3],
    origin: [f64; 3],
) -> Result<(), IoError> {
    if let Some(axis) = spacing.iter().position(|s| !s.is_finite() || *s <= 0.0) {
        return Err(IoError::malformed(
            path,
            format!(
                "spacing {} {} {} is not finite and positive along {}",
                spacing[0],
                spacing[1],
                spacing[2],
                ["x", "y", "z"][axis]
            ),
        ));
    }
    if origin.iter().any(|o| !o.is_finite()) {
        return Err(IoError::malformed(
            path,
            format!(
                "origin {} {} {} is not finite",
                origin[0], origin[1], origin[2]
            ),
        ));
    }
    Ok(())
}

/// The data file a detached header names (`field` is the header's key, for messages):
/// relative names are relative to the header's folder.
pub(crate) fn data_file_path(header: &Path, field: &str, name: &str) -> Result<PathBuf, IoError> {
    if name.trim().is_empty() {
        return Err(IoError::malformed(
            header,
            format!("the '{field}' field names no file"),
        ));
    }
    let name = Path::new(name);
    Ok(if name.is_absolute() {
        name.to_path_buf()
    } else {
        header.parent().unwrap_or(Path::new("")).join(name)
    })
}

/// Opens the data file of a detached header; errors name both files.
pub(crate) fn open_data_file(header: &Path, data: &Path) -> Result<File, IoError> {
    let doing = format!("cannot open the data file of {}", header.display());
    let file = File::open(data).map_err(|e| IoError::access(data, &doing, &e))?;
    let meta = file
        .metadata()
        .map_err(|e| IoError::access(data, &doing, &e))?;
    if !meta.is_file() {
        return Err(IoError::new(
            data,
            IoErrorKind::Access,
            format!("the data file of {} is not a file", header.display()),
        ));
    }
    Ok(file)
}

/// Scale from a length unit to millimetres, for the units headers may declare.
pub(crate) fn millimetres_per(unit: &str) -> Option<f64> {
    match unit.trim().trim_matches('"').to_ascii_lowercase().as_str() {
        "mm" | "millimeter" | "millimeters" | "millimetre" | "millimetres" => Some(1.0),
        "m" | "meter" | "meters" | "metre" | "metres" => Some(1000.0),
        "cm" | "centimeter" | "centimeters" => Some(10.0),
        "um" | "µm" | "micron" | "microns" | "micrometer" | "micrometers" => Some(1e-3),
        _ => None,
    }
}

/// Parses a whitespace-separated list of exactly `n` values of `T`.
pub(crate) fn parse_list<T: std::str::FromStr>(text: &str, n: usize) -> Option<Vec<T>> {
    let values: Vec<T> = text
        .split_whitespace()
        .map(|t| t.parse().ok())
        .collect::<Option<_>>()?;
    (values.len() == n).then_some(values)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decodes_every_type_and_byte_order() {
        assert_eq!(decode(&[0, 255], SampleType::U8, Endian::Big), [0.0, 255.0]);
        assert_eq!(
            decode(&[0xff, 0x80], SampleType::I8, Endian::Big),
            [-1.0, -128.0]
        );
        assert_eq!(
            decode(&[0x0c, 0xc8], SampleType::U16, Endian::Big),
            [3272.0]
        );
        assert_eq!(
            decode(&[0xc8, 0x0c], SampleType::U16, Endian::Little),
            [3272.0]
        );
        assert_eq!(decode(&[0xff, 0xfe], SampleType::I16, Endian::Big), [-2.0]);
        assert_eq!(
            decode(&70000u32.to_le_bytes(), SampleType::U32, Endian::Little),
            [70000.0]
        );
        assert_eq!(
            decode(&(-5i32).to_be_bytes(), SampleType::I32, Endian::Big),
            [-5.0]
        );
        assert_eq!(
            decode(&1.5f32.to_be_bytes(), SampleType::F32, Endian::Big),
            [1.5]
        );
        assert_eq!(
            decode(&(-2.25f64).to_le_bytes(), SampleType::F64, Endian::Little),
            [-2.25]
        );
    }

    #[test]
    fn absurd_sizes_are_refused_before_allocating() {
        let p = Path::new("huge.nrrd");
        let err = check_volume_size(p, [100000, 100000, 100000], SampleType::U16).unwrap_err();
        assert_eq!(err.kind, IoErrorKind::TooLarge);
        assert!(err.message.contains("bytes"), "{err}");
        let err = check_volume_size(p, [usize::MAX, 2, 2], SampleType::U8).unwrap_err();
        assert_eq!(err.kind, IoErrorKind::TooLarge);
        assert_eq!(
            check_volume_size(p, [4, 5, 6], SampleType::I16).unwrap(),
            (120, 240)
        );
    }
}
