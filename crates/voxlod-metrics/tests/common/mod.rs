//! Meshes for the tests and the benchmark: generated shapes and a minimal reader for the
//! shared data's OBJ and ASCII STL files (the io crate is not a dependency of this one).

#![allow(dead_code)]

use std::path::Path;

use glam::Vec3;
use voxlod_core::TriangleMesh;

#[allow(unused_imports)]
pub use voxlod_core::shapes::{icosphere, torus_with, unit_cube};

/// A round torus, major radius 2 and tube radius 1.
pub fn torus(n: u32, m: u32) -> TriangleMesh {
    voxlod_core::shapes::torus(n, m, 2.0, 1.0)
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
