//! `voxlod envelope` and `voxlod lod --then-envelope` end to end: reports that match the files,
//! the guarantees visible from outside (topology, distance within ε), and bad input that fails
//! cleanly with no output file.

mod common;

use common::*;
use voxlod::core::glam::Vec3;
use voxlod::core::{mesh_topology, TriangleMesh};
use voxlod_testkit::data::shared_data_or_skip;
use voxlod_testkit::shapes;

#[test]
fn envelope_writes_a_level_within_epsilon() {
    let dir = tempfile::tempdir().unwrap();
    let sphere = shapes::icosphere(4);
    let input = write_mesh(dir.path(), "sphere.obj", &sphere);
    let out = dir.path().join("sphere-1.ply");
    let report = json(&voxlod(&[
        "envelope",
        arg(&input),
        "-o",
        arg(&out),
        "--epsilon",
        "1%",
        "--samples",
        "20000",
        "--json",
    ]));
    let level = &report["levels"][0];
    let mesh = voxlod::io::read_mesh(&out).unwrap().mesh;
    assert_eq!(
        mesh.triangles.len() as u64,
        level["triangles"].as_u64().unwrap()
    );
    assert!(mesh.triangles.len() * 4 < sphere.triangles.len());
    assert!((level["epsilon_percent"].as_f64().unwrap() - 1.0).abs() < 1e-9);
    let eps = level["epsilon"].as_f64().unwrap();
    let hausdorff = level["distance"]["hausdorff"].as_f64().unwrap();
    assert!(
        hausdorff > 0.0 && hausdorff <= eps * (1.0 + 1e-9),
        "{hausdorff} vs {eps}"
    );
    assert!(level["reduction_percent"].as_f64().unwrap() > 75.0);
    assert!(level["seconds"].as_f64().unwrap() >= 0.0);
    let t = mesh_topology(&mesh);
    assert_eq!(t.genus, Some(0));
    assert!(t.is_closed_manifold());
}

