//! The DICOM Segmentation reader against SEG files written in the test (dicom-object): a ball
//! and a box that touch, on an oblique grid, frames shuffled, 85 by 71 pixels (so frames do
//! not end on a byte), BINARY and FRACTIONAL; and broken ones, each refused in plain words.

use std::path::{Path, PathBuf};

use dicom_pixeldata::PixelDecoder;
use glam::DVec3;
use voxlod_core::{Frame, LabelVolume};
use voxlod_io::{read_label_map, IoErrorKind, LabelMap};
use voxlod_testkit::dicom_seg::{inside, oblique_axes, phantom_seg, write_seg, Kind, Seg, PHANTOM};

fn write(dir: &Path, name: &str, seg: &Seg) -> PathBuf {
    let path = dir.join(name);
    write_seg(&path, seg);
    path
}

/// Centre (world) and count of the voxels holding `label`.
fn label_centroid(map: &LabelVolume, label: u32) -> (DVec3, usize) {
    let world = map.world();
    let [nx, ny, _] = map.grid.dims;
    let (mut sum, mut n) = (DVec3::ZERO, 0usize);
    for (index, &v) in map.values.iter().enumerate() {
        if v == label {
            let (i, j, k) = (index % nx, index / nx % ny, index / (nx * ny));
            sum += world.index_to_world(DVec3::new(i as f64, j as f64, k as f64));
            n += 1;
        }
    }
    (sum / n as f64, n)
}

/// The inside pixels of the frames of `segment`, as written.
fn written_inside(seg: &Seg, segment: u16) -> usize {
    seg.frames
        .iter()
        .filter(|f| f.segment == segment)
        .map(|f| f.pixels.iter().filter(|&&v| inside(seg.kind, v)).count())
        .sum()
}

/// The voxel count in the overlap warning of segments 1 and 2.
fn overlap(map: &LabelMap) -> usize {
    assert_eq!(map.warnings.len(), 1, "{:?}", map.warnings);
    let w = &map.warnings[0];
    assert!(w.contains("segments 1 and 2 overlap in"), "{w}");
    assert!(w.contains("(2) is kept"), "{w}");
    w.split("overlap in ")
        .nth(1)
        .unwrap()
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap()
}

#[test]
fn a_binary_seg_lands_where_the_ball_and_the_box_are_with_names_and_colours() {
    let dir = tempfile::tempdir().unwrap();
    let seg = phantom_seg(Kind::Binary);
    assert_ne!(
        seg.rows as usize * seg.columns as usize % 8,
        0,
        "frames must straddle bytes"
    );
    let path = write(dir.path(), "seg.dcm", &seg);
    let map = read_label_map(&path).unwrap();
    let volume = &map.labels;
    assert_eq!(
        volume.grid.dims[..2],
        [seg.columns as usize, seg.rows as usize]
    );
    assert_eq!(volume.orientation.frame, Frame::Lps);
    let world = volume.world();
    assert!(
        (world.spacing - DVec3::new(0.9, 1.1, 1.5)).length() < 1e-6,
        "{}",
        world.spacing
    );
    let [row, col, normal] = oblique_axes().map(DVec3::from);
    assert!((world.direction.x_axis - row).length() < 1e-6);
    assert!((world.direction.y_axis - col).length() < 1e-6);
    assert!((world.direction.z_axis - normal).length() < 1e-6);
    // Names and colours (sRGB red and green, given as CIELab).
    let names: Vec<&str> = map.table.iter().map(|l| l.name.as_str()).collect();
    assert_eq!(names, ["ball", "box"]);
    assert_eq!(
        map.table.iter().map(|l| l.value).collect::<Vec<_>>(),
        [1, 2]
    );
    for (label, rgb) in map.table.iter().zip([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]) {
        let c = label.color.unwrap();
        assert!(
            (0..3).all(|a| (c[a] - rgb[a]).abs() < 0.01),
            "{c:?} for {}",
            label.name
        );
    }
    // Every written bit is where the frame says: the box (painted last) exactly, the ball but
    // for the cap the box takes, which the warning counts.
    let shared = overlap(&map);
    assert!(shared > 0);
    let (ball, n_ball) = label_centroid(volume, 1);
    let (cube, n_box) = label_centroid(volume, 2);
    assert_eq!(n_box, written_inside(&seg, 2));
    assert_eq!(n_ball + shared, written_inside(&seg, 1));
    // Against the shapes: volumes within 3 %, centres within a voxel.
    let voxel = 0.9 * 1.1 * 1.5;
    let ball_mm3 = 4.0 / 3.0 * std::f64::consts::PI * PHANTOM.ball_radius.powi(3);
    let box_mm3: f64 = (0..3)
        .map(|a| PHANTOM.box_max[a] - PHANTOM.box_min[a])
        .product();
    let ratio = (n_ball + shared) as f64 * voxel / ball_mm3;
    assert!((ratio - 1.0).abs() < 0.03, "ball volume ratio {ratio}");
    let ratio = n_box as f64 * voxel / box_mm3;
    assert!((ratio - 1.0).abs() < 0.03, "box volume ratio {ratio}");
    assert!(
        (ball - DVec3::from(PHANTOM.ball_centre)).length() < 0.9,
        "{ball}"
    );
    assert!(
        (cube - DVec3::from(PHANTOM.box_centre())).length() < 0.9,
        "{cube}"
    );
}

