//! The medical inputs from the command line: a DICOM folder with `--threshold` in Hounsfield
//! units and `--series`, and `voxlod labels` with its flags and outputs (per-label meshes, the
//! glTF with `_LABEL`, the report's volumes and areas).

mod common;

use std::path::{Path, PathBuf};

use common::{arg, assert_clean_failure, centroid_and_volume, json, stderr, voxlod};
use serde_json::Value;
use voxlod::core::glam::DVec3;
use voxlod::core::mesh_topology;
use voxlod_testkit::dicom::{ball_series, write_slice};

const OURS: &str = "1.2.826.0.1.3680043.9.7";
const OTHER: &str = "1.2.826.0.1.3680043.9.8";
const CENTRE: [f64; 3] = [-20.0, -10.0, -8.0];
const RADIUS: f64 = 10.0;

/// A folder with two CT series, files in shuffled order: ours (a ball of bone, +1000 HU in
/// −1000 HU, slope 2, intercept −1024, in-plane axes turned 0.3 rad) and a small other one.
fn two_series(dir: &Path) -> PathBuf {
    let folder = dir.join("CT");
    std::fs::create_dir(&folder).unwrap();
    let ours = ball_series(OURS, 40, 30, [1.0, 1.0, 1.5], 0.3, CENTRE, RADIUS);
    let other = ball_series(OTHER, 8, 3, [1.0; 3], 0.0, [0.0; 3], 2.0);
    for (n, s) in ours.iter().chain(&other).enumerate() {
        write_slice(&folder.join(format!("IM{:04}", (n * 37) % 101)), s);
    }
    folder
}

