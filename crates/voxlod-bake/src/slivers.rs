//! A level's near-coincident vertices snapped together for its charts.
//!
//! Marching cubes puts a vertex on every crossed cell edge; where the surface passes close to
//! a sample, the vertices on that sample's edges lie a small fraction of a voxel apart and
//! their triangles are slivers. xatlas drops triangles of no area from its charts but
//! parameterizes a sliver of a little area like any other, and its parametric area can then
//! dwarf its surface area: the chart is scaled down until its other triangles share a few
//! texels, or it never fits the texture. Measured on the three hyper-cone layers (ε = 0.05) of
//! a unit sphere at 20 and 64 samples and of the three-sphere test scene at 128, on 512²
//! textures: 3 of the 9 atlases failed, and 3 of the other 6 had charts shrunk below a
//! twentieth of the median texel density (94, 256 and 500 triangles of normal size in them);
//! with the ends of every edge shorter than 0.03 voxel snapped together (up to 4.5 % of a
//! layer's triangles losing their area), none failed and at most 26 triangles of a
//! layer were in such charts (0.01 voxel: 277; 0.02: 635, both in one layer).
//!
//! Snapping keeps the vertex indices and the triangles (a sliver becomes a triangle of no
//! area, which xatlas leaves out of every chart); the atlas takes back the level's own
//! positions afterwards, so nothing of the geometry changes, and gives the slivers' corners
//! texture coordinates of the charts around them ([`crate::atlas`]). Cost: O(T α(V)) for T
//! triangles (union-find over the short edges), then O(V).

use voxlod_core::TriangleMesh;

/// Edges shorter than this many voxels have their ends snapped together (where a level's
/// voxel is not known, its median edge length stands for it: a marching-cubes level's edges
/// are about a voxel long).
pub const SNAP_VOXELS: f32 = 0.03;

/// `mesh` with the ends of every edge shorter than `distance` snapped together: each vertex
/// moved to the position of the lowest-numbered vertex it is joined to by such edges (through
/// any chain of them). Indices, triangles and normals are unchanged; a triangle with two
/// corners joined so has no area.
pub fn snapped(mesh: &TriangleMesh, distance: f32) -> TriangleMesh {
    let n = mesh.positions.len();
    let mut root: Vec<u32> = (0..n as u32).collect();
    let limit = distance * distance;
    for t in &mesh.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let (pa, pb) = (mesh.positions[a as usize], mesh.positions[b as usize]);
            if pa.distance_squared(pb) < limit {
                let (ra, rb) = (find(&mut root, a), find(&mut root, b));
                // The lower index is the root, so each class's root is its lowest vertex.
                root[ra.max(rb) as usize] = ra.min(rb);
            }
        }
    }
    let mut out = mesh.clone();
    for v in 0..n as u32 {
        let r = find(&mut root, v);
        out.positions[v as usize] = mesh.positions[r as usize];
    }
    out
}

/// The root of `v`'s class, halving the path on the way.
fn find(root: &mut [u32], mut v: u32) -> u32 {
    while root[v as usize] != v {
        let up = root[root[v as usize] as usize];
        root[v as usize] = up;
        v = up;
    }
    v
}

/// The median edge length of the level's triangles (0 without triangles).
pub fn median_edge(level: &TriangleMesh) -> f32 {
    let mut lengths: Vec<f32> = level
        .triangles
        .iter()
        .flat_map(|t| {
            let p = t.map(|v| level.positions[v as usize]);
            [(p[0], p[1]), (p[1], p[2]), (p[2], p[0])].map(|(a, b)| a.distance(b))
        })
        .collect();
    let mid = lengths.len() / 2;
    if lengths.is_empty() {
        return 0.0;
    }
    *lengths.select_nth_unstable_by(mid, f32::total_cmp).1
}

#[cfg(test)]
mod tests {
    use voxlod_core::glam::Vec3;

    use super::*;

    /// Two triangles sharing an edge, and a sliver whose corners 1 and 4 are 0.001 apart:
    /// only that edge is snapped, to the lower vertex, and the sliver has no area.
    #[test]
    fn short_edges_are_snapped_to_their_lowest_vertex() {
        let positions = vec![
            Vec3::ZERO,
            Vec3::X,
            Vec3::Y,
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(1.001, 0.0, 0.0),
        ];
        let triangles = vec![[0, 1, 2], [1, 3, 2], [1, 4, 3]];
        let mesh = TriangleMesh::new(positions.clone(), triangles.clone());
        let s = snapped(&mesh, 0.01);
        assert_eq!(s.triangles, triangles);
        let mut expect = positions;
        expect[4] = Vec3::X;
        assert_eq!(s.positions, expect);
        let [a, b, c] = s.triangles[2].map(|v| s.positions[v as usize]);
        assert_eq!((b - a).cross(c - a).length(), 0.0);
        // Below every edge: nothing moves.
        assert_eq!(snapped(&mesh, 0.0005).positions, mesh.positions);
    }

    /// A chain of short edges joins its ends even when they are farther apart than the limit.
    #[test]
    fn chains_of_short_edges_join() {
        let positions = vec![
            Vec3::ZERO,
            Vec3::new(0.008, 0.0, 0.0),
            Vec3::new(0.016, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        let mesh = TriangleMesh::new(positions, vec![[0, 1, 3], [1, 2, 3]]);
        let s = snapped(&mesh, 0.01);
        assert_eq!(s.positions[1], Vec3::ZERO);
        assert_eq!(s.positions[2], Vec3::ZERO);
        assert_eq!(s.positions[3], Vec3::Y);
    }
}
