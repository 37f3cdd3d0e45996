//! NRRD volumes: `.nrrd` (header and data in one file) and `.nhdr` (header, with the data in a
//! separate file it names). Read and written by hand: no maintained crate exists, and the part
//! of the format scans use is a short text header.
//!
//! Reading understands the fields `type` (every C spelling of 8-, 16-, 32- and 64-bit integers,
//! `float`, `double`), `dimension` (1 to 3), `sizes`, `endian`, `encoding` (`raw`, `gzip`/`gz`,
//! `ascii`/`text`/`txt`), `space directions` (spacing = length of each vector), `spacings`,
//! `space origin`, `space units` (converted to millimetres), `data file`/`datafile` (one file,
//! relative to the header), `line skip` and `byte skip` (including `-1` for raw data at the end
//! of the file). Comments and `key:=value` pairs are ignored. Not supported: `bzip2` and `hex`
//! encodings, lists of data files, non-spatial axes (colour
//! channels, time). Geometry is the full index-to-world transform (`voxlod_core::world`): the
//! `space directions` vectors give spacing (their lengths) and direction cosines, `space origin`
//! the origin, and `space` the frame (`left-posterior-superior`/`LPS` and
//! `right-anterior-superior`/`RAS` as they are; `left-anterior-superior`/`LAS` turned into RAS;
//! anything else, or `space dimension` alone, an unknown frame). `measurement frame` is ignored:
//! it orients tensor or vector samples, and voxlod reads scalars only.
//!
//! Writing produces `NRRD0004`, `type: float`, little-endian, `space` (or `space dimension: 3`
//! when the frame is unknown), `space directions` (direction times spacing) and `space origin`; encoding `raw`, or `gzip` when
//! [`VolumeWriteOptions::compress`](crate::VolumeWriteOptions) asks. A `.nhdr` gets its data in
//! `<name>.raw` (`<name>.raw.gz` compressed) beside it, or another free name when that one is
//! taken (see [`crate::OutputSet`]); the header records the name, and both files appear together.
//!
//! The samples are decoded straight into `f32` for a volume ([`read`]) or into exact `u32` labels
//! for a label map ([`read_labels`], `decode_target.rs`), raw data block by block on all threads
//! (`block_read.rs`), gzip data block by block as it is inflated (`stream_read.rs`).
//!
//! Cost: O(header) to parse the header, then one read of the N samples in O(N) time; memory at
//! the peak is the decoded samples (4N bytes) plus a block of stored bytes per thread, checked
//! against the budget first (`samples::check_decoded_size`). ASCII data is parsed number by
//! number, O(file size), and its text is held whole.

