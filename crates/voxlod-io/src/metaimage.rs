//! MetaImage (ITK's format): `.mha` (header and data in one file) and `.mhd` (header naming a
//! data file). Read and written by hand: a text header of `Key = Value` lines ending with
//! `ElementDataFile`, then the samples.
//!
//! Reading understands `NDims` (1 to 3), `DimSize`, `ElementType` (`MET_UCHAR`, `MET_CHAR`,
//! `MET_USHORT`, `MET_SHORT`, `MET_UINT`, `MET_INT`, `MET_LONG_LONG`, `MET_ULONG_LONG`,
//! `MET_FLOAT`, `MET_DOUBLE`),
//! `ElementNumberOfChannels` (must be 1), `BinaryDataByteOrderMSB` / `ElementByteOrderMSB`,
//! `CompressedData` (zlib, or gzip), `ElementSpacing` (else `ElementSize`), `Offset` (else
//! `Origin` or `Position`), `HeaderSize` (bytes to skip in a data file; `-1`: the data is at its
//! end) and `ElementDataFile` (`LOCAL` or one file name, relative to the header). Keys are
//! matched without regard to case. Not supported: ASCII data (`BinaryData = False`), lists and
//! patterns of data files, several channels. `TransformMatrix` (else `Rotation` or
//! `Orientation`) gives the direction cosines, its first `NDims` numbers the world direction of
//! the first index axis, as ITK reads them; the world is LPS, ITK's physical space, whenever the
//! header has a `TransformMatrix` or an `AnatomicalOrientation` (which ITK does not use to
//! place the image, and neither do we), else the frame is unknown.
//!
//! Writing produces `MET_FLOAT`, little-endian, with `TransformMatrix`, `Offset` and
//! `ElementSpacing` in LPS (a RAS volume is converted; with `AnatomicalOrientation` when the
//! frame is known), data zlib
//! compressed when [`VolumeWriteOptions::compress`](crate::VolumeWriteOptions) asks; a `.mhd`
//! gets its data in `<name>.raw` (or `<name>.zraw`) beside it, or another free name when that one
//! is taken (see [`crate::OutputSet`]); the header records the name, and both files appear
//! together.
//!
//! The samples are decoded as they are read (and inflated), block by block (`stream_read.rs`):
//! into `f32` for a volume ([`read`]), into exact `u32` labels for a label map
//! ([`read_labels`], `decode_target.rs`).
//!
//! Cost: O(header) to parse the header, then one read of the N samples in O(N) time; memory at
//! the peak is the decoded samples (4N bytes) plus one block of stored bytes, checked against
//! the budget first (`samples::check_decoded_size`).

