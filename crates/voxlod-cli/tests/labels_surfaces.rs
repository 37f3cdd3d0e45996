//! `voxlod labels` without a filter on a generated map: marching cubes per label by default,
//! the shared surface nets with `--shared`, a neuroglancer layer with `--format precomputed`,
//! and the flags that do not go together refused.

mod common;

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use common::{arg, assert_clean_failure, json, voxlod};
use voxlod::core::{mesh_topology, Grid, LabelVolume, TriangleMesh};
use voxlod_testkit::compare::{reversed_key, triangle_keys, TriangleKey};

/// A 30 × 26 × 22 map (spacing 1 × 1 × 2): two balls that touch, the larger with id 2³²−1,
/// and a box across the map's border; written as a uint32 NRRD into `dir`.
fn map(dir: &Path) -> PathBuf {
    let grid = Grid::new([30, 26, 22], [1.0, 1.0, 2.0], [5.0, 0.0, -3.0]).unwrap();
    let values = (0..grid.len())
        .map(|n| [n % 30, n / 30 % 26, n / 780].map(|a| a as f64))
        .map(|[x, y, z]| {
            let ball = |c: [f64; 3], r: f64| {
                (x - c[0]).powi(2) + (y - c[1]).powi(2) + (2.0 * (z - c[2])).powi(2) <= r * r
            };
            if ball([18.0, 13.0, 11.0], 8.0) {
                u32::MAX
            } else if ball([8.0, 13.0, 11.0], 6.0) {
                3
            } else if x < 2.0 && y < 5.0 {
                9
            } else {
                0
            }
        })
        .collect();
    let path = dir.join("map.nrrd");
    let map = LabelVolume::from_vec(grid, values).unwrap();
    voxlod::io::write_label_map(&path, &map).unwrap();
    path
}

fn read(path: &Path) -> TriangleMesh {
    voxlod::io::read_mesh(path).unwrap().mesh
}

#[test]
fn every_label_is_closed_and_outward_and_keeps_its_volume() {
    let dir = tempfile::tempdir().unwrap();
    let map = map(dir.path());
    for (name, flags) in [("plain", &[][..]), ("shared", &["--shared"][..])] {
        let out = dir.path().join(name);
        let mut args = vec!["labels", arg(&map), "-o", arg(&out), "--json"];
        args.extend(flags);
        let report = json(&voxlod(&args));
        let surface = if flags.is_empty() {
            "marching_cubes"
        } else {
            "surface_nets"
        };
        assert_eq!(report["surface"], surface);
        let labels = report["labels"].as_array().unwrap();
        let values: Vec<u64> = labels
            .iter()
            .map(|l| l["label"].as_u64().unwrap())
            .collect();
        assert_eq!(values, [3, 9, u32::MAX as u64]);
        for l in labels {
            let level = &l["levels"][0];
            let mesh = read(&out.join(level["file"].as_str().unwrap()));
            let t = mesh_topology(&mesh);
            assert!(
                t.is_closed_manifold() && t.is_consistently_oriented(),
                "{name} {l}"
            );
            assert_eq!(level["triangles"], mesh.triangles.len());
            assert!(
                level["closed_manifold"].is_null(),
                "measured only with --check"
            );
            let error = mesh.signed_volume() / l["voxel_volume"].as_f64().unwrap() - 1.0;
            // Shared and smoothed: the volume kept; marching cubes cuts the corners.
            let tolerance = if flags.is_empty() { 0.2 } else { 0.01 };
            assert!(
                error.abs() < tolerance,
                "{name} label {}: {error}",
                l["label"]
            );
        }
        assert!(
            report["smoothing"].is_object() != flags.is_empty(),
            "{report}"
        );
    }
}

