//! Light repairs that make a mesh safe for the algorithms without changing the shape it shows:
//! dropping triangles with a repeated vertex or zero area, and exact duplicates (same three
//! vertices in any order; of a pair with opposite windings, the first is kept).
//!
//! Duplicates matter to the inside test: two copies of a face cross every ray twice at the same
//! point, so a parity count would see no surface there at all.
//!
//! Beyond the paper, whose §2 samples closed objects: these repairs, and closing the holes of a
//! scan with fans ([`close_boundary_loops`]), let the inside test of sampling run on the meshes
//! scanners and modellers really write. Cost: O(F log F) for the duplicate sort, near-linear for
//! the hole fans.

use std::collections::{HashMap, HashSet};

use glam::Vec3;
use rayon::prelude::*;

use crate::TriangleMesh;

/// What [`remove_degenerate_and_duplicate_triangles`] removed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RepairReport {
    /// Triangles dropped for a repeated vertex index or zero area.
    pub degenerate_triangles: usize,
    /// Triangles dropped as copies of an earlier one (same three vertices, any order).
    pub duplicate_triangles: usize,
}

impl RepairReport {
    /// Nothing was removed.
    pub fn is_clean(&self) -> bool {
        self.degenerate_triangles == 0 && self.duplicate_triangles == 0
    }
}

/// Removes degenerate triangles (a repeated vertex index or zero area) and exact duplicates.
/// Cost: O(F log F), one parallel sort of the triangles' sorted vertex triples.
pub fn remove_degenerate_and_duplicate_triangles(mesh: &mut TriangleMesh) -> RepairReport {
    let positions = &mesh.positions;
    let degenerate: Vec<bool> = mesh
        .triangles
        .par_iter()
        .map(|&[a, b, c]| {
            let (pa, pb, pc) = (
                positions[a as usize].as_dvec3(),
                positions[b as usize].as_dvec3(),
                positions[c as usize].as_dvec3(),
            );
            a == b || b == c || a == c || (pb - pa).cross(pc - pa).length_squared() == 0.0
        })
        .collect();
    // Sorted vertex triples with their triangle index: equal triples are duplicates; the first
    // in the file is kept.
    let mut keys: Vec<([u32; 3], u32)> = mesh
        .triangles
        .par_iter()
        .enumerate()
        .filter(|(t, _)| !degenerate[*t])
        .map(|(t, tri)| {
            let mut key = *tri;
            key.sort_unstable();
            (key, t as u32)
        })
        .collect();
    keys.par_sort_unstable();
    let mut duplicate = vec![false; mesh.triangles.len()];
    for pair in keys.windows(2) {
        if pair[0].0 == pair[1].0 {
            duplicate[pair[1].1 as usize] = true;
        }
    }
    let report = RepairReport {
        degenerate_triangles: degenerate.iter().filter(|&&d| d).count(),
        duplicate_triangles: duplicate.iter().filter(|&&d| d).count(),
    };
    if !report.is_clean() {
        let mut t = 0;
        mesh.triangles.retain(|_| {
            let keep = !degenerate[t] && !duplicate[t];
            t += 1;
            keep
        });
    }
    report
}

