//! `voxlod lod` on the real data of ../shared/data: scanned meshes with holes, inside-out and
//! non-manifold STL soups, CT and MRI volumes. Every level must come out a closed manifold.
//! Skips, saying why, when ../shared/data is absent (a user's fresh clone).
//!
//! Along every chain the genus never rises from a level to the next (issue 12, item 4).
//!
//! The default test runs at moderate resolutions; `full_resolution_real_data` (ignored by
//! default; `scripts/real-data.sh` runs it) uses the command's defaults: 6 levels from the
//! resolution chosen from a mesh's triangle count, or from 256 for a volume.

mod common;

use common::*;
use voxlod_testkit::data::shared_data_or_skip;

const MESHES: [&str; 11] = [
    "stanford-bunny.obj",
    "fandisk.obj",
    "rocker-arm.obj",
    "wingnut.obj",
    "cgal-pinion-gear.off",
    "cgal-blade.off",
    "utah-teapot.obj",
    "cgal-elephant-with-holes.off",
    "thingi10k-68247.stl",
    "thingi10k-138207.stl",
    "thingi10k-42722.stl",
];

/// Runs lod and checks every level: closed, consistently oriented, non-empty at level 0, and
/// no more handles than the level above; prints the genus sequence.
fn check_lod(input: &std::path::Path, extra: &[&str]) -> serde_json::Value {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let mut args = vec!["lod", arg(input), "-o", arg(&out), "--json"];
    args.extend(extra);
    let report = json(&voxlod(&args));
    let levels = report["levels"].as_array().unwrap();
    assert!(
        levels[0]["triangles"].as_u64().unwrap() > 0,
        "{input:?}: empty level 0"
    );
    let genus: Vec<i64> = levels
        .iter()
        .map(|l| l["genus"].as_i64().unwrap())
        .collect();
    let resolutions: Vec<u64> = (levels.iter())
        .map(|l| l["resolution"].as_u64().unwrap())
        .collect();
    eprintln!("{input:?} {extra:?}: resolutions {resolutions:?}, genus {genus:?}");
    assert!(
        genus.windows(2).all(|w| w[1] <= w[0]),
        "{input:?}: the genus rises along the chain: {genus:?}"
    );
    for (k, l) in levels.iter().enumerate().skip(1) {
        assert_eq!(
            l["handles_removed"].as_i64().unwrap(),
            genus[k - 1] - genus[k],
            "{input:?} level {k}"
        );
    }
    for l in levels {
        assert_eq!(l["closed_manifold"], true, "{input:?} level {}", l["level"]);
        let Some(file) = l["file"].as_str() else {
            assert_eq!(
                l["triangles"], 0,
                "{input:?}: a level without a file must be empty"
            );
            assert!(!out.join(format!("level-{}.ply", l["level"])).exists());
            continue;
        };
        let mesh = voxlod::io::read_mesh(&out.join(file)).unwrap().mesh;
        let t = voxlod::core::mesh_topology(&mesh);
        assert!(
            t.is_closed_manifold() && t.is_consistently_oriented(),
            "{input:?}: {t:?}"
        );
        if !mesh.is_empty() {
            assert!(mesh.signed_volume() > 0.0, "{input:?}: inside out");
        }
    }
    report
}

#[test]
fn every_shared_mesh_gives_closed_levels() {
    for name in MESHES {
        let Some(path) = shared_data_or_skip(
            &format!("meshes/{name}"),
            "every_shared_mesh_gives_closed_levels",
        ) else {
            return;
        };
        let flags = ["--resolution", "64", "--levels", "3"];
        // The blade is an open sheet 0.65 thick and 129 long, closed at its two ends: thinner
        // than a voxel at 64 samples, the filter removes it (it appears from 256 on). No level
        // has a surface: an error, and nothing written.
        if name == "cgal-blade.off" {
            let dir = tempfile::tempdir().unwrap();
            let out = dir.path().join("out");
            let mut args = vec!["lod", arg(&path), "-o", arg(&out)];
            args.extend(flags);
            assert_clean_failure(&voxlod(&args), "no level has a surface");
            assert!(!out.exists());
            continue;
        }
        let report = check_lod(&path, &flags);
        // Scanned holes are closed before sampling; the bunny has five.
        if name == "stanford-bunny.obj" {
            assert_eq!(report["mesh"]["preparation"]["holes_closed"], 5);
            assert_eq!(
                report["levels"][0]["genus"], 0,
                "the closed bunny is a sphere"
            );
        }
    }
}

