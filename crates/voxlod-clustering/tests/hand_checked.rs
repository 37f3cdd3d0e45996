//! Small cases whose results were worked out by hand, for both methods.

mod common;

use common::as_sets;
use voxlod_clustering::{
    low_tan, rossignac_borrel, ClusterOptions, ClusteringError, FloatingCellOptions, Level,
    Synthesis,
};
use voxlod_core::glam::{DVec3, Vec3};
use voxlod_core::{Bounds, TriangleMesh};
use voxlod_testkit::shapes::unit_cube_ringwise;

fn counts(level: &Level) -> (usize, usize, usize) {
    (
        level.mesh.mesh.triangles.len(),
        level.mesh.lines.len(),
        level.mesh.points.len(),
    )
}

fn rb(mesh: &TriangleMesh, options: ClusterOptions) -> Level {
    let mut levels = rossignac_borrel(mesh, &options).unwrap();
    assert_eq!(levels.len(), 1);
    let level = levels.pop().unwrap();
    common::assert_valid(mesh, &level, "rossignac-borrel");
    level
}

fn lt(mesh: &TriangleMesh, options: FloatingCellOptions) -> Level {
    let mut levels = low_tan(mesh, &options).unwrap();
    assert_eq!(levels.len(), 1);
    let level = levels.pop().unwrap();
    common::assert_valid(mesh, &level, "low-tan");
    level
}

#[test]
fn cube_one_cell_is_one_point() {
    let cube = unit_cube_ringwise();
    for synthesis in [Synthesis::Mean, Synthesis::MaxWeight] {
        let level = rb(
            &cube,
            ClusterOptions::smoothing(1).with_synthesis(synthesis),
        );
        assert_eq!(counts(&level), (0, 0, 1));
        assert_eq!(level.mesh.points, vec![0]);
        assert_eq!(level.cluster_of, vec![0; 8]);
        let p = level.mesh.mesh.positions[0];
        match synthesis {
            // Every corner has a right angle as its largest and a face diagonal as its longest
            // edge: equal weights, so the weighted mean is the centre.
            Synthesis::Mean => assert!((p - Vec3::splat(0.5)).abs().max_element() < 1e-6, "{p}"),
            Synthesis::MaxWeight => assert!(cube.positions.contains(&p), "{p}"),
        }
    }
}

#[test]
fn cube_two_cells_is_unchanged() {
    let cube = unit_cube_ringwise();
    for synthesis in [Synthesis::Mean, Synthesis::MaxWeight] {
        let level = rb(
            &cube,
            ClusterOptions::smoothing(2).with_synthesis(synthesis),
        );
        assert_eq!(counts(&level), (12, 0, 0));
        // Clusters are numbered in vertex order, so the cube comes back as it was.
        assert_eq!(level.mesh.mesh.positions, cube.positions);
        let mut got: Vec<_> = level.mesh.mesh.triangles.clone();
        let mut want: Vec<_> = cube.triangles.clone();
        // Same triangles with the same winding, up to rotation of each triple.
        let canon = |t: [u32; 3]| {
            let r = t
                .iter()
                .position(|&v| v == *t.iter().min().unwrap())
                .unwrap();
            [t[r], t[(r + 1) % 3], t[(r + 2) % 3]]
        };
        got.iter_mut().for_each(|t| *t = canon(*t));
        want.iter_mut().for_each(|t| *t = canon(*t));
        got.sort();
        want.sort();
        assert_eq!(got, want);
        // §3.6: normals recomputed, pointing out of the corners.
        let n0 = level.mesh.mesh.normals[0];
        assert!(n0.x < 0.0 && n0.y < 0.0 && n0.z < 0.0);
    }
}

#[test]
fn cube_in_a_shared_scene_box() {
    let cube = unit_cube_ringwise();
    // A scene box of 4 units cut in 2 cells: the whole cube is in one 2-unit cell.
    let scene = Bounds::new(DVec3::ZERO, DVec3::splat(4.0));
    let level = rb(&cube, ClusterOptions::smoothing(2).with_bounds(scene));
    assert_eq!(counts(&level), (0, 0, 1));
    // Cells of 1 unit: the cube's far corners fall in the next cells.
    let level = rb(&cube, ClusterOptions::smoothing(4).with_bounds(scene));
    assert_eq!(counts(&level), (12, 0, 0));
    let level = rb(&cube, ClusterOptions::smoothing(3).with_bounds(scene));
    assert_eq!(counts(&level), (0, 0, 1));
}

