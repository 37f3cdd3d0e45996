//! Refining a mesh to a triangle count without changing its surface: edges split at their
//! midpoints, the longest first ([`split_longest_edges`]).
//!
//! A split edge adds one vertex and, for each triangle beside it, one triangle: a triangle with
//! one split edge becomes two, with two becomes three (its quadrilateral cut along the shorter
//! diagonal), with three becomes four (the midpoint triangle). Every new triangle keeps its
//! parent's winding and lies in its parent's plane, so the surface, its area, its topology
//! (manifold, orientation, boundary loops, genus) and any crossing between two triangles stay
//! what they were; only the count grows.
//!
//! Cost: per round, a sort of the edges (O(E log E)) and one pass over the triangles; each round
//! at most quadruples the count.

use rustc_hash::FxHashMap as HashMap;

use glam::Vec3;

use crate::TriangleMesh;

/// `mesh` with edges split at their midpoints, the longest first, until it has `target`
/// triangles (one fewer where an edge of a closed surface would overshoot by one; more edges
/// on the boundary give one triangle a split). A target at or below the mesh's count gives the
/// mesh unchanged; an empty mesh stays empty. The surface is unchanged (module docs).
pub fn split_longest_edges(mesh: &TriangleMesh, target: usize) -> TriangleMesh {
    let mut out = mesh.clone();
    out.normals.clear();
    while out.triangles.len() < target {
        let before = out.triangles.len();
        out = split_round(&out, target - before);
        if out.triangles.len() == before {
            break;
        }
    }
    out
}

/// One round: the longest edges that add at most `add` triangles split (each adds one triangle
/// per triangle beside it), every edge at most once.
fn split_round(mesh: &TriangleMesh, add: usize) -> TriangleMesh {
    let mut uses: HashMap<(u32, u32), u32> = HashMap::default();
    for &[a, b, c] in &mesh.triangles {
        for (u, w) in [(a, b), (b, c), (c, a)] {
            *uses.entry((u.min(w), u.max(w))).or_default() += 1;
        }
    }
    let length = |&(u, w): &(u32, u32)| {
        mesh.positions[u as usize].distance_squared(mesh.positions[w as usize])
    };
    let mut edges: Vec<((u32, u32), u32)> = uses.into_iter().collect();
    // Longest first; ties by index, so the result does not depend on the map's order.
    edges.sort_unstable_by(|x, y| length(&y.0).total_cmp(&length(&x.0)).then(x.0.cmp(&y.0)));
    let mut positions = mesh.positions.clone();
    let mut midpoint: HashMap<(u32, u32), u32> = HashMap::default();
    let mut added = 0usize;
    for ((u, w), count) in edges {
        if added + count as usize > add {
            continue;
        }
        added += count as usize;
        midpoint.insert((u, w), positions.len() as u32);
        positions.push(0.5 * (positions[u as usize] + positions[w as usize]));
    }
    let mid = |u: u32, w: u32| midpoint.get(&(u.min(w), u.max(w))).copied();
    let mut triangles = Vec::with_capacity(mesh.triangles.len() + added);
    for &t in &mesh.triangles {
        split_triangle(t, &mid, &positions, &mut triangles);
    }
    TriangleMesh::new(positions, triangles)
}

/// Triangle `[a, b, c]` cut at the midpoints `mid` gives for its edges, its winding kept.
fn split_triangle(
    [a, b, c]: [u32; 3],
    mid: &impl Fn(u32, u32) -> Option<u32>,
    positions: &[Vec3],
    out: &mut Vec<[u32; 3]>,
) {
    let m = [mid(a, b), mid(b, c), mid(c, a)];
    let corners = [a, b, c];
    match m.iter().filter(|x| x.is_some()).count() {
        0 => out.push([a, b, c]),
        3 => {
            let [ab, bc, ca] = m.map(Option::unwrap);
            out.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
        }
        1 => {
            // Rotate so that the split edge is the first: corners (p, q, r), midpoint of pq.
            let i = m.iter().position(Option::is_some).unwrap_or(0);
            let (p, q, r) = (corners[i], corners[(i + 1) % 3], corners[(i + 2) % 3]);
            let pq = m[i].unwrap_or(p);
            out.extend([[p, pq, r], [pq, q, r]]);
        }
        _ => {
            // Rotate so that the unsplit edge is the last (r, p): midpoints of pq and qr.
            let i = (m.iter().position(Option::is_none).unwrap_or(0) + 1) % 3;
            let (p, q, r) = (corners[i], corners[(i + 1) % 3], corners[(i + 2) % 3]);
            let (pq, qr) = (m[i].unwrap_or(p), m[(i + 1) % 3].unwrap_or(q));
            out.push([pq, q, qr]);
            // The quadrilateral p, pq, qr, r along its shorter diagonal.
            let at = |v: u32| positions[v as usize];
            if at(p).distance_squared(at(qr)) <= at(pq).distance_squared(at(r)) {
                out.extend([[p, pq, qr], [p, qr, r]]);
            } else {
                out.extend([[p, pq, r], [pq, qr, r]]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh_topology;
    use crate::test_shapes::octahedron;

    #[test]
    fn split_longest_edges_keeps_the_surface_and_its_topology() {
        let mesh = octahedron();
        let (area, volume) = (mesh.area(), mesh.signed_volume());
        for target in [10, 16, 20, 32, 33, 100] {
            let split = split_longest_edges(&mesh, target);
            let t = mesh_topology(&split);
            // Every split of a closed surface's edge adds two triangles.
            let expected = if target % 2 == 0 { target } else { target - 1 };
            assert_eq!(split.triangles.len(), expected, "target {target}");
            assert!(t.is_closed_manifold() && t.is_consistently_oriented());
            assert_eq!((t.genus, t.components), (Some(0), 1));
            assert!((split.area() - area).abs() < 1e-9 * area);
            assert!((split.signed_volume() - volume).abs() < 1e-9 * volume);
        }
    }

    #[test]
    fn split_longest_edges_splits_the_longest_first_and_stops_at_the_count() {
        // A long thin triangle pair (a rectangle 4 × 1): its two long sides and the diagonal
        // are longer than the short sides.
        let p = vec![
            Vec3::ZERO,
            Vec3::new(4.0, 0.0, 0.0),
            Vec3::new(4.0, 1.0, 0.0),
            Vec3::Y,
        ];
        let mesh = TriangleMesh::new(p, vec![[0, 1, 2], [0, 2, 3]]);
        // The diagonal (√17) first: two triangles more.
        let split = split_longest_edges(&mesh, 4);
        assert_eq!(split.triangles.len(), 4);
        assert_eq!(split.positions[4], Vec3::new(2.0, 0.5, 0.0));
        // At or below the count: unchanged.
        assert_eq!(split_longest_edges(&mesh, 2).triangles, mesh.triangles);
        assert!(split_longest_edges(&TriangleMesh::default(), 10).is_empty());
        // An open rectangle's boundary edges add one triangle each: the odd count is reached.
        let t = mesh_topology(&split_longest_edges(&mesh, 5));
        assert_eq!((t.triangles, t.boundary_loops, t.genus), (5, 1, Some(0)));
    }
}
