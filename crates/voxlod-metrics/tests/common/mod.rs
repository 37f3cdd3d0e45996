//! Meshes for the tests and the benchmark: generated shapes and a minimal reader for the
//! shared data's OBJ and ASCII STL files (the io crate is not a dependency of this one).

#![allow(dead_code)]

use std::collections::HashMap;
use std::path::Path;

use glam::{DVec3, Vec3};
use voxlod_core::TriangleMesh;

/// Icosahedron subdivided `level` times, vertices pushed onto the unit sphere (in `f64`, then
/// stored as `f32`): 20·4^level triangles, counter-clockwise seen from outside.
pub fn icosphere(level: u32) -> TriangleMesh {
    let phi = (1.0 + 5f64.sqrt()) / 2.0;
    let mut points: Vec<DVec3> = [
        (-1.0, phi, 0.0),
        (1.0, phi, 0.0),
        (-1.0, -phi, 0.0),
        (1.0, -phi, 0.0),
        (0.0, -1.0, phi),
        (0.0, 1.0, phi),
        (0.0, -1.0, -phi),
        (0.0, 1.0, -phi),
        (phi, 0.0, -1.0),
        (phi, 0.0, 1.0),
        (-phi, 0.0, -1.0),
        (-phi, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| DVec3::new(x, y, z).normalize())
    .collect();
    let mut triangles: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..level {
        let mut midpoints: HashMap<(u32, u32), u32> = HashMap::new();
        let mut midpoint = |a: u32, b: u32, points: &mut Vec<DVec3>| -> u32 {
            *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
                points.push(((points[a as usize] + points[b as usize]) * 0.5).normalize());
                points.len() as u32 - 1
            })
        };
        let mut finer = Vec::with_capacity(triangles.len() * 4);
        for &[a, b, c] in &triangles {
            let ab = midpoint(a, b, &mut points);
            let bc = midpoint(b, c, &mut points);
            let ca = midpoint(c, a, &mut points);
            finer.extend_from_slice(&[[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        triangles = finer;
    }
    TriangleMesh::new(points.iter().map(|p| p.as_vec3()).collect(), triangles)
}

/// A torus around the z axis, major radius `major`, tube radius given per point by `tube`
/// (of the angles around the axis and around the tube), as an `n × m` grid of quads split
/// into 2nm triangles, counter-clockwise seen from outside.
pub fn torus_with(n: u32, m: u32, major: f64, tube: impl Fn(f64, f64) -> f64) -> TriangleMesh {
    let tau = std::f64::consts::TAU;
    let mut positions = Vec::with_capacity((n * m) as usize);
    for i in 0..n {
        let a = i as f64 / n as f64 * tau;
        for j in 0..m {
            let b = j as f64 / m as f64 * tau;
            let r = tube(a, b);
            positions.push(Vec3::new(
                ((major + r * b.cos()) * a.cos()) as f32,
                ((major + r * b.cos()) * a.sin()) as f32,
                (r * b.sin()) as f32,
            ));
        }
    }
    let id = |i: u32, j: u32| (i % n) * m + (j % m);
    let mut triangles = Vec::with_capacity((2 * n * m) as usize);
    for i in 0..n {
        for j in 0..m {
            triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    TriangleMesh::new(positions, triangles)
}

/// A round torus, major radius 2 and tube radius 1.
pub fn torus(n: u32, m: u32) -> TriangleMesh {
    torus_with(n, m, 2.0, |_, _| 1.0)
}

/// The unit cube [0,1]³: 8 vertices, 12 triangles facing outwards.
pub fn unit_cube() -> TriangleMesh {
    let positions = [
        (0., 0., 0.),
        (1., 0., 0.),
        (1., 1., 0.),
        (0., 1., 0.),
        (0., 0., 1.),
        (1., 0., 1.),
        (1., 1., 1.),
        (0., 1., 1.),
    ]
    .iter()
    .map(|&(x, y, z)| Vec3::new(x, y, z))
    .collect();
    let triangles = vec![
        [0, 2, 1],
        [0, 3, 2],
        [4, 5, 6],
        [4, 6, 7],
        [0, 1, 5],
        [0, 5, 4],
        [1, 2, 6],
        [1, 6, 5],
        [2, 3, 7],
        [2, 7, 6],
        [3, 0, 4],
        [3, 4, 7],
    ];
    TriangleMesh::new(positions, triangles)
}

/// Reads the `v` and `f` lines of an OBJ file (faces fan-triangulated, `v/vt/vn` forms and
/// negative indices accepted).
pub fn read_obj(path: &Path) -> TriangleMesh {
    let text = std::fs::read_to_string(path).expect("readable OBJ");
    let mut mesh = TriangleMesh::default();
    for line in text.lines() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let c: Vec<f32> = words.take(3).map(|w| w.parse().unwrap()).collect();
                mesh.positions.push(Vec3::new(c[0], c[1], c[2]));
            }
            Some("f") => {
                let n = mesh.positions.len() as i64;
                let ids: Vec<u32> = words
                    .map(|w| {
                        let i: i64 = w.split('/').next().unwrap().parse().unwrap();
                        (if i < 0 { n + i } else { i - 1 }) as u32
                    })
                    .collect();
                for k in 1..ids.len() - 1 {
                    mesh.triangles.push([ids[0], ids[k], ids[k + 1]]);
                }
            }
            _ => {}
        }
    }
    mesh
}

/// Reads an ASCII STL file as a triangle soup (three new vertices per facet).
pub fn read_ascii_stl(path: &Path) -> TriangleMesh {
    let text = std::fs::read_to_string(path).expect("readable STL");
    let mut mesh = TriangleMesh::default();
    for line in text.lines() {
        let mut words = line.split_whitespace();
        if words.next() == Some("vertex") {
            let c: Vec<f32> = words.take(3).map(|w| w.parse().unwrap()).collect();
            mesh.positions.push(Vec3::new(c[0], c[1], c[2]));
            if mesh.positions.len() % 3 == 0 {
                let base = mesh.positions.len() as u32 - 3;
                mesh.triangles.push([base, base + 1, base + 2]);
            }
        }
    }
    mesh
}
