//! DICOM series in: a folder (or a list of files) of CT or MR slices becomes one volume in
//! Hounsfield units (or the modality's units), placed in LPS by the series geometry
//! (`geometry.rs`).
//!
//! Files are parsed by dicom-object and decoded by dicom-pixeldata (uncompressed, deflate,
//! RLE and the JPEG transfer syntaxes its pure-Rust decoders handle). The headers of every file
//! are read first (up to the pixel data), grouped by SeriesInstanceUID: one series is read, the
//! one asked for or the only one; otherwise the error lists them. Samples are
//! `stored · RescaleSlope + RescaleIntercept` (the modality LUT), slice by slice, so slices with
//! different rescales are fine. Sizes meet the memory budget before the volume is allocated,
//! and every file is parsed inside the panic guard. Beyond the paper (which takes a volume as
//! given, §4); the cost is one header parse per file and one decode per slice.

pub(crate) mod geometry;
mod lengths;
pub(crate) mod seg;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use dicom_dictionary_std::tags;
use dicom_object::{DefaultDicomObject, InMemDicomObject, OpenFileOptions};
use dicom_pixeldata::PixelDecoder;
use glam::DVec3;
use voxlod_core::{memory, Volume};

use crate::dicom::geometry::{stack, SliceGeometry, SpacingTolerance};
use crate::{budget, guard, IoError, IoErrorKind};

/// How a DICOM series is read.
#[derive(Clone, Debug)]
pub struct DicomOptions {
    /// The SeriesInstanceUID to read; `None` reads the only series, and fails listing them
    /// when the input holds several.
    pub series: Option<String>,
    /// How far the distance between two slices may differ from the series' median step, as a
    /// fraction of it (0.01: 1 %).
    pub spacing_tolerance: f64,
}

impl Default for DicomOptions {
    fn default() -> Self {
        DicomOptions {
            series: None,
            spacing_tolerance: 0.01,
        }
    }
}

impl DicomOptions {
    /// The series with this SeriesInstanceUID.
    pub fn series(uid: &str) -> DicomOptions {
        DicomOptions {
            series: Some(uid.to_string()),
            ..DicomOptions::default()
        }
    }
}

/// One series found in the input.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SeriesSummary {
    /// SeriesInstanceUID.
    pub uid: String,
    /// Files of the series.
    pub slices: usize,
    /// SeriesDescription (may be empty).
    pub description: String,
    /// Modality (CT, MR, ...).
    pub modality: String,
}

/// The header of one slice.
#[derive(Clone, Debug)]
struct SliceHeader {
    series: String,
    description: String,
    modality: String,
    rows: u32,
    columns: u32,
    geometry: SliceGeometry,
}

/// Whether a file starts like a DICOM Part 10 file (128-byte preamble, then `DICM`).
pub(crate) fn looks_like_dicom(path: &Path) -> bool {
    use std::io::Read;
    let mut head = [0u8; 132];
    std::fs::File::open(path)
        .and_then(|mut f| f.read_exact(&mut head))
        .is_ok()
        && &head[128..] == b"DICM"
}

/// The files of the inputs: a folder gives its DICOM files (by content, any name; hidden files
/// and DICOMDIR skipped), a file is taken as given.
fn collect_files(inputs: &[PathBuf]) -> Result<Vec<PathBuf>, IoError> {
    let mut files = Vec::new();
    for input in inputs {
        if !input.is_dir() {
            files.push(input.clone());
            continue;
        }
        let entries =
            std::fs::read_dir(input).map_err(|e| IoError::access(input, "cannot list", &e))?;
        let mut found: Vec<PathBuf> = entries
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| {
                let name = p.file_name().map(|n| n.to_string_lossy().into_owned());
                let name = name.unwrap_or_default();
                p.is_file() && !name.starts_with('.') && name != "DICOMDIR" && looks_like_dicom(p)
            })
            .collect();
        if found.is_empty() {
            return Err(IoError::new(
                input,
                IoErrorKind::Empty,
                "the folder holds no DICOM files (no file starts with the DICM preamble)",
            ));
        }
        found.sort();
        files.extend(found);
    }
    Ok(files)
}

/// Parses a file with dicom-object inside the panic guard; `until_pixels` stops before the
/// pixel data.
pub(crate) fn open(path: &Path, until_pixels: bool) -> Result<DefaultDicomObject, IoError> {
    let len = std::fs::metadata(path)
        .map_err(|e| IoError::access(path, "cannot open", &e))?
        .len();
    if len == 0 {
        return Err(IoError::new(path, IoErrorKind::Empty, "the file is empty"));
    }
    budget::check_bytes(path, "reading the DICOM file", len)?;
    let bytes = std::fs::read(path).map_err(|e| IoError::access(path, "cannot read", &e))?;
    crate::dicom::lengths::check_declared_lengths(path, &bytes)?;
    let parsed = guard::quietly(|| {
        let options = OpenFileOptions::new();
        let options = if until_pixels {
            options.read_until(tags::PIXEL_DATA)
        } else {
            options
        };
        // The bytes already read for the length check: the file is read once.
        options.from_reader(bytes.as_slice())
    });
    match parsed {
        Some(Ok(object)) => Ok(object),
        _ if !looks_like_dicom(path) => Err(IoError::malformed(
            path,
            "not a DICOM file: no DICM marker after the 128-byte preamble",
        )),
        _ => Err(IoError::malformed(
            path,
            "the DICOM data set is corrupt or truncated and cannot be parsed",
        )),
    }
}

