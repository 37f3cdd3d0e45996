//! VTK image data through `vtkio`: XML `.vti` and legacy `.vtk` (`STRUCTURED_POINTS`), read and
//! written.
//!
//! Reading takes the first one-component point-data array (of any numeric type) of a
//! single-piece image, with its dimensions (from the extent, which may start anywhere: the
//! origin moves accordingly), spacing and origin. vtkio holds spacing and origin as `f32`, so
//! they survive a VTK round trip to `f32` precision (well below a micrometre for scans).
//! Images with several pieces, or with cell data only, are refused. The `Direction` attribute of
//! an XML image (VTK 9: nine numbers, row by row, its columns the world directions of the index
//! axes), which vtkio drops, is read here from the `<ImageData>` tag; VTK has no anatomical
//! frame, so the frame is unknown. vtkio cannot write a `Direction` either: for an oblique
//! volume it is put into the `<ImageData>` tag of vtkio's output here (`with_direction`), in the
//! volume's own world (its frame is not recorded); legacy files have no place for it, so an
//! oblique volume is refused for `.vtk` output (NRRD, NIfTI, MetaImage and VTI keep it).
//!
//! Writing: one piece, point data `values` as `f32`. Legacy files are binary big-endian; XML
//! files zlib-compressed when [`VolumeWriteOptions::compress`](crate::VolumeWriteOptions) asks.
//! vtkio owns the data it writes, so writing makes one copy of the samples, and its
//! compressor feeds zlib one sample at a time (seconds for a 256³ volume).
//!
//! A label map ([`read_labels`]) takes the array's values as exact `u32` labels: a `UInt32`
//! array as vtkio decoded it, any other type converted, refusing a value that is not a label
//! (`decode_target.rs`).
//!
//! Cost: O(N) for N samples; memory the vtkio model plus the `f32` volume (two copies of the
//! samples at the peak; for a `UInt32` label map, the vtkio model alone).

use std::path::Path;

use voxlod_core::glam::{DMat3, DVec3};
use voxlod_core::{Frame, LabelVolume, Orientation, Volume};
use vtkio::model::{
    Attribute, Attributes, DataArray, DataSet, Extent, IOBuffer, ImageDataPiece, Piece, Version,
    Vtk,
};

use crate::decode_target::{labels_of, BadLabel};
use crate::samples::{self, Decoded, SampleType};
use crate::vtk::{self, Flavor};
use crate::IoError;

/// Reads an image as a volume (`f32` samples).
pub(crate) fn read(path: &Path, flavor: Flavor) -> Result<Volume, IoError> {
    let image = read_image(path, flavor)?;
    samples::check_volume_size(path, image.dims, SampleType::F32)?;
    image
        .map(|values| Ok(vtk::into_f32(values)))?
        .into_volume(path)
}

/// Reads an image as a label map: its array's values as exact `u32` labels, without a copy when
/// it is `UInt32` (`decode_target.rs`; the first value that is not a label is named with its
/// voxel).
pub(crate) fn read_labels(path: &Path, flavor: Flavor) -> Result<LabelVolume, IoError> {
    let image = read_image(path, flavor)?;
    let dims = image.dims;
    samples::check_decoded_size(path, dims, SampleType::U32, "label map")?;
    image
        .map(|values| into_labels(values).map_err(|bad| bad.error(path, dims, 0)))?
        .into_labels(path)
}

/// vtkio's buffer as labels: a `UInt32` one as it is, any other converted (the memory budget
/// was asked for both copies when the file was parsed).
fn into_labels(buffer: IOBuffer) -> Result<Vec<u32>, BadLabel> {
    macro_rules! convert {
        ($values:expr) => {{
            let mut out = vec![0u32; $values.len()];
            labels_of(&$values, &mut out).map(|()| out)
        }};
    }
    match buffer {
        IOBuffer::U32(v) => Ok(v),
        IOBuffer::Bit(v) | IOBuffer::U8(v) => convert!(v),
        IOBuffer::I8(v) => convert!(v),
        IOBuffer::U16(v) => convert!(v),
        IOBuffer::I16(v) => convert!(v),
        IOBuffer::I32(v) => convert!(v),
        IOBuffer::U64(v) => convert!(v),
        IOBuffer::I64(v) => convert!(v),
        IOBuffer::F32(v) => convert!(v),
        IOBuffer::F64(v) => convert!(v),
    }
}