use std::fs::File;
use std::io::{BufRead, BufReader, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use flate2::write::ZlibEncoder;
use voxlod_core::glam::{DMat3, DVec3};
use voxlod_core::{Frame, LabelVolume, Orientation, Volume, WorldTransform};

use crate::atomic::{stage, TempFile};
use crate::blockwise_volume::{BlockwiseVolume, DataStart, StoredSamples};
use crate::decode_target::{AsLabels, AsSamples, DecodeTarget};
use crate::samples::{self, Decoded, SampleType};
use crate::stream_read::read_stream;
use crate::{Endian, IoError};

const MAX_HEADER_BYTES: u64 = 1 << 20;

#[derive(Debug)]
struct Header {
    sample: SampleType,
    dims: [usize; 3],
    endian: Endian,
    compressed: bool,
    spacing: [f64; 3],
    origin: [f64; 3],
    orientation: Orientation,
    /// `None` for `LOCAL`.
    data_file: Option<PathBuf>,
    header_size: i64,
}

fn element_type(name: &str) -> Option<SampleType> {
    Some(match name {
        "MET_UCHAR" => SampleType::U8,
        "MET_CHAR" => SampleType::I8,
        "MET_USHORT" => SampleType::U16,
        "MET_SHORT" => SampleType::I16,
        "MET_UINT" => SampleType::U32,
        "MET_INT" => SampleType::I32,
        "MET_LONG_LONG" => SampleType::I64,
        "MET_ULONG_LONG" => SampleType::U64,
        "MET_FLOAT" => SampleType::F32,
        "MET_DOUBLE" => SampleType::F64,
        _ => return None,
    })
}

fn read_header(path: &Path, reader: &mut impl BufRead) -> Result<Header, IoError> {
    let mut limited = reader.take(MAX_HEADER_BYTES);
    let mut fields: Vec<(String, String)> = Vec::new();
    let mut line = Vec::new();
    loop {
        line.clear();
        let n = limited
            .read_until(b'\n', &mut line)
            .map_err(|e| IoError::access(path, "cannot read", &e))?;
        if n == 0 {
            return Err(if fields.is_empty() {
                IoError::malformed(path, "not a MetaImage file: no 'Key = Value' header")
            } else {
                IoError::malformed(path, "the header has no 'ElementDataFile' line")
            });
        }
        let text = String::from_utf8_lossy(&line);
        let text = text.trim();
        if text.is_empty() {
            continue;
        }
        let Some((key, value)) = text.split_once('=') else {
            return Err(IoError::malformed(
                path,
                format!("header line '{text}' is not 'Key = Value'"),
            ));
        };
        let key = key.trim().to_ascii_lowercase();
        let is_last = key == "elementdatafile";
        fields.push((key, value.trim().to_string()));
        if is_last {
            break;
        }
    }
    interpret(path, &fields)
}

/// The value of a header key (keys are lower-cased when the header is read).
fn field<'a>(fields: &'a [(String, String)], key: &str) -> Option<&'a str> {
    fields
        .iter()
        .find(|(k, _)| k == key)
        .map(|(_, v)| v.as_str())
}

/// Spacing, origin and orientation (LPS when a matrix or `AnatomicalOrientation` is given)
/// from `ElementSpacing`, `Offset` and `TransformMatrix` or their synonyms.
fn interpret_geometry(
    path: &Path,
    fields: &[(String, String)],
    ndims: usize,
) -> Result<([f64; 3], [f64; 3], Orientation), IoError> {
    let get = |key: &str| field(fields, key);
    let bad = |name: &str, value: &str| {
        IoError::malformed(path, format!("cannot understand '{name} = {value}'"))
    };
    let triple = |keys: &[&str], default: f64| -> Result<[f64; 3], IoError> {
        let mut out = [default; 3];
        if let Some((k, text)) = keys.iter().find_map(|k| get(k).map(|v| (*k, v))) {
            let values: Vec<f64> = samples::parse_list(text, ndims).ok_or_else(|| bad(k, text))?;
            out[..ndims].copy_from_slice(&values);
        }
        Ok(out)
    };
    let spacing = triple(&["elementspacing", "elementsize"], 1.0)?;
    let origin = triple(&["offset", "origin", "position"], 0.0)?;
    let matrix = ["transformmatrix", "rotation", "orientation"]
        .iter()
        .find_map(|k| get(k).map(|v| (*k, v)));
    let mut columns = [DVec3::X, DVec3::Y, DVec3::Z];
    if let Some((key, text)) = matrix {
        let m: Vec<f64> = samples::parse_list(text, ndims * ndims).ok_or_else(|| bad(key, text))?;
        for (a, column) in columns.iter_mut().enumerate().take(ndims) {
            for c in 0..ndims {
                column[c] = m[a * ndims + c];
            }
        }
    }
    let frame = if matrix.is_some() || get("anatomicalorientation").is_some() {
        Frame::Lps
    } else {
        Frame::Unknown
    };
    let steps = [0, 1, 2].map(|a| columns[a].normalize_or_zero() * spacing[a]);
    let world = WorldTransform::from_columns(DVec3::from(origin), steps, frame)
        .map_err(|e| IoError::malformed(path, format!("TransformMatrix or ElementSpacing: {e}")))?;
    let orientation = Orientation {
        direction: world.direction,
        frame,
    };
    Ok((spacing, origin, orientation))
}