#[test]
fn a_fractional_seg_thresholds_at_half_the_maximum_and_matches_the_binary_one() {
    let dir = tempfile::tempdir().unwrap();
    let binary = read_label_map(&write(dir.path(), "b.dcm", &phantom_seg(Kind::Binary))).unwrap();
    for max in [200, 255] {
        let seg = phantom_seg(Kind::Fractional(max));
        // Values one below the threshold and at it are both written.
        let values: Vec<u8> = seg.frames.iter().flat_map(|f| f.pixels.clone()).collect();
        let half = max.div_ceil(2);
        assert!(values.contains(&half) && values.contains(&(half - 1)));
        let map = read_label_map(&write(dir.path(), &format!("f{max}.dcm"), &seg)).unwrap();
        assert_eq!(map.labels, binary.labels, "max {max}");
        assert_eq!(map.table, binary.table);
    }
}

#[test]
fn a_folder_with_one_seg_reads_it_and_two_are_listed() {
    let dir = tempfile::tempdir().unwrap();
    let seg = phantom_seg(Kind::Binary);
    let file = write(dir.path(), "a.dcm", &seg);
    std::fs::write(dir.path().join("notes.txt"), "not DICOM").unwrap();
    let from_folder = read_label_map(dir.path()).unwrap();
    assert_eq!(from_folder.labels, read_label_map(&file).unwrap().labels);
    write(dir.path(), "b.dcm", &seg);
    let e = read_label_map(dir.path()).unwrap_err();
    assert!(e.message.contains("2 DICOM Segmentation files"), "{e}");
    assert!(
        e.message.contains("a.dcm") && e.message.contains("b.dcm"),
        "{e}"
    );
}