#[test]
fn lod_reads_a_dicom_folder_with_a_hounsfield_threshold_and_the_series_asked_for() {
    let dir = tempfile::tempdir().unwrap();
    let folder = two_series(dir.path());
    let out = dir.path().join("bone");
    let lod = |extra: &[&str]| {
        let mut args = vec!["lod", arg(&folder), "--threshold", "300", "-o", arg(&out)];
        args.extend(["--resolutions", "48", "--json"]);
        args.extend(extra);
        voxlod(&args)
    };
    // Two series and no --series: refused, listing both and naming the flag.
    let o = lod(&[]);
    assert_clean_failure(&o, "--series");
    let err = stderr(&o);
    assert!(err.contains(OURS) && err.contains(OTHER), "{err}");
    assert!(
        err.contains("30 slices") && err.contains("3 slices"),
        "{err}"
    );
    assert!(!out.exists(), "nothing is written on failure");
    // A series that is not there: refused with the list.
    let o = lod(&["--series", "1.2.3.4"]);
    assert_clean_failure(&o, "no series 1.2.3.4");
    assert!(stderr(&o).contains(OURS), "{}", stderr(&o));

    let report = json(&lod(&["--series", OURS]));
    assert_eq!(report["frame"], "lps", "{report}");
    let file = report["levels"][0]["file"].as_str().unwrap();
    let mesh = voxlod::io::read_mesh(&out.join(file)).unwrap().mesh;
    let t = mesh_topology(&mesh);
    assert!(
        t.is_closed_manifold() && t.is_consistently_oriented(),
        "{t:?}"
    );
    let (c, v) = centroid_and_volume(&mesh);
    let ball = 4.0 / 3.0 * std::f64::consts::PI * RADIUS.powi(3);
    // 300 HU lies at 65 % of the step from -1000 to +1000 HU, so the trilinear surface sits
    // about 0.15 voxel inside the voxelised ball's midpoint surface, and the filter (one cell
    // of about 1 mm) rounds it a little more: measured -7.4 % for this ball of 10 voxels.
    assert!(v < ball && v / ball > 0.9, "volume {v} vs {ball}");
    assert!((c - DVec3::from(CENTRE)).length() < 1.0, "centroid {c}");

    // --series on something that is not DICOM is a usage error.
    let nrrd = dir.path().join("v.nrrd");
    voxlod::io::write_volume(&nrrd, &voxlod_testkit::volumes::small_volume()).unwrap();
    let o = voxlod(&[
        "lod",
        arg(&nrrd),
        "--threshold",
        "1",
        "-o",
        arg(&out),
        "--series",
        OURS,
    ]);
    assert_clean_failure(&o, "is not a DICOM folder");
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn a_threshold_between_the_hounsfield_values_is_needed() {
    // Only OUR series in the folder: no --series needed. Above +1000 HU nothing is inside.
    let dir = tempfile::tempdir().unwrap();
    let folder = dir.path().join("CT");
    std::fs::create_dir(&folder).unwrap();
    for (n, s) in ball_series(OURS, 24, 12, [1.0; 3], 0.0, [-28.0, -23.0, -24.0], 5.0)
        .iter()
        .enumerate()
    {
        write_slice(&folder.join(format!("s{n}.dcm")), s);
    }
    let out = dir.path().join("levels");
    let o = voxlod(&[
        "lod",
        arg(&folder),
        "--threshold",
        "1500",
        "-o",
        arg(&out),
        "--resolutions",
        "16",
    ]);
    assert_clean_failure(&o, "1500");
    let report = json(&voxlod(&[
        "lod",
        arg(&folder),
        "--threshold",
        "-200",
        "-o",
        arg(&out),
        "--resolutions",
        "16",
        "--json",
    ]));
    assert!(
        report["levels"][0]["triangles"].as_u64().unwrap() > 100,
        "{report}"
    );
}

// -------------------------------------------------------------------------------------------
// Label maps.

/// A label map as a Slicer-style `.seg.nrrd` (uint8, LPS, spacing 1 × 1.2 × 0.8): label 1 a ball
/// of radius 7, label 2 a box flush against it, label 3 a ball of radius 5; segment names and
/// colours for labels 1 and 2 only.
fn seg_nrrd(dir: &Path) -> PathBuf {
    let dims = [40usize, 36, 30];
    let spacing = [1.0, 1.2, 0.8];
    let mut bytes = Vec::with_capacity(dims.iter().product());
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                let p = DVec3::new(i as f64, j as f64 * 1.2, k as f64 * 0.8);
                let ball = |c: DVec3, r: f64| (p - c).length() <= r;
                bytes.push(if ball(DVec3::new(12.0, 14.0, 12.0), 7.0) {
                    1u8
                } else if (19..=30).contains(&i) && (6..=22).contains(&j) && (5..=20).contains(&k) {
                    2
                } else if ball(DVec3::new(30.0, 34.0, 15.0), 5.0) {
                    3
                } else {
                    0
                });
            }
        }
    }
    let header = format!(
        "NRRD0004\ntype: uint8\ndimension: 3\nspace: left-posterior-superior\n\
         sizes: {} {} {}\nspace directions: ({},0,0) (0,{},0) (0,0,{})\n\
         space origin: (10,-4,2)\nencoding: raw\n\
         Segment0_Name:=Left Lung\nSegment0_LabelValue:=1\nSegment0_Color:=0.9 0.2 0.1\n\
         Segment0_Layer:=0\nSegment1_Name:=heart\nSegment1_LabelValue:=2\n\
         Segment1_Color:=0.1 0.3 0.9\nSegment1_Layer:=0\n\n",
        dims[0], dims[1], dims[2], spacing[0], spacing[1], spacing[2]
    );
    let path = dir.join("map.seg.nrrd");
    let mut file = header.into_bytes();
    file.extend(bytes);
    std::fs::write(&path, file).unwrap();
    path
}

/// The JSON and binary chunks of a `.glb`.
fn glb_chunks(path: &Path) -> (Value, Vec<u8>) {
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(&bytes[0..4], b"glTF");
    let chunk = |at: usize| {
        let len = u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
        (&bytes[at + 8..at + 8 + len], at + 8 + len)
    };
    let (json_bytes, next) = chunk(12);
    let (bin, _) = chunk(next);
    (serde_json::from_slice(json_bytes).unwrap(), bin.to_vec())
}

/// The `f32` values of a scalar float accessor.
fn float_accessor(doc: &Value, bin: &[u8], index: usize) -> Vec<f32> {
    let a = &doc["accessors"][index];
    assert_eq!(a["componentType"], 5126);
    assert_eq!(a["type"], "SCALAR");
    let view = &doc["bufferViews"][a["bufferView"].as_u64().unwrap() as usize];
    let start = view["byteOffset"].as_u64().unwrap() as usize;
    let count = a["count"].as_u64().unwrap() as usize;
    bin[start..start + 4 * count]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
        .collect()
}