/// For an image of more than three axes: the first axis after the third that holds more than
/// one value, in the words of a message (", axis 4 holds 5 values"), else nothing.
fn longer_axis(dim_size: &str) -> String {
    let longer = dim_size
        .split_whitespace()
        .enumerate()
        .skip(3)
        .find(|(_, n)| *n != "1");
    longer.map_or(String::new(), |(axis, n)| {
        format!(
            " (DimSize = {dim_size}): axis {} holds {n} values",
            axis + 1
        )
    })
}

fn interpret(path: &Path, fields: &[(String, String)]) -> Result<Header, IoError> {
    let get = |key: &str| field(fields, key);
    let require = |key: &str, name: &str| {
        get(key).ok_or_else(|| IoError::malformed(path, format!("the header has no '{name}'")))
    };
    let bad = |name: &str, value: &str| {
        IoError::malformed(path, format!("cannot understand '{name} = {value}'"))
    };
    let flag = |key: &str| get(key).is_some_and(|v| v.eq_ignore_ascii_case("true") || v == "1");

    let ndims_text = require("ndims", "NDims")?;
    let ndims: usize = ndims_text.parse().map_err(|_| bad("NDims", ndims_text))?;
    if !(1..=3).contains(&ndims) {
        return Err(IoError::unsupported(
            path,
            format!(
                "NDims = {ndims}{}: only 1- to 3-dimensional images are read",
                longer_axis(get("dimsize").unwrap_or(""))
            ),
        ));
    }
    let dim_text = require("dimsize", "DimSize")?;
    let sizes: Vec<usize> =
        samples::parse_list(dim_text, ndims).ok_or_else(|| bad("DimSize", dim_text))?;
    let mut dims = [1usize; 3];
    dims[..ndims].copy_from_slice(&sizes);

    let type_name = require("elementtype", "ElementType")?;
    let sample = element_type(&type_name.to_ascii_uppercase()).ok_or_else(|| {
        IoError::unsupported(path, format!("ElementType '{type_name}' is not supported"))
    })?;
    if let Some(channels) = get("elementnumberofchannels") {
        if channels != "1" {
            return Err(IoError::unsupported(
                path,
                format!("{channels} channels per sample: only scalar images are read"),
            ));
        }
    }
    if get("binarydata").is_some_and(|v| v.eq_ignore_ascii_case("false")) {
        return Err(IoError::unsupported(
            path,
            "ASCII MetaImage data is not supported",
        ));
    }
    let endian = if flag("binarydatabyteordermsb") || flag("elementbyteordermsb") {
        Endian::Big
    } else {
        Endian::Little
    };
    let compressed = flag("compresseddata");

    let (spacing, origin, orientation) = interpret_geometry(path, fields, ndims)?;

    let data_name = require("elementdatafile", "ElementDataFile")?;
    let data_file = if data_name.eq_ignore_ascii_case("LOCAL") {
        None
    } else if data_name.starts_with("LIST") || data_name.split_whitespace().count() > 1 {
        return Err(IoError::unsupported(
            path,
            format!("'ElementDataFile = {data_name}': only LOCAL or a single file is supported"),
        ));
    } else {
        Some(samples::data_file_path(path, "ElementDataFile", data_name)?)
    };
    let header_size = match get("headersize") {
        None => 0,
        Some(t) => t
            .parse::<i64>()
            .ok()
            .filter(|&h| h >= -1)
            .ok_or_else(|| bad("HeaderSize", t))?,
    };
    Ok(Header {
        sample,
        dims,
        endian,
        compressed,
        spacing,
        origin,
        orientation,
        data_file,
        header_size,
    })
}