#[test]
fn the_inside_out_stl_gives_the_solid_it_shows() {
    let Some(path) = shared_data_or_skip(
        "meshes/thingi10k-68247.stl",
        "the_inside_out_stl_gives_the_solid_it_shows",
    ) else {
        return;
    };
    let loaded = voxlod::io::read_mesh(&path).unwrap();
    assert!(loaded.mesh.signed_volume() < 0.0, "the file is inside out");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o");
    let report = json(&voxlod(&[
        "lod",
        arg(&path),
        "-o",
        arg(&out),
        "--resolution",
        "96",
        "--levels",
        "1",
        "--json",
    ]));
    assert_eq!(report["levels"][0]["closed_manifold"], true);
    let mesh = voxlod::io::read_mesh(&out.join("level-0.ply"))
        .unwrap()
        .mesh;
    // Outward-facing and of the shell's volume (its thin parts are slightly eroded at 96).
    let (ours, theirs) = (mesh.signed_volume(), -loaded.mesh.signed_volume());
    assert!(
        (ours / theirs - 1.0).abs() < 0.05,
        "volume {ours} vs the shell's {theirs}"
    );
}

const CT_HEAD: &str = "volumes/CThead_256x256x113_uint16be.raw";
const CT_FLAGS: [&str; 8] = [
    "--dims",
    "256,256,113",
    "--dtype",
    "u16",
    "--endian",
    "big",
    "--spacing",
    "1,1,2",
];

#[test]
fn the_ct_head_gives_closed_skin_and_bone() {
    let Some(path) = shared_data_or_skip(CT_HEAD, "the_ct_head_gives_closed_skin_and_bone") else {
        return;
    };
    for threshold in ["500", "1500"] {
        let mut flags = CT_FLAGS.to_vec();
        flags.extend([
            "--threshold",
            threshold,
            "--resolution",
            "96",
            "--levels",
            "3",
        ]);
        let report = check_lod(&path, &flags);
        // Millimetres: the head is about 256 mm across.
        assert!((report["levels"][0]["voxel_size"].as_f64().unwrap() - 256.0 / 96.0).abs() < 0.5);
    }
}

/// The other scans and their routes: thresholded CT, and CT and MRI filtered directly.
fn other_scans() -> [(&'static str, Vec<&'static str>); 4] {
    [
        (
            "volumes/tooth_103x94x161_uint8.nrrd",
            vec!["--threshold", "100"],
        ),
        (
            "volumes/engine_256x256x128_uint8.raw",
            vec!["--dims", "256,256,128", "--threshold", "100"],
        ),
        (
            "volumes/LIDC2_lung_ct_256x256x133_uint8.mha",
            vec!["--direct", "--iso", "100"],
        ),
        (
            "volumes/ch2_colin27_T1.nii.gz",
            vec!["--direct", "--iso", "80"],
        ),
    ]
}

#[test]
fn other_scans_enter_by_threshold_and_directly() {
    for (file, route) in other_scans() {
        let Some(path) = shared_data_or_skip(file, "other_scans_enter_by_threshold_and_directly")
        else {
            continue;
        };
        let mut flags = route.clone();
        flags.extend(["--resolution", "64", "--levels", "2"]);
        check_lod(&path, &flags);
    }
}

#[test]
#[ignore = "a minute or more: run by scripts/real-data.sh"]
fn full_resolution_real_data() {
    for name in MESHES {
        let Some(path) =
            shared_data_or_skip(&format!("meshes/{name}"), "full_resolution_real_data")
        else {
            return;
        };
        check_lod(&path, &[]);
    }
    let Some(path) = shared_data_or_skip(CT_HEAD, "full_resolution_real_data") else {
        return;
    };
    for threshold in ["500", "1500"] {
        let mut flags = CT_FLAGS.to_vec();
        flags.extend(["--threshold", threshold]);
        check_lod(&path, &flags);
    }
    for (file, route) in other_scans() {
        if let Some(path) = shared_data_or_skip(file, "full_resolution_real_data") {
            check_lod(&path, &route);
        }
    }
}
