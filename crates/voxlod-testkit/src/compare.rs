//! Comparing meshes bit for bit: what tests of two routes that must agree exactly (dense and
//! bricked samples, a scan read whole and read blockwise) assert.

use voxlod_core::glam::Vec3;
use voxlod_core::TriangleMesh;

/// The mesh's vertex positions as the bits of their coordinates, sorted: equal for two meshes
/// exactly when they hold the same vertices, in whatever order.
pub fn sorted_vertex_bits(mesh: &TriangleMesh) -> Vec<[u32; 3]> {
    let mut bits: Vec<[u32; 3]> = mesh
        .positions
        .iter()
        .map(|p| p.to_array().map(f32::to_bits))
        .collect();
    bits.sort_unstable();
    bits
}

/// A triangle by its corners' positions (the bits of their coordinates), rotated to start at
/// the smallest: the same key for the same triangle in any mesh, whatever its vertex indices and
/// first corner; the reversed triangle has another key ([`reversed_key`]).
pub type TriangleKey = [[u32; 3]; 3];

/// The key of the triangle of `corners`, in their winding.
pub fn triangle_key(corners: [Vec3; 3]) -> TriangleKey {
    rotated(corners.map(|p| p.to_array().map(f32::to_bits)))
}

/// The key of the same triangle wound the other way.
pub fn reversed_key(key: &TriangleKey) -> TriangleKey {
    rotated([key[0], key[2], key[1]])
}

/// Every triangle of `mesh` by its key, in the mesh's order.
pub fn triangle_keys(mesh: &TriangleMesh) -> Vec<TriangleKey> {
    mesh.triangles
        .iter()
        .map(|t| triangle_key(t.map(|v| mesh.positions[v as usize])))
        .collect()
}

/// Corners rotated to start at the smallest.
fn rotated(corners: TriangleKey) -> TriangleKey {
    let first = (0..3).min_by_key(|&n| corners[n]).expect("three corners");
    std::array::from_fn(|n| corners[(first + n) % 3])
}
