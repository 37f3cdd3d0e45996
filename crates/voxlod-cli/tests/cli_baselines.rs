//! `voxlod cluster` and `voxlod select`: hand-checked counts through files, and bad input.

mod common;

use common::*;
use voxlod::core::glam::Vec3;
use voxlod::core::TriangleMesh;
use voxlod_testkit::shapes;

#[test]
fn a_cube_in_one_cell_is_one_point_in_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let input = write_mesh(dir.path(), "cube.obj", &shapes::unit_cube());
    // Rossignac–Borrel's one grid cell holds the whole cube: one point. Low–Tan's floating cell
    // of side 1 is centred on a corner and reaches no other corner: the cube is unchanged.
    for (method, expected) in [("rossignac-borrel", (0, 0, 1)), ("low-tan", (12, 0, 0))] {
        let out = dir.path().join(format!("{method}.ply"));
        let report = json(&voxlod(&[
            "cluster",
            arg(&input),
            "-o",
            arg(&out),
            "--method",
            method,
            "--cells",
            "1",
            "--json",
        ]));
        let l = &report["levels"][0];
        let counts = |k: &str| l[k].as_u64().unwrap() as usize;
        assert_eq!(
            (
                counts("triangles"),
                counts("dangling_edges"),
                counts("isolated_points")
            ),
            expected,
            "{method}"
        );
        let poly = voxlod::io::read_poly_mesh(&out).unwrap();
        assert_eq!(
            (
                poly.mesh.triangles.len(),
                poly.lines.len(),
                poly.points.len()
            ),
            expected,
            "{method}"
        );
        assert!(l["cluster_seconds"].as_f64().unwrap() >= 0.0);
    }
}

#[test]
fn a_thin_strip_collapses_to_a_thick_edge_in_the_file() {
    // Two triangles 1 long and 0.1 wide: at 4 cells they collapse onto one edge.
    let strip = TriangleMesh::new(
        vec![
            Vec3::ZERO,
            Vec3::X,
            Vec3::new(1.0, 0.1, 0.0),
            Vec3::new(0.0, 0.1, 0.0),
        ],
        vec![[0, 1, 2], [0, 2, 3]],
    );
    let dir = tempfile::tempdir().unwrap();
    let input = write_mesh(dir.path(), "strip.ply", &strip);
    let out = dir.path().join("edge.ply");
    let report = json(&voxlod(&[
        "cluster",
        arg(&input),
        "-o",
        arg(&out),
        "--method",
        "low-tan",
        "--cells",
        "2",
        "--json",
    ]));
    assert_eq!(report["levels"][0]["dangling_edges"], 1);
    let poly = voxlod::io::read_poly_mesh(&out).unwrap();
    assert_eq!(poly.lines.len(), 1);
    let width = poly
        .line_attributes
        .iter()
        .find(|a| a.name == "width")
        .expect("a width");
    // Cauchy's mean width: the collapsed area 0.1 over π times the edge's length, 1.
    let expected = 0.1 / std::f32::consts::PI;
    assert!(
        (width.values[0] / expected - 1.0).abs() < 0.01,
        "{:?}",
        width.values
    );
}

#[test]
fn levels_get_their_own_files_and_select_picks_one() {
    let dir = tempfile::tempdir().unwrap();
    let input = write_mesh(dir.path(), "torus.ply", &shapes::torus(96, 48, 2.0, 0.6));
    let out = dir.path().join("torus.ply");
    let o = voxlod(&[
        "cluster",
        arg(&input),
        "-o",
        arg(&out),
        "--cells",
        "32",
        "--levels",
        "3",
        "--json",
    ]);
    let report = json(&o);
    let sizes: Vec<f64> = report["levels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| l["cell_size"].as_f64().unwrap())
        .collect();
    for k in 0..3 {
        assert!(dir.path().join(format!("torus-{k}.ply")).exists());
    }
    assert!((sizes[1] / sizes[0] - 2.0).abs() < 1e-9 && (sizes[2] / sizes[1] - 2.0).abs() < 1e-9);
    let report_path = dir.path().join("cluster.json");
    std::fs::write(&report_path, stdout(&o)).unwrap();
    // A pixel between the middle and the coarsest cell size: the middle level.
    let pixel = (sizes[1] + sizes[2]) / 2.0;
    let choice = json(&voxlod(&[
        "select",
        arg(&report_path),
        "--pixel-size",
        &pixel.to_string(),
        "--json",
    ]));
    assert_eq!(choice["level"], 1);
    // Smaller than the finest cells: the original.
    let choice = json(&voxlod(&[
        "select",
        arg(&report_path),
        "--pixel-size",
        &(sizes[0] / 2.0).to_string(),
        "--json",
    ]));
    assert_eq!(choice["selection"], "original");
}

#[test]
fn bad_clustering_input_fails_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let cube = write_mesh(d, "cube.obj", &shapes::unit_cube());
    std::fs::write(d.join("nan.obj"), "v 0 0 0\nv 1 0 0\nv 0 nan 0\nf 1 2 3\n").unwrap();
    std::fs::write(d.join("empty.off"), "").unwrap();
    for (input, cells, output, problem) in [
        (&cube, "0", "out.ply", "cell"),
        (&d.join("nan.obj"), "8", "out.ply", "nan.obj"),
        (&d.join("empty.off"), "8", "out.ply", "empty.off"),
        (&cube, "8", "out.obj", "out.obj"),
    ] {
        let out = d.join(output);
        let o = voxlod(&["cluster", arg(input), "-o", arg(&out), "--cells", cells]);
        assert_clean_failure(&o, problem);
        assert!(!out.exists(), "{output} left behind");
    }
    let o = voxlod(&["select", arg(&cube), "--pixel-size", "1"]);
    assert_clean_failure(&o, "cube.obj");
}
