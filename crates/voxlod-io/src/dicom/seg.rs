//! DICOM Segmentation objects (SEG, SOP Class 1.2.840.10008.5.1.4.1.1.66.4) in, as label maps:
//! one map of `u32` labels, the segment numbers (0 outside every segment), and a label table
//! with each segment's name and colour.
//!
//! What is read (DICOM PS3.3 A.51 and C.8.20):
//! - the Segment Sequence (0062,0002): SegmentNumber is the label value, SegmentLabel its name,
//!   RecommendedDisplayCIELabValue its colour, converted to sRGB as C.10.7.1.1 says (16-bit
//!   CIELab scaled back to L* 0–100, a* and b* −128–127, D65 white, then sRGB by palette);
//! - the frames: BINARY (BitsAllocated 1, bits packed least significant first, frames packed
//!   back to back with no padding to a byte, PS3.5 8.1.1) or FRACTIONAL (BitsAllocated 8, a
//!   pixel is inside when it is at least half of MaximumFractionalValue);
//! - the functional groups: per frame, PlanePositionSequence/ImagePositionPatient and
//!   SegmentIdentificationSequence/ReferencedSegmentNumber; per frame or shared,
//!   PlaneOrientationSequence/ImageOrientationPatient and PixelMeasuresSequence (PixelSpacing,
//!   SpacingBetweenSlices, SliceThickness).
//!
//! The distinct frame positions are the slices of the volume: they are sorted along the normal
//! and turned into the index-to-world transform (LPS) by the DICOM series code
//! (`geometry.rs`), so a SEG is refused where a series would be (sheared, uneven or
//! missing planes), with one allowance: writers leave out empty frames, so when
//! SpacingBetweenSlices is given, a gap of a whole number of those steps holds empty planes.
//! Each frame's segment is painted into its plane in increasing segment number, so where
//! segments overlap the later number wins, and a warning says where. Refused with a clear
//! error: missing positions or segment numbers, a segment number the Segment Sequence does not
//! define, frames of mixed sizes, a frame count that does not match the pixel data, and
//! compressed 1-bit pixel data.
//!
//! Beyond the paper (which takes a volume as given, §4). Cost: one parse of the file, one pass
//! over the frames' bits; memory is the label volume (4 bytes a voxel), plus the decoded
//! frames for compressed 8-bit data.

use std::borrow::Cow;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use dicom_core::value::Value;
use dicom_dictionary_std::tags;
use dicom_object::{DefaultDicomObject, InMemDicomObject, Tag};
use dicom_pixeldata::PixelDecoder;
use glam::DVec3;
use palette::{FromColor, Lab, Srgb};
use voxlod_core::{memory, LabelVolume};

use crate::dicom::geometry::{stack, SliceGeometry, SpacingTolerance};
use crate::dicom::{decimals, dimension, looks_like_dicom, open, text};
use crate::label_table::{LabelMap, LabelName};
use crate::{budget, guard, IoError};

/// SOP Class UID of Segmentation Storage.
pub const SEGMENTATION_STORAGE: &str = "1.2.840.10008.5.1.4.1.1.66.4";

/// How far a plane step may stray from the others (or from SpacingBetweenSlices), as a
/// fraction of it: the series reader's default.
const SPACING_TOLERANCE: SpacingTolerance = SpacingTolerance { relative: 0.01 };

/// Two frame positions closer than this (mm) are the same plane.
const SAME_PLANE: f64 = 1e-3;

/// Whether `path` is a DICOM Part 10 file of Segmentation Storage (read from the file meta
/// group only).
pub fn is_dicom_seg(path: &Path) -> bool {
    use std::io::{Read, Seek, SeekFrom};
    if !path.is_file() || !looks_like_dicom(path) {
        return false;
    }
    let Ok(mut file) = std::fs::File::open(path) else {
        return false;
    };
    if file.seek(SeekFrom::Start(128)).is_err() {
        return false;
    }
    let reader = std::io::BufReader::new(file.take(1 << 16));
    guard::quietly(|| dicom_object::meta::FileMetaTable::from_reader(reader))
        .and_then(Result::ok)
        .is_some_and(|meta| meta.media_storage_sop_class_uid() == SEGMENTATION_STORAGE)
}

