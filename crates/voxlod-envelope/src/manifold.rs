//! What the envelope method assumes of its input (paper §3.2: "every edge has either one or two
//! adjacent triangles", and normals that agree), checked with the offending edges named, and a
//! repair that cuts a mesh into a manifold without moving any point.
//!
//! The check: no triangle repeats a vertex; every edge is used by at most two triangles, in
//! opposite directions (consistent orientation, so that vertex normals and the two sides of the
//! envelope mean something); the triangles around every vertex form a single fan. Cost: one sort
//! of the 3F half-edges and a pass over each vertex's triangles.
//!
//! The repair ([`repair_for_envelope`]): drops triangles that repeat a vertex and exact
//! duplicates, pairs the two directions of every edge (a half-edge a→b with a b→a, in triangle
//! order; what is left over becomes border), then gives each fan of corners around a vertex its
//! own copy of the vertex (corners are joined across paired edges by a union-find). Positions
//! are unchanged; a non-manifold edge becomes two or more border edges and a pinched vertex
//! becomes several vertices. A triangle that still shares an unpaired edge with another after
//! that (possible when the sheets meeting at the edge are joined elsewhere around both ends) is
//! detached with its own three vertices. Cost: O(F log F).

use std::fmt;

use rayon::prelude::*;
use serde::Serialize;
use voxlod_core::TriangleMesh;

use super::{EnvelopeError, ManifoldProblems};

/// At most this many offending items are named in an error message.
const NAMED: usize = 6;

/// Checks that `mesh` is a consistently oriented 2-manifold (with or without border); the error
/// names the first offending edges, vertices and triangles.
pub fn check_manifold(mesh: &TriangleMesh) -> Result<(), EnvelopeError> {
    let problems = manifold_problems(mesh);
    if problems.is_empty() {
        Ok(())
    } else {
        Err(EnvelopeError::NotManifold(problems))
    }
}

/// Each vertex's triangles (its star), over the triangles `keep` accepts, as a compressed
/// table: `offsets[v]..offsets[v + 1]` indexes `list` for vertex `v` (a counting sort,
/// triangles in order).
pub(crate) fn stars(
    tris: &[[u32; 3]],
    n: usize,
    keep: impl Fn(&[u32; 3]) -> bool,
) -> (Vec<u32>, Vec<u32>) {
    let mut offsets = vec![0u32; n + 1];
    for tri in tris.iter().filter(|t| keep(t)) {
        for &v in tri {
            offsets[v as usize + 1] += 1;
        }
    }
    for i in 0..n {
        offsets[i + 1] += offsets[i];
    }
    let mut fill = offsets.clone();
    let mut list = vec![0u32; offsets[n] as usize];
    for (t, tri) in tris.iter().enumerate() {
        if keep(tri) {
            for &v in tri {
                list[fill[v as usize] as usize] = t as u32;
                fill[v as usize] += 1;
            }
        }
    }
    (offsets, list)
}

#[inline]
fn edge_key(a: u32, b: u32) -> u64 {
    ((a.min(b) as u64) << 32) | a.max(b) as u64
}

/// Everything [`check_manifold`] refuses, counted, with examples.
pub fn manifold_problems(mesh: &TriangleMesh) -> ManifoldProblems {
    let mut p = ManifoldProblems::default();
    for (t, &[a, b, c]) in mesh.triangles.iter().enumerate() {
        if a == b || b == c || a == c {
            p.degenerate_triangles += 1;
            if p.examples.len() < NAMED {
                p.examples
                    .push(format!("triangle {t} repeats a vertex ({a}, {b}, {c})"));
            }
        }
    }
    // Half-edges (undirected key, forward?) of the proper triangles, grouped by edge.
    let mut half: Vec<(u64, bool)> = mesh
        .triangles
        .par_iter()
        .filter(|&&[a, b, c]| a != b && b != c && a != c)
        .flat_map_iter(|&[a, b, c]| [(a, b), (b, c), (c, a)].map(|(u, v)| (edge_key(u, v), u < v)))
        .collect();
    half.par_sort_unstable();
    let mut start = 0;
    while start < half.len() {
        let key = half[start].0;
        let mut end = start + 1;
        while end < half.len() && half[end].0 == key {
            end += 1;
        }
        let (a, b) = (key >> 32, key & 0xffff_ffff);
        if end - start > 2 {
            p.non_manifold_edges += 1;
            if p.examples.len() < NAMED {
                p.examples
                    .push(format!("edge {a}–{b} ({} triangles)", end - start));
            }
        } else if end - start == 2 && half[start].1 == half[start + 1].1 {
            p.inconsistent_edges += 1;
            if p.examples.len() < NAMED {
                p.examples
                    .push(format!("edge {a}–{b} used twice in the same direction"));
            }
        }
        start = end;
    }
    let pinched = pinched_vertices(mesh);
    p.non_manifold_vertices = pinched.len();
    for v in pinched.iter().take(NAMED.saturating_sub(p.examples.len())) {
        p.examples.push(format!("vertex {v} joins separate fans"));
    }
    p
}

