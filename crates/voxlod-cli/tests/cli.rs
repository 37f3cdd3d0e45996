//! The `voxlod` command line end to end: outputs that can be checked, and bad input that must
//! fail cleanly (one line naming the file and the problem, non-zero exit, no partial output).

mod common;

use common::*;
use voxlod::core::{mesh_topology, Grid, Volume};

#[test]
fn lod_writes_closed_levels_and_a_report() {
    let dir = tempfile::tempdir().unwrap();
    let input = write_mesh(dir.path(), "block.obj", &holed_block());
    let out = dir.path().join("levels");
    let o = voxlod(&[
        "lod",
        arg(&input),
        "-o",
        arg(&out),
        "--resolutions",
        "40,20,3",
        "--json",
    ]);
    let report = json(&o);
    let levels = report["levels"].as_array().unwrap();
    assert_eq!(levels.len(), 3);
    let resolutions: Vec<u64> = levels
        .iter()
        .map(|l| l["resolution"].as_u64().unwrap())
        .collect();
    assert_eq!(resolutions, vec![40, 20, 3]);
    for l in levels {
        let path = out.join(l["file"].as_str().unwrap());
        let mesh = voxlod::io::read_mesh(&path).unwrap().mesh;
        assert_eq!(
            mesh.triangles.len() as u64,
            l["triangles"].as_u64().unwrap()
        );
        assert!(!mesh.normals.is_empty(), "PLY keeps the gradient normals");
        let t = mesh_topology(&mesh);
        assert!(
            t.is_closed_manifold() && t.is_consistently_oriented(),
            "{t:?}"
        );
        assert_eq!(l["closed_manifold"], true);
        assert_eq!(t.genus, l["genus"].as_i64());
    }
    // Genus drops as detail goes: the through-hole (0.8 wide in a block 2 wide) survives at 40
    // and 20 samples and is filtered away at 3, where the filter's radius is 2/3.
    assert_eq!(levels[0]["genus"], 1);
    assert_eq!(levels[1]["genus"], 1);
    assert_eq!(levels[2]["genus"], 0);
    assert!(levels[2]["triangles"].as_u64().unwrap() > 0);
    let on_disk: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert_eq!(on_disk["levels"], report["levels"]);
}

#[test]
fn lod_by_budget_says_what_preparing_the_mesh_repaired() {
    // An icosphere of 320 triangles given twice: the copies are dropped before the levels are
    // made, and the report and standard error say so.
    let dir = tempfile::tempdir().unwrap();
    let mut mesh = voxlod_testkit::shapes::icosphere(2);
    let copies = mesh.triangles.clone();
    mesh.triangles.extend(copies);
    let input = write_mesh(dir.path(), "twice.obj", &mesh);
    let out = dir.path().join("levels");
    let report = json(&voxlod(&[
        "lod",
        arg(&input),
        "-o",
        arg(&out),
        "--triangles",
        "100",
        "--json",
    ]));
    let summary = &report["mesh"];
    assert_eq!(summary["triangles"], 640, "{report}");
    assert_eq!(
        summary["preparation"]["duplicate_triangles"], 320,
        "{report}"
    );
    assert_eq!(
        summary["preparation"]["degenerate_triangles"], 0,
        "{report}"
    );
    let o = voxlod(&["lod", arg(&input), "-o", arg(&out), "--triangles", "100"]);
    assert!(
        stderr(&o).contains("twice.obj: 320 duplicate triangles dropped"),
        "{}",
        stderr(&o)
    );
}

/// A tetrahedron in a `.gltf` file with its buffer beside it, its node moved by (10, 0, 0).
fn tetrahedron_gltf(dir: &std::path::Path) -> std::path::PathBuf {
    let positions: [[f32; 3]; 4] = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    let indices: [u16; 12] = [0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3];
    let mut bytes: Vec<u8> = positions
        .iter()
        .flatten()
        .flat_map(|c| c.to_le_bytes())
        .collect();
    bytes.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
    std::fs::write(dir.join("tet.bin"), &bytes).unwrap();
    let document = serde_json::json!({
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "translation": [10.0, 0.0, 0.0]}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "buffers": [{"byteLength": bytes.len(), "uri": "tet.bin"}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 48},
            {"buffer": 0, "byteOffset": 48, "byteLength": 24}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
             "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 1.0]},
            {"bufferView": 1, "componentType": 5123, "count": 12, "type": "SCALAR"}
        ]
    });
    let path = dir.join("tet.gltf");
    std::fs::write(&path, document.to_string()).unwrap();
    path
}

