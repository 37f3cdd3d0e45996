//! One face with 200,000 corners, non-convex, in an OBJ file: it must load (the textbook ear
//! clipping is quadratic and took minutes) and be split into n - 2 triangles that all keep
//! the face's winding and add up to its area, which for triangles of one simple polygon means
//! they tile it. Not a timing: the test simply has to finish.

use voxlod_io::read_mesh;

/// Twice the signed area of a closed polygon (shoelace).
fn double_area(points: &[[f64; 2]]) -> f64 {
    (0..points.len())
        .map(|i| {
            let (a, b) = (points[i], points[(i + 1) % points.len()]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum()
}

/// Writes the polygon as an OBJ face, reads it, and checks the triangulation.
fn check_face(points: &[[f64; 2]]) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("face.obj");
    let mut text = String::with_capacity(points.len() * 24);
    for p in points {
        text.push_str(&format!("v {} {} 0\n", p[0], p[1]));
    }
    text.push('f');
    for i in 1..=points.len() {
        text.push_str(&format!(" {i}"));
    }
    text.push('\n');
    std::fs::write(&path, text).unwrap();

    let loaded = read_mesh(&path).unwrap_or_else(|e| panic!("{e}"));
    let mesh = &loaded.mesh;
    assert_eq!(loaded.polygons_triangulated, 1);
    assert_eq!(mesh.triangles.len(), points.len() - 2);
    let mut total = 0.0;
    for (t, tri) in mesh.triangles.iter().enumerate() {
        let [a, b, c] = tri.map(|v| points[v as usize]);
        let twice = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        assert!(twice > 0.0, "triangle {t} {tri:?} is inverted or flat");
        total += twice;
    }
    let expected = double_area(points);
    assert!(
        (total - expected).abs() <= 1e-9 * expected,
        "triangles cover {total}, the face {expected}"
    );
}

#[test]
fn star_of_200000_corners() {
    let n = 200_000;
    let points: Vec<[f64; 2]> = (0..n)
        .map(|i| {
            let angle = std::f64::consts::TAU * i as f64 / n as f64;
            let r = if i % 2 == 0 { 2.0 } else { 1.0 };
            [r * angle.cos(), r * angle.sin()]
        })
        .collect();
    check_face(&points);
}

#[test]
fn comb_of_200000_corners() {
    // A base [0, 2T] x [0, 1] with T teeth [2t + 0.5, 2t + 1.5] x [1, 3], counter-clockwise:
    // 4T + 4 corners, half of them reflex.
    let teeth = 49_999;
    let mut points = vec![
        [0.0, 0.0],
        [2.0 * teeth as f64, 0.0],
        [2.0 * teeth as f64, 1.0],
    ];
    for t in (0..teeth).rev() {
        let x = 2.0 * t as f64;
        points.extend([
            [x + 1.5, 1.0],
            [x + 1.5, 3.0],
            [x + 0.5, 3.0],
            [x + 0.5, 1.0],
        ]);
    }
    points.push([0.0, 1.0]);
    assert_eq!(points.len(), 200_000);
    assert_eq!(double_area(&points), 2.0 * 4.0 * teeth as f64);
    check_face(&points);
}