/// Vertices whose incident proper triangles are not connected through edges at the vertex.
fn pinched_vertices(mesh: &TriangleMesh) -> Vec<u32> {
    let n = mesh.positions.len();
    let proper = |&[a, b, c]: &[u32; 3]| a != b && b != c && a != c;
    let (offsets, around) = stars(&mesh.triangles, n, proper);
    (0..n)
        .into_par_iter()
        .filter(|&v| {
            let ts = &around[offsets[v] as usize..offsets[v + 1] as usize];
            if ts.len() <= 1 {
                return false;
            }
            // Link edges (the two other vertices of each triangle); one fan iff they connect.
            let link: Vec<[u32; 2]> = ts
                .iter()
                .map(|&t| {
                    let tri = mesh.triangles[t as usize];
                    let i = tri.iter().position(|&w| w as usize == v).unwrap_or(0);
                    [tri[(i + 1) % 3], tri[(i + 2) % 3]]
                })
                .collect();
            let mut ids: Vec<u32> = link.iter().flatten().copied().collect();
            ids.sort_unstable();
            ids.dedup();
            let mut parent: Vec<usize> = (0..ids.len()).collect();
            fn find(parent: &mut [usize], mut x: usize) -> usize {
                while parent[x] != x {
                    parent[x] = parent[parent[x]];
                    x = parent[x];
                }
                x
            }
            for [a, b] in &link {
                let ia = ids.binary_search(a).unwrap_or(0);
                let ib = ids.binary_search(b).unwrap_or(0);
                let (ra, rb) = (find(&mut parent, ia), find(&mut parent, ib));
                parent[ra] = rb;
            }
            let root = find(&mut parent, 0);
            (1..ids.len()).any(|i| find(&mut parent, i) != root)
        })
        .map(|v| v as u32)
        .collect()
}

/// What [`repair_for_envelope`] changed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct ManifoldRepair {
    /// Triangles with a repeated vertex index, dropped.
    pub degenerate_triangles_removed: usize,
    /// Second and later copies of a triangle (same vertices, either winding), dropped.
    pub duplicate_triangles_removed: usize,
    /// Half-edges left without a partner in the opposite direction (now border).
    pub half_edges_unpaired: usize,
    /// Vertices added by giving each fan its own copy of a vertex.
    pub vertices_added: usize,
    /// Triangles given their own three vertices as a last resort.
    pub triangles_detached: usize,
}

impl ManifoldRepair {
    /// Whether the repair changed the mesh at all.
    pub fn changed_anything(&self) -> bool {
        *self != ManifoldRepair::default()
    }
}

/// What the repair did, in words: "2 duplicate triangles removed, 3 vertices added to give each
/// fan its own, 6 half-edges left as border", or "nothing to repair".
impl fmt::Display for ManifoldRepair {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut parts = Vec::new();
        for (n, one, many) in [
            (
                self.degenerate_triangles_removed,
                "triangle that repeats a vertex removed",
                "triangles that repeat a vertex removed",
            ),
            (
                self.duplicate_triangles_removed,
                "duplicate triangle removed",
                "duplicate triangles removed",
            ),
            (
                self.vertices_added,
                "vertex added to give each fan its own",
                "vertices added to give each fan its own",
            ),
            (
                self.triangles_detached,
                "triangle detached with its own vertices",
                "triangles detached with their own vertices",
            ),
            (
                self.half_edges_unpaired,
                "half-edge without an opposite partner left as border",
                "half-edges without an opposite partner left as border",
            ),
        ] {
            if n > 0 {
                parts.push(format!("{n} {}", if n == 1 { one } else { many }));
            }
        }
        if parts.is_empty() {
            write!(f, "nothing to repair")
        } else {
            write!(f, "{}", parts.join(", "))
        }
    }
}