#[test]
fn the_mesh_commands_read_a_gltf_file_as_its_scene_in_world_space() {
    let dir = tempfile::tempdir().unwrap();
    let gltf = tetrahedron_gltf(dir.path());
    let obj = dir.path().join("tet.obj");
    std::fs::write(
        &obj,
        "v 10 0 0\nv 11 0 0\nv 10 1 0\nv 10 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n",
    )
    .unwrap();
    let compared = json(&voxlod(&["compare", arg(&gltf), arg(&obj), "--json"]));
    assert!(
        compared["hausdorff"].as_f64().unwrap() < 1e-6,
        "the node's translation is applied: {compared}"
    );
    let inspected = json(&voxlod(&["inspect", arg(&gltf), "--json"]));
    assert_eq!(inspected["format"], "glTF", "{inspected}");
    assert_eq!(inspected["triangles"], 4, "{inspected}");
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap();
    for args in [
        vec!["cluster", arg(&gltf), "-o", "c.ply", "--cells", "4"],
        vec!["envelope", arg(&gltf), "-o", "e.ply", "--epsilon", "1%"],
        vec!["voxelize", arg(&gltf), "-o", "v.nrrd", "--resolution", "16"],
    ] {
        let args: Vec<String> = (args.iter().enumerate())
            .map(|(i, a)| match i {
                3 => out.join(a).display().to_string(),
                _ => a.to_string(),
            })
            .collect();
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        voxlod(&args);
    }
    let level = voxlod::io::read_mesh(&out.join("e.ply")).unwrap().mesh;
    assert!((level.bounds().min.x - 10.0).abs() < 1e-6);
}

#[test]
fn lod_writes_every_mesh_format() {
    let dir = tempfile::tempdir().unwrap();
    let input = write_mesh(dir.path(), "block.stl", &holed_block());
    for format in ["ply", "obj", "stl", "vtp", "vtk"] {
        let out = dir.path().join(format);
        let o = voxlod(&[
            "lod",
            arg(&input),
            "-o",
            arg(&out),
            "--resolution",
            "16",
            "--levels",
            "2",
            "--format",
            format,
            "--json",
        ]);
        let report = json(&o);
        for l in report["levels"].as_array().unwrap() {
            let mesh = voxlod::io::read_mesh(&out.join(l["file"].as_str().unwrap()))
                .unwrap()
                .mesh;
            // STL is a soup, welded on load: the counts survive every format.
            assert_eq!(
                mesh.triangles.len() as u64,
                l["triangles"].as_u64().unwrap(),
                "{format}"
            );
            assert!(mesh_topology(&mesh).is_closed_manifold(), "{format}");
        }
    }
}

#[test]
fn voxelize_then_contour_gives_the_lod_level() {
    let dir = tempfile::tempdir().unwrap();
    let input = write_mesh(dir.path(), "block.off", &holed_block());
    let volume = dir.path().join("density.nrrd");
    let o = voxlod(&[
        "voxelize",
        arg(&input),
        "-o",
        arg(&volume),
        "--resolution",
        "24",
        "--filter",
        "gaussian",
        "--json",
    ]);
    let v = json(&o);
    assert!(volume.exists());
    let surface = dir.path().join("surface.ply");
    let o = voxlod(&[
        "contour",
        arg(&volume),
        "-o",
        arg(&surface),
        "--iso",
        "0.5",
        "--json",
    ]);
    let c = json(&o);
    for key in ["read_seconds", "contour_seconds", "write_seconds"] {
        assert!(c[key].as_f64().unwrap() >= 0.0, "{key}");
    }
    assert_eq!(c["dims"], v["dims"]);
    let out = dir.path().join("lod");
    let o = voxlod(&[
        "lod",
        arg(&input),
        "-o",
        arg(&out),
        "--resolutions",
        "24",
        "--filter",
        "gaussian",
        "--json",
    ]);
    let l = json(&o);
    // `contour` gives marching cubes as is; `lod` gives the same unless its levels are cleaned
    // (clean_mesh collapses slivers and needles: it only removes triangles, keeping the
    // surface closed).
    let (raw, cleaned) = (
        c["triangles"].as_u64().unwrap(),
        l["levels"][0]["triangles"].as_u64().unwrap(),
    );
    assert!(cleaned <= raw && cleaned * 10 >= raw * 8, "{raw} {cleaned}");
    assert_eq!(c["genus"], l["levels"][0]["genus"]);
    assert_eq!(l["levels"][0]["closed_manifold"], true);
    assert_eq!(c["closed_manifold"], true);
}

/// A 20³ u16 big-endian raw sphere of radius 6 samples (values 1000 inside, 0 outside),
/// spacing 1 × 1 × 2.
fn raw_sphere(dir: &std::path::Path) -> std::path::PathBuf {
    let mut bytes = Vec::new();
    for k in 0..20i32 {
        for j in 0..20i32 {
            for i in 0..20i32 {
                let (x, y, z) = (i - 10, j - 10, 2 * (k - 10));
                let inside = x * x + y * y + z * z <= 64;
                bytes.extend_from_slice(&(if inside { 1000u16 } else { 0 }).to_be_bytes());
            }
        }
    }
    let path = dir.join("sphere.raw");
    std::fs::write(&path, bytes).unwrap();
    path
}