#[test]
fn vertices_outside_a_given_box_go_to_its_border_cells() {
    let cube = unit_cube_ringwise();
    // A box covering only the corner at the origin, cut in 2 cells of 0.25: every vertex with a
    // coordinate 1 is clamped into the last cell along that axis, so the cube keeps its 8
    // corners apart.
    let small = Bounds::new(DVec3::ZERO, DVec3::splat(0.5));
    let level = rb(&cube, ClusterOptions::smoothing(2).with_bounds(small));
    assert_eq!(counts(&level), (12, 0, 0));
    // With one cell everything is clamped into it.
    let level = rb(&cube, ClusterOptions::smoothing(1).with_bounds(small));
    assert_eq!(counts(&level), (0, 0, 1));
}

#[test]
fn cube_with_floating_cells() {
    let cube = unit_cube_ringwise();
    // Cells of side 1 centred on a corner reach only half-way to the next corners: unchanged.
    let level = lt(&cube, FloatingCellOptions::single(1));
    assert_eq!(counts(&level), (12, 0, 0));
    let level = lt(&cube, FloatingCellOptions::single(2));
    assert_eq!(counts(&level), (12, 0, 0));
    // A cell of side 2 (a 2-unit scene box, 1 cell) centred on a corner holds the whole cube.
    let scene = Bounds::new(DVec3::ZERO, DVec3::splat(2.0));
    let level = lt(&cube, FloatingCellOptions::single(1).with_bounds(scene));
    assert_eq!(counts(&level), (0, 0, 1));
    // The representative is a corner of the cube (the heaviest; all tie, so vertex 0).
    assert_eq!(level.mesh.mesh.positions, vec![Vec3::ZERO]);
}

/// A 10 × 0.1 rectangle in two triangles.
fn thin_quad() -> TriangleMesh {
    TriangleMesh::new(
        vec![
            Vec3::ZERO,
            Vec3::new(10.0, 0.0, 0.0),
            Vec3::new(10.0, 0.1, 0.0),
            Vec3::new(0.0, 0.1, 0.0),
        ],
        vec![[0, 1, 2], [0, 2, 3]],
    )
}

#[test]
fn two_triangles_collapse_to_an_edge() {
    let quad = thin_quad();
    // 2 cells of 5 along x: {0, 3} and {1, 2}; both triangles become the edge between them.
    let level = rb(&quad, ClusterOptions::smoothing(2));
    assert_eq!(counts(&level), (0, 1, 0));
    assert_eq!(level.mesh.lines, vec![[0, 1]]);
    assert_eq!(level.cluster_of, vec![0, 1, 1, 0]);
    let p = level.mesh.mesh.positions[0];
    assert!(p.x.abs() < 1e-6 && (p.y - 0.05).abs() < 1e-3, "{p}");
    // With widths: a one-sided ribbon 0.1 wide over 10 gets 0.1/π.
    let level = rb(&quad, ClusterOptions::smoothing(2).with_thick_edges(true));
    let width = &level.mesh.line_attributes[0];
    assert_eq!(width.name, "width");
    assert!(
        (width.values[0] - 0.1 / std::f32::consts::PI).abs() < 1e-4,
        "{width:?}"
    );

    // Floating cells of side 5: vertex 0 (heaviest, ties with 2, lower index) takes 3, then 2
    // takes 1.
    let level = lt(&quad, FloatingCellOptions::single(2));
    assert_eq!(counts(&level), (0, 1, 0));
    assert_eq!(level.cluster_of, vec![0, 1, 1, 0]);
    assert_eq!(
        level.mesh.mesh.positions,
        vec![quad.positions[0], quad.positions[2]]
    );
    let names: Vec<&str> = level
        .mesh
        .line_attributes
        .iter()
        .map(|a| a.name.as_str())
        .collect();
    assert_eq!(names, ["width", "normal_x", "normal_y", "normal_z"]);
    let w = level.mesh.line_attributes[0].values[0];
    assert!((w - 0.1 / std::f32::consts::PI).abs() < 1e-4, "{w}");
    let n: Vec<f32> = level.mesh.line_attributes[1..]
        .iter()
        .map(|a| a.values[0])
        .collect();
    assert!(
        (n[2].abs() - 1.0).abs() < 1e-4,
        "the ribbon's normal is ±z: {n:?}"
    );
}