use std::fs::File;
use std::io::{BufRead, BufReader, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use flate2::write::GzEncoder;
use voxlod_core::glam::{DMat3, DVec3};
use voxlod_core::{Frame, Grid, LabelVolume, Orientation, Volume, WorldTransform};

use crate::atomic::{stage, TempFile};
use crate::block_read;
use crate::blockwise_volume::{BlockwiseVolume, DataStart, StoredSamples};
use crate::decode_target::{AsLabels, AsSamples, DecodeTarget};
use crate::samples::{self, millimetres_per, Decoded, SampleType};
use crate::stream_read::read_stream;
use crate::{Endian, IoError, IoErrorKind};

/// The longest header we accept: real ones are a few hundred bytes.
const MAX_HEADER_BYTES: u64 = 1 << 20;

#[derive(Clone, Copy, Debug, PartialEq)]
enum Encoding {
    Raw,
    Gzip,
    Ascii,
}

/// The fields of a NRRD header that matter to us.
#[derive(Debug)]
struct Header {
    sample: SampleType,
    dims: [usize; 3],
    endian: Endian,
    encoding: Encoding,
    spacing: [f64; 3],
    origin: [f64; 3],
    orientation: Orientation,
    data_file: Option<PathBuf>,
    line_skip: usize,
    byte_skip: i64,
}

fn sample_type(name: &str) -> Option<SampleType> {
    Some(match name {
        "signed char" | "int8" | "int8_t" => SampleType::I8,
        "uchar" | "unsigned char" | "uint8" | "uint8_t" => SampleType::U8,
        "short" | "short int" | "signed short" | "signed short int" | "int16" | "int16_t" => {
            SampleType::I16
        }
        "ushort" | "unsigned short" | "unsigned short int" | "uint16" | "uint16_t" => {
            SampleType::U16
        }
        "int" | "signed int" | "int32" | "int32_t" => SampleType::I32,
        "uint" | "unsigned int" | "uint32" | "uint32_t" => SampleType::U32,
        "longlong"
        | "long long"
        | "long long int"
        | "signed long long"
        | "signed long long int"
        | "int64"
        | "int64_t" => SampleType::I64,
        "ulonglong" | "unsigned long long" | "unsigned long long int" | "uint64" | "uint64_t" => {
            SampleType::U64
        }
        "float" => SampleType::F32,
        "double" => SampleType::F64,
        _ => return None,
    })
}

/// Parses `(x,y,z)` vectors; `none` stands for a non-spatial axis.
fn parse_vectors(text: &str) -> Option<Vec<Option<Vec<f64>>>> {
    let mut out = Vec::new();
    let mut rest = text.trim();
    while !rest.is_empty() {
        if let Some(after) = rest.strip_prefix("none") {
            out.push(None);
            rest = after.trim_start();
            continue;
        }
        let inner = rest.strip_prefix('(')?;
        let close = inner.find(')')?;
        let vector = inner[..close]
            .split(',')
            .map(|c| c.trim().parse::<f64>().ok())
            .collect::<Option<Vec<f64>>>()?;
        out.push(Some(vector));
        rest = inner[close + 1..].trim_start();
    }
    Some(out)
}

/// Reads header lines up to the blank line (or the end, for a detached header). Returns the
/// fields and the reader positioned at the first data byte.
fn read_header(path: &Path, reader: &mut impl BufRead) -> Result<Header, IoError> {
    let mut limited = reader.take(MAX_HEADER_BYTES);
    let mut line = Vec::new();
    let mut first = true;
    let mut fields: Vec<(String, String)> = Vec::new();
    loop {
        line.clear();
        let n = limited
            .read_until(b'\n', &mut line)
            .map_err(|e| IoError::access(path, "cannot read", &e))?;
        if n == 0 {
            if limited.limit() == 0 {
                return Err(IoError::malformed(
                    path,
                    format!("no end of the header within {MAX_HEADER_BYTES} bytes"),
                ));
            }
            break;
        }
        let text = String::from_utf8_lossy(&line);
        let text = text.trim_end_matches(['\n', '\r']);
        if first {
            if !text.starts_with("NRRD000") {
                return Err(IoError::malformed(
                    path,
                    "not a NRRD file: it does not start with the NRRD000x magic",
                ));
            }
            first = false;
            continue;
        }
        if text.is_empty() {
            break;
        }
        if text.starts_with('#') || text.contains(":=") {
            continue;
        }
        let Some((key, value)) = text.split_once(':') else {
            return Err(IoError::malformed(
                path,
                format!("header line '{text}' is not 'field: value'"),
            ));
        };
        fields.push((key.trim().to_ascii_lowercase(), value.trim().to_string()));
    }
    if first {
        return Err(IoError::new(path, IoErrorKind::Empty, "the file is empty"));
    }
    interpret(path, &fields)
}

/// The header's fields by lower-case name, with the errors that name the file.
struct Fields<'a> {
    path: &'a Path,
    fields: &'a [(String, String)],
}

impl<'a> Fields<'a> {
    /// The value of the first field called by one of `names`, if any.
    fn get(&self, names: &[&str]) -> Option<&'a str> {
        self.fields
            .iter()
            .find(|(k, _)| names.contains(&k.as_str()))
            .map(|(_, v)| v.as_str())
    }

    /// As [`Fields::get`], an error naming `names[0]` when the field is absent.
    fn require(&self, names: &[&str]) -> Result<&'a str, IoError> {
        self.get(names).ok_or_else(|| {
            IoError::malformed(self.path, format!("the header has no '{}' field", names[0]))
        })
    }

    fn bad(&self, field: &str, value: &str) -> IoError {
        IoError::malformed(self.path, format!("cannot understand '{field}: {value}'"))
    }
}

