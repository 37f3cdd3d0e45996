//! Uncompressed volumes read window by window (issue "Scale", item 3): the samples of a
//! headerless raw file, of a NRRD with `encoding: raw` (attached or in its data file) or of a
//! MetaImage without `CompressedData` lie in the file x fastest, then y, then z, so any box of
//! them is found by arithmetic and read with positioned reads, never the whole file.
//!
//! [`BlockwiseVolume`] holds the open data file, where its first sample is, the sample type, byte
//! order and the geometry its header gave; [`BlockwiseVolume::read_window`] reads one box as an
//! `f32` volume placed where it sits in the scan (the windows a [`voxlod` blockwise
//! route](https://docs.rs/voxlod) asks for, a few layers of blocks at a time). Opening checks that
//! the file holds every sample its header promises (a short file is [`IoErrorKind::Truncated`]
//! naming it, before any sample is read); each window is checked against the memory budget before
//! it is allocated. The whole volume is never checked against the budget: not holding it is the
//! point.
//!
//! Compressed data (NRRD `gzip`, MetaImage `CompressedData`) and NRRD `ascii` have no random
//! access: the openers return `None` for them, and such files are read whole as before.
//! Streaming them in z order per level would need the sampler to ask for its windows in file
//! order and read the file once per level; a scan large enough to need it is rarely compressed.
//!
//! Not in the voxel paper (He et al. 1995), which holds the whole volume. **Cost** per window of
//! `ex × ey × ez` samples: `ez` reads of one span of `ey` rows of the file (or `ey × ez` reads of
//! one row when the window is narrow against a wide file, so that no more than about four times
//! the window's bytes are read), then the decoding of the window's samples, O(window); memory is
//! the window as `f32` plus one span of stored bytes.

use std::fs::File;
use std::path::{Path, PathBuf};

use voxlod_core::{Grid, Orientation, Volume};

use crate::samples::{self, SampleType};
use crate::{Endian, IoError, IoErrorKind};

/// A span of rows is read at once when it holds at most this many times the rows' own bytes (or
/// is small, below [`SMALL_SPAN_BYTES`]); otherwise each row is read by itself.
const SPAN_WASTE_FACTOR: u64 = 4;

/// Spans up to this size are read at once whatever their waste.
const SMALL_SPAN_BYTES: u64 = 256 << 10;

/// Where the first sample of a data file is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum DataStart {
    /// At this byte.
    At(u64),
    /// The samples are the last bytes of the file (NRRD `byte skip: -1`, MetaImage
    /// `HeaderSize = -1`).
    AtEnd,
}

/// What a header says about its samples: how they are stored and where they lie in the world.
#[derive(Clone, Copy, Debug)]
pub(crate) struct StoredSamples {
    pub(crate) dims: [usize; 3],
    pub(crate) sample: SampleType,
    pub(crate) endian: Endian,
    pub(crate) spacing: [f64; 3],
    pub(crate) origin: [f64; 3],
    pub(crate) orientation: Orientation,
}

/// An uncompressed volume on disk, read window by window (see the module documentation).
#[derive(Debug)]
pub struct BlockwiseVolume {
    /// The file holding the samples (a detached header's data file).
    data_path: PathBuf,
    file: File,
    /// Byte of the first sample.
    offset: u64,
    sample: SampleType,
    endian: Endian,
    grid: Grid,
    orientation: Orientation,
    /// [`SMALL_SPAN_BYTES`], lowered by tests to reach the row-by-row reads on small files.
    small_span_bytes: u64,
}