/// The first one-component point-data array of a single-piece image, as vtkio holds it, with
/// the image's geometry.
fn read_image(path: &Path, flavor: Flavor) -> Result<Decoded<IOBuffer>, IoError> {
    let vtk = vtk::load(path, flavor)?;
    let DataSet::ImageData {
        extent,
        origin,
        spacing,
        pieces,
        ..
    } = vtk.data
    else {
        return Err(IoError::unsupported(
            path,
            "holds no image data (a mesh or another data set): only images are read as volumes",
        ));
    };
    if pieces.len() != 1 {
        return Err(IoError::unsupported(
            path,
            format!(
                "image in {} pieces; only single-piece images are read",
                pieces.len()
            ),
        ));
    }
    let piece = match pieces.into_iter().next() {
        Some(Piece::Inline(piece)) => *piece,
        _ => {
            return Err(IoError::unsupported(
                path,
                "image pieces stored in other files (parallel VTK) are not supported",
            ))
        }
    };
    let ImageDataPiece {
        extent: piece_extent,
        data,
    } = piece;

    // The piece's extent, which for a single piece is the whole extent.
    let used = match (&piece_extent, &extent) {
        (Extent::Ranges(_), _) => piece_extent,
        _ => extent,
    };
    let (start, dims) = extent_start_and_dims(path, &used)?;

    let array = data.point.into_iter().find_map(|a| match a {
        Attribute::DataArray(DataArray { elem, data, .. }) if elem.num_comp() == 1 => Some(data),
        _ => None,
    });
    let Some(buffer) = array else {
        return Err(IoError::unsupported(
            path,
            "the image has no one-component point-data array (cell data and vectors are not read)",
        ));
    };
    samples::refuse_zero_dims(path, dims)?;
    let count = dims.iter().try_fold(1usize, |n, &d| n.checked_mul(d));
    let count = count.unwrap_or(usize::MAX);
    if buffer.len() != count {
        return Err(IoError::truncated(
            path,
            format!(
                "a {}x{}x{} image needs {count} samples, the file has {}",
                dims[0],
                dims[1],
                dims[2],
                buffer.len()
            ),
        ));
    }
    let spacing = spacing.map(|s| s as f64);
    let direction = match flavor {
        Flavor::Xml => xml_direction(path)?,
        Flavor::Legacy => DMat3::IDENTITY,
    };
    let first = direction * (DVec3::from(start.map(|s| s as f64)) * DVec3::from(spacing));
    let origin = [0, 1, 2].map(|a| origin[a] as f64 + first[a]);
    let orientation = Orientation {
        direction: voxlod_core::WorldTransform::from_columns(
            DVec3::ZERO,
            [direction.x_axis, direction.y_axis, direction.z_axis],
            Frame::Unknown,
        )
        .map_err(|e| IoError::malformed(path, format!("Direction: {e}")))?
        .direction,
        frame: Frame::Unknown,
    };
    Ok(Decoded {
        dims,
        spacing,
        origin,
        orientation,
        values: buffer,
    })
}

/// The first index and the sample counts of an extent, in i64: an extent's width can overflow
/// the i32 it is stored in.
fn extent_start_and_dims(path: &Path, used: &Extent) -> Result<([i64; 3], [usize; 3]), IoError> {
    match used {
        Extent::Ranges(ranges) => {
            let start = ranges.clone().map(|r| *r.start() as i64);
            let end = ranges.clone().map(|r| *r.end() as i64);
            if let Some(axis) = (0..3).find(|&a| end[a] < start[a]) {
                return Err(IoError::malformed(
                    path,
                    format!(
                        "the extent ends before it starts along {} ({} < {})",
                        ["x", "y", "z"][axis],
                        end[axis],
                        start[axis]
                    ),
                ));
            }
            Ok((start, [0, 1, 2].map(|a| (end[a] - start[a] + 1) as usize)))
        }
        Extent::Dims(dims) => Ok(([0; 3], dims.map(|d| d as usize))),
    }
}