#[test]
fn shared_neighbours_meet_on_the_same_triangles_without_gap_or_overlap() {
    let dir = tempfile::tempdir().unwrap();
    let map = map(dir.path());
    let out = dir.path().join("shared");
    voxlod(&[
        "labels",
        arg(&map),
        "-o",
        arg(&out),
        "--shared",
        "--smooth",
        "4",
    ]);
    let small = triangle_keys(&read(&out.join("label-3.ply")));
    let large = triangle_keys(&read(&out.join(format!("label-{}.ply", u32::MAX))));
    let mut seen: HashMap<TriangleKey, usize> = HashMap::new();
    for t in small.iter().chain(&large) {
        *seen.entry(*t).or_default() += 1;
    }
    assert!(
        seen.values().all(|&n| n == 1),
        "a triangle used twice the same way round"
    );
    let between = small
        .iter()
        .filter(|t| seen.contains_key(&reversed_key(t)))
        .count();
    assert!(
        between >= 8,
        "{between} triangles shared between the two balls"
    );
}

#[test]
fn a_precomputed_layer_holds_every_label_at_every_level() {
    let dir = tempfile::tempdir().unwrap();
    let map = map(dir.path());
    let out = dir.path().join("layer");
    let plain = dir.path().join("plain");
    voxlod(&["labels", arg(&map), "-o", arg(&plain)]);
    std::fs::copy(
        plain.join("label-3.ply"),
        dir.path().join("layer-source-3.ply"),
    )
    .unwrap();
    let report = json(&voxlod(&[
        "labels",
        arg(&map),
        "-o",
        arg(&out),
        "--format",
        "precomputed",
        "--levels",
        "2",
        "--unit",
        "mm",
        "--json",
    ]));
    let layer = &report["precomputed"];
    assert_eq!(layer["lods"], 2, "{report}");
    assert_eq!(layer["resolution"], serde_json::json!([1e6, 1e6, 2e6]));
    let info: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("info")).unwrap()).unwrap();
    assert_eq!(info["type"], "segmentation");
    assert_eq!(info["mesh"], "mesh");
    for label in [3u64, 9, u32::MAX as u64] {
        let stored = voxlod::precomputed::read::read_mesh(&out, label).unwrap();
        let fragments = stored.fragments().unwrap();
        let per_lod = |k: usize| -> usize {
            fragments
                .iter()
                .filter(|f| f.lod == k)
                .map(|f| f.fragment.triangles.len())
                .sum()
        };
        assert!(per_lod(0) > 0 && per_lod(1) > 0, "label {label}");
        assert!(per_lod(1) <= per_lod(0), "label {label}");
    }
    assert!(out.join("report.json").is_file());
    // The layer's labels read back and meshed again: the same labels, placed in nanometres.
    let again = dir.path().join("again");
    let report = json(&voxlod(&["labels", arg(&out), "-o", arg(&again), "--json"]));
    let values: Vec<u64> = report["labels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| l["label"].as_u64().unwrap())
        .collect();
    assert_eq!(values, [3, 9, u32::MAX as u64]);
    let ball = read(&again.join("label-3.ply"));
    let before = read(&dir.path().join("layer-source-3.ply"));
    let scale: f64 = 1e6; // mm to nm
    let volume = ball.signed_volume() / scale.powi(3);
    assert!(
        (volume / before.signed_volume() - 1.0).abs() < 1e-6,
        "{volume}"
    );
}

#[test]
fn a_label_smaller_than_a_level_s_error_holds_the_finer_surface_with_a_warning() {
    // A one-voxel label beside a ball of radius 7: simplified within 2, 4 and 8 voxels, the
    // voxel's octahedron would be flattened to two triangles back to back, then dropped. It
    // keeps its 8 triangles at every level instead, and the warning names one label.
    let dir = tempfile::tempdir().unwrap();
    let grid = Grid::new([24, 24, 24], [1.0; 3], [0.0; 3]).unwrap();
    let mut values = vec![0u32; grid.len()];
    for (n, v) in values.iter_mut().enumerate() {
        let [x, y, z] = [n % 24, n / 24 % 24, n / 576].map(|a| a as f64 - 12.0);
        if x * x + y * y + z * z <= 49.0 {
            *v = 2;
        }
    }
    values[grid.index(1, 1, 1)] = 5;
    let path = dir.path().join("speck.nrrd");
    voxlod::io::write_label_map(&path, &LabelVolume::from_vec(grid, values).unwrap()).unwrap();
    let out = dir.path().join("layer");
    let report = json(&voxlod(&[
        "labels",
        arg(&path),
        "-o",
        arg(&out),
        "--format",
        "precomputed",
        "--levels",
        "4",
        "--json",
    ]));
    let warnings = report["warnings"].as_array().unwrap();
    assert_eq!(warnings.len(), 1, "{report}");
    assert!(
        (warnings[0].as_str().unwrap())
            .starts_with("1 label(s) have no surface at some coarser levels"),
        "{report}"
    );
    let per_lod = |label: u64| -> Vec<usize> {
        let fragments = (voxlod::precomputed::read::read_mesh(&out, label).unwrap())
            .fragments()
            .unwrap();
        (0..4)
            .map(|k| {
                (fragments.iter())
                    .filter(|f| f.lod == k)
                    .map(|f| f.fragment.triangles.len())
                    .sum()
            })
            .collect()
    };
    assert_eq!(per_lod(5), [8, 8, 8, 8]);
    let ball = per_lod(2);
    assert!(ball.windows(2).all(|w| w[1] < w[0]), "{ball:?}");
}