impl BlockwiseVolume {
    /// Opens `data_path`, whose samples start at `start` and are laid out as `stored` says;
    /// `header` (the file the geometry came from) is named by geometry errors. Fails unless the
    /// file holds every sample.
    pub(crate) fn open(
        header: &Path,
        data_path: &Path,
        start: DataStart,
        stored: &StoredSamples,
    ) -> Result<BlockwiseVolume, IoError> {
        let data_bytes = stored_bytes(data_path, stored.dims, stored.sample)?;
        samples::check_geometry(header, stored.spacing, stored.origin)?;
        let grid = Grid::new(stored.dims, stored.spacing, stored.origin)
            .map_err(|e| IoError::from_core(header, e))?;
        let file =
            File::open(data_path).map_err(|e| IoError::access(data_path, "cannot open", &e))?;
        let len = file
            .metadata()
            .map_err(|e| IoError::access(data_path, "cannot read", &e))?
            .len();
        let short = |from: u64| {
            let [nx, ny, nz] = stored.dims;
            IoError::truncated(
                data_path,
                format!(
                    "the data is truncated: {nx}x{ny}x{nz} {} samples need {data_bytes} bytes \
                     from byte {from}, but the file has {len} bytes",
                    stored.sample.name()
                ),
            )
        };
        let offset = match start {
            DataStart::At(offset) => offset,
            DataStart::AtEnd => len.checked_sub(data_bytes).ok_or_else(|| short(0))?,
        };
        if offset.checked_add(data_bytes).is_none_or(|end| end > len) {
            return Err(short(offset));
        }
        Ok(BlockwiseVolume {
            data_path: data_path.to_path_buf(),
            file,
            offset,
            sample: stored.sample,
            endian: stored.endian,
            grid,
            orientation: stored.orientation,
            small_span_bytes: SMALL_SPAN_BYTES,
        })
    }

    /// The samples' grid: dimensions x, y, z, spacing and origin (millimetres when the header
    /// names a unit).
    pub fn grid(&self) -> Grid {
        self.grid
    }

    /// The direction cosines and anatomical frame the header gave (identity and unknown for a
    /// raw file).
    pub fn orientation(&self) -> Orientation {
        self.orientation
    }

    /// The file the samples are read from (the data file of a detached header).
    pub fn path(&self) -> &Path {
        &self.data_path
    }

