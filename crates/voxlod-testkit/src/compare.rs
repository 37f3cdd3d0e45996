//! Comparing meshes bit for bit: what tests of two routes that must agree exactly (dense and
//! bricked samples, a scan read whole and read blockwise) assert.

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