/// The header's meaning, from its fields, read in the order below.
fn interpret(path: &Path, fields: &[(String, String)]) -> Result<Header, IoError> {
    let fields = Fields { path, fields };
    let (sample, dimension, dims) = interpret_layout(&fields)?;
    let (endian, encoding) = interpret_storage(&fields)?;
    let (spacing, origin, orientation) = interpret_geometry(&fields, dimension)?;
    let (data_file, line_skip, byte_skip) = interpret_data_location(&fields)?;
    Ok(Header {
        sample,
        dims,
        endian,
        encoding,
        spacing,
        origin,
        orientation,
        data_file,
        line_skip,
        byte_skip,
    })
}

/// `type`, `dimension` and `sizes`: the sample type, the number of axes, the dimensions (1
/// along the missing axes).
fn interpret_layout(fields: &Fields) -> Result<(SampleType, usize, [usize; 3]), IoError> {
    let type_name = fields.require(&["type"])?;
    let sample = sample_type(type_name).ok_or_else(|| {
        IoError::unsupported(
            fields.path,
            format!("sample type '{type_name}' is not supported"),
        )
    })?;
    let dimension_text = fields.require(&["dimension"])?;
    let dimension: usize = dimension_text
        .parse()
        .map_err(|_| fields.bad("dimension", dimension_text))?;
    if !(1..=3).contains(&dimension) {
        return Err(refuse_dimension(fields, dimension));
    }
    let sizes_text = fields.require(&["sizes"])?;
    let sizes: Vec<usize> = samples::parse_list(sizes_text, dimension)
        .ok_or_else(|| fields.bad("sizes", sizes_text))?;
    let mut dims = [1usize; 3];
    dims[..dimension].copy_from_slice(&sizes);
    Ok((sample, dimension, dims))
}

/// The refusal of a `dimension` beyond 3, naming the first axis after the third that holds more
/// than one value (a 4-D map: a time series, or channels).
fn refuse_dimension(fields: &Fields, dimension: usize) -> IoError {
    let sizes = fields.get(&["sizes"]).unwrap_or("");
    let longer = sizes
        .split_whitespace()
        .enumerate()
        .skip(3)
        .find(|(_, n)| *n != "1");
    let axis = match longer {
        Some((axis, n)) => format!(": axis {} holds {n} values", axis + 1),
        None => String::new(),
    };
    IoError::unsupported(
        fields.path,
        format!(
            "dimension {dimension} (sizes {sizes}){axis}; only 1- to 3-dimensional scalar volumes are read"
        ),
    )
}

/// `endian` (little when absent) and `encoding`.
fn interpret_storage(fields: &Fields) -> Result<(Endian, Encoding), IoError> {
    let endian = match fields.get(&["endian"]) {
        Some("little") | None => Endian::Little,
        Some("big") => Endian::Big,
        Some(other) => return Err(fields.bad("endian", other)),
    };
    let encoding = match fields.require(&["encoding"])? {
        "raw" => Encoding::Raw,
        "gzip" | "gz" => Encoding::Gzip,
        "ascii" | "text" | "txt" => Encoding::Ascii,
        other => {
            return Err(IoError::unsupported(
                fields.path,
                format!("encoding '{other}' is not supported (raw, gzip and ascii are)"),
            ))
        }
    };
    Ok((endian, encoding))
}

/// The frame of a `space` field, and whether x must be negated to reach it (LAS to RAS).
fn space_frame(space: Option<&str>) -> (Frame, bool) {
    match space.map(|s| s.trim().to_ascii_lowercase()).as_deref() {
        Some("left-posterior-superior" | "lps") => (Frame::Lps, false),
        Some("right-anterior-superior" | "ras") => (Frame::Ras, false),
        Some("left-anterior-superior" | "las") => (Frame::Ras, true),
        _ => (Frame::Unknown, false),
    }
}

