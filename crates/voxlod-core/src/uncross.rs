//! Crossing triangles taken apart by edge flips (beyond the paper).
//!
//! A quadric collapse can fold one sheet through another close to it in a few places (module
//! [`crate::crossing_pairs`]); each such place is a pair of triangles, long after the collapse,
//! that cut through each other. Flipping an edge of a crossing triangle (the quad of the two
//! triangles beside that edge triangulated along its other diagonal) often takes the pair
//! apart while the surface moves only inside that quad, and the vertices, the topology and
//! every other triangle stay as they are.
//!
//! [`uncrossed`] tries, pass after pass, the flip of every edge of a triangle in a crossing
//! pair, and keeps a flip where the two new triangles cross fewer others than the two old ones
//! did and the flip is sound: the edge has two triangles, the new diagonal is not an edge
//! already (the mesh stays a manifold with the same edges elsewhere), neither new triangle is
//! degenerate, and the quad does not fold (the new triangles face within 90° of each other and
//! of the old pair). A triangle flipped in a pass is not flipped again in that pass. Passes
//! repeat while some flip was kept, at most [`PASSES`].
//!
//! Cost: per pass one [`crossing_pairs`] (O(F log F)), and per flip tried a scan of every
//! triangle's box against the quad's, O(F): meant for the few folds a collapse makes.

use std::collections::HashMap;

use glam::DVec3;

use crate::crossings::{bounds, boxes_apart, triangles_cross};
use crate::{crossing_pairs, TriangleMesh};

/// Passes at most.
pub const PASSES: usize = 8;

/// `mesh` with crossing pairs taken apart by edge flips (module docs), and the crossing pairs
/// it still has. The mesh is unchanged where no flip helped.
pub fn uncrossed(mesh: &TriangleMesh) -> (TriangleMesh, usize) {
    let mut mesh = mesh.clone();
    let mut pairs = crossing_pairs(&mesh);
    let margin = 1e-9 * mesh.bounds().diagonal().max(f64::MIN_POSITIVE);
    for _ in 0..PASSES {
        if pairs.is_empty() || !flip_pass(&mut mesh, &pairs, margin) {
            break;
        }
        pairs = crossing_pairs(&mesh);
    }
    (mesh, pairs.len())
}

/// One pass over the edges of the triangles in `pairs`; whether a flip was kept.
fn flip_pass(mesh: &mut TriangleMesh, pairs: &[(u32, u32)], margin: f64) -> bool {
    let edges = edge_triangles(mesh);
    let mut crossing: Vec<u32> = pairs.iter().flat_map(|&(s, t)| [s, t]).collect();
    crossing.sort_unstable();
    crossing.dedup();
    let mut touched = vec![false; mesh.triangles.len()];
    let mut kept = false;
    for &t in &crossing {
        for k in 0..3 {
            if touched[t as usize] {
                break;
            }
            let tri = mesh.triangles[t as usize];
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            let Some(&[s, u]) = edges.get(&key(a, b)).map(Vec::as_slice) else {
                continue;
            };
            let other = if s == t { u } else { s };
            if touched[other as usize] {
                continue;
            }
            if let Some(flipped) = sound_flip(mesh, &edges, t, other, (a, b)) {
                if crossings_of(mesh, &flipped, [t, other], margin)
                    < crossings_of(mesh, &corner_sets(mesh, [t, other]), [t, other], margin)
                {
                    mesh.triangles[t as usize] = flipped[0].1;
                    mesh.triangles[other as usize] = flipped[1].1;
                    touched[t as usize] = true;
                    touched[other as usize] = true;
                    kept = true;
                }
            }
        }
    }
    kept
}

/// The key of the edge between vertices `a` and `b`.
fn key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

/// Every edge's triangles.
fn edge_triangles(mesh: &TriangleMesh) -> HashMap<(u32, u32), Vec<u32>> {
    let mut edges: HashMap<(u32, u32), Vec<u32>> = HashMap::with_capacity(mesh.triangles.len());
    for (t, tri) in mesh.triangles.iter().enumerate() {
        for k in 0..3 {
            edges
                .entry(key(tri[k], tri[(k + 1) % 3]))
                .or_default()
                .push(t as u32);
        }
    }
    edges
}