/// Cuts `mesh` into a consistently oriented 2-manifold without moving any point (see the module
/// documentation). Normals, when present, are copied to the added vertices.
pub fn repair_for_envelope(mesh: &TriangleMesh) -> (TriangleMesh, ManifoldRepair) {
    let mut report = ManifoldRepair::default();
    let mut out = mesh.clone();
    let mut seen = std::collections::HashSet::with_capacity(out.triangles.len());
    out.triangles.retain(|&[a, b, c]| {
        if a == b || b == c || a == c {
            report.degenerate_triangles_removed += 1;
            return false;
        }
        let mut key = [a, b, c];
        key.sort_unstable();
        if !seen.insert(key) {
            report.duplicate_triangles_removed += 1;
            return false;
        }
        true
    });
    for _ in 0..4 {
        let partner = pair_half_edges(&out.triangles);
        if report.half_edges_unpaired == 0 {
            report.half_edges_unpaired = count_unpaired(&out.triangles, &partner);
        }
        report.vertices_added += split_fans(&mut out, &partner);
        if manifold_problems(&out).is_empty() {
            break;
        }
        report.triangles_detached += detach_crowded(&mut out);
    }
    (out, report)
}

/// For each half-edge `3t + e` (edge e of triangle t, from corner e to corner e+1), the half-edge
/// it is paired with in the opposite direction, or `u32::MAX`.
fn pair_half_edges(triangles: &[[u32; 3]]) -> Vec<u32> {
    let mut half: Vec<(u64, bool, u32)> = triangles
        .iter()
        .enumerate()
        .flat_map(|(t, &tri)| {
            (0..3).map(move |e| {
                let (a, b) = (tri[e], tri[(e + 1) % 3]);
                (edge_key(a, b), a < b, (3 * t + e) as u32)
            })
        })
        .collect();
    half.sort_unstable();
    let mut partner = vec![u32::MAX; half.len()];
    let mut start = 0;
    while start < half.len() {
        let mut end = start + 1;
        while end < half.len() && half[end].0 == half[start].0 {
            end += 1;
        }
        // Sorted by direction then id: forwards first. Pair them in order with backwards.
        let group = &half[start..end];
        let split = group.iter().position(|h| h.1).unwrap_or(group.len());
        let (backward, forward) = group.split_at(split);
        for (f, b) in forward.iter().zip(backward) {
            partner[f.2 as usize] = b.2;
            partner[b.2 as usize] = f.2;
        }
        start = end;
    }
    partner
}

fn count_unpaired(triangles: &[[u32; 3]], partner: &[u32]) -> usize {
    // Border edges of a manifold (used once) are not a repair: count only edges used more.
    let mut uses = std::collections::HashMap::<u64, u32>::new();
    for &[a, b, c] in triangles {
        for (u, v) in [(a, b), (b, c), (c, a)] {
            *uses.entry(edge_key(u, v)).or_default() += 1;
        }
    }
    (0..partner.len())
        .filter(|&h| {
            let tri = triangles[h / 3];
            let (a, b) = (tri[h % 3], tri[(h + 1) % 3]);
            partner[h] == u32::MAX && uses[&edge_key(a, b)] > 1
        })
        .count()
}

/// Gives every fan of corners around a vertex its own vertex; returns how many were added.
fn split_fans(mesh: &mut TriangleMesh, partner: &[u32]) -> usize {
    let corners = mesh.triangles.len() * 3;
    let mut parent: Vec<u32> = (0..corners as u32).collect();
    fn find(parent: &mut [u32], mut x: u32) -> u32 {
        while parent[x as usize] != x {
            parent[x as usize] = parent[parent[x as usize] as usize];
            x = parent[x as usize];
        }
        x
    }
    let union = |parent: &mut Vec<u32>, a: u32, b: u32| {
        let (ra, rb) = (find(parent, a), find(parent, b));
        if ra != rb {
            parent[ra.max(rb) as usize] = ra.min(rb);
        }
    };
    for (h, &g) in partner.iter().enumerate().take(corners) {
        let g = g as usize;
        if g == u32::MAX as usize || g < h {
            continue;
        }
        // Half-edge h runs corner h → corner next(h); its partner g runs the other way, so
        // corner h matches next(g) and next(h) matches g.
        let next = |x: usize| (x / 3) * 3 + (x % 3 + 1) % 3;
        union(&mut parent, h as u32, next(g) as u32);
        union(&mut parent, next(h) as u32, g as u32);
    }
    // The first fan met at each vertex keeps its id; every other fan gets a new vertex.
    let mut first_root = vec![u32::MAX; mesh.positions.len()];
    let mut new_id = std::collections::HashMap::<u32, u32>::new();
    let mut added = 0;
    for c in 0..corners {
        let (t, i) = (c / 3, c % 3);
        let v = mesh.triangles[t][i];
        let root = find(&mut parent, c as u32);
        if first_root[v as usize] == u32::MAX {
            first_root[v as usize] = root;
        } else if first_root[v as usize] != root {
            let id = *new_id.entry(root).or_insert_with(|| {
                mesh.positions.push(mesh.positions[v as usize]);
                if !mesh.normals.is_empty() {
                    mesh.normals.push(mesh.normals[v as usize]);
                }
                added += 1;
                (mesh.positions.len() - 1) as u32
            });
            mesh.triangles[t][i] = id;
        }
    }
    added
}