#[test]
fn left_out_empty_planes_are_put_back_but_gaps_without_a_step_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let whole = phantom_seg(Kind::Binary);
    let full = read_label_map(&write(dir.path(), "whole.dcm", &whole)).unwrap();
    // Leave out every frame of one middle plane, as a writer does with empty frames.
    let mut positions: Vec<[f64; 3]> = whole.frames.iter().map(|f| f.position).collect();
    let normal = DVec3::from(oblique_axes()[2]);
    positions.sort_by(|a, b| {
        DVec3::from(*a)
            .dot(normal)
            .total_cmp(&DVec3::from(*b).dot(normal))
    });
    positions.dedup();
    let gone = positions[positions.len() / 2];
    let mut holed = whole.clone();
    holed.frames.retain(|f| f.position != gone);
    let map = read_label_map(&write(dir.path(), "holed.dcm", &holed)).unwrap();
    assert_eq!(map.labels.grid, full.labels.grid);
    let plane = positions.len() / 2;
    let per = whole.columns as usize * whole.rows as usize;
    let (a, b) = (&map.labels.values, &full.labels.values);
    assert!(a[plane * per..(plane + 1) * per].iter().all(|&v| v == 0));
    assert!(b[plane * per..(plane + 1) * per].iter().any(|&v| v != 0));
    assert_eq!(a[..plane * per], b[..plane * per]);
    assert_eq!(a[(plane + 1) * per..], b[(plane + 1) * per..]);
    // Without SpacingBetweenSlices the gap is missing planes.
    holed.spacing_between = None;
    let path = write(dir.path(), "nostep.dcm", &holed);
    let e = read_label_map(&path).unwrap_err();
    assert!(e.message.contains("missing"), "{e}");
    // A frame off the planes' rhythm: unequal spacing.
    let mut uneven = whole.clone();
    let moved = uneven
        .frames
        .iter()
        .position(|f| f.position == gone)
        .unwrap();
    let p = &mut uneven.frames[moved].position;
    *p = [0, 1, 2].map(|a| p[a] + normal[a] * 0.4);
    let e = read_label_map(&write(dir.path(), "uneven.dcm", &uneven)).unwrap_err();
    assert!(e.message.contains("uneven"), "{e}");
}

/// Asserts a clean error: of `kind`, naming the file, containing `words`, on one line.
fn refused(path: &Path, kind: IoErrorKind, words: &str) {
    let e = read_label_map(path).unwrap_err();
    let text = e.to_string();
    assert_eq!(e.kind, kind, "{text}");
    assert!(text.starts_with(&path.display().to_string()), "{text}");
    assert!(text.contains(words), "{text}");
    assert!(
        !text.contains('\n') && !text.contains("::") && !text.contains("Error("),
        "{text}"
    );
}

#[test]
fn broken_segs_are_refused_in_plain_words_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let good = phantom_seg(Kind::Binary);
    let mut short = good.clone();
    short.pixel_bytes = Some(1000);
    refused(
        &write(dir.path(), "short.dcm", &short),
        IoErrorKind::Truncated,
        "PixelData holds 1000 bytes",
    );
    write_too_long(dir.path(), &good);
    let mut no_groups = good.clone();
    no_groups.omit_per_frame = true;
    refused(
        &write(dir.path(), "groups.dcm", &no_groups),
        IoErrorKind::Malformed,
        "Per-Frame Functional Groups Sequence (5200,9230) is missing",
    );
    let mut stray = good.clone();
    stray.frames[3].segment = 9;
    refused(
        &write(dir.path(), "stray.dcm", &stray),
        IoErrorKind::Malformed,
        "refers to segment 9, which the Segment Sequence does not define",
    );
    let mut jpeg = good.clone();
    jpeg.encapsulated = Some("1.2.840.10008.1.2.4.50".into());
    refused(
        &write(dir.path(), "jpeg.dcm", &jpeg),
        IoErrorKind::Unsupported,
        "1-bit pixel data in a compressed transfer syntax (1.2.840.10008.1.2.4.50)",
    );
    // A length that claims 4 GiB in a small file is refused before any parser makes room for
    // it (dicom-parser would allocate it first).
    let path = write(dir.path(), "huge.dcm", &good);
    let mut all = std::fs::read(&path).unwrap();
    let header = b"\xe0\x7f\x10\x00OB\x00\x00";
    let at = all.windows(8).position(|w| w == header).unwrap() + 8;
    all[at..at + 4].copy_from_slice(&0xFFFF_FFF0u32.to_le_bytes());
    std::fs::write(&path, &all).unwrap();
    refused(
        &path,
        IoErrorKind::Truncated,
        "declares 4294967280 bytes but only",
    );
    // A file cut short is a clean error too.
    let path = write(dir.path(), "cut.dcm", &good);
    let all = std::fs::read(&path).unwrap();
    std::fs::write(&path, &all[..all.len() / 2]).unwrap();
    let e = read_label_map(&path).unwrap_err();
    assert!(
        e.to_string().starts_with(&path.display().to_string()),
        "{e}"
    );
}

