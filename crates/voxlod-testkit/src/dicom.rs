//! DICOM slices written in code (with dicom-object), for the series reader's tests: any
//! position, orientation, spacing, rescale and series, uncompressed explicit VR little endian.

use std::path::Path;

use dicom_core::{DataElement, PrimitiveValue, VR};
use dicom_dictionary_std::tags;
use dicom_object::{FileMetaTableBuilder, InMemDicomObject};

/// One CT slice to write.
#[derive(Clone, Debug)]
pub struct Slice {
    pub series_uid: String,
    pub instance: u32,
    pub rows: u16,
    pub columns: u16,
    /// Between rows, then between columns (DICOM's order).
    pub pixel_spacing: [f64; 2],
    pub position: [f64; 3],
    /// Row direction, then column direction.
    pub orientation: [f64; 6],
    pub slope: f64,
    pub intercept: f64,
    /// Stored values, row by row (`rows * columns` of them).
    pub stored: Vec<u16>,
}

fn text(obj: &mut InMemDicomObject, tag: dicom_core::Tag, vr: VR, value: &str) {
    obj.put(DataElement::new(tag, vr, PrimitiveValue::from(value)));
}

fn decimals(values: &[f64]) -> String {
    values
        .iter()
        .map(|v| format!("{v}"))
        .collect::<Vec<_>>()
        .join("\\")
}

/// Writes `slice` as a DICOM Part 10 file at `path`.
pub fn write_slice(path: &Path, slice: &Slice) {
    let sop_uid = format!("{}.{}", slice.series_uid, slice.instance + 1000);
    let mut obj = InMemDicomObject::new_empty();
    text(
        &mut obj,
        tags::SOP_CLASS_UID,
        VR::UI,
        "1.2.840.10008.5.1.4.1.1.2",
    );
    text(&mut obj, tags::SOP_INSTANCE_UID, VR::UI, &sop_uid);
    text(&mut obj, tags::MODALITY, VR::CS, "CT");
    text(
        &mut obj,
        tags::SERIES_INSTANCE_UID,
        VR::UI,
        &slice.series_uid,
    );
    text(
        &mut obj,
        tags::INSTANCE_NUMBER,
        VR::IS,
        &slice.instance.to_string(),
    );
    text(
        &mut obj,
        tags::IMAGE_POSITION_PATIENT,
        VR::DS,
        &decimals(&slice.position),
    );
    text(
        &mut obj,
        tags::IMAGE_ORIENTATION_PATIENT,
        VR::DS,
        &decimals(&slice.orientation),
    );
    text(
        &mut obj,
        tags::PIXEL_SPACING,
        VR::DS,
        &decimals(&slice.pixel_spacing),
    );
    text(
        &mut obj,
        tags::RESCALE_SLOPE,
        VR::DS,
        &decimals(&[slice.slope]),
    );
    text(
        &mut obj,
        tags::RESCALE_INTERCEPT,
        VR::DS,
        &decimals(&[slice.intercept]),
    );
    text(
        &mut obj,
        tags::PHOTOMETRIC_INTERPRETATION,
        VR::CS,
        "MONOCHROME2",
    );
    let us = |v: u16| PrimitiveValue::from(v);
    obj.put(DataElement::new(tags::SAMPLES_PER_PIXEL, VR::US, us(1)));
    obj.put(DataElement::new(tags::ROWS, VR::US, us(slice.rows)));
    obj.put(DataElement::new(tags::COLUMNS, VR::US, us(slice.columns)));
    obj.put(DataElement::new(tags::BITS_ALLOCATED, VR::US, us(16)));
    obj.put(DataElement::new(tags::BITS_STORED, VR::US, us(16)));
    obj.put(DataElement::new(tags::HIGH_BIT, VR::US, us(15)));
    obj.put(DataElement::new(tags::PIXEL_REPRESENTATION, VR::US, us(0)));
    let pixels: Vec<u8> = slice.stored.iter().flat_map(|v| v.to_le_bytes()).collect();
    obj.put(DataElement::new(
        tags::PIXEL_DATA,
        VR::OW,
        PrimitiveValue::from(pixels),
    ));
    let meta = FileMetaTableBuilder::new()
        .transfer_syntax("1.2.840.10008.1.2.1")
        .media_storage_sop_class_uid("1.2.840.10008.5.1.4.1.1.2")
        .media_storage_sop_instance_uid(&sop_uid);
    obj.with_meta(meta)
        .expect("a complete file meta group")
        .write_to_file(path)
        .expect("the slice is written");
}

/// A series of `slices` axial slices of `size × size` pixels through a ball of `radius` mm
/// centred at `centre` (LPS, mm), 1000 HU inside and −1000 HU outside, stored as
/// `(HU − intercept) / slope`; the in-plane axes are turned by `angle` radians about z.
pub fn ball_series(
    uid: &str,
    size: u16,
    slices: u32,
    spacing: [f64; 3],
    angle: f64,
    centre: [f64; 3],
    radius: f64,
) -> Vec<Slice> {
    let (slope, intercept) = (2.0, -1024.0);
    let row = [angle.cos(), angle.sin(), 0.0];
    let col = [-angle.sin(), angle.cos(), 0.0];
    let origin = [-40.0, -35.0, -30.0];
    (0..slices)
        .map(|k| {
            let z = origin[2] + k as f64 * spacing[2];
            let position = [origin[0], origin[1], z];
            let mut stored = Vec::with_capacity(size as usize * size as usize);
            for r in 0..size as usize {
                for c in 0..size as usize {
                    let (x, y) = (c as f64 * spacing[0], r as f64 * spacing[1]);
                    let p = [
                        position[0] + row[0] * x + col[0] * y,
                        position[1] + row[1] * x + col[1] * y,
                        z,
                    ];
                    let d2: f64 = (0..3).map(|a| (p[a] - centre[a]).powi(2)).sum();
                    let hu = if d2 <= radius * radius {
                        1000.0
                    } else {
                        -1000.0
                    };
                    stored.push(((hu - intercept) / slope) as u16);
                }
            }
            Slice {
                series_uid: uid.to_string(),
                instance: k + 1,
                rows: size,
                columns: size,
                pixel_spacing: [spacing[1], spacing[0]],
                position,
                orientation: [row[0], row[1], row[2], col[0], col[1], col[2]],
                slope,
                intercept,
                stored,
            }
        })
        .collect()
}