#[test]
fn a_precomputed_layer_with_a_filter_holds_the_filter_pyramid() {
    let dir = tempfile::tempdir().unwrap();
    let map = map(dir.path());
    let (out, files) = (dir.path().join("layer"), dir.path().join("files"));
    let pyramid = ["--levels", "3", "--filter", "hypercone", "--json"];
    let mut layer_args = vec![
        "labels",
        arg(&map),
        "-o",
        arg(&out),
        "--format",
        "precomputed",
    ];
    layer_args.extend(pyramid);
    let report = json(&voxlod(&layer_args));
    assert_eq!(report["surface"], "filtered", "{report}");
    assert_eq!(report["precomputed"]["coarser_levels"], "filtered");
    let mut file_args = vec!["labels", arg(&map), "-o", arg(&files)];
    file_args.extend(pyramid);
    let files_report = json(&voxlod(&file_args));
    assert_eq!(
        files_report["warnings"][0],
        "1 label(s) have no surface at some levels (thinner than those levels' filter): those levels have no file (labels 9)"
    );
    // The map's voxel is 1 × 1 × 2: a volume in the stored space (voxels) is twice as large in
    // the world.
    for label in [3u64, u32::MAX as u64] {
        let fragments = voxlod::precomputed::read::read_mesh(&out, label)
            .unwrap()
            .fragments()
            .unwrap();
        for k in 0..3 {
            let stored: f64 = (fragments.iter())
                .filter(|f| f.lod == k)
                .map(|f| {
                    let positions = f.positions.iter().map(|p| p.as_vec3()).collect();
                    TriangleMesh::new(positions, f.fragment.triangles.clone()).signed_volume()
                })
                .sum();
            let level = read(&files.join(format!("label-{label}-{k}.ply")));
            let (v, w) = (2.0 * stored, level.signed_volume());
            assert!(
                w > 0.0 && (v / w - 1.0).abs() < 1e-3,
                "label {label} level {k}: {v} against {w}"
            );
        }
    }
    // The box 2 voxels across vanishes under the coarsest filter: that level holds level 1.
    let carried = &report["warnings"][0];
    assert!(
        carried
            .as_str()
            .unwrap()
            .starts_with("1 label(s) have no surface at some coarser levels"),
        "{report}"
    );
    assert!(!files.join("label-9-2.ply").exists());
    // A map whose every label vanishes under the filter: an error naming the file, no output.
    let speck = dir.path().join("speck.nrrd");
    let grid = Grid::new([6, 6, 6], [1.0; 3], [0.0; 3]).unwrap();
    let mut values = vec![0u32; grid.len()];
    values[grid.index(3, 3, 3)] = 5;
    let one = LabelVolume::from_vec(grid, values).unwrap();
    voxlod::io::write_label_map(&speck, &one).unwrap();
    let empty = dir.path().join("empty-layer");
    let mut speck_args = vec!["labels", arg(&speck), "-o", arg(&empty), "--format"];
    speck_args.extend(["precomputed", "--filter", "hypercone"]);
    let failed = voxlod(&speck_args);
    assert_clean_failure(&failed, "speck.nrrd: no label has a surface at any level");
    assert!(!empty.exists());
}