/// A SEG whose NumberOfFrames and functional groups name three frames fewer than its pixel
/// data holds is refused as a frame count that does not match.
fn write_too_long(dir: &Path, seg: &Seg) {
    let path = dir.join("long.dcm");
    write_seg(&path, seg);
    let mut obj = dicom_object::open_file(&path).unwrap();
    let groups = obj
        .element(dicom_dictionary_std::tags::PER_FRAME_FUNCTIONAL_GROUPS_SEQUENCE)
        .unwrap()
        .items()
        .unwrap()
        .to_vec();
    let kept = groups[..groups.len() - 3].to_vec();
    obj.put(dicom_core::DataElement::new(
        dicom_dictionary_std::tags::PER_FRAME_FUNCTIONAL_GROUPS_SEQUENCE,
        dicom_core::VR::SQ,
        dicom_core::value::DataSetSequence::from(kept.clone()),
    ));
    obj.put(dicom_core::DataElement::new(
        dicom_dictionary_std::tags::NUMBER_OF_FRAMES,
        dicom_core::VR::IS,
        dicom_core::PrimitiveValue::from(kept.len().to_string()),
    ));
    obj.write_to_file(&path).unwrap();
    refused(
        &path,
        IoErrorKind::Malformed,
        "NumberOfFrames does not match the pixel data",
    );
}

/// The reason the reader unpacks 1-bit frames itself: dicom-pixeldata 0.10 takes every frame to
/// start on a byte. When this test fails, the crate has been fixed and `src/dicom/seg.rs` may use
/// it for 1-bit data again.
#[test]
fn dicom_pixeldata_still_misreads_frames_that_do_not_end_on_a_byte() {
    let dir = tempfile::tempdir().unwrap();
    let seg = phantom_seg(Kind::Binary);
    let path = write(dir.path(), "seg.dcm", &seg);
    let obj = dicom_object::open_file(&path).unwrap();
    let differs = (1..seg.frames.len()).any(|k| {
        let decoded = obj.decode_pixel_data_frame(k as u32).unwrap();
        let ones: Vec<bool> = decoded.data().iter().map(|&v| v != 0).collect();
        let written: Vec<bool> = seg.frames[k].pixels.iter().map(|&v| v == 1).collect();
        ones != written
    });
    assert!(
        differs,
        "dicom-pixeldata now unpacks packed 1-bit frames correctly"
    );
}

/// pydicom (an independent reader, which unpacks frames that straddle bytes since 3.0) sees
/// the same bits in every frame of the written SEG as the reader paints: the packing convention
/// (least significant bit first, no padding between frames) is not only ours.
#[test]
fn pydicom_reads_the_same_frames_from_the_written_seg() {
    let dir = tempfile::tempdir().unwrap();
    let seg = phantom_seg(Kind::Binary);
    let path = write(dir.path(), "seg.dcm", &seg);
    let script = "import sys, pydicom\n\
        ds = pydicom.dcmread(sys.argv[1])\n\
        a = ds.pixel_array\n\
        for k, g in enumerate(ds.PerFrameFunctionalGroupsSequence):\n\
        \x20   s = g.SegmentIdentificationSequence[0].ReferencedSegmentNumber\n\
        \x20   print(s, int(a[k].sum()), int(a[k].ravel().nonzero()[0].sum()))\n";
    let Some(out) = voxlod_testkit::peers::run_python(script, &[path.as_os_str()]) else {
        return;
    };
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines.len(), seg.frames.len());
    for (line, frame) in lines.iter().zip(&seg.frames) {
        let fields: Vec<&str> = line.split(' ').collect();
        assert_eq!(fields[0], frame.segment.to_string());
        let ones = frame.pixels.iter().filter(|&&v| v == 1).count();
        assert_eq!(fields[1], ones.to_string());
        // Where the ones are: the sum of their indices.
        let ones_at: usize = (0..frame.pixels.len())
            .filter(|&i| frame.pixels[i] == 1)
            .sum();
        assert_eq!(fields[2], ones_at.to_string());
    }
    // And the map the reader makes holds, per segment, those bits (the overlap aside).
    let map = read_label_map(&path).unwrap();
    let (_, n_box) = label_centroid(&map.labels, 2);
    let box_ones: usize = lines
        .iter()
        .filter(|l| l.starts_with("2 "))
        .map(|l| l.split(' ').nth(1).unwrap().parse::<usize>().unwrap())
        .sum();
    assert_eq!(n_box, box_ones);
}

