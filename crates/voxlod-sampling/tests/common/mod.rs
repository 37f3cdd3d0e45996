//! Meshes built in code for the tests.

use glam::Vec3;
use voxlod_core::{shapes, TriangleMesh};

/// An icosphere of radius `r` centred at `c`.
pub fn icosphere(levels: u32, r: f32, c: Vec3) -> TriangleMesh {
    let mut mesh = shapes::icosphere(levels);
    mesh.positions.iter_mut().for_each(|p| *p = *p * r + c);
    mesh
}

/// Appends `other` to `mesh`.
pub fn append(mesh: &mut TriangleMesh, other: &TriangleMesh) {
    let base = mesh.positions.len() as u32;
    mesh.positions.extend_from_slice(&other.positions);
    mesh.triangles
        .extend(other.triangles.iter().map(|t| t.map(|v| v + base)));
}