/// Reads a MetaImage volume (`f32` samples).
pub(crate) fn read(path: &Path) -> Result<Volume, IoError> {
    read_as(path, &AsSamples, "volume")?.into_volume(path)
}

/// Reads a MetaImage label map (exact `u32` labels, `decode_target.rs`).
pub(crate) fn read_labels(path: &Path) -> Result<LabelVolume, IoError> {
    read_as(path, &AsLabels::default(), "label map")?.into_labels(path)
}

/// The samples decoded by `target` (a `noun` for the budget's message), read as they are
/// inflated or from the file, with their geometry.
fn read_as<T: DecodeTarget>(
    path: &Path,
    target: &T,
    noun: &str,
) -> Result<Decoded<Vec<T::Item>>, IoError> {
    let file = File::open(path).map_err(|e| IoError::access(path, "cannot open", &e))?;
    let mut reader = BufReader::with_capacity(1 << 20, file);
    let header = read_header(path, &mut reader)?;
    let (_, data_bytes) = samples::check_decoded_size(path, header.dims, header.sample, noun)?;

    let (data_path, mut data) = match &header.data_file {
        None => (path.to_path_buf(), reader),
        Some(other) => {
            let f = samples::open_data_file(path, other)?;
            let mut data = BufReader::with_capacity(1 << 20, f);
            if header.header_size == -1 {
                if header.compressed {
                    return Err(IoError::malformed(
                        path,
                        "'HeaderSize = -1' cannot be used with compressed data",
                    ));
                }
                let len = data
                    .get_ref()
                    .metadata()
                    .map_err(|e| IoError::access(other, "cannot read", &e))?
                    .len();
                let start = len.checked_sub(data_bytes as u64).ok_or_else(|| {
                    IoError::truncated(
                        other,
                        format!("the image data is truncated: expected {data_bytes} bytes, the file has {len}"),
                    )
                })?;
                data.seek(SeekFrom::Start(start))
                    .map_err(|e| IoError::access(other, "cannot read", &e))?;
            } else if header.header_size > 0 {
                data.seek(SeekFrom::Start(header.header_size as u64))
                    .map_err(|e| IoError::access(other, "cannot read", &e))?;
            }
            (other.clone(), data)
        }
    };
    let (dims, stored) = (header.dims, (header.sample, header.endian));
    let values = if header.compressed {
        let inflated = samples::inflater(&mut data);
        let what = "compressed image data";
        read_stream(&data_path, inflated, dims, stored, target, what)?
    } else {
        read_stream(&data_path, &mut data, dims, stored, target, "image data")?
    };
    Ok(Decoded {
        dims,
        spacing: header.spacing,
        origin: header.origin,
        orientation: header.orientation,
        values,
    })
}