/// The direction vectors of `space directions` in millimetres (one per axis; `None` for 'none').
fn direction_vectors(
    fields: &Fields,
    dimension: usize,
    unit_scale: [f64; 3],
) -> Result<Option<Vec<DVec3>>, IoError> {
    let Some(text) = fields.get(&["space directions"]) else {
        return Ok(None);
    };
    let vectors = parse_vectors(text).ok_or_else(|| fields.bad("space directions", text))?;
    if vectors.len() != dimension {
        return Err(fields.bad("space directions", text));
    }
    let mut out = Vec::with_capacity(dimension);
    for (axis, v) in vectors.iter().enumerate() {
        let Some(v) = v else {
            return Err(IoError::unsupported(
                fields.path,
                format!(
                    "axis {axis} is not spatial ('none' direction): only scalar volumes are read"
                ),
            ));
        };
        let c = |i: usize| v.get(i).copied().unwrap_or(0.0) * unit_scale[i];
        out.push(DVec3::new(c(0), c(1), c(2)));
    }
    Ok(Some(out))
}

/// The index steps of a 1- or 2-D image completed to three (the normal of the plane, or the
/// remaining axes), of unit length.
fn complete_steps(mut steps: Vec<DVec3>) -> [DVec3; 3] {
    if steps.len() == 2 {
        let n = steps[0].cross(steps[1]).normalize_or_zero();
        steps.push(if n == DVec3::ZERO { DVec3::Z } else { n });
    }
    if steps.len() == 1 {
        steps.extend([DVec3::Y, DVec3::Z]);
    }
    [steps[0], steps[1], steps[2]]
}

/// Spacing, origin and orientation in millimetres, from `space`, `space units`, `space
/// directions` (or `spacings`) and `space origin`.
fn interpret_geometry(
    fields: &Fields,
    dimension: usize,
) -> Result<([f64; 3], [f64; 3], Orientation), IoError> {
    // Units to millimetres, when declared and known.
    let mut unit_scale = [1.0f64; 3];
    if let Some(units) = fields.get(&["space units"]) {
        for (axis, unit) in units.split_whitespace().take(3).enumerate() {
            unit_scale[axis] = millimetres_per(unit).unwrap_or(1.0);
        }
    }
    let (frame, flip_x) = space_frame(fields.get(&["space"]));
    let flip = DMat3::from_diagonal(DVec3::new(if flip_x { -1.0 } else { 1.0 }, 1.0, 1.0));
    let mut origin = DVec3::ZERO;
    if let Some(text) = fields.get(&["space origin"]) {
        let vectors = parse_vectors(text).ok_or_else(|| fields.bad("space origin", text))?;
        match vectors.as_slice() {
            [Some(v)] if (1..=3).contains(&v.len()) => {
                for (axis, c) in v.iter().enumerate() {
                    origin[axis] = c * unit_scale[axis];
                }
            }
            _ => return Err(fields.bad("space origin", text)),
        }
    }
    let directions = direction_vectors(fields, dimension, unit_scale)?;
    let source = if directions.is_some() {
        "'space directions'"
    } else {
        "'spacings'"
    };
    let steps = match directions {
        Some(steps) => complete_steps(steps),
        None => {
            let mut spacing = [1.0f64; 3];
            if let Some(text) = fields.get(&["spacings"]) {
                let values: Vec<f64> = samples::parse_list(text, dimension)
                    .ok_or_else(|| fields.bad("spacings", text))?;
                spacing[..dimension].copy_from_slice(&values);
            }
            let [sx, sy, sz] = spacing;
            [DVec3::X * sx, DVec3::Y * sy, DVec3::Z * sz]
        }
    };
    let world = WorldTransform::from_columns(flip * origin, steps.map(|s| flip * s), frame)
        .map_err(|e| IoError::malformed(fields.path, format!("{source}: {e}")))?;
    let orientation = Orientation {
        direction: world.direction,
        frame,
    };
    Ok((
        world.spacing.to_array(),
        world.origin.to_array(),
        orientation,
    ))
}

