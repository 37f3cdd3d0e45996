//! A triangle mesh made an oriented manifold by cutting it where it is not one
//! ([`make_manifold`]): each connected piece oriented consistently, and vertices split so that
//! every edge has at most two triangles, which traverse it in opposite directions, and every
//! vertex is one fan. No vertex moves; the split copies of a vertex keep its position, and
//! triangles are added only where a flattened part is inflated (step 0).
//!
//! 0. **Pockets.** Two triangles on the same three vertices wound opposite ways (a flattened
//!    pocket a collapse leaves where a thin part was) enclose nothing: both are dropped, which
//!    keeps a closed surface closed; where the two are a whole part on their own (a small part
//!    a collapse flattened), they become a tetrahedron instead, the one vertex it adds a tenth
//!    of an edge below their centre, so the part keeps its place. Exact copies (wound the same
//!    way) keep one.
//! 1. **Orientation.** Across every edge shared by exactly two triangles, a walk over the mesh
//!    flips triangles so that neighbours agree; each piece keeps the orientation most of its
//!    triangles had. Where the walk meets itself with a disagreement (a Möbius strip), that
//!    edge is cut instead.
//! 2. **Cutting.** An edge with three or more triangles is where sheets touch (a collapse that
//!    pinched a thin neck, parts glued along an edge). Its triangles are sorted by angle around
//!    it and paired: each one running against the edge's direction with the next one
//!    counter-clockwise running along it. With outward orientation the two bound the same
//!    wedge of the solid, so touching surfaces come apart as closed surfaces instead of opening
//!    up; what is left (a sheet folded onto itself) pairs with its next unpaired neighbour
//!    wound the other way. Triangles left unpaired, and the Möbius cuts, join nothing. A vertex gets one copy per
//!    group of its corners that the joining edges connect.
//! 3. **What still meets.** Where the groups of both ends of such an edge joined up again by
//!    other paths (two surfaces touching along a chain of edges, paired differently at one of
//!    them), the edge's triangles beyond one pair get their own copies of its two vertices,
//!    and step 2 runs again for the vertices that leaves pinched.
//!
//! A mesh that is already an oriented manifold comes back unchanged. Cost: O(F log F) (one sort
//! of the edges), O(F) memory.

use rayon::prelude::*;

use crate::rows::Rows;
use crate::topology::UnionFind;
use crate::TriangleMesh;

/// What [`make_manifold`] changed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct ManifoldReport {
    /// Triangles dropped as flattened pockets or copies (step 0).
    pub dropped_triangles: usize,
    /// Flattened parts made tetrahedra (step 0).
    pub inflated_parts: usize,
    /// Triangles whose orientation was reversed to agree with their piece.
    pub flipped_triangles: usize,
    /// Vertices added as copies where the mesh was cut.
    pub split_vertices: usize,
}

/// Orients each connected piece of `mesh` consistently (module docs, step 1, without the
/// cuts: a Möbius strip keeps one disagreeing edge); returns the triangles flipped.
pub fn orient_consistently(mesh: &mut TriangleMesh) -> usize {
    let flips = orientation(&sorted_edges(&mesh.triangles), mesh.triangles.len());
    apply_flips(mesh, &flips)
}

/// Reverses the triangles marked in `flips`; returns how many.
fn apply_flips(mesh: &mut TriangleMesh, flips: &[bool]) -> usize {
    let mut flipped = 0;
    for (t, flip) in mesh.triangles.iter_mut().zip(flips) {
        if *flip {
            t.swap(1, 2);
            flipped += 1;
        }
    }
    if flipped > 0 && !mesh.normals.is_empty() {
        mesh.compute_vertex_normals();
    }
    flipped
}