/// Closes every hole of the mesh with a fan of triangles around the centroid of its boundary
/// loop, and returns how many loops it closed. Boundary edges are those used by exactly one
/// triangle; they are chained into closed loops (a vertex where two holes touch is passed
/// through twice). Afterwards every former boundary edge is used twice. The fans ignore
/// orientation and may cut through the mesh for a strongly curved loop: they serve the parity
/// inside test, which only needs every edge used an even number of times, not a fair surface.
/// Edges of a boundary that do not chain into a loop (an open non-manifold fin) are left.
/// Triangles with a repeated vertex cover nothing and are passed over: collapsed to an edge
/// they would use it twice and hide a hole there, collapsed to a point they have no edge.
pub fn close_boundary_loops(mesh: &mut TriangleMesh) -> usize {
    // Boundary edges: the undirected edge keys that occur once (one parallel sort).
    let mut keys: Vec<u64> = mesh
        .triangles
        .par_iter()
        .filter(|&&[a, b, c]| a != b && b != c && a != c)
        .flat_map_iter(|&[a, b, c]| [(a, b), (b, c), (c, a)])
        .map(|(u, v)| ((u.min(v) as u64) << 32) | u.max(v) as u64)
        .collect();
    keys.par_sort_unstable();
    let boundary: Vec<(u32, u32)> = keys
        .chunk_by(|a, b| a == b)
        .filter(|run| run.len() == 1)
        .map(|run| ((run[0] >> 32) as u32, run[0] as u32))
        .collect();
    drop(keys);
    if boundary.is_empty() {
        return 0;
    }
    let mut neighbours: HashMap<u32, Vec<u32>> = HashMap::new();
    for &(u, v) in &boundary {
        neighbours.entry(u).or_default().push(v);
        neighbours.entry(v).or_default().push(u);
    }
    let mut used: HashSet<(u32, u32)> = HashSet::new();
    let mut closed = 0;
    for &(start, first) in &boundary {
        if used.contains(&(start, first)) {
            continue;
        }
        // Walk from `start` along unused boundary edges until we come back.
        let mut loop_vertices = vec![start];
        let mut edges = vec![(start, first)];
        used.insert((start, first));
        let mut at = first;
        while at != start {
            let next = neighbours[&at]
                .iter()
                .copied()
                .find(|&w| !used.contains(&(at.min(w), at.max(w))));
            let Some(w) = next else { break };
            used.insert((at.min(w), at.max(w)));
            edges.push((at.min(w), at.max(w)));
            loop_vertices.push(at);
            at = w;
        }
        if at != start || loop_vertices.len() < 3 {
            continue; // an open chain: nothing to close
        }
        let centroid = loop_vertices
            .iter()
            .map(|&v| mesh.positions[v as usize])
            .sum::<Vec3>()
            / loop_vertices.len() as f32;
        let c = mesh.positions.len() as u32;
        mesh.positions.push(centroid);
        if !mesh.normals.is_empty() {
            mesh.normals.push(Vec3::ZERO);
        }
        for i in 0..loop_vertices.len() {
            let (a, b) = (
                loop_vertices[i],
                loop_vertices[(i + 1) % loop_vertices.len()],
            );
            mesh.triangles.push([b, a, c]);
        }
        closed += 1;
    }
    closed
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_shapes::unit_cube;
    use glam::Vec3;

    #[test]
    fn closes_holes_with_fans() {
        let mut cube = unit_cube();
        cube.triangles.truncate(10); // open the x = 0 side: one square hole
        assert_eq!(close_boundary_loops(&mut cube), 1);
        assert_eq!(cube.positions.len(), 9);
        assert_eq!(cube.triangles.len(), 14);
        let t = crate::mesh_topology(&cube);
        assert_eq!(t.boundary_edges, 0);
        assert_eq!(t.non_manifold_edges, 0);
        // A closed mesh is left alone.
        let mut whole = unit_cube();
        assert_eq!(close_boundary_loops(&mut whole), 0);
        assert_eq!(whole, unit_cube());
    }

    #[test]
    fn collapsed_triangles_neither_hide_nor_make_holes() {
        // Dropping the last two triangles opens the x = 1 side: a hole bounded by 1-3-7-5.
        let mut open = unit_cube();
        open.triangles.truncate(10);
        let (u, v) = (1, 3);
        let mut m = open.clone();
        m.triangles.push([u, u, v]);
        m.positions.push(Vec3::splat(7.0));
        m.triangles.push([8, 8, 8]);
        assert_eq!(close_boundary_loops(&mut m), 1);
        let t = crate::mesh_topology(&m);
        assert_eq!(t.boundary_edges, 0);
        // A lone collapsed triangle is no hole.
        let mut point = TriangleMesh::new(vec![Vec3::ZERO], vec![[0, 0, 0]]);
        assert_eq!(close_boundary_loops(&mut point), 0);
        assert_eq!(point.triangles.len(), 1);
    }

    #[test]
    fn drops_degenerate_and_duplicate_triangles() {
        let mut cube = unit_cube();
        cube.triangles.push([2, 1, 0]); // duplicate of [0, 2, 1] reversed
        cube.triangles.push([0, 0, 3]); // repeated index
        cube.positions.push(Vec3::new(2.0, 0.0, 0.0));
        cube.triangles.push([0, 1, 8]); // collinear: zero area
        let report = remove_degenerate_and_duplicate_triangles(&mut cube);
        assert_eq!(report.duplicate_triangles, 1);
        assert_eq!(report.degenerate_triangles, 2);
        assert_eq!(cube.triangles, unit_cube().triangles);
    }
}