/// The `Direction` of the `<ImageData>` tag (identity when absent), from the first 64 KiB.
fn xml_direction(path: &Path) -> Result<DMat3, IoError> {
    use std::io::Read;
    let mut head = Vec::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(1 << 16).read_to_end(&mut head))
        .map_err(|e| IoError::access(path, "cannot read", &e))?;
    let mut reader = quick_xml::Reader::from_reader(&head[..]);
    let mut buf = Vec::new();
    loop {
        match reader.read_event_into(&mut buf) {
            Ok(quick_xml::events::Event::Start(tag) | quick_xml::events::Event::Empty(tag))
                if tag.name().as_ref() == b"ImageData" =>
            {
                let Some(attr) = tag
                    .attributes()
                    .flatten()
                    .find(|a| a.key.as_ref() == b"Direction")
                else {
                    return Ok(DMat3::IDENTITY);
                };
                let text = String::from_utf8_lossy(&attr.value).into_owned();
                let m: Vec<f64> = samples::parse_list(&text, 9).ok_or_else(|| {
                    IoError::malformed(path, format!("cannot understand Direction=\"{text}\""))
                })?;
                return Ok(DMat3::from_cols_array(&[
                    m[0], m[3], m[6], m[1], m[4], m[7], m[2], m[5], m[8],
                ]));
            }
            Ok(quick_xml::events::Event::Eof) | Err(_) => return Ok(DMat3::IDENTITY),
            _ => buf.clear(),
        }
    }
}

pub(crate) fn write(
    path: &Path,
    volume: &Volume,
    flavor: Flavor,
    compress: bool,
) -> Result<crate::atomic::TempFile, IoError> {
    let g = &volume.grid;
    if g.dims.iter().any(|&d| d > i32::MAX as usize) {
        return Err(IoError::unsupported(path, "VTK extents are 32-bit"));
    }
    let last = g.dims.map(|d| d as i32 - 1);
    let extent = Extent::Ranges([0..=last[0], 0..=last[1], 0..=last[2]]);
    let piece = ImageDataPiece {
        extent: extent.clone(),
        data: Attributes {
            point: vec![Attribute::scalars("values", 1).with_data(volume.as_slice().to_vec())],
            cell: Vec::new(),
        },
    };
    let vtk = Vtk {
        version: match flavor {
            Flavor::Legacy => Version::new_legacy(3, 0),
            Flavor::Xml => Version::new_xml(1, 0),
        },
        title: "written by voxlod".to_string(),
        byte_order: match flavor {
            Flavor::Legacy => vtkio::model::ByteOrder::BigEndian,
            Flavor::Xml => vtkio::model::ByteOrder::LittleEndian,
        },
        file_path: None,
        data: DataSet::ImageData {
            extent,
            origin: g.origin.map(|o| o as f32),
            spacing: g.spacing.map(|s| s as f32),
            meta: None,
            pieces: vec![Piece::Inline(Box::new(piece))],
        },
    };
    if flavor == Flavor::Xml && !volume.orientation.is_axis_aligned() {
        return vtk::save_patched(path, vtk, compress, |xml| {
            with_direction(xml, volume.orientation.direction)
        });
    }
    vtk::save(path, vtk, flavor, compress)
}

/// vtkio's XML with ` Direction="..."` (row by row) added to the `<ImageData` tag.
fn with_direction(xml: Vec<u8>, direction: DMat3) -> Result<Vec<u8>, String> {
    const TAG: &[u8] = b"<ImageData";
    let at = xml
        .windows(TAG.len())
        .position(|w| w == TAG)
        .ok_or("vtkio wrote no <ImageData> tag")?
        + TAG.len();
    let rows: Vec<String> = (0..3)
        .flat_map(|r| (0..3).map(move |c| direction.col(c)[r]))
        .map(|v| v.to_string())
        .collect();
    let attribute = format!(" Direction=\"{}\"", rows.join(" "));
    let mut out = Vec::with_capacity(xml.len() + attribute.len());
    out.extend_from_slice(&xml[..at]);
    out.extend_from_slice(attribute.as_bytes());
    out.extend_from_slice(&xml[at..]);
    Ok(out)
}