/// The SEG file `path` names: the file itself, or the one SEG file of a folder. `None` when
/// there is none; a folder with several is an error listing them.
pub fn find_dicom_seg(path: &Path) -> Result<Option<PathBuf>, IoError> {
    if !path.is_dir() {
        return Ok(is_dicom_seg(path).then(|| path.to_path_buf()));
    }
    let entries = std::fs::read_dir(path).map_err(|e| IoError::access(path, "cannot list", &e))?;
    let mut found: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| is_dicom_seg(p))
        .collect();
    found.sort();
    match found.len() {
        0 | 1 => Ok(found.pop()),
        n => Err(IoError::unsupported(
            path,
            format!(
                "the folder holds {n} DICOM Segmentation files; give one of them: {}",
                found
                    .iter()
                    .map(|p| p.display().to_string())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        )),
    }
}

/// One frame: where it lies and which segment it paints.
#[derive(Clone, Debug)]
struct Frame {
    segment: u16,
    position: DVec3,
    orientation: [DVec3; 2],
    /// Between rows, then between columns.
    pixel_spacing: [f64; 2],
    spacing_between: Option<f64>,
    thickness: Option<f64>,
}

/// How the frames' pixels are stored.
#[derive(Clone, Copy, Debug)]
enum Encoding {
    /// One bit a pixel, packed across frames.
    Bits,
    /// One byte a pixel; inside from this value on.
    Bytes { inside_from: u16 },
}

/// Reads the SEG file `path` (a file, or a folder holding one) as a label map.
pub fn read_dicom_seg(path: &Path) -> Result<LabelMap, IoError> {
    let file = find_dicom_seg(path)?.ok_or_else(|| {
        IoError::unsupported(
            path,
            format!("not a DICOM Segmentation (SOP Class {SEGMENTATION_STORAGE})"),
        )
    })?;
    let path = file.as_path();
    let obj = open(path, false)?;
    let rows = dimension(&obj, path, tags::ROWS, "Rows")?;
    let columns = dimension(&obj, path, tags::COLUMNS, "Columns")?;
    let table = read_segments(&obj, path)?;
    let encoding = read_encoding(&obj, path)?;
    let frames = read_frames(&obj, path, &table)?;
    let (planes, world) = plane_geometry(path, &frames)?;
    let dims = [columns as usize, rows as usize, planes.len()];
    let count = dims.iter().map(|&d| d as u64).product::<u64>();
    budget::check_count(path, "the voxels of the segmentation", count, 4)?;
    let pixels = frame_pixels(&obj, path, encoding, [rows, columns], frames.len())?;
    let mut values: Vec<u32> = memory::zeroed_vec(count as usize);
    let overlaps = paint(&mut values, &frames, &planes, &pixels, encoding, dims);
    let (grid, orientation) = world.split(dims).map_err(|e| IoError::from_core(path, e))?;
    let labels = LabelVolume::from_vec(grid, values)
        .map(|v| v.oriented(orientation))
        .map_err(|e| IoError::from_core(path, e))?;
    let warnings = overlaps
        .into_iter()
        .map(|((low, high), voxels)| {
            format!(
                "{}: segments {low} and {high} overlap in {voxels} voxels; the later segment number ({high}) is kept there",
                path.display()
            )
        })
        .collect();
    Ok(LabelMap {
        labels,
        table,
        warnings,
    })
}

/// A single unsigned integer attribute, or `None` when absent.
fn unsigned(obj: &InMemDicomObject, tag: Tag) -> Option<u32> {
    obj.element_opt(tag)
        .ok()
        .flatten()
        .and_then(|e| e.to_int::<u32>().ok())
}

/// The items of a sequence attribute, or `None` when absent (or not a sequence).
fn items(obj: &InMemDicomObject, tag: Tag) -> Option<&[InMemDicomObject]> {
    obj.element_opt(tag).ok().flatten().and_then(|e| e.items())
}

/// The first item of the sequence `tag` inside the functional group `group`.
fn group_item(group: Option<&InMemDicomObject>, tag: Tag) -> Option<&InMemDicomObject> {
    group.and_then(|g| items(g, tag)).and_then(|i| i.first())
}