#[test]
fn envelope_series_names_each_level() {
    let dir = tempfile::tempdir().unwrap();
    let ring = shapes::torus(48, 16, 1.0, 0.3);
    let input = write_mesh(dir.path(), "ring.obj", &ring);
    let out = dir.path().join("ring.ply");
    let o = voxlod(&[
        "envelope",
        arg(&input),
        "-o",
        arg(&out),
        "--levels",
        "1%,2%,4%",
        "--samples",
        "0",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("level 2: ε"), "{}", stdout(&o));
    let mut last = usize::MAX;
    for k in 0..3 {
        let mesh = voxlod::io::read_mesh(&dir.path().join(format!("ring-{k}.ply")))
            .unwrap()
            .mesh;
        assert!(mesh.triangles.len() <= last);
        last = mesh.triangles.len();
        assert_eq!(mesh_topology(&mesh).genus, Some(1), "level {k}");
    }
    assert!(!out.exists(), "a series writes ring-K.ply, not ring.ply");
}

#[test]
fn envelope_refuses_bad_input_without_writing() {
    let dir = tempfile::tempdir().unwrap();
    let sphere = write_mesh(dir.path(), "sphere.obj", &shapes::icosphere(2));
    let out = dir.path().join("out.ply");
    for eps in ["0", "-1%", "abc", "0%"] {
        let o = voxlod(&["envelope", arg(&sphere), "-o", arg(&out), "--epsilon", eps]);
        assert_clean_failure(&o, "ε must be a positive");
        assert!(!out.exists());
    }
    let o = voxlod(&[
        "envelope",
        arg(&sphere),
        "-o",
        arg(&out),
        "--levels",
        "2%,1%",
    ]);
    assert_clean_failure(&o, "growing");
    assert!(!out.exists() && !dir.path().join("out-0.ply").exists());

    // An empty mesh: vertices, no faces.
    let empty = dir.path().join("empty.obj");
    std::fs::write(&empty, "v 0 0 0\nv 1 0 0\nv 0 1 0\n").unwrap();
    let o = voxlod(&["envelope", arg(&empty), "-o", arg(&out), "--epsilon", "1%"]);
    assert_clean_failure(&o, "empty.obj");
    assert!(!out.exists());

    // A fin on a sphere: named, refused, then repaired on request.
    let mut fin: TriangleMesh = shapes::icosphere(2);
    let [a, b, _] = fin.triangles[0];
    fin.positions.push(Vec3::new(3.0, 3.0, 3.0));
    fin.triangles.push([a, b, (fin.positions.len() - 1) as u32]);
    let fin_path = write_mesh(dir.path(), "fin.obj", &fin);
    let o = voxlod(&[
        "envelope",
        arg(&fin_path),
        "-o",
        arg(&out),
        "--epsilon",
        "1%",
    ]);
    assert_clean_failure(&o, &format!("edge {}–{} (3 triangles)", a.min(b), a.max(b)));
    assert!(stderr(&o).contains("--repair"));
    assert!(!out.exists());
    let report = json(&voxlod(&[
        "envelope",
        arg(&fin_path),
        "-o",
        arg(&out),
        "--epsilon",
        "1%",
        "--repair",
        "--samples",
        "0",
        "--json",
    ]));
    assert!(report["repair"]["half_edges_unpaired"].as_u64().unwrap() >= 1);
    assert!(out.exists());
}

#[test]
fn lod_then_envelope_keeps_the_genus_of_each_level() {
    let dir = tempfile::tempdir().unwrap();
    let input = write_mesh(dir.path(), "block.obj", &holed_block());
    let out = dir.path().join("levels");
    let report = json(&voxlod(&[
        "lod",
        arg(&input),
        "-o",
        arg(&out),
        "--resolutions",
        "48,24",
        "--then-envelope",
        "1vox",
        "--json",
    ]));
    for l in report["levels"].as_array().unwrap() {
        let env = &l["envelope"];
        let before = env["triangles_before"].as_u64().unwrap();
        let after = env["triangles"].as_u64().unwrap();
        assert!(after * 2 <= before, "{before} -> {after}");
        assert_eq!(env["genus"], l["genus"]);
        assert!(env["hausdorff"].as_f64().unwrap() <= env["epsilon"].as_f64().unwrap() * 1.000001);
        let mesh = voxlod::io::read_mesh(&out.join(l["file"].as_str().unwrap()))
            .unwrap()
            .mesh;
        assert_eq!(mesh.triangles.len() as u64, after);
        assert_eq!(mesh_topology(&mesh).genus, Some(1));
    }
    let o = voxlod(&[
        "lod",
        arg(&input),
        "-o",
        arg(&dir.path().join("bad")),
        "--then-envelope",
        "0vox",
    ]);
    assert_clean_failure(&o, "--then-envelope");
}

/// Envelopes after marching cubes: a 128³ level of the bunny loses at least half its
/// triangles with ε of one voxel, and keeps the genus the filter gave it.
#[test]
fn bunny_at_128_halves_with_one_voxel() {
    let Some(bunny) = shared_data_or_skip(
        "meshes/stanford-bunny.obj",
        "bunny_at_128_halves_with_one_voxel",
    ) else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("levels");
    let report = json(&voxlod(&[
        "lod",
        arg(&bunny),
        "-o",
        arg(&out),
        "--resolutions",
        "128",
        "--then-envelope",
        "1vox",
        "--json",
    ]));
    let l = &report["levels"][0];
    let env = &l["envelope"];
    let before = env["triangles_before"].as_u64().unwrap();
    let after = env["triangles"].as_u64().unwrap();
    eprintln!(
        "bunny 128: {before} -> {after} triangles ({:.1} % fewer), ε {:.5}, measured {:.5}, {:.2} s",
        env["reduction_percent"].as_f64().unwrap(),
        env["epsilon"].as_f64().unwrap(),
        env["hausdorff"].as_f64().unwrap(),
        env["seconds"].as_f64().unwrap()
    );
    assert!(after * 2 <= before);
    assert!((env["epsilon"].as_f64().unwrap() - l["voxel_size"].as_f64().unwrap()).abs() < 1e-12);
    let mesh = voxlod::io::read_mesh(&out.join(l["file"].as_str().unwrap()))
        .unwrap()
        .mesh;
    let t = mesh_topology(&mesh);
    assert_eq!(t.genus, l["genus"].as_i64());
    assert_eq!(t.components as u64, l["components"].as_u64().unwrap());
}
