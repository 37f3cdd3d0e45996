//! Shared helpers of the integration tests: small meshes built in code, reading the shared data
//! through voxlod-io, a naive reference of the §3.5 elimination rules, and a checker of valid
//! output.
#![allow(dead_code)]

use std::collections::{BTreeSet, HashSet};
use std::path::Path;

use voxlod_baselines::Level;
use voxlod_core::glam::Vec3;
use voxlod_core::{PolyMesh, TriangleMesh};

/// Unit cube, 8 vertices, 12 outward triangles.
pub fn unit_cube() -> TriangleMesh {
    let p = Vec3::new;
    TriangleMesh::new(
        vec![
            p(0., 0., 0.),
            p(1., 0., 0.),
            p(1., 1., 0.),
            p(0., 1., 0.),
            p(0., 0., 1.),
            p(1., 0., 1.),
            p(1., 1., 1.),
            p(0., 1., 1.),
        ],
        vec![
            [0, 2, 1],
            [0, 3, 2],
            [4, 5, 6],
            [4, 6, 7],
            [0, 1, 5],
            [0, 5, 4],
            [1, 2, 6],
            [1, 6, 5],
            [2, 3, 7],
            [2, 7, 6],
            [3, 0, 4],
            [3, 4, 7],
        ],
    )
}

/// A closed prism along x from 0 to `length`: rings of the cross-section `section` (y, z
/// points, counter-clockwise) every `spacing` starting at `spacing / 2`, closed by a fan to a
/// centre point at each end (x = 0 and x = `length`).
pub fn prism(section: &[(f32, f32)], length: f32, spacing: f32) -> TriangleMesh {
    let n = section.len() as u32;
    let rings = (length / spacing).round() as u32;
    let mut positions = Vec::new();
    for r in 0..rings {
        let x = spacing * (r as f32 + 0.5);
        for &(y, z) in section {
            positions.push(Vec3::new(x, y, z));
        }
    }
    let start = positions.len() as u32;
    positions.push(Vec3::ZERO);
    positions.push(Vec3::new(length, 0.0, 0.0));
    let mut triangles = Vec::new();
    for r in 0..rings - 1 {
        for i in 0..n {
            let a = r * n + i;
            let b = r * n + (i + 1) % n;
            let (c, d) = (a + n, b + n);
            triangles.push([a, b, d]);
            triangles.push([a, d, c]);
        }
    }
    let last = (rings - 1) * n;
    for i in 0..n {
        triangles.push([start, (i + 1) % n, i]);
        triangles.push([start + 1, last + i, last + (i + 1) % n]);
    }
    TriangleMesh::new(positions, triangles)
}

/// A regular `n`-gon of diameter `d` centred on the x axis.
pub fn round_section(n: usize, d: f32) -> Vec<(f32, f32)> {
    (0..n)
        .map(|i| {
            let a = i as f32 * std::f32::consts::TAU / n as f32;
            (0.5 * d * a.cos(), 0.5 * d * a.sin())
        })
        .collect()
}

#[allow(unused_imports)]
pub use voxlod_core::shapes::torus;

/// Reads a mesh with voxlod-io (STL soups are welded there).
pub fn read_mesh(path: &Path) -> TriangleMesh {
    voxlod_io::read_mesh(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .mesh
}

/// The meshes of the shared data folder, or none after printing why the test skips.
pub fn shared_meshes(test: &str) -> Vec<std::path::PathBuf> {
    let Some(any) = voxlod_core::testdata::shared_data_or_skip("meshes/fandisk.obj", test) else {
        return Vec::new();
    };
    let dir = any.parent().unwrap().to_path_buf();
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            matches!(
                p.extension().and_then(|e| e.to_str()),
                Some("obj" | "off" | "stl")
            )
        })
        .collect();
    files.sort();
    files
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