#[test]
fn flags_that_do_not_go_together_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let map = map(dir.path());
    let out = dir.path().join("out");
    let cases: [(&[&str], &str); 5] = [
        (
            &["--smooth", "3"],
            "--smooth smooths the --shared surface: add --shared",
        ),
        (
            &["--shared", "--levels", "2"],
            "--shared meshes the labels together without a filter",
        ),
        (
            &["--format", "precomputed", "--shared", "--radius", "2"],
            "--shared meshes the labels together without a filter: it does not go with --filter or --radius",
        ),
        (
            &["--quantization-bits", "10"],
            "apply to --format precomputed only",
        ),
        (&["--levels", "0"], "--levels must be at least 1"),
    ];
    for (flags, message) in cases {
        let mut args = vec!["labels", arg(&map), "-o", arg(&out)];
        args.extend(flags);
        let o = voxlod(&args);
        assert_clean_failure(&o, message);
        assert_eq!(o.status.code(), Some(2), "{flags:?}");
        assert!(!out.exists());
    }
}

#[test]
fn triangles_budgets_every_label_and_the_report_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let map = map(dir.path());
    for (name, flags) in [
        ("shared", &["--shared", "--smooth", "8"][..]),
        ("plain", &[][..]),
    ] {
        let out = dir.path().join(name);
        let mut args = vec!["labels", arg(&map), "-o", arg(&out), "--json"];
        args.extend(flags);
        args.extend(["--triangles", "500", "--check"]);
        let report = json(&voxlod(&args));
        assert_eq!(report["triangles_budget"], 500, "{name}: {report}");
        assert_eq!(report["labels_above_budget"], 0, "{name}: {report}");
        for label in report["labels"].as_array().unwrap() {
            let level = &label["levels"][0];
            let file = out.join(level["file"].as_str().unwrap());
            let mesh = read(&file);
            let n = mesh.triangles.len();
            assert_eq!(level["triangles"].as_u64(), Some(n as u64));
            assert!(
                (100..=550).contains(&n),
                "{name} label {}: {n}",
                label["label"]
            );
            assert_eq!(
                level["closed_manifold"], true,
                "{name} label {}",
                label["label"]
            );
            let change =
                level["volume"].as_f64().unwrap() / label["voxel_volume"].as_f64().unwrap();
            assert!(
                (change - 1.0).abs() < 0.1,
                "{name} label {}: {change}",
                label["label"]
            );
        }
    }
}

#[test]
fn triangles_is_refused_below_four_and_beside_the_filtered_levels_or_a_layer() {
    let dir = tempfile::tempdir().unwrap();
    let map = map(dir.path());
    let out = dir.path().join("out");
    let cases: [(&[&str], &str); 3] = [
        (&["--triangles", "3"], "--triangles must be at least 4"),
        (
            &["--triangles", "500", "--levels", "2"],
            "--triangles reduces the one-pass surfaces",
        ),
        (
            &["--triangles", "500", "--format", "precomputed"],
            "--triangles does not apply to --format precomputed",
        ),
    ];
    for (flags, message) in cases {
        let o = voxlod(&[&["labels", arg(&map), "-o", arg(&out)][..], flags].concat());
        assert_clean_failure(&o, message);
        assert_eq!(
            (o.status.code(), out.exists()),
            (Some(2), false),
            "{flags:?}"
        );
    }
}

#[test]
fn labels_held_above_the_budget_are_named_in_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let map = map(dir.path());
    let out = dir.path().join("tight");
    let report = json(&voxlod(&[
        "labels",
        arg(&map),
        "-o",
        arg(&out),
        "--json",
        "--shared",
        "--triangles",
        "4",
    ]));
    let above = report["labels_above_budget"].as_u64().unwrap();
    assert!(above >= 1, "{report}");
    let warning = report["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|w| w.as_str())
        .find(|w| w.contains("stay above --triangles 4"))
        .unwrap_or_else(|| panic!("no warning: {report}"));
    assert!(
        warning.starts_with(&format!("{above} label(s)")),
        "{warning}"
    );
    assert!(warning.contains("the largest, label"), "{warning}");
}
