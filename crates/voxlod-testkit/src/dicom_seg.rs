//! DICOM Segmentation objects written in code (with dicom-object), for the SEG reader's tests:
//! any plane geometry, segments with names and CIELab colours, BINARY frames bit-packed across
//! frame boundaries (PS3.5 8.1.1) or FRACTIONAL bytes, and switches that break one thing at a
//! time. The phantom is a ball and a box that touch, on an oblique grid.

use std::path::Path;

use dicom_core::value::{DataSetSequence, PixelFragmentSequence};
use dicom_core::{DataElement, PrimitiveValue, VR};
use dicom_dictionary_std::tags;
use dicom_object::{FileMetaTableBuilder, InMemDicomObject};

/// SOP Class UID of Segmentation Storage.
pub const SEGMENTATION_STORAGE: &str = "1.2.840.10008.5.1.4.1.1.66.4";

/// One segment of the Segment Sequence.
#[derive(Clone, Debug)]
pub struct Segment {
    pub number: u16,
    pub label: String,
    /// RecommendedDisplayCIELabValue, DICOM's 16-bit scaling.
    pub lab: [u16; 3],
}

/// One frame: the segment it shows, where it lies, and its pixels row by row (0 or 1 for
/// BINARY, 0 to the maximum for FRACTIONAL).
#[derive(Clone, Debug)]
pub struct Frame {
    pub segment: u16,
    pub position: [f64; 3],
    pub pixels: Vec<u8>,
}

/// How the frames are stored.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Kind {
    /// BitsAllocated 1, packed.
    Binary,
    /// BitsAllocated 8 with this MaximumFractionalValue.
    Fractional(u8),
}

/// A segmentation to write.
#[derive(Clone, Debug)]
pub struct Seg {
    pub rows: u16,
    pub columns: u16,
    /// Row direction, then column direction.
    pub orientation: [f64; 6],
    /// Between rows, then between columns (DICOM's order).
    pub pixel_spacing: [f64; 2],
    pub spacing_between: Option<f64>,
    pub segments: Vec<Segment>,
    /// In the order they are written.
    pub frames: Vec<Frame>,
    pub kind: Kind,
    /// Leave out the Per-Frame Functional Groups Sequence.
    pub omit_per_frame: bool,
    /// Keep only this many bytes of the pixel data.
    pub pixel_bytes: Option<usize>,
    /// Write the pixel data encapsulated under this transfer syntax (its bytes as one fragment,
    /// not really compressed).
    pub encapsulated: Option<String>,
}

/// The bits of `values` (0 or not), least significant bit first, with no padding between
/// frames (PS3.5 8.1.1), the whole padded to an even length.
pub fn pack_bits(values: impl Iterator<Item = u8>) -> Vec<u8> {
    let mut bytes = Vec::new();
    for (i, v) in values.enumerate() {
        if i % 8 == 0 {
            bytes.push(0);
        }
        if v != 0 {
            *bytes.last_mut().unwrap() |= 1 << (i % 8);
        }
    }
    if bytes.len() % 2 == 1 {
        bytes.push(0);
    }
    bytes
}

fn text(obj: &mut InMemDicomObject, tag: dicom_core::Tag, vr: VR, value: &str) {
    obj.put(DataElement::new(tag, vr, PrimitiveValue::from(value)));
}

fn decimals(values: &[f64]) -> String {
    let text: Vec<String> = values.iter().map(|v| format!("{v:.6}")).collect();
    text.join("\\")
}

fn us(obj: &mut InMemDicomObject, tag: dicom_core::Tag, value: u16) {
    obj.put(DataElement::new(tag, VR::US, PrimitiveValue::from(value)));
}

/// A sequence attribute holding these items.
fn sequence(obj: &mut InMemDicomObject, tag: dicom_core::Tag, items: Vec<InMemDicomObject>) {
    obj.put(DataElement::new(tag, VR::SQ, DataSetSequence::from(items)));
}

/// A sequence of one item holding one text attribute.
fn one_item(tag: dicom_core::Tag, vr: VR, value: &str) -> Vec<InMemDicomObject> {
    let mut item = InMemDicomObject::new_empty();
    text(&mut item, tag, vr, value);
    vec![item]
}