/// Makes `mesh` an oriented manifold by cutting it (module docs).
///
/// ```
/// use voxlod_core::{glam::Vec3, manifold::make_manifold, mesh_topology, TriangleMesh};
///
/// // Three triangles on one edge (a fin on a folded sheet), one of them wound the other way:
/// // two pair up across the edge, the third keeps it to itself.
/// let mut fin = TriangleMesh::new(
///     vec![Vec3::ZERO, Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z],
///     vec![[0, 1, 2], [0, 3, 1], [0, 1, 4]],
/// );
/// assert_eq!(mesh_topology(&fin).non_manifold_edges, 1);
/// let report = make_manifold(&mut fin);
/// let t = mesh_topology(&fin);
/// assert!(t.is_manifold() && t.is_consistently_oriented());
/// assert_eq!(fin.triangles.len(), 3);
/// assert_eq!(report.split_vertices, 2);
/// ```
pub fn make_manifold(mesh: &mut TriangleMesh) -> ManifoldReport {
    let (dropped_triangles, inflated_parts) = drop_pockets(mesh);
    let flipped_triangles = orient_consistently(mesh);
    let mut split_vertices = split_corners(mesh, &sorted_edges(&mesh.triangles));
    let detached = detach_still_shared(mesh);
    if detached > 0 {
        // Detaching can leave a vertex pinched between two fans: split them.
        split_vertices += detached + split_corners(mesh, &sorted_edges(&mesh.triangles));
    }
    ManifoldReport {
        dropped_triangles,
        inflated_parts,
        flipped_triangles,
        split_vertices,
    }
}

/// Drops both triangles of each pair on the same vertices wound opposite ways, and all but one
/// of exact copies (module docs, step 0); returns how many were dropped.
fn drop_pockets(mesh: &mut TriangleMesh) -> (usize, usize) {
    // The sorted vertices, and whether the triangle winds them in that order's rotation.
    let key = |t: &[u32; 3]| {
        let mut s = *t;
        s.sort_unstable();
        let even = [[t[0], t[1], t[2]], [t[1], t[2], t[0]], [t[2], t[0], t[1]]].contains(&s);
        (s, even)
    };
    let uses = sorted_edges(&mesh.triangles);
    let edge_uses = |a: u32, b: u32| {
        let e = (a.min(b), a.max(b));
        let lo = uses.partition_point(|u| u.edge < e);
        uses[lo..].iter().take_while(|u| u.edge == e).count()
    };
    let mut order: Vec<usize> = (0..mesh.triangles.len()).collect();
    order.sort_unstable_by_key(|&i| key(&mesh.triangles[i]));
    let mut keep = vec![false; mesh.triangles.len()];
    let mut inflate = Vec::new();
    for run in order.chunk_by(|&a, &b| key(&mesh.triangles[a]).0 == key(&mesh.triangles[b]).0) {
        // Opposite windings cancel in pairs; of what is left, one triangle stays.
        let even = run.iter().filter(|&&i| key(&mesh.triangles[i]).1).count();
        let odd = run.len() - even;
        let [a, b, c] = key(&mesh.triangles[run[0]]).0;
        let isolated = [(a, b), (b, c), (c, a)]
            .iter()
            .all(|&(x, y)| edge_uses(x, y) == 2);
        if run.len() == 2 && even == 1 && isolated {
            // A whole part flattened into two faces: a tetrahedron keeps its place.
            inflate.push(run[0]);
        } else if even != odd {
            let winding = even > odd;
            if let Some(&i) = run.iter().find(|&&i| key(&mesh.triangles[i]).1 == winding) {
                keep[i] = true;
            }
        }
    }
    let before = mesh.triangles.len();
    let inflated: Vec<[u32; 3]> = inflate.iter().map(|&i| mesh.triangles[i]).collect();
    let mut next = keep.iter();
    mesh.triangles.retain(|_| *next.next().unwrap_or(&true));
    let dropped = before - mesh.triangles.len();
    for t in &inflated {
        add_tetrahedron(mesh, *t);
    }
    (dropped - 2 * inflated.len(), inflated.len())
}

/// Adds the tetrahedron on the corners of `t` and a point below its centre (a tenth of its
/// mean edge along its normal), wound outwards.
fn add_tetrahedron(mesh: &mut TriangleMesh, [a, b, c]: [u32; 3]) {
    let p = |v: u32| mesh.positions[v as usize];
    let (pa, pb, pc) = (p(a), p(b), p(c));
    let normal = (pb - pa).cross(pc - pa).normalize_or_zero();
    let mean_edge = (pa.distance(pb) + pb.distance(pc) + pc.distance(pa)) / 3.0;
    let apex = (pa + pb + pc) / 3.0 - normal * (0.1 * mean_edge);
    let d = mesh.positions.len() as u32;
    mesh.positions.push(apex);
    if !mesh.normals.is_empty() {
        mesh.normals.push(normal);
    }
    mesh.triangles
        .extend([[a, b, c], [b, a, d], [c, b, d], [a, c, d]]);
}

