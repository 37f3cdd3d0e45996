//! The end of [`super::clean_mesh`]: components that cleaning flattened get their raw triangles
//! back, and the live triangles are gathered into the output mesh.

use glam::{DVec3, Vec3};
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

/// The live triangles of `surface` and the vertices they use, renumbered in the order the
/// triangles first use them.
pub(super) fn compact(surface: &Surface) -> TriangleMesh {
    gather(
        &surface.triangles,
        surface.positions.len(),
        |t| surface.alive[t],
        |v| surface.positions[v].as_vec3(),
        &surface.normals,
    )
}

/// What [`compact`] gives for `mesh` untouched (every triangle live, positions as they are):
/// the output of a cleaning that found nothing to do.
pub(super) fn compact_mesh(mesh: &TriangleMesh) -> TriangleMesh {
    gather(
        &mesh.triangles,
        mesh.positions.len(),
        |_| true,
        |v| mesh.positions[v],
        &mesh.normals,
    )
}

/// The triangles for which `alive` holds, their vertices renumbered in order of first use,
/// with their `position` and (when there are normals) their normal.
fn gather(
    all: &[[u32; 3]],
    vertices: usize,
    alive: impl Fn(usize) -> bool,
    position: impl Fn(usize) -> Vec3,
    all_normals: &[Vec3],
) -> TriangleMesh {
    let mut index = vec![u32::MAX; vertices];
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    let live = (0..all.len()).filter(|&t| alive(t)).count();
    let mut triangles = Vec::with_capacity(live);
    for (t, tri) in all.iter().enumerate() {
        if !alive(t) {
            continue;
        }
        triangles.push(tri.map(|v| {
            if index[v as usize] == u32::MAX {
                index[v as usize] = positions.len() as u32;
                positions.push(position(v as usize));
                if !all_normals.is_empty() {
                    normals.push(all_normals[v as usize]);
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

    #[test]
    fn components_are_named_by_their_smallest_vertex() {
        // Two triangles sharing nothing, listed so that the larger indices come first, and an
        // unused vertex 6.
        let mesh = TriangleMesh::new(vec![Vec3::ZERO; 7], vec![[5, 3, 1], [4, 2, 0], [1, 5, 3]]);
        assert_eq!(vertex_components(&mesh), vec![0, 1, 0, 1, 0, 1, 6]);
    }
}