#[test]
fn raw_volumes_keep_their_spacing_through_both_routes() {
    let dir = tempfile::tempdir().unwrap();
    let raw = raw_sphere(dir.path());
    let flags = [
        "--dims",
        "20,20,20",
        "--dtype",
        "u16",
        "--endian",
        "big",
        "--spacing",
        "1,1,2",
    ];
    for (route, iso) in [
        (vec!["--threshold", "500"], None),
        (vec!["--direct"], Some("400")),
    ] {
        let out = dir.path().join(route[0].trim_start_matches('-'));
        let mut args = vec![
            "lod",
            arg(&raw),
            "-o",
            arg(&out),
            "--resolution",
            "32",
            "--levels",
            "2",
            "--json",
        ];
        args.extend(&flags);
        args.extend(&route);
        if let Some(iso) = iso {
            args.extend(["--iso", iso]);
        }
        let report = json(&voxlod(&args));
        let mesh = voxlod::io::read_mesh(&out.join("level-0.ply"))
            .unwrap()
            .mesh;
        assert!(mesh_topology(&mesh).is_closed_manifold(), "{route:?}");
        // In millimetres: the sphere spans about 16 mm in x and 16 mm in z (8 slices of 2 mm).
        let size = mesh.bounds().size();
        assert!(
            (size.x - 16.0).abs() < 2.5 && (size.z - 16.0).abs() < 3.0,
            "{route:?}: {size}"
        );
        assert_eq!(report["route"], route[0].trim_start_matches('-'));
    }
}

#[test]
fn demo_prints_table_1_beside_the_paper() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("demo");
    let o = voxlod(&["demo", "-o", arg(&out)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    assert!(
        text.contains("322,214") && text.contains("paper triangles"),
        "{text}"
    );
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    let rows = report["table1"].as_array().unwrap();
    assert_eq!(rows.len(), 6);
    assert_eq!(report["spheres"], 820);
    let counts: Vec<u64> = rows
        .iter()
        .map(|r| r["triangles"].as_u64().unwrap())
        .collect();
    assert!(
        counts.windows(2).all(|w| w[0] > w[1]),
        "triangles fall with resolution: {counts:?}"
    );
    assert!(rows.iter().all(|r| r["closed_manifold"] == true));
    for r in rows {
        assert!(out.join(r["file"].as_str().unwrap()).exists());
    }
}

// ----------------------------------------------------------------------------------------
// Bad input.

#[test]
fn bad_meshes_fail_cleanly_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("empty.obj"), "").unwrap();
    std::fs::write(d.join("nan.obj"), "v 0 0 0\nv 1 0 0\nv 0 nan 0\nf 1 2 3\n").unwrap();
    std::fs::write(
        d.join("inf.off"),
        "OFF\n3 1 0\n0 0 0\n1 0 0\n0 inf 0\n3 0 1 2\n",
    )
    .unwrap();
    std::fs::write(d.join("nofaces.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\n").unwrap();
    std::fs::write(
        d.join("flat.obj"),
        "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\nf 1 2 3\n",
    )
    .unwrap();
    std::fs::write(d.join("garbage.ply"), b"ply\nformat binary_little_endian 1.0\nelement vertex 1000\nproperty float x\nproperty float y\nproperty float z\nend_header\n\x01\x02").unwrap();
    std::fs::write(d.join("shape.xyz"), "1 2 3\n").unwrap();
    for (file, problem) in [
        ("empty.obj", "empty"),
        ("nan.obj", "vertex"),
        ("inf.off", "vertex"),
        ("nofaces.obj", "triangles"),
        ("flat.obj", "flat.obj"),
        ("garbage.ply", "garbage.ply"),
        ("shape.xyz", "extension"),
        ("missing.obj", "missing.obj"),
    ] {
        let out = d.join(format!("out-{file}"));
        let o = voxlod(&[
            "lod",
            arg(&d.join(file)),
            "-o",
            arg(&out),
            "--resolution",
            "16",
        ]);
        assert_clean_failure(&o, file);
        assert_clean_failure(&o, problem);
        assert!(files_in(&out).is_empty(), "{file}: output left behind");
    }
}