/// highdicom's Python (`VOXLOD_HIGHDICOM_PYTHON`, else `~/.cache/voxlod-highdicom/bin/python`:
/// a virtual environment with `pip install highdicom`), or a recorded skip.
fn highdicom_python() -> Option<PathBuf> {
    let python = std::env::var_os("VOXLOD_HIGHDICOM_PYTHON")
        .map(PathBuf::from)
        .or_else(|| {
            std::env::var_os("HOME")
                .map(|h| PathBuf::from(h).join(".cache/voxlod-highdicom/bin/python"))
        })
        .filter(|p| p.is_file());
    if python.is_none() {
        voxlod_testkit::skips::skip(
            "no highdicom: make a venv at ~/.cache/voxlod-highdicom with `pip install highdicom` (or set VOXLOD_HIGHDICOM_PYTHON)",
        );
    }
    python
}

/// A SEG that highdicom (an independent writer) makes from a shuffled oblique CT series, BINARY
/// (45x37 frames straddling bytes, empty frames left out) and FRACTIONAL: the reader finds every
/// label's voxels and their world centroid as the script computes them from its masks.
#[test]
fn a_seg_written_by_highdicom_is_placed_voxel_for_voxel() {
    let Some(python) = highdicom_python() else {
        return;
    };
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/highdicom_seg.py");
    let dir = tempfile::tempdir().unwrap();
    for (kind, bits) in [("binary", "1"), ("fractional", "8")] {
        let path = dir.path().join(format!("{kind}.dcm"));
        let out = std::process::Command::new(&python)
            .arg(&script)
            .arg(&path)
            .arg(kind)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let out = String::from_utf8(out.stdout).unwrap();
        let lines: Vec<Vec<&str>> = out.lines().map(|l| l.split(' ').collect()).collect();
        assert_eq!(lines[3][2], bits, "{out}");
        let map = read_label_map(&path).unwrap();
        assert_eq!(map.labels.orientation.frame, Frame::Lps);
        let names: Vec<&str> = map.table.iter().map(|l| l.name.as_str()).collect();
        assert_eq!(names, ["ball", "box"]);
        for (label, rgb) in map.table.iter().zip([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]) {
            let c = label.color.unwrap();
            assert!((0..3).all(|a| (c[a] - rgb[a]).abs() < 0.01), "{c:?}");
        }
        assert_eq!(overlap(&map).to_string(), lines[2][1], "{out}");
        for line in &lines[..2] {
            let (centre, n) = label_centroid(&map.labels, line[0].parse().unwrap());
            assert_eq!(n.to_string(), line[1], "label {}", line[0]);
            let expected: Vec<f64> = line[2..5].iter().map(|v| v.parse().unwrap()).collect();
            let expected = DVec3::new(expected[0], expected[1], expected[2]);
            assert!(
                (centre - expected).length() < 1e-3,
                "{centre} vs {expected}"
            );
        }
    }
}