fn segment_sequence(seg: &Seg) -> Vec<InMemDicomObject> {
    seg.segments
        .iter()
        .map(|s| {
            let mut item = InMemDicomObject::new_empty();
            us(&mut item, tags::SEGMENT_NUMBER, s.number);
            text(&mut item, tags::SEGMENT_LABEL, VR::LO, &s.label);
            text(&mut item, tags::SEGMENT_ALGORITHM_TYPE, VR::CS, "MANUAL");
            item.put(DataElement::new(
                tags::RECOMMENDED_DISPLAY_CIE_LAB_VALUE,
                VR::US,
                PrimitiveValue::U16(s.lab.to_vec().into()),
            ));
            item
        })
        .collect()
}

fn functional_groups(seg: &Seg, obj: &mut InMemDicomObject) {
    let mut shared = InMemDicomObject::new_empty();
    let orientation = one_item(
        tags::IMAGE_ORIENTATION_PATIENT,
        VR::DS,
        &decimals(&seg.orientation),
    );
    sequence(&mut shared, tags::PLANE_ORIENTATION_SEQUENCE, orientation);
    let mut measures = InMemDicomObject::new_empty();
    text(
        &mut measures,
        tags::PIXEL_SPACING,
        VR::DS,
        &decimals(&seg.pixel_spacing),
    );
    if let Some(s) = seg.spacing_between {
        text(
            &mut measures,
            tags::SPACING_BETWEEN_SLICES,
            VR::DS,
            &decimals(&[s]),
        );
        text(
            &mut measures,
            tags::SLICE_THICKNESS,
            VR::DS,
            &decimals(&[s]),
        );
    }
    sequence(&mut shared, tags::PIXEL_MEASURES_SEQUENCE, vec![measures]);
    sequence(obj, tags::SHARED_FUNCTIONAL_GROUPS_SEQUENCE, vec![shared]);
    if seg.omit_per_frame {
        return;
    }
    let per_frame = seg
        .frames
        .iter()
        .map(|f| {
            let mut group = InMemDicomObject::new_empty();
            let position = one_item(tags::IMAGE_POSITION_PATIENT, VR::DS, &decimals(&f.position));
            sequence(&mut group, tags::PLANE_POSITION_SEQUENCE, position);
            let mut id = InMemDicomObject::new_empty();
            us(&mut id, tags::REFERENCED_SEGMENT_NUMBER, f.segment);
            sequence(&mut group, tags::SEGMENT_IDENTIFICATION_SEQUENCE, vec![id]);
            group
        })
        .collect();
    sequence(obj, tags::PER_FRAME_FUNCTIONAL_GROUPS_SEQUENCE, per_frame);
}

fn pixel_data(seg: &Seg, obj: &mut InMemDicomObject) {
    let all = seg.frames.iter().flat_map(|f| f.pixels.iter().copied());
    let (bits, mut bytes) = match seg.kind {
        Kind::Binary => (1, pack_bits(all)),
        Kind::Fractional(max) => {
            us(obj, tags::MAXIMUM_FRACTIONAL_VALUE, u16::from(max));
            text(
                obj,
                tags::SEGMENTATION_FRACTIONAL_TYPE,
                VR::CS,
                "PROBABILITY",
            );
            let mut bytes: Vec<u8> = all.collect();
            if bytes.len() % 2 == 1 {
                bytes.push(0);
            }
            (8, bytes)
        }
    };
    let kind = if seg.kind == Kind::Binary {
        "BINARY"
    } else {
        "FRACTIONAL"
    };
    text(obj, tags::SEGMENTATION_TYPE, VR::CS, kind);
    for (tag, v) in [
        (tags::BITS_ALLOCATED, bits),
        (tags::BITS_STORED, bits),
        (tags::HIGH_BIT, bits - 1),
        (tags::SAMPLES_PER_PIXEL, 1),
        (tags::PIXEL_REPRESENTATION, 0),
        (tags::ROWS, seg.rows),
        (tags::COLUMNS, seg.columns),
    ] {
        us(obj, tag, v);
    }
    if let Some(n) = seg.pixel_bytes {
        bytes.truncate(n);
    }
    if seg.encapsulated.is_some() {
        let fragments = PixelFragmentSequence::new(Vec::<u32>::new(), vec![bytes]);
        obj.put(DataElement::new(tags::PIXEL_DATA, VR::OB, fragments));
    } else {
        obj.put(DataElement::new(
            tags::PIXEL_DATA,
            VR::OB,
            PrimitiveValue::from(bytes),
        ));
    }
}