/// The Segment Sequence as a label table, in segment number order.
fn read_segments(obj: &InMemDicomObject, path: &Path) -> Result<Vec<LabelName>, IoError> {
    let segments = items(obj, tags::SEGMENT_SEQUENCE)
        .filter(|s| !s.is_empty())
        .ok_or_else(|| IoError::malformed(path, "the Segment Sequence (0062,0002) is missing"))?;
    let mut table: Vec<LabelName> = Vec::with_capacity(segments.len());
    for (k, item) in segments.iter().enumerate() {
        let number = unsigned(item, tags::SEGMENT_NUMBER)
            .filter(|&n| (1..=u32::from(u16::MAX)).contains(&n))
            .ok_or_else(|| {
                IoError::malformed(
                    path,
                    format!(
                        "item {} of the Segment Sequence has no SegmentNumber from 1 to 65535",
                        k + 1
                    ),
                )
            })?;
        if table.iter().any(|l| l.value == i64::from(number)) {
            return Err(IoError::malformed(
                path,
                format!("the Segment Sequence defines segment {number} twice"),
            ));
        }
        let color = item
            .element_opt(tags::RECOMMENDED_DISPLAY_CIE_LAB_VALUE)
            .ok()
            .flatten()
            .and_then(|e| e.to_multi_int::<u16>().ok())
            .filter(|v| v.len() == 3)
            .map(|v| cielab_to_srgb([v[0], v[1], v[2]]));
        table.push(LabelName {
            value: i64::from(number),
            name: text(item, tags::SEGMENT_LABEL),
            color,
        });
    }
    table.sort_by_key(|l| l.value);
    Ok(table)
}

/// A DICOM 16-bit CIELab colour (PS3.3 C.10.7.1.1: L* 0–100 and a*, b* −128–127 scaled
/// linearly to 0–65535) as sRGB in 0..=1, D65 white, out-of-gamut values clamped.
pub fn cielab_to_srgb(lab: [u16; 3]) -> [f32; 3] {
    let scale = |v: u16| f64::from(v) / 65535.0;
    let lab = Lab::<palette::white_point::D65, f64>::new(
        scale(lab[0]) * 100.0,
        scale(lab[1]) * 255.0 - 128.0,
        scale(lab[2]) * 255.0 - 128.0,
    );
    let rgb = Srgb::from_color(lab);
    [rgb.red, rgb.green, rgb.blue].map(|c| c.clamp(0.0, 1.0) as f32)
}

/// BitsAllocated and SegmentationType: how a pixel is stored and when it is inside.
fn read_encoding(obj: &DefaultDicomObject, path: &Path) -> Result<Encoding, IoError> {
    let kind = text(obj, tags::SEGMENTATION_TYPE);
    let bits = unsigned(obj, tags::BITS_ALLOCATED);
    let samples = unsigned(obj, tags::SAMPLES_PER_PIXEL).unwrap_or(1);
    if samples != 1 {
        return Err(IoError::malformed(
            path,
            format!("SamplesPerPixel is {samples}; a segmentation has one sample a pixel"),
        ));
    }
    let compressed = matches!(
        obj.element_opt(tags::PIXEL_DATA)
            .ok()
            .flatten()
            .map(|e| e.value()),
        Some(Value::PixelSequence(_))
    );
    match (kind.as_str(), bits) {
        ("BINARY", Some(1)) if compressed => Err(IoError::unsupported(
            path,
            format!(
                "1-bit pixel data in a compressed transfer syntax ({}) is not supported; convert the file to Explicit VR Little Endian",
                obj.meta().transfer_syntax()
            ),
        )),
        ("BINARY", Some(1)) => Ok(Encoding::Bits),
        ("BINARY", Some(8)) => Ok(Encoding::Bytes { inside_from: 1 }),
        ("FRACTIONAL", Some(8)) => {
            let max = unsigned(obj, tags::MAXIMUM_FRACTIONAL_VALUE)
                .filter(|&m| (1..=255).contains(&m))
                .ok_or_else(|| {
                    IoError::malformed(path, "a FRACTIONAL segmentation needs a MaximumFractionalValue from 1 to 255")
                })?;
            Ok(Encoding::Bytes {
                inside_from: max.div_ceil(2) as u16,
            })
        }
        (kind, bits) => Err(IoError::unsupported(
            path,
            format!(
                "SegmentationType '{kind}' with BitsAllocated {}: only BINARY (1 bit) and FRACTIONAL (8 bits) segmentations are read",
                bits.map_or("missing".to_string(), |b| b.to_string())
            ),
        )),
    }
}