/// `data file`, `line skip` and `byte skip`: where the samples start.
fn interpret_data_location(fields: &Fields) -> Result<(Option<PathBuf>, usize, i64), IoError> {
    let data_file = match fields.get(&["data file", "datafile"]) {
        None => None,
        Some(name) if name.starts_with("LIST") || name.split_whitespace().count() > 1 => {
            return Err(IoError::unsupported(
                fields.path,
                format!("'data file: {name}': only a single data file is supported"),
            ))
        }
        Some(name) => Some(samples::data_file_path(fields.path, "data file", name)?),
    };
    let line_skip = match fields.get(&["line skip", "lineskip"]) {
        None => 0,
        Some(t) => t.parse().map_err(|_| fields.bad("line skip", t))?,
    };
    let byte_skip = match fields.get(&["byte skip", "byteskip"]) {
        None => 0,
        Some(t) => t
            .parse::<i64>()
            .ok()
            .filter(|&b| b >= -1)
            .ok_or_else(|| fields.bad("byte skip", t))?,
    };
    Ok((data_file, line_skip, byte_skip))
}

/// Reads a NRRD volume (`f32` samples).
pub(crate) fn read(path: &Path) -> Result<Volume, IoError> {
    read_as(path, &AsSamples, "volume")?.into_volume(path)
}

/// Reads a NRRD label map (exact `u32` labels, `decode_target.rs`).
pub(crate) fn read_labels(path: &Path) -> Result<LabelVolume, IoError> {
    read_as(path, &AsLabels::default(), "label map")?.into_labels(path)
}

/// The samples decoded by `target` (a `noun` for the budget's message) with their geometry.
fn read_as<T: DecodeTarget>(
    path: &Path,
    target: &T,
    noun: &str,
) -> Result<Decoded<Vec<T::Item>>, IoError> {
    let file = File::open(path).map_err(|e| IoError::access(path, "cannot open", &e))?;
    let mut reader = BufReader::with_capacity(1 << 20, file);
    let header = read_header(path, &mut reader)?;
    let (_, data_bytes) = samples::check_decoded_size(path, header.dims, header.sample, noun)?;

    // Where the data lives: after the header, or in the file it names (errors then name that
    // file, since it is the one that is short or missing).
    let (data_path, mut data): (PathBuf, BufReader<File>) = match &header.data_file {
        None => (path.to_path_buf(), reader),
        Some(other) => {
            let f = samples::open_data_file(path, other)?;
            (other.clone(), BufReader::with_capacity(1 << 20, f))
        }
    };
    let data_path = data_path.as_path();
    skip_lines(data_path, &mut data, header.line_skip)?;

    let stored = (header.sample, header.endian);
    let dims = header.dims;
    let values = match header.encoding {
        Encoding::Raw => {
            if header.byte_skip == -1 {
                // The data is the last `data_bytes` bytes of the file.
                let len = data
                    .get_ref()
                    .metadata()
                    .map_err(|e| IoError::access(data_path, "cannot read", &e))?
                    .len();
                let start = len.checked_sub(data_bytes as u64).ok_or_else(|| {
                    IoError::truncated(
                        data_path,
                        format!("the data is truncated: expected {data_bytes} bytes, the file has {len}"),
                    )
                })?;
                data.seek(SeekFrom::Start(start))
                    .map_err(|e| IoError::access(data_path, "cannot read", &e))?;
            } else {
                skip(data_path, &mut data, header.byte_skip as u64)?;
            }
            let offset = (data.stream_position())
                .map_err(|e| IoError::access(data_path, "cannot read", &e))?;
            let file = data.get_ref();
            block_read::read_decoded(data_path, file, offset, dims, stored, target, "raw data")?
        }
        Encoding::Gzip => {
            if header.byte_skip == -1 {
                return Err(IoError::malformed(
                    path,
                    "'byte skip: -1' is only allowed with raw encoding",
                ));
            }
            let mut inflated = flate2::bufread::MultiGzDecoder::new(data);
            // For compressed data, byte skip counts decompressed bytes.
            skip(data_path, &mut inflated, header.byte_skip as u64)?;
            read_stream(data_path, inflated, dims, stored, target, "gzip data")?
        }
        Encoding::Ascii => read_ascii(data_path, data, dims, target)?,
    };
    Ok(Decoded {
        dims,
        spacing: header.spacing,
        origin: header.origin,
        orientation: header.orientation,
        values,
    })
}