/// A text attribute, trimmed; empty when absent.
pub(crate) fn text(obj: &InMemDicomObject, tag: dicom_object::Tag) -> String {
    obj.element_opt(tag)
        .ok()
        .flatten()
        .and_then(|e| e.to_str().ok())
        .map(|s| {
            s.trim_matches(|c: char| c.is_whitespace() || c == '\0')
                .to_string()
        })
        .unwrap_or_default()
}

/// A multi-valued decimal attribute with exactly `n` finite values, or `None` when absent;
/// present but wrong is an error naming the attribute.
pub(crate) fn decimals(
    obj: &InMemDicomObject,
    path: &Path,
    tag: dicom_object::Tag,
    name: &str,
    n: usize,
) -> Result<Option<Vec<f64>>, IoError> {
    let Some(element) = obj.element_opt(tag).ok().flatten() else {
        return Ok(None);
    };
    match element.to_multi_float64() {
        Ok(v) if v.len() == n && v.iter().all(|x| x.is_finite()) => Ok(Some(v)),
        _ => Err(IoError::malformed(
            path,
            format!("{name} must hold {n} finite numbers"),
        )),
    }
}

/// Rows or Columns: present, positive.
pub(crate) fn dimension(
    obj: &InMemDicomObject,
    path: &Path,
    tag: dicom_object::Tag,
    name: &str,
) -> Result<u32, IoError> {
    obj.element_opt(tag)
        .ok()
        .flatten()
        .and_then(|e| e.to_int::<u32>().ok())
        .filter(|&n| n > 0)
        .ok_or_else(|| IoError::malformed(path, format!("{name} is missing or zero: not an image")))
}

/// The header of one slice.
fn read_header(path: &Path) -> Result<SliceHeader, IoError> {
    let obj = open(path, true)?;
    let rows = dimension(&obj, path, tags::ROWS, "Rows")?;
    let columns = dimension(&obj, path, tags::COLUMNS, "Columns")?;
    if obj.meta().media_storage_sop_class_uid() == crate::SEGMENTATION_STORAGE {
        return Err(IoError::unsupported(
            path,
            "a DICOM Segmentation is a label map, not a scan: read it as labels (voxlod labels)",
        ));
    }
    let frames = text(&obj, tags::NUMBER_OF_FRAMES);
    if !frames.is_empty() && frames != "1" {
        return Err(IoError::unsupported(
            path,
            format!("a multi-frame image ({frames} frames) is not supported; give a series of single-frame slices"),
        ));
    }
    let position = decimals(
        &obj,
        path,
        tags::IMAGE_POSITION_PATIENT,
        "ImagePositionPatient",
        3,
    )?
    .map(|v| DVec3::new(v[0], v[1], v[2]));
    let orientation = decimals(
        &obj,
        path,
        tags::IMAGE_ORIENTATION_PATIENT,
        "ImageOrientationPatient",
        6,
    )?
    .map(|v| [DVec3::new(v[0], v[1], v[2]), DVec3::new(v[3], v[4], v[5])]);
    let spacing = decimals(&obj, path, tags::PIXEL_SPACING, "PixelSpacing", 2)?
        .unwrap_or_else(|| vec![1.0, 1.0]);
    if spacing.iter().any(|s| *s <= 0.0) {
        return Err(IoError::malformed(path, "PixelSpacing must be positive"));
    }
    let thickness = decimals(&obj, path, tags::SLICE_THICKNESS, "SliceThickness", 1)
        .ok()
        .flatten()
        .map(|v| v[0]);
    Ok(SliceHeader {
        series: text(&obj, tags::SERIES_INSTANCE_UID),
        description: text(&obj, tags::SERIES_DESCRIPTION),
        modality: text(&obj, tags::MODALITY),
        rows,
        columns,
        geometry: SliceGeometry {
            path: path.to_path_buf(),
            position,
            orientation,
            pixel_spacing: [spacing[0], spacing[1]],
            thickness,
        },
    })
}

/// The headers of every file, grouped by series.
fn read_headers(inputs: &[PathBuf]) -> Result<BTreeMap<String, Vec<SliceHeader>>, IoError> {
    let files = collect_files(inputs)?;
    let mut series: BTreeMap<String, Vec<SliceHeader>> = BTreeMap::new();
    for file in &files {
        let header = read_header(file)?;
        series
            .entry(header.series.clone())
            .or_default()
            .push(header);
    }
    Ok(series)
}