/// Every frame's segment and plane, from the per-frame and shared functional groups.
fn read_frames(
    obj: &DefaultDicomObject,
    path: &Path,
    table: &[LabelName],
) -> Result<Vec<Frame>, IoError> {
    let per_frame = items(obj, tags::PER_FRAME_FUNCTIONAL_GROUPS_SEQUENCE)
        .filter(|f| !f.is_empty())
        .ok_or_else(|| {
            IoError::malformed(
                path,
                "the Per-Frame Functional Groups Sequence (5200,9230) is missing, so the frames cannot be placed",
            )
        })?;
    let declared = text(obj, tags::NUMBER_OF_FRAMES);
    if declared.parse::<usize>().ok() != Some(per_frame.len()) {
        return Err(IoError::malformed(
            path,
            format!(
                "NumberOfFrames is '{declared}' but the Per-Frame Functional Groups Sequence has {} items",
                per_frame.len()
            ),
        ));
    }
    let shared = items(obj, tags::SHARED_FUNCTIONAL_GROUPS_SEQUENCE).and_then(|s| s.first());
    per_frame
        .iter()
        .enumerate()
        .map(|(k, group)| read_frame(path, k, group, shared, table))
        .collect()
}

/// One frame's functional groups (its own first, then the shared ones).
fn read_frame(
    path: &Path,
    k: usize,
    group: &InMemDicomObject,
    shared: Option<&InMemDicomObject>,
    table: &[LabelName],
) -> Result<Frame, IoError> {
    let frame = k + 1;
    let either = |tag: Tag| group_item(Some(group), tag).or_else(|| group_item(shared, tag));
    let segment = group_item(Some(group), tags::SEGMENT_IDENTIFICATION_SEQUENCE)
        .and_then(|s| unsigned(s, tags::REFERENCED_SEGMENT_NUMBER))
        .ok_or_else(|| {
            IoError::malformed(
                path,
                format!("frame {frame} has no ReferencedSegmentNumber"),
            )
        })?;
    if !table.iter().any(|l| l.value == i64::from(segment)) {
        return Err(IoError::malformed(
            path,
            format!("frame {frame} refers to segment {segment}, which the Segment Sequence does not define"),
        ));
    }
    let position = match group_item(Some(group), tags::PLANE_POSITION_SEQUENCE) {
        Some(p) => decimals(
            p,
            path,
            tags::IMAGE_POSITION_PATIENT,
            "ImagePositionPatient",
            3,
        )?,
        None => None,
    }
    .ok_or_else(|| {
        IoError::malformed(
            path,
            format!("frame {frame} has no ImagePositionPatient, so it cannot be placed"),
        )
    })?;
    let orientation = match either(tags::PLANE_ORIENTATION_SEQUENCE) {
        Some(o) => decimals(
            o,
            path,
            tags::IMAGE_ORIENTATION_PATIENT,
            "ImageOrientationPatient",
            6,
        )?,
        None => None,
    }
    .ok_or_else(|| {
        IoError::malformed(
            path,
            format!("frame {frame} has no ImageOrientationPatient"),
        )
    })?;
    let measures = either(tags::PIXEL_MEASURES_SEQUENCE).ok_or_else(|| {
        IoError::malformed(
            path,
            format!("frame {frame} has no Pixel Measures (PixelSpacing)"),
        )
    })?;
    let spacing = decimals(measures, path, tags::PIXEL_SPACING, "PixelSpacing", 2)?
        .filter(|s| s.iter().all(|&v| v > 0.0))
        .ok_or_else(|| {
            IoError::malformed(path, format!("frame {frame} has no positive PixelSpacing"))
        })?;
    let positive = |tag, name| -> Result<Option<f64>, IoError> {
        Ok(decimals(measures, path, tag, name, 1)?
            .map(|v| v[0])
            .filter(|&v| v > 0.0))
    };
    Ok(Frame {
        segment: segment as u16,
        position: DVec3::new(position[0], position[1], position[2]),
        orientation: [
            DVec3::new(orientation[0], orientation[1], orientation[2]),
            DVec3::new(orientation[3], orientation[4], orientation[5]),
        ],
        pixel_spacing: [spacing[0], spacing[1]],
        spacing_between: positive(tags::SPACING_BETWEEN_SLICES, "SpacingBetweenSlices")?,
        thickness: positive(tags::SLICE_THICKNESS, "SliceThickness")?,
    })
}