    /// The stored sample type ("uint8", "int16", …).
    pub fn sample_type(&self) -> &'static str {
        self.sample.name()
    }

    /// Bytes one stored sample takes.
    pub fn sample_bytes(&self) -> usize {
        self.sample.size()
    }

    /// Byte of the data file where the first sample is.
    pub fn data_offset(&self) -> u64 {
        self.offset
    }

    /// The samples `start .. start + extent` (x, y, z indices) as a volume whose grid is the
    /// window's: same spacing, origin moved to the window's first sample, axis-aligned (the
    /// orientation is the scan's, [`BlockwiseVolume::orientation`]). The window must lie inside the
    /// volume; its size is checked against the memory budget before reading.
    pub fn read_window(&self, start: [usize; 3], extent: [usize; 3]) -> Result<Volume, IoError> {
        let dims = self.grid.dims;
        if (0..3).any(|a| extent[a] == 0 || start[a].saturating_add(extent[a]) > dims[a]) {
            return Err(IoError::malformed(
                &self.data_path,
                format!(
                    "the window from sample ({}, {}, {}) of {}x{}x{} samples is not inside the \
                     {}x{}x{} volume",
                    start[0],
                    start[1],
                    start[2],
                    extent[0],
                    extent[1],
                    extent[2],
                    dims[0],
                    dims[1],
                    dims[2]
                ),
            ));
        }
        let (count, _) = samples::check_volume_size(&self.data_path, extent, self.sample)?;
        let mut values = Vec::with_capacity(count);
        let mut span = Vec::new();
        for z in start[2]..start[2] + extent[2] {
            self.read_plane(z, start, extent, &mut span, &mut values)?;
        }
        let origin =
            [0, 1, 2].map(|a| self.grid.origin[a] + start[a] as f64 * self.grid.spacing[a]);
        let grid = Grid::new(extent, self.grid.spacing, origin)
            .map_err(|e| IoError::from_core(&self.data_path, e))?;
        Volume::from_vec(grid, values).map_err(|e| IoError::from_core(&self.data_path, e))
    }

    /// Every sample, as one volume (checked against the memory budget first).
    pub fn read_all(&self) -> Result<Volume, IoError> {
        self.read_window([0; 3], self.grid.dims)
    }

    /// Appends the window's rows of plane `z` to `values`, reading them as one span of the
    /// file (through `span`) or row by row.
    fn read_plane(
        &self,
        z: usize,
        start: [usize; 3],
        extent: [usize; 3],
        span: &mut Vec<u8>,
        values: &mut Vec<f32>,
    ) -> Result<(), IoError> {
        let size = self.sample.size() as u64;
        let [nx, ny, _] = self.grid.dims.map(|d| d as u64);
        let [ex, ey] = [extent[0] as u64, extent[1] as u64];
        let row_bytes = ex * size;
        let row_at = |y: u64| {
            let index = (z as u64 * ny + y) * nx + start[0] as u64;
            self.offset + index * size
        };
        let first = row_at(start[1] as u64);
        let span_bytes = ((ey - 1) * nx + ex) * size;
        if span_bytes
            <= self
                .small_span_bytes
                .max(SPAN_WASTE_FACTOR * row_bytes * ey)
        {
            span.resize(span_bytes as usize, 0);
            self.read_at(span, first, z)?;
            for j in 0..ey {
                let from = (j * nx * size) as usize;
                let row = &span[from..from + row_bytes as usize];
                values.extend(samples::decode(row, self.sample, self.endian));
            }
        } else {
            span.resize(row_bytes as usize, 0);
            for y in start[1] as u64..start[1] as u64 + ey {
                self.read_at(span, row_at(y), z)?;
                values.extend(samples::decode(span, self.sample, self.endian));
            }
        }
        Ok(())
    }

    /// Fills `buf` from byte `at` of the data file; `z` names the plane in errors.
    fn read_at(&self, buf: &mut [u8], at: u64, z: usize) -> Result<(), IoError> {
        read_exact_at(&self.file, buf, at).map_err(|e| {
            if e.kind() == std::io::ErrorKind::UnexpectedEof {
                IoError::truncated(
                    &self.data_path,
                    format!(
                        "the file ends within plane z = {z} (byte {at}): it is shorter than \
                         when it was opened"
                    ),
                )
            } else {
                IoError::access(&self.data_path, "cannot read", &e)
            }
        })
    }
}

/// Bytes the samples of `dims` take on disk, refusing a count no file can hold.
fn stored_bytes(path: &Path, dims: [usize; 3], sample: SampleType) -> Result<u64, IoError> {
    samples::refuse_zero_dims(path, dims)?;
    dims.iter()
        .try_fold(sample.size() as u64, |acc, &d| acc.checked_mul(d as u64))
        .ok_or_else(|| {
            IoError::new(
                path,
                IoErrorKind::TooLarge,
                format!(
                    "a {}x{}x{} {} volume has more bytes than a file can hold",
                    dims[0],
                    dims[1],
                    dims[2],
                    sample.name()
                ),
            )
        })
}

/// A positioned read that leaves no cursor behind, so windows can be read from several
/// threads at once.
#[cfg(unix)]
pub(crate) fn read_exact_at(file: &File, buf: &mut [u8], at: u64) -> std::io::Result<()> {
    std::os::unix::fs::FileExt::read_exact_at(file, buf, at)
}