/// One triangle's use of an undirected edge: the edge (smaller vertex first), the triangle,
/// and whether the triangle runs from the smaller vertex to the larger.
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
struct EdgeUse {
    edge: (u32, u32),
    triangle: u32,
    forward: bool,
}

/// Whether each of `triangles` has an edge used by one triangle or by more than two: a
/// border, or where sheets touch. Cost: O(F log F) (the edge sort).
pub fn on_open_edges(triangles: &[[u32; 3]]) -> Vec<bool> {
    let mut open = vec![false; triangles.len()];
    for run in edge_runs(&sorted_edges(triangles)) {
        if run.len() != 2 {
            run.iter().for_each(|u| open[u.triangle as usize] = true);
        }
    }
    open
}

/// Whether each of `triangles` has an edge used by an odd number of triangles: where the
/// surface does not bound a volume (a border, or three sheets along an edge). Closed parts that
/// touch along edges (four uses) bound one. Cost: O(F log F) (the edge sort).
pub fn on_odd_edges(triangles: &[[u32; 3]]) -> Vec<bool> {
    let mut odd = vec![false; triangles.len()];
    for run in edge_runs(&sorted_edges(triangles)) {
        if run.len() % 2 == 1 {
            run.iter().for_each(|u| odd[u.triangle as usize] = true);
        }
    }
    odd
}

/// Every edge use, sorted by edge.
fn sorted_edges(triangles: &[[u32; 3]]) -> Vec<EdgeUse> {
    let mut uses: Vec<EdgeUse> = Vec::with_capacity(3 * triangles.len());
    for (t, tri) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            if a != b {
                uses.push(EdgeUse {
                    edge: (a.min(b), a.max(b)),
                    triangle: t as u32,
                    forward: a < b,
                });
            }
        }
    }
    // Every use differs from every other (a triangle uses an edge at most once each way), so
    // the order is the same on any number of threads.
    uses.par_sort_unstable();
    uses
}

/// The runs of `uses` that share an edge.
fn edge_runs(uses: &[EdgeUse]) -> impl Iterator<Item = &[EdgeUse]> {
    uses.chunk_by(|a, b| a.edge == b.edge)
}

/// Which triangles to flip (module docs, step 1).
fn orientation(uses: &[EdgeUse], triangles: usize) -> Vec<bool> {
    let neighbours = neighbours(uses, triangles);
    let mut flip = vec![false; triangles];
    let mut seen = vec![false; triangles];
    let mut stack = Vec::new();
    let mut piece = Vec::new();
    for start in 0..triangles {
        if seen[start] {
            continue;
        }
        piece.clear();
        seen[start] = true;
        stack.push(start as u32);
        while let Some(t) = stack.pop() {
            piece.push(t);
            for &(n, agree) in neighbours.row(t as usize) {
                if !seen[n as usize] {
                    seen[n as usize] = true;
                    flip[n as usize] = flip[t as usize] ^ !agree;
                    stack.push(n);
                }
            }
        }
        // Keep the orientation most of the piece had.
        let flipped = piece.iter().filter(|&&t| flip[t as usize]).count();
        if 2 * flipped > piece.len() {
            for &t in &piece {
                flip[t as usize] = !flip[t as usize];
            }
        }
    }
    flip
}

/// Each triangle's neighbours across its two-triangle edges, in the order of the edges' runs,
/// with whether the pair agrees as it stands.
fn neighbours(uses: &[EdgeUse], triangles: usize) -> Rows<(u32, bool)> {
    let across = || {
        (edge_runs(uses))
            .filter_map(|run| match run {
                [a, b] => {
                    let agree = a.forward != b.forward;
                    Some([
                        (a.triangle, (b.triangle, agree)),
                        (b.triangle, (a.triangle, agree)),
                    ])
                }
                _ => None,
            })
            .flatten()
    };
    Rows::new(triangles, across)
}