#[test]
fn bad_options_fail_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let input = write_mesh(d, "block.ply", &holed_block());
    let out = d.join("out");
    for (extra, problem) in [
        (vec!["--resolution", "0"], "at least 1"),
        (vec!["--resolutions", "32,0"], "resolution 0"),
        (vec!["--resolution", "100000000"], "bytes"),
        (vec!["--iso", "1.5"], "between 0 and 1"),
        (vec!["--radius", "0"], "radius"),
        (vec!["--levels", "0"], "at least 1"),
    ] {
        let mut args = vec!["lod", arg(&input), "-o", arg(&out)];
        args.extend(&extra);
        let o = voxlod(&args);
        assert_clean_failure(&o, problem);
        assert!(files_in(&out).is_empty(), "{extra:?}: output left behind");
    }
}

#[test]
fn bad_volumes_fail_cleanly_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let raw = raw_sphere(d);
    let out = d.join("surface.ply");
    // Wrong dimensions for the file size.
    let o = voxlod(&[
        "contour",
        arg(&raw),
        "-o",
        arg(&out),
        "--iso",
        "1",
        "--dims",
        "20,20,21",
        "--dtype",
        "u16",
    ]);
    assert_clean_failure(&o, "sphere.raw");
    assert!(!out.exists());
    // A raw file without dims.
    let o = voxlod(&["contour", arg(&raw), "-o", arg(&out), "--iso", "1"]);
    assert_clean_failure(&o, "--dims");
    // An iso value outside the data's range.
    let o = voxlod(&[
        "contour",
        arg(&raw),
        "-o",
        arg(&out),
        "--iso",
        "5000",
        "--dims",
        "20,20,20",
        "--dtype",
        "u16",
        "--endian",
        "big",
    ]);
    assert_clean_failure(&o, "--iso 5000 is above the data's maximum");
    assert!(!out.exists());
    // A volume given to lod without a route.
    let lod_out = d.join("levels");
    let o = voxlod(&[
        "lod",
        arg(&raw),
        "-o",
        arg(&lod_out),
        "--dims",
        "20,20,20",
        "--dtype",
        "u16",
    ]);
    assert_clean_failure(&o, "--threshold");
    assert!(files_in(&lod_out).is_empty());
    // A threshold above every sample.
    let o = voxlod(&[
        "lod",
        arg(&raw),
        "-o",
        arg(&lod_out),
        "--dims",
        "20,20,20",
        "--dtype",
        "u16",
        "--endian",
        "big",
        "--threshold",
        "99999",
    ]);
    assert_clean_failure(&o, "above every value");
    // A truncated NRRD.
    let grid = Grid::unit([8, 8, 8]).unwrap();
    let v = Volume::from_vec(grid, vec![1.0; 512]).unwrap();
    let nrrd = d.join("cut.nrrd");
    voxlod::io::write_volume(&nrrd, &v).unwrap();
    let bytes = std::fs::read(&nrrd).unwrap();
    std::fs::write(&nrrd, &bytes[..bytes.len() - 100]).unwrap();
    let o = voxlod(&["contour", arg(&nrrd), "-o", arg(&out), "--iso", "0.5"]);
    assert_clean_failure(&o, "cut.nrrd");
    assert!(!out.exists());
}

#[test]
fn help_teaches() {
    let o = voxlod(&["--help"]);
    let text = stdout(&o);
    for command in ["demo", "lod", "voxelize", "contour"] {
        assert!(text.contains(command), "{command} missing from --help");
    }
    let o = voxlod(&["lod", "--help"]);
    let text = stdout(&o);
    assert!(
        text.contains("Examples:") && text.contains("--threshold") && text.contains("--direct")
    );
}

#[test]
fn contour_closes_surfaces_cut_by_the_volume_boundary_on_request() {
    let dir = tempfile::tempdir().unwrap();
    // A slab filling the volume's middle third in z: it touches the x and y boundaries.
    let grid = Grid::unit([10, 10, 12]).unwrap();
    let data: Vec<f32> = (0..grid.len())
        .map(|i| {
            if (4..8).contains(&(i / 100)) {
                1.0
            } else {
                0.0
            }
        })
        .collect();
    let volume = dir.path().join("slab.nrrd");
    voxlod::io::write_volume(&volume, &Volume::from_vec(grid, data).unwrap()).unwrap();
    for (close, closed) in [(false, false), (true, true)] {
        let out = dir.path().join(format!("slab-{close}.ply"));
        let mut args = vec![
            "contour",
            arg(&volume),
            "-o",
            arg(&out),
            "--iso",
            "0.5",
            "--json",
        ];
        if close {
            args.push("--close");
        }
        let report = json(&voxlod(&args));
        assert_eq!(report["closed_manifold"], closed);
        let t = mesh_topology(&voxlod::io::read_mesh(&out).unwrap().mesh);
        assert_eq!(t.is_closed_manifold(), closed);
        if closed {
            assert_eq!(t.genus, Some(0));
        }
    }
}
