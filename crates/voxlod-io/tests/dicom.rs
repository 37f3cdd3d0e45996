//! The DICOM series reader against series written in the test (dicom-object, by hand-chosen
//! geometry) and the pydicom CT slice of the shared data (against pydicom when it is there).

mod common;

use std::path::{Path, PathBuf};

use common::assert_error;
use glam::DVec3;
use voxlod_core::Frame;
use voxlod_io::{list_dicom_series, read_dicom_series, read_volume, DicomOptions, IoErrorKind};
use voxlod_testkit::dicom::{ball_series, write_slice, Slice};

const SPACING: [f64; 3] = [1.5, 1.25, 2.0];
const CENTRE: [f64; 3] = [-5.0, 3.0, 2.0];
const RADIUS: f64 = 12.0;

/// Writes the slices under scrambled names (so neither name nor write order gives the order).
fn write_series(dir: &Path, slices: &[Slice], tag: &str) {
    for (n, s) in slices.iter().enumerate() {
        let scrambled = (n * 7919 + 13) % 1009;
        write_slice(&dir.join(format!("{tag}{scrambled:04}.dcm")), s);
    }
}

fn phantom(dir: &Path) -> Vec<Slice> {
    let slices = ball_series("1.2.3.4.100", 48, 24, SPACING, 0.4, CENTRE, RADIUS);
    write_series(dir, &slices, "a");
    slices
}

/// Centre and volume of the samples above 0 HU, in world coordinates.
fn bright_centroid(volume: &voxlod_core::Volume) -> (DVec3, f64, usize) {
    let world = volume.world();
    let (mut sum, mut n) = (DVec3::ZERO, 0usize);
    for ((k, j, i), &v) in volume.values.indexed_iter() {
        if v > 0.0 {
            sum += world.index_to_world(DVec3::new(i as f64, j as f64, k as f64));
            n += 1;
        }
    }
    let voxel = volume.grid.spacing.iter().product::<f64>();
    (sum / n as f64, n as f64 * voxel, n)
}

#[test]
fn a_shuffled_oblique_series_lands_where_the_ball_is_in_hounsfield_units() {
    let dir = tempfile::tempdir().unwrap();
    phantom(dir.path());
    let volume = read_dicom_series(&[dir.path().to_path_buf()], &DicomOptions::default()).unwrap();
    assert_eq!(volume.grid.dims, [48, 48, 24]);
    assert_eq!(volume.orientation.frame, Frame::Lps);
    assert_eq!(volume.range(), Some((-1000.0, 1000.0)));
    let world = volume.world();
    assert!((world.spacing - DVec3::from(SPACING)).length() < 1e-9);
    assert!((world.direction.x_axis - DVec3::new(0.4f64.cos(), 0.4f64.sin(), 0.0)).length() < 1e-9);
    let (centre, volume_mm3, _) = bright_centroid(&volume);
    let voxel = SPACING[0].min(SPACING[1]).min(SPACING[2]);
    assert!((centre - DVec3::from(CENTRE)).length() < voxel, "{centre}");
    let ball = 4.0 / 3.0 * std::f64::consts::PI * RADIUS.powi(3);
    assert!(
        (volume_mm3 / ball - 1.0).abs() < 0.03,
        "{volume_mm3} vs {ball}"
    );
}

#[test]
fn a_second_series_must_be_chosen_and_is_listed() {
    let dir = tempfile::tempdir().unwrap();
    phantom(dir.path());
    let other = ball_series("1.2.3.4.200", 16, 3, [1.0; 3], 0.0, [0.0; 3], 4.0);
    write_series(dir.path(), &other, "b");
    let inputs = [dir.path().to_path_buf()];
    let err = read_dicom_series(&inputs, &DicomOptions::default()).unwrap_err();
    assert_eq!(err.kind, IoErrorKind::Unsupported);
    assert!(
        err.message.contains("1.2.3.4.100 (24 slices")
            && err.message.contains("1.2.3.4.200 (3 slices"),
        "{err}"
    );
    let listed = list_dicom_series(&inputs).unwrap();
    assert_eq!(listed.len(), 2);
    let chosen = read_dicom_series(&inputs, &DicomOptions::series("1.2.3.4.200")).unwrap();
    assert_eq!(chosen.grid.dims, [16, 16, 3]);
    let err = read_dicom_series(&inputs, &DicomOptions::series("9.9")).unwrap_err();
    assert!(err.message.contains("no series 9.9"), "{err}");
}