/// The pairs of an edge's triangles that join across it (module docs, step 2).
fn joined_pairs(run: &[EdgeUse], mesh: &TriangleMesh) -> Vec<(EdgeUse, EdgeUse)> {
    match run {
        [a, b] if a.forward != b.forward => return vec![(*a, *b)],
        [_] | [_, _] => return Vec::new(),
        _ => {}
    }
    let p = |v: u32| mesh.positions[v as usize].as_dvec3();
    let (v0, v1) = run[0].edge;
    let e = (p(v1) - p(v0)).normalize_or_zero();
    if e == crate::glam::DVec3::ZERO {
        return Vec::new();
    }
    let x = e.any_orthonormal_vector();
    let y = e.cross(x);
    let angle = |u: &EdgeUse| {
        let third = mesh.triangles[u.triangle as usize]
            .into_iter()
            .find(|&v| v != v0 && v != v1)
            .unwrap_or(v0);
        let d = p(third) - p(v0);
        d.dot(y).atan2(d.dot(x))
    };
    let mut around: Vec<(f64, EdgeUse)> = run.iter().map(|u| (angle(u), *u)).collect();
    around.sort_by(|a, b| a.0.total_cmp(&b.0));
    let k = around.len();
    let mut taken = vec![false; k];
    let mut pairs = Vec::new();
    // Backward then forward counter-clockwise: the two bound a wedge of solid. Then, for what
    // is left (sheets folded onto themselves), any neighbours wound opposite ways.
    for first_backward in [true, false] {
        for i in 0..k {
            let j = (i + 1..i + k)
                .map(|j| j % k)
                .find(|&j| !taken[j])
                .unwrap_or(i);
            let (a, b) = (around[i].1, around[j].1);
            if i != j && !taken[i] && a.forward != first_backward && b.forward == first_backward {
                taken[i] = true;
                taken[j] = true;
                pairs.push((a, b));
            }
        }
    }
    pairs
}

/// Step 3 of the module docs; returns the copies added.
fn detach_still_shared(mesh: &mut TriangleMesh) -> usize {
    let uses = sorted_edges(&mesh.triangles);
    let mut added = 0;
    for run in edge_runs(&uses).filter(|r| r.len() > 2) {
        let pair = joined_pairs(run, mesh).first().copied();
        let (v0, v1) = run[0].edge;
        for u in run {
            if pair.is_some_and(|(a, b)| a.triangle == u.triangle || b.triangle == u.triangle) {
                continue;
            }
            for corner in mesh.triangles[u.triangle as usize].iter_mut() {
                if *corner == v0 || *corner == v1 {
                    mesh.positions.push(mesh.positions[*corner as usize]);
                    if !mesh.normals.is_empty() {
                        mesh.normals.push(mesh.normals[*corner as usize]);
                    }
                    *corner = (mesh.positions.len() - 1) as u32;
                    added += 1;
                }
            }
        }
    }
    added
}

