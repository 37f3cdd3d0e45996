//! `voxlod labels` on DICOM Segmentation objects written in the test (dicom-object): a ball and
//! a box that touch, on an oblique grid, frames shuffled, BINARY (85 by 71 pixels, so the
//! frames' bits straddle bytes) and FRACTIONAL; and a SEG the reader refuses.

mod common;

use std::path::Path;

use common::{arg, assert_clean_failure, centroid_and_volume, json, voxlod};
use serde_json::Value;
use voxlod::core::glam::DVec3;
use voxlod::core::mesh_topology;
use voxlod_testkit::dicom_seg::{phantom_seg, write_seg, Kind, PHANTOM};

/// Runs `voxlod labels INPUT -o OUT --json` and checks both structures: closed outward meshes,
/// volumes within 3 % of voxel count × voxel volume (and of the shapes), centroids within a
/// voxel of the world centres, names and colours, and the overlap warning.
fn check_ball_and_box(input: &Path, out: &Path) -> Value {
    let report = json(&voxlod(&["labels", arg(input), "-o", arg(out), "--json"]));
    assert_eq!(report["frame"], "lps", "{report}");
    let labels = report["labels"].as_array().unwrap();
    assert_eq!(labels.len(), 2, "{report}");
    let warnings = report["warnings"].as_array().unwrap();
    assert_eq!(warnings.len(), 1, "{report}");
    assert!(warnings[0]
        .as_str()
        .unwrap()
        .contains("segments 1 and 2 overlap"));
    let box_mm3: f64 = (0..3)
        .map(|a| PHANTOM.box_max[a] - PHANTOM.box_min[a])
        .product();
    let ball_mm3 = 4.0 / 3.0 * std::f64::consts::PI * PHANTOM.ball_radius.powi(3);
    let expected = [
        ("ball", [1.0, 0.0, 0.0], PHANTOM.ball_centre, ball_mm3),
        ("box", [0.0, 1.0, 0.0], PHANTOM.box_centre(), box_mm3),
    ];
    for (l, (name, rgb, centre, shape_mm3)) in labels.iter().zip(expected) {
        assert_eq!(l["name"], name, "{l}");
        let colour: Vec<f64> = l["color"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c.as_f64().unwrap())
            .collect();
        assert!((0..3).all(|a| (colour[a] - rgb[a]).abs() < 0.01), "{l}");
        let level = &l["levels"][0];
        let file = level["file"].as_str().unwrap();
        assert_eq!(file, format!("label-{}-{name}.ply", l["label"]));
        let mesh = voxlod::io::read_mesh(&out.join(file)).unwrap().mesh;
        let topology = mesh_topology(&mesh);
        assert!(
            topology.is_closed_manifold() && topology.is_consistently_oriented(),
            "{l}"
        );
        let (centroid, volume) = centroid_and_volume(&mesh);
        let voxel_volume = l["voxel_volume"].as_f64().unwrap();
        let voxels = l["voxels"].as_f64().unwrap();
        assert!(
            (voxel_volume / (voxels * 0.9 * 1.1 * 1.5) - 1.0).abs() < 1e-4,
            "{l}"
        );
        assert!(
            volume > 0.0 && (volume / voxel_volume - 1.0).abs() < 0.03,
            "{volume} {l}"
        );
        // The box takes a thin cap of the ball: within 3 % of the shape as well.
        assert!(
            (volume / shape_mm3 - 1.0).abs() < 0.03,
            "{volume} vs {shape_mm3}"
        );
        assert!(
            (centroid - DVec3::from(centre)).length() < 0.9,
            "{name}: {centroid}"
        );
    }
    report
}

#[test]
fn labels_meshes_a_binary_seg_where_its_structures_are_with_their_names_and_colours() {
    let dir = tempfile::tempdir().unwrap();
    let seg = dir.path().join("seg.dcm");
    write_seg(&seg, &phantom_seg(Kind::Binary));
    check_ball_and_box(&seg, &dir.path().join("out"));
}

#[test]
fn labels_reads_a_folder_holding_one_fractional_seg() {
    let dir = tempfile::tempdir().unwrap();
    let folder = dir.path().join("SEG");
    std::fs::create_dir(&folder).unwrap();
    write_seg(&folder.join("IM0001"), &phantom_seg(Kind::Fractional(255)));
    check_ball_and_box(&folder, &dir.path().join("out"));
}

#[test]
fn labels_refuses_a_compressed_one_bit_seg_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("jpeg.dcm");
    let mut seg = phantom_seg(Kind::Binary);
    seg.encapsulated = Some("1.2.840.10008.1.2.4.50".into());
    write_seg(&path, &seg);
    let out = dir.path().join("out");
    let o = voxlod(&["labels", arg(&path), "-o", arg(&out)]);
    assert_clean_failure(
        &o,
        &format!("{}: 1-bit pixel data in a compressed", path.display()),
    );
    assert!(!out.exists(), "no output folder is left");
}