/// A big triangle (vertices 0–2) and, far from it, a small hexagonal fan (centre 3, rim 4–9).
fn triangle_and_fan() -> TriangleMesh {
    let mut positions = vec![
        Vec3::ZERO,
        Vec3::new(10.0, 0.0, 0.0),
        Vec3::new(0.0, 10.0, 0.0),
    ];
    let centre = Vec3::new(7.0, 7.0, 5.0);
    positions.push(centre);
    for i in 0..6 {
        let a = i as f32 * std::f32::consts::PI / 3.0;
        positions.push(centre + 0.1 * Vec3::new(a.cos(), a.sin(), 0.0));
    }
    let mut triangles = vec![[0, 1, 2]];
    triangles.extend((0..6u32).map(|i| [3, 4 + i, 4 + (i + 1) % 6]));
    TriangleMesh::new(positions, triangles)
}

#[test]
fn a_fan_collapses_to_a_point() {
    let mesh = triangle_and_fan();
    for synthesis in [Synthesis::Mean, Synthesis::MaxWeight] {
        // Cells of 2.5: the big triangle's corners are in three cells, the fan in one.
        let level = rb(
            &mesh,
            ClusterOptions::smoothing(4).with_synthesis(synthesis),
        );
        assert_eq!(counts(&level), (1, 0, 1));
        assert_eq!(level.mesh.mesh.triangles, vec![[0, 1, 2]]);
        assert_eq!(level.mesh.points, vec![3]);
        let p = level.mesh.mesh.positions[3];
        assert!((p - Vec3::new(7.0, 7.0, 5.0)).length() <= 0.1 + 1e-6, "{p}");
        if synthesis == Synthesis::MaxWeight {
            // Rim vertices (120° between rim edges) outweigh the flat centre.
            assert!((p - Vec3::new(7.0, 7.0, 5.0)).length() > 0.09, "{p}");
        }
    }
    let level = lt(&mesh, FloatingCellOptions::single(4));
    assert_eq!(counts(&level), (1, 0, 1));
    assert_eq!(level.mesh.mesh.triangles.len(), 1);
    // Centres in weight order: the big triangle's acute corners (1, 2), then 0, then the fan.
    assert_eq!(
        level.mesh.mesh.positions[..3],
        [mesh.positions[1], mesh.positions[2], mesh.positions[0]]
    );
    assert_eq!(level.mesh.points, vec![3]);
}

/// A = 0 (0, 0, 0), B = 1 (10, 0, 0), C = 2 (0, 10, 0), with D = 3 and E = 4 next to A.
fn near_a() -> Vec<Vec3> {
    vec![
        Vec3::ZERO,
        Vec3::new(10.0, 0.0, 0.0),
        Vec3::new(0.0, 10.0, 0.0),
        Vec3::new(0.1, 0.1, 0.0),
        Vec3::new(0.2, 0.05, 0.0),
    ]
}

#[test]
fn elimination_rules() {
    // (triangles, expected counts) with cells of 2.5 (A, D, E together) for both methods.
    type Case<'a> = (&'a [[u32; 3]], (usize, usize, usize));
    let cases: [Case; 5] = [
        // A–D–B collapses onto edge A–B, which triangle A–B–C still bounds: the edge goes.
        (&[[0, 1, 2], [0, 3, 1]], (1, 0, 0)),
        // Without the big triangle the edge dangles.
        (&[[0, 3, 1]], (0, 1, 0)),
        // A–D–E collapses to point A, which bounds the dangling edge A–B: the point goes.
        (&[[0, 3, 1], [0, 3, 4]], (0, 1, 0)),
        // ... and on its own it is an isolated point.
        (&[[0, 3, 4]], (0, 0, 1)),
        // Duplicates, whatever their winding, count once.
        (
            &[[0, 1, 2], [2, 1, 3], [4, 2, 1], [0, 3, 4], [3, 4, 0]],
            (1, 0, 0),
        ),
    ];
    for (triangles, expected) in cases {
        let mesh = TriangleMesh::new(near_a(), triangles.to_vec());
        let what = format!("{triangles:?}");
        // Box of the used vertices: from A to (10, 10) in all cases but the lone small triangle.
        let scene = Bounds::new(DVec3::ZERO, DVec3::new(10.0, 10.0, 0.0));
        let level = rb(&mesh, ClusterOptions::smoothing(4).with_bounds(scene));
        assert_eq!(counts(&level), expected, "rossignac-borrel {what}");
        assert_eq!(
            as_sets(&level.mesh),
            common::naive_elimination(&mesh.triangles, &level.cluster_of)
        );
        let level = lt(&mesh, FloatingCellOptions::single(4).with_bounds(scene));
        assert_eq!(counts(&level), expected, "low-tan {what}");
    }
}