/// Writes `seg` as a DICOM Part 10 file at `path`.
pub fn write_seg(path: &Path, seg: &Seg) {
    let sop_uid = "1.2.826.0.1.3680043.10.1390.7";
    let mut obj = InMemDicomObject::new_empty();
    text(&mut obj, tags::SOP_CLASS_UID, VR::UI, SEGMENTATION_STORAGE);
    text(&mut obj, tags::SOP_INSTANCE_UID, VR::UI, sop_uid);
    text(&mut obj, tags::MODALITY, VR::CS, "SEG");
    text(
        &mut obj,
        tags::SERIES_INSTANCE_UID,
        VR::UI,
        "1.2.826.0.1.3680043.10.1390.8",
    );
    text(
        &mut obj,
        tags::PHOTOMETRIC_INTERPRETATION,
        VR::CS,
        "MONOCHROME2",
    );
    text(
        &mut obj,
        tags::NUMBER_OF_FRAMES,
        VR::IS,
        &seg.frames.len().to_string(),
    );
    sequence(&mut obj, tags::SEGMENT_SEQUENCE, segment_sequence(seg));
    functional_groups(seg, &mut obj);
    pixel_data(seg, &mut obj);
    let syntax = seg.encapsulated.as_deref().unwrap_or("1.2.840.10008.1.2.1");
    let meta = FileMetaTableBuilder::new()
        .transfer_syntax(syntax)
        .media_storage_sop_class_uid(SEGMENTATION_STORAGE)
        .media_storage_sop_instance_uid(sop_uid);
    obj.with_meta(meta)
        .expect("a complete file meta group")
        .write_to_file(path)
        .expect("the segmentation is written");
}

/// The two structures of the phantom, in world (LPS) millimetres.
#[derive(Clone, Copy, Debug)]
pub struct Phantom {
    pub ball_centre: [f64; 3],
    pub ball_radius: f64,
    pub box_min: [f64; 3],
    pub box_max: [f64; 3],
}

/// A ball of radius 16 and a box that touches it (the box takes a 0.5 mm cap of the ball):
/// large enough, at about a millimetre a voxel, for the filter's pull on convex surfaces to
/// stay within 3 % of their volumes.
pub const PHANTOM: Phantom = Phantom {
    ball_centre: [-8.0, 2.0, 1.0],
    ball_radius: 16.0,
    box_min: [7.5, -6.0, -6.0],
    box_max: [29.5, 12.0, 10.0],
};

impl Phantom {
    /// The box's centre.
    pub fn box_centre(&self) -> [f64; 3] {
        [0, 1, 2].map(|a| (self.box_min[a] + self.box_max[a]) / 2.0)
    }

    /// How far inside the segment (1: ball, 2: box) a point is, in mm (negative outside).
    pub fn depth(&self, segment: u16, p: [f64; 3]) -> f64 {
        if segment == 1 {
            let d2: f64 = (0..3).map(|a| (p[a] - self.ball_centre[a]).powi(2)).sum();
            self.ball_radius - d2.sqrt()
        } else {
            (0..3)
                .map(|a| (p[a] - self.box_min[a]).min(self.box_max[a] - p[a]))
                .fold(f64::INFINITY, f64::min)
        }
    }
}

