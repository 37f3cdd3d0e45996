//! Shared helpers of the integration tests: reading the shared data through voxlod-io, a naive
//! reference of the §3.5 elimination rules, and a checker of valid output (meshes made in code
//! and the shared data lookup come from voxlod-testkit).
#![allow(dead_code, unused_imports)]

use std::collections::{BTreeSet, HashSet};
use std::path::Path;

use voxlod_clustering::Level;
use voxlod_core::{PolyMesh, TriangleMesh};

pub use voxlod_testkit::data::shared_meshes;
pub use voxlod_testkit::shapes::{prism, round_section, torus};

/// Reads a mesh with voxlod-io (STL soups are welded there).
pub fn read_mesh(path: &Path) -> TriangleMesh {
    voxlod_io::read_mesh(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .mesh
}

/// Sorted vertex triple.
pub fn sorted3(t: [u32; 3]) -> [u32; 3] {
    let mut k = t;
    k.sort_unstable();
    k
}

/// The §3.5 rules, written out naively with sets: (triangles, edges, points) as sorted tuples.
pub fn naive_elimination(
    triangles: &[[u32; 3]],
    cluster_of: &[u32],
) -> (BTreeSet<[u32; 3]>, BTreeSet<[u32; 2]>, BTreeSet<u32>) {
    let mut tris = BTreeSet::new();
    let mut edges = BTreeSet::new();
    let mut points = BTreeSet::new();
    for t in triangles {
        let m = t.map(|v| cluster_of[v as usize]);
        let distinct: BTreeSet<u32> = m.iter().copied().collect();
        match distinct.len() {
            3 => {
                tris.insert(sorted3(m));
            }
            2 => {
                let v: Vec<u32> = distinct.into_iter().collect();
                edges.insert([v[0], v[1]]);
            }
            _ => {
                points.insert(m[0]);
            }
        }
    }
    let mut tri_edges = HashSet::new();
    let mut on_something = HashSet::new();
    for t in &tris {
        tri_edges.insert([t[0], t[1]]);
        tri_edges.insert([t[0], t[2]]);
        tri_edges.insert([t[1], t[2]]);
        on_something.extend(t.iter().copied());
    }
    for e in &edges {
        on_something.extend(e.iter().copied());
    }
    edges.retain(|e| !tri_edges.contains(e));
    points.retain(|p| !on_something.contains(p));
    (tris, edges, points)
}

/// The output as sets, for comparison with [`naive_elimination`].
pub fn as_sets(poly: &PolyMesh) -> (BTreeSet<[u32; 3]>, BTreeSet<[u32; 2]>, BTreeSet<u32>) {
    (
        poly.mesh.triangles.iter().map(|&t| sorted3(t)).collect(),
        poly.lines
            .iter()
            .map(|&[a, b]| [a.min(b), a.max(b)])
            .collect(),
        poly.points.iter().copied().collect(),
    )
}

/// Everything a level must satisfy, whatever the input: indices in range, no degenerate or
/// duplicate triangle, edge or point, no edge bounding a triangle, no point on an edge or a
/// triangle, every vertex used, finite positions and normals, attributes sized, the cluster map
/// consistent with the input's used vertices and the report consistent with the mesh.
pub fn assert_valid(input: &TriangleMesh, level: &Level, what: &str) {
    let poly = &level.mesh;
    poly.validate().unwrap_or_else(|e| panic!("{what}: {e}"));
    let n = poly.mesh.positions.len();
    assert!(
        poly.mesh.positions.iter().all(|p| p.is_finite()),
        "{what}: non-finite position"
    );
    assert_eq!(poly.mesh.normals.len(), n, "{what}: normals");
    assert!(
        poly.mesh.normals.iter().all(|p| p.is_finite()),
        "{what}: non-finite normal"
    );
    let mut tris = HashSet::new();
    let mut tri_edges = HashSet::new();
    let mut used = vec![false; n];
    for &t in &poly.mesh.triangles {
        assert!(
            t[0] != t[1] && t[1] != t[2] && t[0] != t[2],
            "{what}: degenerate {t:?}"
        );
        let k = sorted3(t);
        assert!(tris.insert(k), "{what}: duplicate triangle {t:?}");
        tri_edges.extend([[k[0], k[1]], [k[0], k[2]], [k[1], k[2]]]);
        for v in t {
            used[v as usize] = true;
        }
    }
    let mut edges = HashSet::new();
    for &[a, b] in &poly.lines {
        assert_ne!(a, b, "{what}: degenerate edge");
        let k = [a.min(b), a.max(b)];
        assert!(edges.insert(k), "{what}: duplicate edge {k:?}");
        assert!(
            !tri_edges.contains(&k),
            "{what}: edge {k:?} bounds a triangle"
        );
    }
    for &[a, b] in &poly.lines {
        used[a as usize] = true;
        used[b as usize] = true;
    }
    let mut points = HashSet::new();
    for &p in &poly.points {
        assert!(points.insert(p), "{what}: duplicate point {p}");
        assert!(
            !used[p as usize],
            "{what}: point {p} bounds an edge or triangle"
        );
    }
    for &p in &poly.points {
        used[p as usize] = true;
    }
    assert!(
        used.iter().all(|&u| u),
        "{what}: a vertex of the output is unused"
    );

    assert_eq!(level.cluster_of.len(), input.positions.len(), "{what}");
    let mut referenced = vec![false; input.positions.len()];
    for t in &input.triangles {
        for &v in t {
            referenced[v as usize] = true;
        }
    }
    for (v, &c) in level.cluster_of.iter().enumerate() {
        if referenced[v] {
            assert!((c as usize) < n, "{what}: vertex {v} in cluster {c} of {n}");
        } else {
            assert_eq!(c, u32::MAX, "{what}: unused vertex {v} clustered");
        }
    }
    let r = &level.report;
    assert_eq!(r.clusters, n, "{what}");
    assert_eq!(r.triangles, poly.mesh.triangles.len(), "{what}");
    assert_eq!(r.dangling_edges, poly.lines.len(), "{what}");
    assert_eq!(r.isolated_points, poly.points.len(), "{what}");
    assert!(
        r.cluster_seconds >= 0.0 && r.cluster_seconds.is_finite(),
        "{what}"
    );
}