#[test]
fn labels_writes_named_closed_meshes_their_volumes_and_one_gltf_with_label_per_vertex() {
    let dir = tempfile::tempdir().unwrap();
    let map = seg_nrrd(dir.path());
    let out = dir.path().join("models");
    let report = json(&voxlod(&[
        "labels",
        arg(&map),
        "-o",
        arg(&out),
        "--check",
        "--json",
    ]));
    let labels = report["labels"].as_array().unwrap();
    assert_eq!(labels.len(), 3, "{report}");
    assert_eq!(report["frame"], "lps");
    assert_eq!(report["all_labels_gltf"], "labels.glb");
    let (doc, bin) = glb_chunks(&out.join("labels.glb"));
    assert_eq!(doc["nodes"].as_array().unwrap().len(), 3);
    for (n, l) in labels.iter().enumerate() {
        let value = l["label"].as_i64().unwrap();
        let level = &l["levels"][0];
        let file = level["file"].as_str().unwrap();
        let expected_name = match value {
            1 => "label-1-left-lung.ply",
            2 => "label-2-heart.ply",
            _ => "label-3.ply",
        };
        assert_eq!(file, expected_name);
        let mesh = voxlod::io::read_mesh(&out.join(file)).unwrap().mesh;
        assert_eq!(level["triangles"], mesh.triangles.len());
        assert_eq!(level["closed_manifold"], true, "{l}");
        // Volume against the voxel count: within 3 % (6 % for the small ball, see
        // tests/medical.rs); the report's figures are the written mesh's.
        let voxel_volume = l["voxel_volume"].as_f64().unwrap();
        assert!(
            (voxel_volume - l["voxels"].as_f64().unwrap() * 0.96).abs() < 1e-6,
            "{l}"
        );
        let v = level["volume"].as_f64().unwrap();
        assert!(
            (v - mesh.signed_volume()).abs() < 1e-6 * v.abs().max(1.0),
            "{l}"
        );
        let tolerance = if value == 3 { 0.06 } else { 0.03 };
        assert!((v / voxel_volume - 1.0).abs() < tolerance, "{l}");
        assert!((level["area"].as_f64().unwrap() - mesh.area()).abs() < 1e-3 * mesh.area());
        if value == 3 {
            // A ball of radius 5: area 4πr² to the filter's rounding and the voxel steps.
            let sphere = 4.0 * std::f64::consts::PI * 25.0;
            assert!(
                (mesh.area() / sphere - 1.0).abs() < 0.1,
                "area {}",
                mesh.area()
            );
        }
        // The glTF node of this label: its name, colour and one _LABEL per vertex.
        let node = &doc["nodes"][n];
        let gltf_mesh = &doc["meshes"][node["mesh"].as_u64().unwrap() as usize];
        let primitive = &gltf_mesh["primitives"][0];
        let positions =
            &doc["accessors"][primitive["attributes"]["POSITION"].as_u64().unwrap() as usize];
        assert_eq!(positions["count"], mesh.positions.len(), "label {value}");
        let indices = &doc["accessors"][primitive["indices"].as_u64().unwrap() as usize];
        assert_eq!(indices["count"], 3 * mesh.triangles.len());
        let tags = float_accessor(
            &doc,
            &bin,
            primitive["attributes"]["_LABEL"].as_u64().unwrap() as usize,
        );
        assert_eq!(tags.len(), mesh.positions.len());
        assert!(tags.iter().all(|&t| t == value as f32), "label {value}");
        let material = &doc["materials"][primitive["material"].as_u64().unwrap() as usize];
        let colour = &material["pbrMetallicRoughness"]["baseColorFactor"];
        match value {
            1 => {
                assert_eq!(node["name"], "label 1 (Left Lung)");
                assert!((colour[0].as_f64().unwrap() - 0.9).abs() < 1e-6, "{colour}");
            }
            3 => assert_eq!(node["name"], "label 3"),
            _ => {}
        }
    }
    assert!(
        !out.join("labels.vtp").exists(),
        "the VTP of all labels is for --format vtp"
    );
    // With VTK's files, all three in one VTP too, the label per vertex.
    let out = dir.path().join("vtk");
    let report = json(&voxlod(&[
        "labels",
        arg(&map),
        "-o",
        arg(&out),
        "--format",
        "vtp",
        "--json",
    ]));
    assert_eq!(report["all_labels"], "labels.vtp");
    let vtp = voxlod::io::read_poly_mesh(&out.join("labels.vtp")).unwrap();
    let label = vtp
        .vertex_attributes
        .iter()
        .find(|a| a.name == "label")
        .unwrap();
    for value in [1.0, 2.0, 3.0] {
        assert!(label.values.contains(&value));
    }
}