#[test]
fn missing_slices_mixed_sizes_and_tilt_are_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let mut slices = ball_series("1.2.3", 16, 6, [1.0; 3], 0.0, [0.0; 3], 4.0);
    slices.remove(3);
    write_series(dir.path(), &slices, "m");
    let err = read_dicom_series(&[dir.path().to_path_buf()], &DicomOptions::default()).unwrap_err();
    assert!(err.message.contains("missing"), "{err}");

    let dir = tempfile::tempdir().unwrap();
    let mut slices = ball_series("1.2.3", 16, 4, [1.0; 3], 0.0, [0.0; 3], 4.0);
    let small = ball_series("1.2.3", 8, 4, [1.0; 3], 0.0, [0.0; 3], 4.0);
    slices[2] = Slice {
        position: slices[2].position,
        instance: 3,
        ..small[2].clone()
    };
    write_series(dir.path(), &slices, "s");
    let err = read_dicom_series(&[dir.path().to_path_buf()], &DicomOptions::default()).unwrap_err();
    assert!(err.message.contains("mixed sizes"), "{err}");

    let dir = tempfile::tempdir().unwrap();
    let mut slices = ball_series("1.2.3", 16, 4, [1.0; 3], 0.0, [0.0; 3], 4.0);
    for (k, s) in slices.iter_mut().enumerate() {
        s.position[1] += 0.5 * k as f64;
    }
    write_series(dir.path(), &slices, "t");
    let err = read_dicom_series(&[dir.path().to_path_buf()], &DicomOptions::default()).unwrap_err();
    assert!(err.message.contains("gantry tilt"), "{err}");
}

#[test]
fn corrupt_truncated_and_hostile_files_are_clean_errors() {
    let dir = tempfile::tempdir().unwrap();
    let slices = ball_series("1.2.3", 16, 2, [1.0; 3], 0.0, [0.0; 3], 4.0);
    let good = dir.path().join("good.dcm");
    write_slice(&good, &slices[0]);
    let bytes = std::fs::read(&good).unwrap();

    let truncated = dir.path().join("truncated.dcm");
    std::fs::write(&truncated, &bytes[..bytes.len() - 100]).unwrap();
    // The pixel data's declared length runs past the end (`src/dicom/lengths.rs`).
    assert_error(
        read_volume(&truncated, None),
        IoErrorKind::Truncated,
        &truncated,
    );

    let not_dicom = dir.path().join("text.dcm");
    std::fs::write(&not_dicom, b"hello, not a DICOM file at all").unwrap();
    assert_error(
        read_volume(&not_dicom, None),
        IoErrorKind::Malformed,
        &not_dicom,
    );

    let empty = dir.path().join("empty.dcm");
    std::fs::write(&empty, b"").unwrap();
    assert_error(read_volume(&empty, None), IoErrorKind::Empty, &empty);

    // Rows and Columns at their largest: 65535 x 65535 samples of a 2-byte file.
    let mut huge = slices[1].clone();
    huge.rows = u16::MAX;
    huge.columns = u16::MAX;
    huge.stored = vec![0; 4];
    let hostile = dir.path().join("hostile.dcm");
    write_slice(&hostile, &huge);
    let err = read_volume(&hostile, None).unwrap_err();
    assert!(
        matches!(err.kind, IoErrorKind::Malformed | IoErrorKind::TooLarge),
        "{err}"
    );
    assert!(
        err.to_string().contains("hostile.dcm") && !err.to_string().contains("::"),
        "{err}"
    );

    let no_dicom_dir = tempfile::tempdir().unwrap();
    std::fs::write(no_dicom_dir.path().join("notes.txt"), b"x").unwrap();
    let err = read_volume(no_dicom_dir.path(), None).unwrap_err();
    assert_eq!(err.kind, IoErrorKind::Empty, "{err}");
}

fn shared_ct_slice() -> Option<PathBuf> {
    voxlod_testkit::data::shared_data_or_skip(
        "volumes/pydicom_CT_small.dcm",
        "the_pydicom_ct_slice_reads_in_hounsfield_units",
    )
}

#[test]
fn the_pydicom_ct_slice_reads_in_hounsfield_units() {
    let Some(path) = shared_ct_slice() else {
        return;
    };
    let volume = read_volume(&path, None).unwrap();
    assert_eq!(volume.grid.dims, [128, 128, 1]);
    assert_eq!(volume.orientation.frame, Frame::Lps);
    let (lo, hi) = volume.range().unwrap();
    // pydicom: pixel_array * RescaleSlope + RescaleIntercept.
    let script = "import sys, pydicom\nd = pydicom.dcmread(sys.argv[1])\na = d.pixel_array * float(d.RescaleSlope) + float(d.RescaleIntercept)\nprint(a.min(), a.max(), *d.ImagePositionPatient)";
    match voxlod_testkit::peers::run_python(script, &[path.as_os_str()]) {
        Some(out) => {
            let v: Vec<f64> = out.split_whitespace().map(|s| s.parse().unwrap()).collect();
            assert_eq!((lo as f64, hi as f64), (v[0], v[1]));
            let origin = volume.world().origin;
            assert!(
                (origin - DVec3::new(v[2], v[3], v[4])).length() < 1e-4,
                "{origin}"
            );
        }
        None => {
            // Without pydicom: its figures for this file (stored 128..2191, slope 1, intercept
            // -1024).
            assert_eq!((lo, hi), (-896.0, 1167.0));
        }
    }
}