#[test]
fn unused_vertices_are_ignored() {
    let mut cube = unit_cube_ringwise();
    cube.positions.push(Vec3::splat(100.0));
    let level = rb(&cube, ClusterOptions::smoothing(2));
    assert_eq!(counts(&level), (12, 0, 0));
    assert_eq!(level.cluster_of[8], u32::MAX);
    let level = lt(&cube, FloatingCellOptions::single(2));
    assert_eq!(counts(&level), (12, 0, 0));
}

#[test]
fn bad_input_is_refused_with_a_clear_message() {
    let cube = unit_cube_ringwise();
    let message = |r: Result<Vec<Level>, ClusteringError>| r.unwrap_err().to_string();

    let m = message(rossignac_borrel(&cube, &ClusterOptions::smoothing(0)));
    assert_eq!(m, "the number of cells per axis must be at least 1 (got 0)");
    let m = message(low_tan(&cube, &FloatingCellOptions::single(0)));
    assert_eq!(m, "the number of cells per axis must be at least 1 (got 0)");

    let empty = TriangleMesh::new(cube.positions.clone(), vec![]);
    assert_eq!(
        message(rossignac_borrel(&empty, &ClusterOptions::default())),
        "the mesh has no triangles"
    );
    assert_eq!(
        message(low_tan(&empty, &FloatingCellOptions::default())),
        "the mesh has no triangles"
    );
    assert_eq!(
        message(rossignac_borrel(
            &TriangleMesh::default(),
            &ClusterOptions::default()
        )),
        "the mesh has no triangles"
    );

    let mut nan = cube.clone();
    nan.positions[5].z = f32::NAN;
    let m = message(rossignac_borrel(&nan, &ClusterOptions::default()));
    assert_eq!(m, "vertex 5 has a non-finite coordinate (1, 0, NaN)");
    let mut inf = cube.clone();
    inf.positions[2].x = f32::INFINITY;
    let m = message(low_tan(&inf, &FloatingCellOptions::default()));
    assert_eq!(m, "vertex 2 has a non-finite coordinate (inf, 1, 0)");

    let mut bad = cube.clone();
    bad.triangles[7][2] = 8;
    let m = message(rossignac_borrel(&bad, &ClusterOptions::default()));
    assert_eq!(
        m,
        "triangle 7 refers to vertex 8 but there are only 8 vertices"
    );

    let m = message(rossignac_borrel(&cube, &ClusterOptions::series(64, 0)));
    assert_eq!(m, "the number of levels must be at least 1 (got 0)");
    let m = message(low_tan(&cube, &FloatingCellOptions::series(64, 8)));
    assert!(
        m.starts_with("8 levels starting from 64 cells per axis: at most 7"),
        "{m}"
    );

    let m = message(rossignac_borrel(&cube, &ClusterOptions::smoothing(1 << 21)));
    assert!(m.contains("too many"), "{m}");

    let nan_box = Bounds::new(DVec3::ZERO, DVec3::new(1.0, f64::NAN, 1.0));
    let m = message(rossignac_borrel(
        &cube,
        &ClusterOptions::default().with_bounds(nan_box),
    ));
    assert!(
        m.starts_with("the clustering box must be finite and not empty"),
        "{m}"
    );
    let m = message(low_tan(
        &cube,
        &FloatingCellOptions::default().with_bounds(Bounds::EMPTY),
    ));
    assert!(
        m.starts_with("the clustering box must be finite and not empty"),
        "{m}"
    );
    // One line each.
    assert!(!m.contains('\n'));
}

#[test]
fn degenerate_input_triangles_are_handled() {
    // Triangles with a repeated index or zero area, as the bad shared meshes have.
    let mesh = TriangleMesh::new(
        vec![
            Vec3::ZERO,
            Vec3::X,
            Vec3::Y,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::splat(3.0),
        ],
        vec![[0, 1, 2], [0, 0, 1], [0, 1, 3], [4, 4, 4]],
    );
    for cells in [1, 2, 3, 8, 64] {
        let level = rb(&mesh, ClusterOptions::smoothing(cells));
        assert_eq!(
            as_sets(&level.mesh),
            common::naive_elimination(&mesh.triangles, &level.cluster_of)
        );
        lt(&mesh, FloatingCellOptions::single(cells));
    }
    // At fine cells: the triangle, the zero-area one (three distinct vertices: kept, §3.5 only
    // looks at clusters), and the lone point 4.
    let level = rb(&mesh, ClusterOptions::smoothing(64));
    assert_eq!(counts(&level), (2, 0, 1));
}