/// Gives its own three vertices to every triangle on an edge still used more than twice or
/// twice in the same direction; returns how many.
fn detach_crowded(mesh: &mut TriangleMesh) -> usize {
    let mut uses = std::collections::HashMap::<u64, Vec<(usize, bool)>>::new();
    for (t, &[a, b, c]) in mesh.triangles.iter().enumerate() {
        for (u, v) in [(a, b), (b, c), (c, a)] {
            uses.entry(edge_key(u, v)).or_default().push((t, u < v));
        }
    }
    let mut detach = std::collections::BTreeSet::new();
    for list in uses.values() {
        let crowded = list.len() > 2 || (list.len() == 2 && list[0].1 == list[1].1);
        if crowded {
            // Keep the first; detach the rest.
            detach.extend(list.iter().skip(1).map(|&(t, _)| t));
        }
    }
    for &t in &detach {
        for i in 0..3 {
            let v = mesh.triangles[t][i] as usize;
            mesh.positions.push(mesh.positions[v]);
            if !mesh.normals.is_empty() {
                mesh.normals.push(mesh.normals[v]);
            }
            mesh.triangles[t][i] = (mesh.positions.len() - 1) as u32;
        }
    }
    detach.len()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use voxlod_core::mesh_topology;

    fn cube() -> TriangleMesh {
        voxlod_testkit::shapes::unit_cube_ringwise()
    }

    #[test]
    fn a_cube_passes() {
        assert!(check_manifold(&cube()).is_ok());
        let (m, r) = repair_for_envelope(&cube());
        assert!(!r.changed_anything());
        assert_eq!(r.to_string(), "nothing to repair");
        assert_eq!(m, cube());
    }

    #[test]
    fn a_fin_is_named_and_cut() {
        let mut m = cube();
        // A fin on edge 0–1 (already used by two triangles).
        m.positions.push(Vec3::new(0.5, -1.0, -1.0));
        m.triangles.push([0, 1, 8]);
        let e = check_manifold(&m).unwrap_err().to_string();
        assert!(e.contains("edge 0–1 (3 triangles)"), "{e}");
        let (fixed, r) = repair_for_envelope(&m);
        assert!(
            check_manifold(&fixed).is_ok(),
            "{:?}",
            manifold_problems(&fixed)
        );
        assert!(r.half_edges_unpaired >= 1);
        assert_eq!(fixed.triangles.len(), 13);
        // Positions only copied, never moved.
        for (t, tri) in fixed.triangles.iter().enumerate() {
            for (&v, &w) in tri.iter().zip(&m.triangles[t]) {
                assert_eq!(fixed.positions[v as usize], m.positions[w as usize]);
            }
        }
    }

    #[test]
    fn pinched_and_flipped_and_degenerate() {
        // Two cubes sharing vertex 6 / 0 of the second.
        let a = cube();
        let mut b = cube();
        for p in &mut b.positions {
            *p += Vec3::ONE;
        }
        let mut m = a.clone();
        let base = m.positions.len() as u32;
        m.positions.extend(b.positions.iter().skip(1));
        for t in &b.triangles {
            m.triangles
                .push(t.map(|v| if v == 0 { 6 } else { base + v - 1 }));
        }
        let problems = manifold_problems(&m);
        assert_eq!(problems.non_manifold_vertices, 1);
        assert!(problems
            .examples
            .iter()
            .any(|e| e == "vertex 6 joins separate fans"));
        let (fixed, r) = repair_for_envelope(&m);
        assert_eq!(r.vertices_added, 1);
        assert_eq!(r.to_string(), "1 vertex added to give each fan its own");
        let topo = mesh_topology(&fixed);
        assert_eq!(topo.components, 2);
        assert!(topo.is_closed_manifold());

        let mut flipped = cube();
        flipped.triangles[0].swap(1, 2);
        let problems = manifold_problems(&flipped);
        assert_eq!(problems.inconsistent_edges, 3);
        let (fixed, _) = repair_for_envelope(&flipped);
        assert!(check_manifold(&fixed).is_ok());

        let mut degenerate = cube();
        degenerate.triangles.push([1, 1, 2]);
        assert_eq!(manifold_problems(&degenerate).degenerate_triangles, 1);
        let (fixed, r) = repair_for_envelope(&degenerate);
        assert_eq!(r.degenerate_triangles_removed, 1);
        assert_eq!(fixed, cube());
    }
}