/// A positioned read that leaves no cursor behind, so windows can be read from several
/// threads at once.
#[cfg(windows)]
pub(crate) fn read_exact_at(file: &File, mut buf: &mut [u8], mut at: u64) -> std::io::Result<()> {
    use std::os::windows::fs::FileExt;
    while !buf.is_empty() {
        match file.seek_read(buf, at) {
            Ok(0) => return Err(std::io::ErrorKind::UnexpectedEof.into()),
            Ok(n) => {
                buf = &mut buf[n..];
                at += n as u64;
            }
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stored(dims: [usize; 3], sample: SampleType) -> StoredSamples {
        StoredSamples {
            dims,
            sample,
            endian: Endian::Little,
            spacing: [1.0; 3],
            origin: [0.0; 3],
            orientation: Orientation::default(),
        }
    }

    #[test]
    fn a_short_file_is_refused_at_opening_naming_it() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("short.raw");
        std::fs::write(&path, vec![0u8; 100]).unwrap();
        let s = stored([5, 5, 5], SampleType::U8);
        let err = BlockwiseVolume::open(&path, &path, DataStart::At(0), &s).unwrap_err();
        assert_eq!(err.kind, IoErrorKind::Truncated);
        assert!(err.to_string().contains("short.raw"), "{err}");
        assert!(
            err.message.contains("125 bytes") && err.message.contains("100"),
            "{err}"
        );
        let err = BlockwiseVolume::open(&path, &path, DataStart::AtEnd, &s).unwrap_err();
        assert_eq!(err.kind, IoErrorKind::Truncated);
        // 100 bytes hold 4x5x5 samples after a 0-byte start, or the last 100 of a longer file.
        let s = stored([4, 5, 5], SampleType::U8);
        assert_eq!(
            BlockwiseVolume::open(&path, &path, DataStart::AtEnd, &s)
                .unwrap()
                .offset,
            0
        );
        let err = BlockwiseVolume::open(&path, &path, DataStart::At(1), &s).unwrap_err();
        assert!(err.message.contains("from byte 1"), "{err}");
    }

    #[test]
    fn absurd_dimensions_fail_before_anything_is_read() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("tiny.raw");
        std::fs::write(&path, [0u8; 8]).unwrap();
        let s = stored([usize::MAX, usize::MAX, 2], SampleType::I16);
        let err = BlockwiseVolume::open(&path, &path, DataStart::At(0), &s).unwrap_err();
        assert_eq!(err.kind, IoErrorKind::TooLarge);
        let s = stored([1 << 20, 1 << 20, 1 << 10], SampleType::I16);
        let err = BlockwiseVolume::open(&path, &path, DataStart::At(0), &s).unwrap_err();
        assert_eq!(err.kind, IoErrorKind::Truncated);
    }

    #[test]
    fn windows_of_both_read_patterns_agree_with_the_file() {
        // 300 samples wide: a narrow window reads row by row, a wide one in spans.
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("ramp.raw");
        let dims = [300usize, 7, 5];
        let values: Vec<u16> = (0..dims.iter().product::<usize>() as u32)
            .map(|i| (i * 7 % 65521) as u16)
            .collect();
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_be_bytes()).collect();
        std::fs::write(&path, [vec![9u8; 3], bytes].concat()).unwrap();
        let mut s = stored(dims, SampleType::U16);
        s.endian = Endian::Big;
        let mut scan = BlockwiseVolume::open(&path, &path, DataStart::At(3), &s).unwrap();
        scan.small_span_bytes = 0;
        for (start, extent) in [
            ([0, 0, 0], [300, 7, 5]),
            ([299, 6, 4], [1, 1, 1]),
            ([10, 2, 1], [3, 4, 3]),
            ([100, 0, 2], [150, 7, 2]),
        ] {
            let w = scan.read_window(start, extent).unwrap();
            for k in 0..extent[2] {
                for j in 0..extent[1] {
                    for i in 0..extent[0] {
                        let (x, y, z) = (start[0] + i, start[1] + j, start[2] + k);
                        let want = values[(z * dims[1] + y) * dims[0] + x] as f32;
                        assert_eq!(w.get(i, j, k), want, "{start:?} {extent:?}");
                    }
                }
            }
            assert_eq!(w.grid.origin, start.map(|s| s as f64));
        }
        let err = scan.read_window([298, 0, 0], [3, 1, 1]).unwrap_err();
        assert!(err.message.contains("not inside"), "{err}");
    }
}