/// The planes of the volume (their positions, sorted along the normal) and its transform,
/// from the distinct frame positions, by the series reader's `stack`.
fn plane_geometry(
    path: &Path,
    frames: &[Frame],
) -> Result<(Vec<DVec3>, voxlod_core::WorldTransform), IoError> {
    let first = &frames[0];
    let [row, col] = first.orientation;
    let normal = row.cross(col).normalize_or_zero();
    let depth = |p: DVec3| p.dot(normal);
    let mut positions: Vec<DVec3> = frames.iter().map(|f| f.position).collect();
    positions.sort_by(|a, b| depth(*a).total_cmp(&depth(*b)));
    positions.dedup_by(|a, b| (*a - *b).length() < SAME_PLANE);
    let planes = fill_empty_planes(path, &positions, first.spacing_between, normal)?;
    // `stack` refuses a slice whose orientation or pixel spacing differs from the first one's:
    // the first frame that differs (if any) goes in front of the planes, for it to be refused
    // by the same check and named.
    let mut slices: Vec<SliceGeometry> = frames
        .iter()
        .enumerate()
        .filter(|(_, f)| {
            f.orientation != first.orientation || f.pixel_spacing != first.pixel_spacing
        })
        .take(1)
        .map(|(k, f)| slice_geometry(path, &format!("frame {}", k + 1), f, f.position))
        .collect();
    slices.extend(
        (planes.iter().enumerate())
            .map(|(j, &p)| slice_geometry(path, &format!("plane {}", j + 1), first, p)),
    );
    let world = stack(path, &mut slices, SPACING_TOLERANCE)?;
    if let (Some(given), true) = (first.spacing_between, planes.len() > 1) {
        let measured = world.spacing.z;
        if (measured - given).abs() > SPACING_TOLERANCE.relative * given {
            return Err(IoError::unsupported(
                path,
                format!("the frames are {measured:.3} mm apart but SpacingBetweenSlices says {given:.3} mm: unequal spacing"),
            ));
        }
    }
    let planes = slices.iter().filter_map(|s| s.position).collect();
    Ok((planes, world))
}

/// What `stack` needs of a plane: the frame's orientation, spacing and thickness at `position`
/// (named `what`, a frame or a plane, for its messages).
fn slice_geometry(path: &Path, what: &str, frame: &Frame, position: DVec3) -> SliceGeometry {
    SliceGeometry {
        path: PathBuf::from(format!("{} ({what})", path.display())),
        position: Some(position),
        orientation: Some(frame.orientation),
        pixel_spacing: frame.pixel_spacing,
        thickness: frame.thickness.or(frame.spacing_between),
    }
}

/// The sorted distinct positions with the planes of left-out empty frames put back: a gap of
/// a whole number (two or more) of SpacingBetweenSlices steps. Without that attribute, or
/// for other gaps, the positions are returned as they are (and `stack` refuses the gap).
fn fill_empty_planes(
    path: &Path,
    positions: &[DVec3],
    step: Option<f64>,
    normal: DVec3,
) -> Result<Vec<DVec3>, IoError> {
    let Some(step) = step else {
        return Ok(positions.to_vec());
    };
    let missing = |a: DVec3, b: DVec3| -> u64 {
        let ratio = (b - a).dot(normal) / step;
        let whole = ratio.round();
        if whole >= 2.0 && (ratio - whole).abs() < 0.1 {
            (whole as u64).saturating_sub(1)
        } else {
            0
        }
    };
    let total = positions
        .windows(2)
        .map(|w| missing(w[0], w[1]))
        .fold(positions.len() as u64, u64::saturating_add);
    budget::check_count(path, "the planes of the segmentation", total, 64)?;
    let mut planes = Vec::with_capacity(total as usize);
    for (k, &p) in positions.iter().enumerate() {
        planes.push(p);
        if let Some(&next) = positions.get(k + 1) {
            let gap = missing(p, next);
            let stride = (next - p) / (gap + 1) as f64;
            planes.extend((1..=gap).map(|j| p + stride * j as f64));
        }
    }
    Ok(planes)
}