/// The samples of a MetaImage without `CompressedData`, after its header or in its data file,
/// for reading window by window ([`BlockwiseVolume`]); `None` for compressed data, which has no
/// random access and is read whole ([`read`]).
pub(crate) fn open_blockwise(path: &Path) -> Result<Option<BlockwiseVolume>, IoError> {
    let file = File::open(path).map_err(|e| IoError::access(path, "cannot open", &e))?;
    let mut reader = BufReader::new(file);
    let header = read_header(path, &mut reader)?;
    if header.compressed {
        return Ok(None);
    }
    let (data_path, start) = match &header.data_file {
        None => {
            let at = reader
                .stream_position()
                .map_err(|e| IoError::access(path, "cannot read", &e))?;
            (path.to_path_buf(), DataStart::At(at))
        }
        Some(other) if header.header_size == -1 => (other.clone(), DataStart::AtEnd),
        Some(other) => (
            other.clone(),
            DataStart::At(header.header_size.max(0) as u64),
        ),
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

/// ITK's three-letter code of a direction in LPS: for each index axis, the side it runs
/// from (`R` for +x, `A` for +y, `I` for +z), by its largest component.
fn orientation_code(direction: DMat3) -> String {
    (0..3)
        .map(|a| {
            let d = direction.col(a);
            let axis = (0..3)
                .max_by(|&i, &j| d[i].abs().total_cmp(&d[j].abs()))
                .unwrap_or(a);
            let from = [['R', 'L'], ['A', 'P'], ['I', 'S']][axis];
            if d[axis] >= 0.0 {
                from[0]
            } else {
                from[1]
            }
        })
        .collect()
}

fn header_text(volume: &Volume, compressed_size: Option<u64>, data_file: &str) -> String {
    let g = &volume.grid;
    let [nx, ny, nz] = g.dims;
    let [sx, sy, sz] = g.spacing;
    // MetaImage's world is ITK's, LPS: a RAS volume is converted.
    let world = volume.world().in_frame(Frame::Lps);
    let [ox, oy, oz] = world.origin.to_array();
    let matrix: Vec<String> = (0..3)
        .flat_map(|a| world.direction.col(a).to_array())
        .map(|v| v.to_string())
        .collect();
    let matrix = matrix.join(" ");
    let anatomical = match world.frame {
        Frame::Unknown => String::new(),
        _ => format!(
            "AnatomicalOrientation = {}\n",
            orientation_code(world.direction)
        ),
    };
    let mut text = format!(
        "ObjectType = Image\n\
         NDims = 3\n\
         BinaryData = True\n\
         BinaryDataByteOrderMSB = False\n\
         CompressedData = {}\n",
        if compressed_size.is_some() {
            "True"
        } else {
            "False"
        }
    );
    if let Some(size) = compressed_size {
        text.push_str(&format!("CompressedDataSize = {size}\n"));
    }
    text.push_str(&format!(
        "TransformMatrix = {matrix}\n\
         Offset = {ox} {oy} {oz}\n\
         {anatomical}ElementSpacing = {sx} {sy} {sz}\n\
         DimSize = {nx} {ny} {nz}\n\
         ElementType = MET_FLOAT\n\
         ElementDataFile = {data_file}\n"
    ));
    text
}

/// The samples as little-endian `f32`, zlib-compressed if asked.
fn data_bytes(volume: &Volume, compress: bool) -> std::io::Result<Vec<u8>> {
    let mut out = Vec::new();
    if compress {
        let mut z = ZlibEncoder::new(&mut out, flate2::Compression::new(6));
        crate::raw::write_samples_f32_le(&mut z, volume.as_slice())?;
        z.finish()?;
    } else {
        crate::raw::write_samples_f32_le(&mut out, volume.as_slice())?;
    }
    Ok(out)
}

/// Writes a `.mha` with the data after the header (`ElementDataFile = LOCAL`).
pub(crate) fn write(path: &Path, volume: &Volume, compress: bool) -> Result<TempFile, IoError> {
    if compress {
        // The header states the compressed size, so the data is compressed first.
        let data =
            data_bytes(volume, true).map_err(|e| IoError::access(path, "cannot compress", &e))?;
        let header = header_text(volume, Some(data.len() as u64), "LOCAL");
        stage(path, |w| {
            w.write_all(header.as_bytes())?;
            w.write_all(&data)
        })
    } else {
        let header = header_text(volume, None, "LOCAL");
        stage(path, |w| {
            w.write_all(header.as_bytes())?;
            crate::raw::write_samples_f32_le(w, volume.as_slice())
        })
    }
}

/// The data file that the MetaImage header `path` names, if it can be read and names one.
pub(crate) fn data_file_of(path: &Path) -> Option<PathBuf> {
    let file = File::open(path).ok()?;
    read_header(path, &mut BufReader::new(file)).ok()?.data_file
}

/// Writes a `.mhd` and its data file `data_path` (in the same folder, chosen by
/// [`crate::OutputSet`]): the data file's temporary first, then the header's.
pub(crate) fn write_detached(
    path: &Path,
    data_path: &Path,
    volume: &Volume,
    compress: bool,
) -> Result<[TempFile; 2], IoError> {
    let data_name = crate::detached::name_in_header(path, data_path)?;
    let data = if compress {
        Some(data_bytes(volume, true).map_err(|e| IoError::access(path, "cannot compress", &e))?)
    } else {
        None
    };
    let header = header_text(volume, data.as_ref().map(|d| d.len() as u64), &data_name);
    // The header first, so that an unwritable directory is reported for the file asked for.
    let mut header_file = TempFile::create(path)?;
    let mut data_file = TempFile::create(data_path)?;
    data_file.write_with(|w| match &data {
        Some(bytes) => w.write_all(bytes),
        None => crate::raw::write_samples_f32_le(w, volume.as_slice()),
    })?;
    header_file.write_with(|w| w.write_all(header.as_bytes()))?;
    Ok([data_file, header_file])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::IoErrorKind;

    fn header_of(text: &str) -> Result<Header, IoError> {
        read_header(Path::new("d/t.mha"), &mut text.as_bytes())
    }

    #[test]
    fn reads_an_itk_header() {
        let h = header_of(
            "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n\
             CompressedData = True\nCompressedDataSize = 1486837\n\
             TransformMatrix = 1 0 0 0 -1 0 0 0 -1\nOffset = 0 360 332.5\n\
             ElementSpacing = 1.40625 1.40625 2.5\nDimSize = 256 256 133\n\
             ElementType = MET_UCHAR\nElementDataFile = LOCAL\n",
        )
        .unwrap();
        assert_eq!(h.dims, [256, 256, 133]);
        assert_eq!(h.spacing, [1.40625, 1.40625, 2.5]);
        assert_eq!(h.origin, [0.0, 360.0, 332.5]);
        assert!(h.compressed);
        assert_eq!(h.sample, SampleType::U8);
        assert!(h.data_file.is_none());

        let h = header_of("NDims = 2\nDimSize = 3 4\nElementType = MET_SHORT\nElementByteOrderMSB = True\nElementDataFile = t.raw\n").unwrap();
        assert_eq!(h.dims, [3, 4, 1]);
        assert_eq!(h.endian, Endian::Big);
        assert_eq!(h.data_file.as_deref(), Some(Path::new("d/t.raw")));
    }

    #[test]
    fn refuses_what_it_cannot_read() {
        for (text, kind, needle) in [
            ("NDims = 3\nDimSize = 1 1 1\nElementType = MET_UCHAR\n", IoErrorKind::Malformed, "ElementDataFile"),
            ("NDims = 3\nElementType = MET_UCHAR\nElementDataFile = LOCAL\n", IoErrorKind::Malformed, "DimSize"),
            ("NDims = 4\nElementDataFile = LOCAL\n", IoErrorKind::Unsupported, "NDims = 4"),
            ("NDims = 3\nDimSize = 1 1 1\nElementType = MET_STRING\nElementDataFile = LOCAL\n", IoErrorKind::Unsupported, "MET_STRING"),
            ("NDims = 4\nDimSize = 2 2 2 3\nElementDataFile = LOCAL\n", IoErrorKind::Unsupported, "axis 4 holds 3 values"),
            ("NDims = 3\nDimSize = 1 1 1\nElementType = MET_UCHAR\nElementNumberOfChannels = 3\nElementDataFile = LOCAL\n", IoErrorKind::Unsupported, "channels"),
            ("garbage without equals\n", IoErrorKind::Malformed, "Key = Value"),
        ] {
            let err = header_of(text).err().unwrap_or_else(|| panic!("accepted {text:?}"));
            assert_eq!(err.kind, kind, "{err}");
            assert!(err.message.contains(needle), "{needle}: {err}");
        }
    }
}
