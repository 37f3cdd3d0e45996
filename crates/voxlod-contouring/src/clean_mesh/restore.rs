//! The end of [`super::clean_mesh`]: components that cleaning flattened get their raw triangles
//! back, and the live triangles are gathered into the output mesh.

use glam::DVec3;
use voxlod_core::TriangleMesh;

use super::work::Surface;

/// A component whose enclosed volume cleaning shrank below this fraction of the raw one (or
/// turned over) is given back its raw triangles (see `restore_flattened`).
const MIN_VOLUME_KEPT: f64 = 0.25;

/// The component of every vertex of `mesh` (through shared triangles), named by its smallest
/// vertex; unused vertices get their own. A union-find with the smaller root kept.
fn vertex_components(mesh: &TriangleMesh) -> Vec<u32> {
    let mut root: Vec<u32> = (0..mesh.positions.len() as u32).collect();
    fn find(root: &mut [u32], mut v: u32) -> u32 {
        while root[v as usize] != v {
            let up = root[root[v as usize] as usize];
            root[v as usize] = up;
            v = up;
        }
        v
    }
    for tri in &mesh.triangles {
        for &w in &tri[1..] {
            let (x, y) = (find(&mut root, tri[0]), find(&mut root, w));
            root[x.max(y) as usize] = x.min(y);
        }
    }
    for v in 0..root.len() as u32 {
        root[v as usize] = find(&mut root, v);
    }
    root
}

/// Six times the signed volume enclosed by triangle `p` with the point `origin`.
fn signed_volume6(p: [DVec3; 3], origin: DVec3) -> f64 {
    (p[0] - origin).dot((p[1] - origin).cross(p[2] - origin))
}

/// Gives every component that cleaning flattened or turned over its raw triangles back (see
/// the module documentation of `clean_mesh`); returns how many. Collapses only merge
/// neighbours and flips keep a triangle's slot, so every vertex and triangle slot stays in its
/// raw component.
pub(super) fn restore_flattened(surface: &mut Surface, raw: &TriangleMesh) -> usize {
    let label = vertex_components(raw);
    let origin = |l: u32| raw.positions[l as usize].as_dvec3();
    // (raw, cleaned) volumes, by the component's smallest vertex.
    let mut volumes = vec![(0.0f64, 0.0f64); raw.positions.len()];
    for (t, tri) in raw.triangles.iter().enumerate() {
        let l = label[tri[0] as usize];
        let sums = &mut volumes[l as usize];
        sums.0 += signed_volume6(raw.corners(t), origin(l));
        if surface.alive[t] {
            let p = surface.triangles[t].map(|v| surface.positions[v as usize]);
            sums.1 += signed_volume6(p, origin(l));
        }
    }
    let flattened: Vec<bool> = (volumes.iter())
        .map(|&(before, after)| after * before.signum() < MIN_VOLUME_KEPT * before.abs())
        .collect();
    drop(volumes);
    for (t, tri) in raw.triangles.iter().enumerate() {
        if !flattened[label[tri[0] as usize] as usize] {
            continue;
        }
        surface.triangles[t] = *tri;
        surface.alive[t] = true;
        for &v in tri {
            surface.positions[v as usize] = raw.positions[v as usize].as_dvec3();
            if !surface.normals.is_empty() {
                surface.normals[v as usize] = raw.normals[v as usize];
            }
        }
    }
    flattened.iter().filter(|&&f| f).count()
}

/// The live triangles and the vertices they use, numbered in order of first use.
pub(super) fn compact(surface: &Surface) -> TriangleMesh {
    let mut index = vec![u32::MAX; surface.positions.len()];
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    let live = surface.alive.iter().filter(|&&a| a).count();
    let mut triangles = Vec::with_capacity(live);
    for (t, tri) in surface.triangles.iter().enumerate() {
        if !surface.alive[t] {
            continue;
        }
        triangles.push(tri.map(|v| {
            if index[v as usize] == u32::MAX {
                index[v as usize] = positions.len() as u32;
                positions.push(surface.positions[v as usize].as_vec3());
                if !surface.normals.is_empty() {
                    normals.push(surface.normals[v as usize]);
                }
            }
            index[v as usize]
        }));
    }
    TriangleMesh {
        positions,
        normals,
        triangles,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn components_are_named_by_their_smallest_vertex() {
        // Two triangles sharing nothing, listed so that the larger indices come first, and an
        // unused vertex 6.
        let mesh = TriangleMesh::new(vec![Vec3::ZERO; 7], vec![[5, 3, 1], [4, 2, 0], [1, 5, 3]]);
        assert_eq!(vertex_components(&mesh), vec![0, 1, 0, 1, 0, 1, 6]);
    }
}