/// The frames' pixel data: the stored bytes of native (uncompressed) pixel data, or the frames
/// decoded by dicom-pixeldata for compressed 8-bit data; its length checked against the
/// frames it must hold.
///
/// 1-bit data is always read here from the stored bytes, never through dicom-pixeldata:
/// dicom-pixeldata 0.10 unpacks BitsAllocated 1 as if every frame started on a byte (frame size
/// `rows * columns / 8`, rounded down), which is wrong whenever `rows * columns` is not a
/// multiple of 8, since PS3.5 8.1.1 packs the frames back to back without padding (its
/// `decode_pixel_data` and `decode_pixel_data_frame`, lib.rs, added in dicom-rs PRs 654 and
/// 668).
fn frame_pixels<'a>(
    obj: &'a DefaultDicomObject,
    path: &Path,
    encoding: Encoding,
    [rows, columns]: [u32; 2],
    frames: usize,
) -> Result<Cow<'a, [u8]>, IoError> {
    let pixels = u64::from(rows) * u64::from(columns) * frames as u64;
    let needed = match encoding {
        Encoding::Bits => pixels.div_ceil(8),
        Encoding::Bytes { .. } => pixels,
    };
    budget::check_count(path, "the pixels of the segmentation's frames", needed, 1)?;
    let element = obj
        .element_opt(tags::PIXEL_DATA)
        .ok()
        .flatten()
        .ok_or_else(|| IoError::truncated(path, "the PixelData is missing"))?;
    let data: Cow<[u8]> = match element.value() {
        Value::Primitive(p) => p.to_bytes(),
        _ => decode_compressed(obj, path)?.into(),
    };
    let len = data.len() as u64;
    if len < needed {
        return Err(IoError::truncated(
            path,
            format!("the PixelData holds {len} bytes where {frames} frames of {columns}x{rows} need {needed}"),
        ));
    }
    // Native pixel data is padded to an even length; anything longer is a wrong frame count.
    if len > needed + (needed % 2) {
        return Err(IoError::malformed(
            path,
            format!(
                "the PixelData holds {len} bytes, more than {frames} frames of {columns}x{rows} need ({needed}): NumberOfFrames does not match the pixel data{}",
                if matches!(encoding, Encoding::Bits) { " (or each frame is padded to a byte, which the standard does not allow)" } else { "" }
            ),
        ));
    }
    Ok(data)
}

/// Compressed 8-bit frames, decoded by dicom-pixeldata inside the panic guard.
fn decode_compressed(obj: &DefaultDicomObject, path: &Path) -> Result<Vec<u8>, IoError> {
    guard::quietly(|| obj.decode_pixel_data().ok().map(|d| d.data().to_vec()))
        .flatten()
        .ok_or_else(|| {
            IoError::malformed(
                path,
                format!(
                    "the pixel data cannot be decoded (transfer syntax {}): truncated, or a compression without a pure-Rust decoder",
                    obj.meta().transfer_syntax()
                ),
            )
        })
}

/// Paints every frame's inside pixels with its segment number, segments in increasing order;
/// returns how many voxels each pair of segments shares.
fn paint(
    values: &mut [u32],
    frames: &[Frame],
    planes: &[DVec3],
    pixels: &[u8],
    encoding: Encoding,
    dims: [usize; 3],
) -> BTreeMap<(u16, u16), usize> {
    let per_frame = dims[0] * dims[1];
    let mut order: Vec<usize> = (0..frames.len()).collect();
    order.sort_by_key(|&k| frames[k].segment);
    let mut overlaps = BTreeMap::new();
    for k in order {
        let frame = &frames[k];
        let Some(plane) = planes
            .iter()
            .position(|p| (*p - frame.position).length() < SAME_PLANE)
        else {
            continue;
        };
        let label = u32::from(frame.segment);
        let target = &mut values[plane * per_frame..(plane + 1) * per_frame];
        for (i, voxel) in target.iter_mut().enumerate() {
            let inside = match encoding {
                Encoding::Bits => {
                    let bit = k * per_frame + i;
                    (pixels[bit / 8] >> (bit % 8)) & 1 == 1
                }
                Encoding::Bytes { inside_from } => {
                    u16::from(pixels[k * per_frame + i]) >= inside_from
                }
            };
            if !inside {
                continue;
            }
            if *voxel != 0 && *voxel != label {
                *overlaps.entry((*voxel as u16, frame.segment)).or_insert(0) += 1;
            }
            *voxel = label;
        }
    }
    overlaps
}
