//! Minimal readers of the shared data's OBJ and ASCII STL files, independent of `voxlod-io`: for
//! the crates below it (metrics) and for checking voxlod-io against something else.

use std::path::Path;

use glam::Vec3;
use voxlod_core::TriangleMesh;

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