/// The series in the inputs, with their slice counts and descriptions.
pub fn list_dicom_series(inputs: &[PathBuf]) -> Result<Vec<SeriesSummary>, IoError> {
    Ok(read_headers(inputs)?
        .into_iter()
        .map(|(uid, slices)| SeriesSummary {
            slices: slices.len(),
            description: slices[0].description.clone(),
            modality: slices[0].modality.clone(),
            uid,
        })
        .collect())
}

fn describe(all: &BTreeMap<String, Vec<SliceHeader>>) -> String {
    all.iter()
        .map(|(uid, s)| {
            let d = &s[0].description;
            format!(
                "{uid} ({} slices{}{})",
                s.len(),
                if d.is_empty() { "" } else { ", " },
                d
            )
        })
        .collect::<Vec<_>>()
        .join("; ")
}

/// The slices of the series to read: the one asked for, or the only one.
fn choose_series(
    name: &Path,
    mut all: BTreeMap<String, Vec<SliceHeader>>,
    wanted: Option<&str>,
) -> Result<Vec<SliceHeader>, IoError> {
    match wanted {
        Some(uid) => all.remove(uid).ok_or_else(|| {
            IoError::malformed(
                name,
                format!("no series {uid}; the input holds: {}", describe(&all)),
            )
        }),
        None if all.len() == 1 => Ok(all.into_values().next().unwrap_or_default()),
        None => Err(IoError::unsupported(
            name,
            format!(
                "{} series are mixed here; choose one with --series UID: {}",
                all.len(),
                describe(&all)
            ),
        )),
    }
}

/// Reads one series of the inputs (folders or files) as a volume in LPS.
pub fn read_dicom_series(inputs: &[PathBuf], options: &DicomOptions) -> Result<Volume, IoError> {
    let name = inputs.first().cloned().unwrap_or_default();
    let all = read_headers(inputs)?;
    let headers = choose_series(&name, all, options.series.as_deref())?;
    let (rows, columns) = (headers[0].rows, headers[0].columns);
    if let Some(odd) = headers
        .iter()
        .find(|h| (h.rows, h.columns) != (rows, columns))
    {
        return Err(IoError::unsupported(
            &odd.geometry.path,
            format!(
                "it is {}x{} pixels where the series' first slice is {columns}x{rows}: mixed sizes",
                odd.columns, odd.rows
            ),
        ));
    }
    let mut geometry: Vec<SliceGeometry> = headers.into_iter().map(|h| h.geometry).collect();
    let tolerance = SpacingTolerance {
        relative: options.spacing_tolerance,
    };
    let world = stack(&name, &mut geometry, tolerance)?;
    let dims = [columns as usize, rows as usize, geometry.len()];
    let count = (dims[0] as u64) * (dims[1] as u64) * (dims[2] as u64);
    budget::check_count(&name, "the samples of the DICOM series", count, 4)?;
    let mut values: Vec<f32> = memory::zeroed_vec(count as usize);
    let per_slice = dims[0] * dims[1];
    for (k, slice) in geometry.iter().enumerate() {
        let samples = decode_slice(&slice.path, rows, columns)?;
        values[k * per_slice..(k + 1) * per_slice].copy_from_slice(&samples);
    }
    let (grid, orientation) = world
        .split(dims)
        .map_err(|e| IoError::from_core(&name, e))?;
    Volume::from_vec(grid, values)
        .map(|v| v.oriented(orientation))
        .map_err(|e| IoError::from_core(&name, e))
}

/// The samples of one slice after the modality LUT (rescale slope and intercept).
fn decode_slice(path: &Path, rows: u32, columns: u32) -> Result<Vec<f32>, IoError> {
    let obj = open(path, false)?;
    let bits = obj
        .element_opt(tags::BITS_ALLOCATED)
        .ok()
        .flatten()
        .and_then(|e| e.to_int::<u64>().ok())
        .unwrap_or(16);
    let bytes_each = bits.div_ceil(8).max(1) * 2 + 4;
    budget::check_count(
        path,
        "the pixels of the slice",
        u64::from(rows) * u64::from(columns),
        bytes_each,
    )?;
    let decoded = guard::quietly(|| {
        let pixels = obj.decode_pixel_data().ok()?;
        if pixels.rows() != rows || pixels.columns() != columns || pixels.samples_per_pixel() != 1 {
            return Some(Err(()));
        }
        pixels.to_vec_frame::<f32>(0).ok().map(Ok)
    });
    match decoded {
        Some(Some(Ok(samples))) if samples.len() == (rows * columns) as usize => {
            if samples.iter().any(|v| !v.is_finite()) {
                return Err(IoError::new(path, IoErrorKind::NonFinite, "a rescaled sample is not finite"));
            }
            Ok(samples)
        }
        Some(Some(Err(()))) => Err(IoError::unsupported(
            path,
            "the pixel data is not one grey sample per pixel of the size Rows and Columns give (colour images are not volumes)",
        )),
        _ => Err(IoError::malformed(
            path,
            format!(
                "the pixel data cannot be decoded (transfer syntax {}): missing, truncated, or a compression without a pure-Rust decoder",
                obj.meta().transfer_syntax().trim_end_matches('\0')
            ),
        )),
    }
}