/// The samples of a NRRD with `encoding: raw`, attached or in its data file, for reading
/// window by window ([`BlockwiseVolume`]); `None` for gzip and ascii data, which have no random
/// access and are read whole ([`read`]).
pub(crate) fn open_blockwise(path: &Path) -> Result<Option<BlockwiseVolume>, IoError> {
    let file = File::open(path).map_err(|e| IoError::access(path, "cannot open", &e))?;
    let mut reader = BufReader::new(file);
    let header = read_header(path, &mut reader)?;
    if header.encoding != Encoding::Raw {
        return Ok(None);
    }
    let (data_path, mut data) = match &header.data_file {
        None => (path.to_path_buf(), reader),
        Some(other) => (
            other.clone(),
            BufReader::new(samples::open_data_file(path, other)?),
        ),
    };
    skip_lines(&data_path, &mut data, header.line_skip)?;
    let start = if header.byte_skip == -1 {
        DataStart::AtEnd
    } else {
        let at = data
            .stream_position()
            .map_err(|e| IoError::access(&data_path, "cannot read", &e))?;
        DataStart::At(at.saturating_add(header.byte_skip as u64))
    };
    let stored = StoredSamples {
        dims: header.dims,
        sample: header.sample,
        endian: header.endian,
        spacing: header.spacing,
        origin: header.origin,
        orientation: header.orientation,
    };
    BlockwiseVolume::open(path, &data_path, start, &stored).map(Some)
}

/// Skips the `lines` lines of `line skip` at the start of the data.
fn skip_lines(path: &Path, data: &mut impl BufRead, lines: usize) -> Result<(), IoError> {
    for line in 0..lines {
        let mut skipped = Vec::new();
        let n = data
            .read_until(b'\n', &mut skipped)
            .map_err(|e| IoError::access(path, "cannot read", &e))?;
        if n == 0 {
            return Err(IoError::truncated(
                path,
                format!("the file ends after {line} of the {lines} lines to skip"),
            ));
        }
    }
    Ok(())
}

fn skip(path: &Path, reader: &mut impl Read, bytes: u64) -> Result<(), IoError> {
    let skipped = std::io::copy(&mut reader.take(bytes), &mut std::io::sink())
        .map_err(|e| IoError::access(path, "cannot read", &e))?;
    if skipped < bytes {
        return Err(IoError::truncated(
            path,
            format!("the file ends within the {bytes} bytes to skip"),
        ));
    }
    Ok(())
}

