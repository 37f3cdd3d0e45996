//! A mesh's connected components: triangles that share a vertex index belong together (weld a
//! triangle soup first, see [`crate::weld`]). Cost: a union-find pass over the triangles and a
//! hash of the roots, O(F α(V)).

use std::collections::HashMap;

use crate::topology::UnionFind;
use crate::TriangleMesh;

/// The triangles of each connected component, components in the order of their first
/// triangle, triangles in the mesh's order.
///
/// ```
/// use voxlod_core::components::{submesh, triangle_components};
/// use voxlod_core::{glam::Vec3, TriangleMesh};
///
/// let pair = TriangleMesh::new(
///     vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z, Vec3::ONE],
///     vec![[0, 1, 2], [3, 4, 4], [0, 2, 1]],
/// );
/// let parts = triangle_components(&pair);
/// assert_eq!(parts, vec![vec![0, 2], vec![1]]);
/// assert_eq!(submesh(&pair, &parts[1]).positions, vec![Vec3::Z, Vec3::ONE]);
/// ```
pub fn triangle_components(mesh: &TriangleMesh) -> Vec<Vec<u32>> {
    let mut links = UnionFind::new(mesh.positions.len());
    for &[a, b, c] in &mesh.triangles {
        links.union(a, b);
        links.union(b, c);
    }
    let mut index_of = HashMap::new();
    let mut out: Vec<Vec<u32>> = Vec::new();
    for (t, tri) in mesh.triangles.iter().enumerate() {
        let i = *index_of.entry(links.find(tri[0])).or_insert_with(|| {
            out.push(Vec::new());
            out.len() - 1
        });
        out[i].push(t as u32);
    }
    out
}

/// The mesh of `triangles` of `mesh` alone, with only the vertices they use (in the order of
/// first use).
pub fn submesh(mesh: &TriangleMesh, triangles: &[u32]) -> TriangleMesh {
    let mut index = HashMap::new();
    let mut positions = Vec::new();
    let tris = triangles
        .iter()
        .map(|&t| {
            mesh.triangles[t as usize].map(|v| {
                *index.entry(v).or_insert_with(|| {
                    positions.push(mesh.positions[v as usize]);
                    positions.len() as u32 - 1
                })
            })
        })
        .collect();
    TriangleMesh::new(positions, tris)
}