#[test]
fn labels_flags_choose_labels_levels_filter_and_the_envelope_step() {
    let dir = tempfile::tempdir().unwrap();
    let map = seg_nrrd(dir.path());
    let out = dir.path().join("models");
    let run = |extra: &[&str]| {
        let mut args = vec!["labels", arg(&map), "-o", arg(&out), "--json"];
        args.extend(extra);
        voxlod(&args)
    };
    let of = |report: &Value, label: i64| -> Value {
        report["labels"]
            .as_array()
            .unwrap()
            .iter()
            .find(|l| l["label"] == label)
            .cloned()
            .unwrap_or(Value::Null)
    };
    // --labels: only those, in the report, the files and the glTF.
    let r = json(&run(&["--labels", "1,3"]));
    let values: Vec<i64> = r["labels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| l["label"].as_i64().unwrap())
        .collect();
    assert_eq!(values, vec![1, 3]);
    assert!(!out.join("label-2-heart.ply").exists());
    assert_eq!(
        glb_chunks(&out.join("labels.glb")).0["nodes"]
            .as_array()
            .unwrap()
            .len(),
        2
    );
    let o = run(&["--labels", "1,9"]);
    assert_clean_failure(&o, "no label 9");

    // --levels 3: three files per label, each coarser.
    let r = json(&run(&["--labels", "2", "--levels", "3"]));
    let levels = of(&r, 2)["levels"].as_array().unwrap().clone();
    assert_eq!(levels.len(), 3);
    let tris: Vec<u64> = levels
        .iter()
        .map(|l| l["triangles"].as_u64().unwrap())
        .collect();
    assert!(tris[0] > tris[1] && tris[1] > tris[2], "{tris:?}");
    for (k, l) in levels.iter().enumerate() {
        assert_eq!(l["file"], format!("label-2-heart-{k}.ply"));
        assert!(out.join(l["file"].as_str().unwrap()).exists());
    }
    let o = run(&["--levels", "0"]);
    assert_clean_failure(&o, "--levels");
    assert_eq!(o.status.code(), Some(2));

    // --filter gaussian: another surface of the same structure.
    let hyper = json(&run(&["--labels", "1"]));
    let gauss = json(&run(&["--labels", "1", "--filter", "gaussian"]));
    let (h, g) = (&of(&hyper, 1)["levels"][0], &of(&gauss, 1)["levels"][0]);
    assert_ne!(h["volume"], g["volume"]);
    assert_eq!(g["closed_manifold"], true);

    // --then-envelope: fewer triangles, within the bound it reports, still closed.
    let env = json(&run(&["--labels", "1", "--then-envelope", "1vox"]));
    let e = &of(&env, 1)["levels"][0];
    assert!(e["envelope"].is_object(), "{e}");
    assert!(
        e["triangles"].as_u64().unwrap() < h["triangles"].as_u64().unwrap() / 2,
        "{} vs {}",
        e["triangles"],
        h["triangles"]
    );
    assert_eq!(e["closed_manifold"], true);
}

#[test]
fn labels_no_clean_keeps_plain_marching_cubes_and_labels_run_in_parallel_in_order() {
    let dir = tempfile::tempdir().unwrap();
    let map = seg_nrrd(dir.path());
    let run = |name: &str, extra: &[&str]| {
        let out = dir.path().join(name);
        let mut args = vec!["labels", arg(&map), "-o", arg(&out), "--json"];
        args.extend(extra);
        json(&voxlod(&args))
    };
    let cleaned = run("cleaned", &["--levels", "1"]);
    let plain = run("plain", &["--levels", "1", "--no-clean"]);
    let (cleaned, plain) = (
        cleaned["labels"].as_array().unwrap(),
        plain["labels"].as_array().unwrap(),
    );
    // The labels come back in increasing order, whichever finished first.
    let values: Vec<i64> = plain.iter().map(|l| l["label"].as_i64().unwrap()).collect();
    assert_eq!(values, vec![1, 2, 3]);
    for (c, p) in cleaned.iter().zip(plain) {
        let (c, p) = (&c["levels"][0], &p["levels"][0]);
        // A cleaned level is contoured with its vertices kept 0.072 cell from the samples (no
        // short edge for cleaning to collapse): marching cubes' triangles, moved vertices, the
        // same solid; --no-clean keeps the plain vertices. Where many samples of a label's
        // filtered density sit exactly at the iso value (on the faces of the heart's box), the
        // kept distance moves its surface outward: 3093 → 3121 mm³, nearer the voxels' 3133.
        assert_eq!(p["triangles"], c["triangles"], "{p} vs {c}");
        assert_eq!(p["closed_manifold"], true);
        let (vp, vc) = (p["volume"].as_f64().unwrap(), c["volume"].as_f64().unwrap());
        assert!(vp != vc && (vp / vc - 1.0).abs() < 0.01, "{vp} vs {vc}");
    }
}