/// Splits vertices by the groups of corners that joining edges connect (module docs, step 2);
/// returns the copies added.
fn split_corners(mesh: &mut TriangleMesh, uses: &[EdgeUse]) -> usize {
    let corner = |t: u32, v: u32, tris: &[[u32; 3]]| -> u32 {
        let k = tris[t as usize].iter().position(|&x| x == v).unwrap_or(0);
        3 * t + k as u32
    };
    let tris = &mesh.triangles;
    let mut groups = UnionFind::new(3 * tris.len());
    for run in edge_runs(uses) {
        for (a, b) in joined_pairs(run, mesh) {
            let (v0, v1) = a.edge;
            groups.union(corner(a.triangle, v0, tris), corner(b.triangle, v0, tris));
            groups.union(corner(a.triangle, v1, tris), corner(b.triangle, v1, tris));
        }
    }
    // The first group to reach a vertex keeps it; later groups get copies.
    let mut owner: Vec<u32> = vec![u32::MAX; mesh.positions.len()];
    let mut copy_of_group: std::collections::HashMap<u32, u32> = Default::default();
    let mut added = 0;
    for c in 0..3 * tris.len() as u32 {
        let v = mesh.triangles[(c / 3) as usize][(c % 3) as usize];
        let root = groups.find(c);
        let target = if owner[v as usize] == u32::MAX || owner[v as usize] == root {
            owner[v as usize] = root;
            v
        } else {
            *copy_of_group.entry(root).or_insert_with(|| {
                added += 1;
                mesh.positions.push(mesh.positions[v as usize]);
                if !mesh.normals.is_empty() {
                    mesh.normals.push(mesh.normals[v as usize]);
                }
                (mesh.positions.len() - 1) as u32
            })
        };
        mesh.triangles[(c / 3) as usize][(c % 3) as usize] = target;
    }
    added
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::glam::Vec3;
    use crate::mesh_topology;
    use crate::test_shapes::octahedron;

    #[test]
    fn an_oriented_manifold_comes_back_unchanged() {
        let mut mesh = octahedron();
        let before = mesh.clone();
        assert_eq!(make_manifold(&mut mesh), ManifoldReport::default());
        assert_eq!(mesh, before);
    }

    #[test]
    fn a_minority_of_flipped_triangles_is_turned_back() {
        let mut mesh = octahedron();
        mesh.triangles[2].swap(0, 1);
        mesh.triangles[6].swap(1, 2);
        // Each flip turns its three edges; the two share the edge 2-3, which agrees again.
        assert_eq!(mesh_topology(&mesh).inconsistent_edges, 4);
        let report = make_manifold(&mut mesh);
        assert_eq!(report.flipped_triangles, 2);
        assert_eq!(report.split_vertices, 0);
        let t = mesh_topology(&mesh);
        assert!(t.is_closed_manifold() && t.is_consistently_oriented());
        assert!(mesh.signed_volume() > 0.0);
    }

    #[test]
    fn two_octahedra_touching_at_a_vertex_get_one_copy_of_it() {
        let mut mesh = octahedron();
        let other = octahedron();
        let n = mesh.positions.len() as u32;
        // The second octahedron shifted by 2 along x shares the first's +x vertex (index 0)
        // with its own -x vertex (index 2).
        mesh.positions
            .extend(other.positions.iter().map(|p| *p + Vec3::X * 2.0));
        let remap = |v: u32| if v == 2 { 0 } else { v + n };
        mesh.triangles
            .extend(other.triangles.iter().map(|t| t.map(remap)));
        mesh.remove_unreferenced_vertices();
        assert_eq!(mesh_topology(&mesh).non_manifold_vertices, 1);
        let report = make_manifold(&mut mesh);
        assert_eq!(
            report,
            ManifoldReport {
                dropped_triangles: 0,
                inflated_parts: 0,
                flipped_triangles: 0,
                split_vertices: 1
            }
        );
        let t = mesh_topology(&mesh);
        assert!(t.is_closed_manifold() && t.is_consistently_oriented());
        assert_eq!(t.components, 2);
    }

    #[test]
    fn two_closed_wedges_touching_along_an_edge_come_apart_closed() {
        // Two tetrahedra sharing the edge 0-1 (on the z axis), on opposite sides of it.
        let positions = vec![
            Vec3::ZERO,
            Vec3::Z,
            Vec3::new(1.0, 0.2, 0.5),
            Vec3::new(1.0, -0.2, 0.5),
            Vec3::new(-1.0, 0.2, 0.5),
            Vec3::new(-1.0, -0.2, 0.5),
        ];
        let tetra = |a: u32, b: u32, c: u32, d: u32| {
            // Outward for a positively oriented (a, b, c, d).
            vec![[a, c, b], [a, b, d], [a, d, c], [b, c, d]]
        };
        let mut triangles = tetra(0, 1, 2, 3);
        triangles.extend(tetra(0, 1, 5, 4));
        let mut mesh = TriangleMesh::new(positions, triangles);
        if mesh.signed_volume() < 0.0 {
            mesh.flip_orientation();
        }
        let before = mesh_topology(&mesh);
        assert_eq!(before.non_manifold_edges, 1);
        let report = make_manifold(&mut mesh);
        let t = mesh_topology(&mesh);
        assert!(
            t.is_closed_manifold() && t.is_consistently_oriented(),
            "{t:?}"
        );
        assert_eq!((t.components, t.genus), (2, Some(0)));
        assert_eq!(report.split_vertices, 2);
    }

    #[test]
    fn a_flattened_pocket_is_dropped_and_copies_keep_one() {
        let mut mesh = octahedron();
        // A pocket: one face again, wound the other way, and a copy of another face.
        let pocket = [
            mesh.triangles[0][0],
            mesh.triangles[0][2],
            mesh.triangles[0][1],
        ];
        let copy = [
            mesh.triangles[3][1],
            mesh.triangles[3][2],
            mesh.triangles[3][0],
        ];
        mesh.triangles.push(pocket);
        mesh.triangles.push(copy);
        let report = make_manifold(&mut mesh);
        assert_eq!(report.dropped_triangles, 3);
        assert_eq!(mesh.triangles.len(), 7);
        let t = mesh_topology(&mesh);
        assert!(t.is_manifold() && t.is_consistently_oriented());
        assert_eq!(t.boundary_loops, 1); // the face lost with its pocket
    }

    #[test]
    fn a_part_flattened_to_two_faces_becomes_a_tetrahedron() {
        let mut mesh = octahedron();
        let n = mesh.positions.len() as u32;
        mesh.positions.extend([
            Vec3::new(5.0, 0.0, 0.0),
            Vec3::new(6.0, 0.0, 0.0),
            Vec3::new(5.0, 1.0, 0.0),
        ]);
        mesh.triangles.push([n, n + 1, n + 2]);
        mesh.triangles.push([n, n + 2, n + 1]);
        let report = make_manifold(&mut mesh);
        assert_eq!((report.dropped_triangles, report.inflated_parts), (0, 1));
        assert_eq!(mesh.triangles.len(), 12);
        let t = mesh_topology(&mesh);
        assert!(
            t.is_closed_manifold() && t.is_consistently_oriented(),
            "{t:?}"
        );
        assert_eq!(
            (t.components, t.genus, t.duplicate_triangles),
            (2, Some(0), 0)
        );
        // Both pieces wound outwards: the octahedron's 4/3 plus the small tetrahedron's.
        let tetra = 0.5 / 3.0 * 0.1 * (2.0 + 2f64.sqrt()) / 3.0;
        assert!(
            (mesh.signed_volume() - (4.0 / 3.0 + tetra)).abs() < 1e-5,
            "{}",
            mesh.signed_volume()
        );
    }

    #[test]
    fn a_mobius_strip_is_cut_open() {
        // A strip of 8 quads whose ends meet with a half twist.
        let n = 8;
        let mut positions = Vec::new();
        for i in 0..n {
            let a = i as f32 / n as f32 * std::f32::consts::TAU;
            let (c, s) = (a.cos(), a.sin());
            let tw = a / 2.0;
            for side in [-1.0f32, 1.0] {
                let r = 2.0 + 0.5 * side * tw.cos();
                positions.push(Vec3::new(r * c, r * s, 0.5 * side * tw.sin()));
            }
        }
        let mut triangles = Vec::new();
        for i in 0..n as u32 {
            let (a, b) = (2 * i, 2 * i + 1);
            let (c, d) = if i + 1 == n as u32 {
                (1, 0)
            } else {
                (2 * i + 2, 2 * i + 3)
            };
            triangles.push([a, c, b]);
            triangles.push([b, c, d]);
        }
        let mut mesh = TriangleMesh::new(positions, triangles);
        assert_eq!(mesh_topology(&mesh).genus, None);
        let report = make_manifold(&mut mesh);
        let t = mesh_topology(&mesh);
        assert!(t.is_manifold() && t.is_consistently_oriented(), "{t:?}");
        assert_eq!(report.split_vertices, 2);
        assert_eq!(t.boundary_loops, 1);
    }

    #[test]
    fn on_odd_edges_marks_borders_and_three_sheets_not_closed_surfaces_touching() {
        // Two triangles sharing an edge: every other edge is a border.
        assert_eq!(on_odd_edges(&[[0, 1, 2], [2, 1, 3]]), [true, true]);
        // A closed octahedron, and two of them sharing an edge (four uses): no odd edge.
        let one = octahedron();
        assert!(on_odd_edges(&one.triangles).iter().all(|&o| !o));
        let mut two = one.triangles.clone();
        let n = one.positions.len() as u32;
        let [a, b, _] = one.triangles[0];
        let shift = |v: u32| if v == a || v == b { v } else { v + n };
        two.extend(one.triangles.iter().map(|t| t.map(shift)));
        assert!(on_odd_edges(&two).iter().all(|&o| !o));
        // Three triangles on one edge: odd, all three marked.
        let fan = on_odd_edges(&[[0, 1, 2], [1, 0, 3], [0, 1, 4]]);
        assert_eq!(fan, [true, true, true]);
    }
}