/// Whitespace-separated numbers, as many as the grid of `dims` has samples, decoded by
/// `target` as `f64` values.
fn read_ascii<T: DecodeTarget>(
    path: &Path,
    reader: impl Read,
    dims: [usize; 3],
    target: &T,
) -> Result<Vec<T::Item>, IoError> {
    let count = dims.iter().product::<usize>();
    let mut text = String::new();
    reader
        .take((count as u64).saturating_mul(64))
        .read_to_string(&mut text)
        .map_err(|e| IoError::malformed(path, format!("the ascii data is not text: {e}")))?;
    let mut values = vec![T::Item::default(); count];
    let mut tokens = text.split_whitespace();
    let mut bytes = Vec::new();
    for (b, out) in values.chunks_mut(samples::BLOCK).enumerate() {
        bytes.clear();
        for token in tokens.by_ref().take(out.len()) {
            let v: f64 = token.parse().map_err(|_| {
                IoError::malformed(path, format!("'{token}' in the ascii data is not a number"))
            })?;
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        let found = b * samples::BLOCK + bytes.len() / 8;
        if found < (b * samples::BLOCK + out.len()) {
            return Err(IoError::truncated(
                path,
                format!("the ascii data is truncated: expected {count} values, found {found}"),
            ));
        }
        let first = b * samples::BLOCK;
        (target.decode(&bytes, SampleType::F64, Endian::Little, out))
            .map_err(|bad| bad.error(path, dims, first))?;
    }
    Ok(values)
}

/// The header text for samples of `type_name` on `g` placed by `orientation`, with their data
/// attached or in `data_file`.
fn header_text(
    (g, orientation): (&Grid, &Orientation),
    type_name: &str,
    compress: bool,
    data_file: Option<&str>,
) -> String {
    let [nx, ny, nz] = g.dims;
    let world = WorldTransform::of(g, orientation);
    let step = |a: usize| {
        let v = world.direction.col(a) * world.spacing[a];
        format!("({},{},{})", v.x, v.y, v.z)
    };
    let (x, y, z) = (step(0), step(1), step(2));
    let [ox, oy, oz] = g.origin;
    let space = match orientation.frame {
        Frame::Lps => "space: left-posterior-superior",
        Frame::Ras => "space: right-anterior-superior",
        Frame::Unknown => "space dimension: 3",
    };
    let mut text = format!(
        "NRRD0004\n\
         # written by voxlod\n\
         type: {type_name}\n\
         dimension: 3\n\
         {space}\n\
         sizes: {nx} {ny} {nz}\n\
         space directions: {x} {y} {z}\n\
         kinds: domain domain domain\n\
         space origin: ({ox},{oy},{oz})\n\
         endian: little\n\
         encoding: {}\n",
        if compress { "gzip" } else { "raw" }
    );
    match data_file {
        Some(name) => text.push_str(&format!("data file: {name}\n")),
        None => text.push('\n'),
    }
    text
}

fn write_data(w: &mut impl Write, volume: &Volume, compress: bool) -> std::io::Result<()> {
    if compress {
        let mut gz = GzEncoder::new(w, flate2::Compression::new(6));
        crate::raw::write_samples_f32_le(&mut gz, volume.as_slice())?;
        gz.finish()?;
        Ok(())
    } else {
        crate::raw::write_samples_f32_le(w, volume.as_slice())
    }
}

/// Writes a `.nrrd` with attached data.
pub(crate) fn write(path: &Path, volume: &Volume, compress: bool) -> Result<TempFile, IoError> {
    let header = header_text((&volume.grid, &volume.orientation), "float", compress, None);
    stage(path, |w| {
        w.write_all(header.as_bytes())?;
        write_data(w, volume, compress)
    })
}

/// Writes a label map as a `.nrrd` of raw `uint32` samples (little-endian), with the geometry
/// of [`write`].
pub(crate) fn write_labels(w: &mut impl Write, labels: &LabelVolume) -> std::io::Result<()> {
    let place = (&labels.grid, &labels.orientation);
    w.write_all(header_text(place, "uint32", false, None).as_bytes())?;
    crate::raw::write_labels_le(w, &labels.values)
}

/// The data file that the NRRD header `path` names, if it can be read and names one.
pub(crate) fn data_file_of(path: &Path) -> Option<PathBuf> {
    let file = File::open(path).ok()?;
    read_header(path, &mut BufReader::new(file)).ok()?.data_file
}

/// Writes a `.nhdr` and its data file `data_path` (in the same folder, chosen by
/// [`crate::OutputSet`]): the data file's temporary first, then the header's.
pub(crate) fn write_detached(
    path: &Path,
    data_path: &Path,
    volume: &Volume,
    compress: bool,
) -> Result<[TempFile; 2], IoError> {
    let data_name = crate::detached::name_in_header(path, data_path)?;
    let place = (&volume.grid, &volume.orientation);
    let header = header_text(place, "float", compress, Some(&data_name));
    // The header first, so that an unwritable directory is reported for the file asked for.
    let mut header_file = TempFile::create(path)?;
    let mut data_file = TempFile::create(data_path)?;
    data_file.write_with(|w| write_data(w, volume, compress))?;
    header_file.write_with(|w| w.write_all(header.as_bytes()))?;
    Ok([data_file, header_file])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header_of(text: &str) -> Result<Header, IoError> {
        read_header(Path::new("dir/t.nrrd"), &mut text.as_bytes())
    }

    #[test]
    fn understands_the_usual_fields() {
        let h = header_of(
            "NRRD0004\n# comment\ntype: unsigned short\ndimension: 3\nsizes: 4 5 6\n\
             space: left-posterior-superior\n\
             space directions: (0.5,0,0) (0,0,-0.5) (0,2,0)\nspace origin: (1, -2.5, 3)\n\
             endian: big\nencoding: gz\nkey:=value\ndata file: t.raw.gz\n\n",
        )
        .unwrap();
        assert_eq!(h.sample, SampleType::U16);
        assert_eq!(h.dims, [4, 5, 6]);
        assert_eq!(h.spacing, [0.5, 0.5, 2.0]);
        assert_eq!(h.origin, [1.0, -2.5, 3.0]);
        assert_eq!(h.endian, Endian::Big);
        assert_eq!(h.encoding, Encoding::Gzip);
        assert_eq!(h.data_file.as_deref(), Some(Path::new("dir/t.raw.gz")));

        let h = header_of(
            "NRRD0001\ntype: float\ndimension: 2\nsizes: 7 8\nspacings: 0.25 4\nencoding: raw\n\n",
        )
        .unwrap();
        assert_eq!(h.dims, [7, 8, 1]);
        assert_eq!(h.spacing, [0.25, 4.0, 1.0]);

        let h = header_of("NRRD0005\ntype: float\ndimension: 3\nsizes: 2 2 2\nspace units: \"m\" \"m\" \"m\"\nspace directions: (0.001,0,0) (0,0.001,0) (0,0,0.002)\nencoding: raw\n\n").unwrap();
        assert!((h.spacing[2] - 2.0).abs() < 1e-12);
    }

    #[test]
    fn refuses_what_it_cannot_read() {
        for (text, kind, needle) in [
            ("P6\n", IoErrorKind::Malformed, "NRRD000x"),
            ("NRRD0004\ndimension: 3\nsizes: 1 1 1\nencoding: raw\n\n", IoErrorKind::Malformed, "'type'"),
            ("NRRD0004\ntype: block\ndimension: 1\nsizes: 1\nencoding: raw\n\n", IoErrorKind::Unsupported, "block"),
            ("NRRD0004\ntype: int\ndimension: 4\nsizes: 2 2 2 5\nencoding: raw\n\n", IoErrorKind::Unsupported, "axis 4 holds 5 values"),
            ("NRRD0004\ntype: float\ndimension: 4\nsizes: 3 1 1 1\nencoding: raw\n\n", IoErrorKind::Unsupported, "dimension 4"),
            ("NRRD0004\ntype: float\ndimension: 3\nsizes: 1 1\nencoding: raw\n\n", IoErrorKind::Malformed, "sizes"),
            ("NRRD0004\ntype: float\ndimension: 3\nsizes: 1 1 1\nencoding: bzip2\n\n", IoErrorKind::Unsupported, "bzip2"),
            ("NRRD0004\ntype: float\ndimension: 3\nsizes: 1 1 1\nencoding: raw\nspace directions: (1,0,0) none (0,0,1)\n\n", IoErrorKind::Unsupported, "not spatial"),
            ("NRRD0004\nthis is not a field\n", IoErrorKind::Malformed, "not 'field: value'"),
        ] {
            let err = header_of(text).err().unwrap_or_else(|| panic!("accepted {text:?}"));
            assert_eq!(err.kind, kind, "{err}");
            assert!(err.message.contains(needle), "{needle}: {err}");
        }
    }
}