/// The two triangles `t` = (a, b, c) and `other` = (b, a, d) beside edge (a, b) triangulated
/// along (c, d) instead, as (corners, indices), where that flip is sound (module docs).
fn sound_flip(
    mesh: &TriangleMesh,
    edges: &HashMap<(u32, u32), Vec<u32>>,
    t: u32,
    other: u32,
    (a, b): (u32, u32),
) -> Option<[([DVec3; 3], [u32; 3]); 2]> {
    let apex = |tri: [u32; 3]| tri.into_iter().find(|&v| v != a && v != b);
    let c = apex(mesh.triangles[t as usize])?;
    let d = apex(mesh.triangles[other as usize])?;
    // `other` runs b → a: the shared edge with opposite orientation.
    let o = mesh.triangles[other as usize];
    let runs_back = (0..3).any(|k| o[k] == b && o[(k + 1) % 3] == a);
    if c == d || !runs_back || edges.contains_key(&key(c, d)) {
        return None;
    }
    let p = |v: u32| mesh.positions[v as usize].as_dvec3();
    let new = [[a, d, c], [b, c, d]];
    let normal = |tri: [u32; 3]| (p(tri[1]) - p(tri[0])).cross(p(tri[2]) - p(tri[0]));
    let old = normal(mesh.triangles[t as usize]) + normal(o);
    let (n0, n1) = (normal(new[0]), normal(new[1]));
    let scale = (p(a) - p(b))
        .length_squared()
        .max((p(c) - p(d)).length_squared());
    let degenerate = |n: DVec3| n.length() <= 1e-12 * scale;
    let folds = n0.dot(n1) <= 0.0 || n0.dot(old) <= 0.0 || n1.dot(old) <= 0.0;
    if degenerate(n0) || degenerate(n1) || folds {
        return None;
    }
    Some(new.map(|tri| (tri.map(p), tri)))
}

/// The corners and indices of triangles `ts`.
fn corner_sets(mesh: &TriangleMesh, ts: [u32; 2]) -> [([DVec3; 3], [u32; 3]); 2] {
    ts.map(|t| (mesh.corners(t as usize), mesh.triangles[t as usize]))
}

/// How many (triangle of `quad`, triangle of `mesh` other than `skip`) pairs cross.
fn crossings_of(
    mesh: &TriangleMesh,
    quad: &[([DVec3; 3], [u32; 3]); 2],
    skip: [u32; 2],
    margin: f64,
) -> usize {
    let boxes = quad.map(|(c, _)| bounds(c));
    let mut count = 0;
    for (u, tri) in mesh.triangles.iter().enumerate() {
        if skip.contains(&(u as u32)) {
            continue;
        }
        let corners = mesh.corners(u);
        let b = bounds(corners);
        for (k, (c, ids)) in quad.iter().enumerate() {
            if !boxes_apart(boxes[k], b, margin) && triangles_cross(*c, *ids, corners, *tri, margin)
            {
                count += 1;
            }
        }
    }
    count
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// A square of two triangles split along (0, 2), its corner 3 raised (the flat half
    /// (0, 1, 2) at z = 0), and a small triangle standing through that flat half near corner 1,
    /// below the surface the other diagonal makes (z = y / 2 there): flipping the square's
    /// diagonal to (1, 3) takes the pair apart.
    fn folded() -> TriangleMesh {
        TriangleMesh::new(
            vec![
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(4.0, 0.0, 0.0),
                Vec3::new(4.0, 4.0, 0.0),
                Vec3::new(0.0, 4.0, 2.0),
                Vec3::new(3.0, 0.5, -0.1),
                Vec3::new(3.0, 0.5, 0.1),
                Vec3::new(3.5, 0.6, 0.1),
            ],
            vec![[0, 1, 2], [0, 2, 3], [4, 6, 5]],
        )
    }

    /// `tri` turned to start at its smallest index.
    fn canonical(tri: [u32; 3]) -> [u32; 3] {
        let k = (0..3).min_by_key(|&k| tri[k]).unwrap();
        [tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]]
    }

    #[test]
    fn a_flip_takes_a_crossing_pair_apart_and_keeps_the_vertices() {
        let mesh = folded();
        assert_eq!(crossing_pairs(&mesh), vec![(0, 2)]);
        let (out, left) = uncrossed(&mesh);
        assert_eq!(left, 0);
        assert!(crossing_pairs(&out).is_empty());
        assert_eq!(out.positions, mesh.positions);
        let mut square: Vec<[u32; 3]> = out.triangles[..2].iter().map(|&t| canonical(t)).collect();
        square.sort_unstable();
        // The other diagonal, both halves still counter-clockwise seen from above.
        assert_eq!(square, vec![[0, 1, 3], [1, 2, 3]]);
        assert_eq!(out.triangles[2], mesh.triangles[2]);
    }

    #[test]
    fn a_crossing_no_flip_helps_is_left_as_it_was() {
        // A tall triangle through the middle of the square: it crosses whichever way the
        // square is split.
        let mut mesh = folded();
        mesh.positions[4] = Vec3::new(2.0, 2.0, -1.0);
        mesh.positions[5] = Vec3::new(2.0, 2.0, 3.0);
        mesh.positions[6] = Vec3::new(2.1, 1.8, 3.0);
        let before = crossing_pairs(&mesh).len();
        assert!(before > 0);
        let (out, left) = uncrossed(&mesh);
        assert_eq!(left, before);
        assert_eq!(out.triangles, mesh.triangles);
    }
}