/// The oblique grid of the phantom: row direction, column direction, their normal.
pub fn oblique_axes() -> [[f64; 3]; 3] {
    let (a, b) = (0.5f64, 0.3f64);
    let row = [a.cos(), a.sin(), 0.0];
    let col = [-a.sin() * b.cos(), a.cos() * b.cos(), b.sin()];
    let normal = [
        row[1] * col[2] - row[2] * col[1],
        row[2] * col[0] - row[0] * col[2],
        row[0] * col[1] - row[1] * col[0],
    ];
    [row, col, normal]
}

/// The phantom as a SEG: 85 columns (0.9 mm apart) by 71 rows (1.1 mm), planes 1.5 mm apart
/// along an oblique normal; every non-empty frame of the ball (segment 1, "ball") and the box
/// (segment 2, "box"), in a shuffled order. FRACTIONAL frames hold at least half of `max`
/// exactly inside (more the deeper) and less outside.
pub fn phantom_seg(kind: Kind) -> Seg {
    let (rows, columns, planes) = (71u16, 85u16, 52usize);
    let (dx, dy, step) = (0.9, 1.1, 1.5);
    let [row, col, normal] = oblique_axes();
    let centre = [2.75, 2.0, 1.0];
    let half = [
        columns as f64 * dx / 2.0,
        rows as f64 * dy / 2.0,
        planes as f64 * step / 2.0,
    ];
    let origin: [f64; 3] =
        [0, 1, 2].map(|a| centre[a] - row[a] * half[0] - col[a] * half[1] - normal[a] * half[2]);
    let mut frames = Vec::new();
    for k in 0..planes {
        let position = [0, 1, 2].map(|a| origin[a] + normal[a] * step * k as f64);
        for segment in [1u16, 2] {
            let pixels: Vec<u8> = (0..rows as usize)
                .flat_map(|r| (0..columns as usize).map(move |c| (r, c)))
                .map(|(r, c)| {
                    let p = [0, 1, 2]
                        .map(|a| position[a] + row[a] * c as f64 * dx + col[a] * r as f64 * dy);
                    stored_value(kind, PHANTOM.depth(segment, p))
                })
                .collect();
            if pixels.iter().any(|&v| inside(kind, v)) {
                frames.push(Frame {
                    segment,
                    position,
                    pixels,
                });
            }
        }
    }
    // A fixed shuffle: neither file order nor segment order gives the planes' order.
    let n = frames.len();
    let coprime = |m: usize| (2..=m).all(|d| !m.is_multiple_of(d) || !n.is_multiple_of(d));
    let stride = (37..).find(|&m| coprime(m)).unwrap();
    let shuffled: Vec<Frame> = (0..n)
        .map(|i| frames[(i * stride + 11) % n].clone())
        .collect();
    Seg {
        rows,
        columns,
        orientation: [row[0], row[1], row[2], col[0], col[1], col[2]],
        pixel_spacing: [dy, dx],
        spacing_between: Some(step),
        segments: vec![
            // sRGB red and green in CIELab (L* 53.24, a* 80.09, b* 67.20; 87.73, −86.18, 83.18).
            Segment {
                number: 1,
                label: "ball".into(),
                lab: [34891, 53480, 50167],
            },
            Segment {
                number: 2,
                label: "box".into(),
                lab: [57497, 10747, 54273],
            },
        ],
        frames: shuffled,
        kind,
        omit_per_frame: false,
        pixel_bytes: None,
        encapsulated: None,
    }
}

/// Whether a stored value is inside (BINARY: 1; FRACTIONAL: at least half the maximum).
pub fn inside(kind: Kind, value: u8) -> bool {
    match kind {
        Kind::Binary => value == 1,
        Kind::Fractional(max) => 2 * u16::from(value) >= u16::from(max),
    }
}

/// The stored value of a pixel `depth` mm inside a segment.
fn stored_value(kind: Kind, depth: f64) -> u8 {
    match kind {
        Kind::Binary => u8::from(depth >= 0.0),
        Kind::Fractional(max) => {
            let half = u16::from(max).div_ceil(2) as f64;
            let v = if depth >= 0.0 {
                (half + depth * 4.0).min(f64::from(max))
            } else {
                (half - 1.0 + depth * 4.0).ceil().max(0.0)
            };
            v as u8
        }
    }
}
