//! Coincident copies of a vertex moved apart ([`separate_coincident`]), so that a reader that
//! welds vertices by position (an STL reader, trimesh, glTF tools,
//! [`voxlod_core::weld::weld_vertices`]) sees the same oriented manifold as the indices do.
//!
//! [`voxlod_core::manifold::make_manifold`] cuts a pinch (two sheets touching at a vertex or
//! along an edge) by splitting vertices into copies at the same coordinates. Here the
//! referenced vertices are grouped by their exact coordinates (`+0.0` and `-0.0` alike, as the
//! weld keys them), and each group's copies are sorted into **classes**: copies that welding
//! would join into one manifold fan stay together. Copies are joined by a **seam**: two edges
//! of one triangle each on the same two positions, wound against each other, with no other
//! edge on those positions (as in a soup, or a mesh split along texture seams); the copies at
//! both ends join. Where the classes, moved as units, would still put more than two triangles
//! or two wound alike on one edge of the welded mesh (a seam on the positions of a cut edge's
//! ends, joined through other seams), the seams at that edge's classes are given up and the
//! classes joined again. A group of one class is left alone; in a group of several, each class
//! moves, all its copies by the same step, into its own fan:
//!
//! - **direction**: towards the mean of its fan's triangle centroids; where that mean is (to a
//!   thousandth of the fan's size) the vertex itself (a flat fan), along the fan's inward
//!   normal (minus the sum of its triangles' area vectors); a fan with neither (no triangle of
//!   non-zero area) stays, and its copies are counted as still coincident;
//! - **distance**: [`STEP`] of `h`, the shortest distance from the vertex to the line of an
//!   opposite edge in its fan (the smallest height of its fan's triangles over their opposite
//!   edges), raised to a few units in the last place of its coordinates where that step would
//!   vanish in `f32`, but never beyond [`MOST`] of `h`.
//!
//! **Orientation kept.** Moving corner `p` of triangle `(p, a, b)` by `d` changes its area
//! vector `n = (a − p) × (b − p)` by exactly `(b − a) × d`, of length at most
//! `|b − a| |d| = |n| |d| / h`; so a step of at most `h / 32` turns the triangle's normal by
//! at most asin(1/32) < 0.032 rad. A move is kept only where, after rounding to `f32`, it is
//! at most `h / 32` (with `h` from the positions at the time) and the position changed; each
//! vertex moves once, so a triangle turns by less than 0.094 rad in all (normals before and
//! after agree to a dot product above 0.995) and no triangle flips (a triangle of zero area,
//! which has no orientation to keep, does not count towards `h`).
//!
//! **Apart after welding.** The classes of a group move in different directions (into
//! different fans), so they end at different `f32` positions; a vertex pinched by sheets that
//! a plane through it separates (two solids touching) moves to its own side of that plane. What
//! still shares a position afterwards is counted ([`Separation::still_coincident`]).
//!
//! A mesh without coincident referenced vertices is not changed. Cost: O(V log V) for a mesh
//! without them (one sort of the referenced vertices' coordinates; 7 ms for 164k vertices);
//! with them, O(F) expected for each round of joining classes (one unless seams are given up)
//! and the coincident vertices' fans.

use std::collections::{HashMap, HashSet};

use voxlod_core::glam::{DVec3, Vec3};
use voxlod_core::TriangleMesh;

/// The step into a fan, as a fraction of the fan's smallest height over an opposite edge.
pub const STEP: f64 = 1e-3;

/// The longest step a vertex may take where `f32` resolution forces more than [`STEP`], as a
/// fraction of that height (a kept move, rounded, is within twice this).
pub const MOST: f64 = 1.0 / 64.0;

/// What [`separate_coincident`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Separation {
    /// Vertices moved off a position they shared with a vertex of another fan.
    pub moved: usize,
    /// Referenced vertices that still share their position with a vertex of another class
    /// (a fan without area, or a step `f32` cannot hold): a weld still joins them.
    pub still_coincident: usize,
}

/// Moves every referenced vertex that shares its exact position with one of another fan a
/// tiny step into its own fan (module docs), so that welding by position gives the mesh's own
/// topology. Triangles, indices and normals are not changed, and no triangle's normal turns by
/// more than 0.094 rad. Cost in the module docs.
///
/// ```
/// use voxlod_budget::separate::separate_coincident;
/// use voxlod_core::{glam::Vec3, mesh_topology, weld::weld_vertices, TriangleMesh};
///
/// // Two triangles touching at one point, each with its own copy of it.
/// let p = Vec3::ZERO;
/// let mut bowtie = TriangleMesh::new(
///     vec![p, Vec3::X, Vec3::Y, p, -Vec3::X, -Vec3::Y],
///     vec![[0, 1, 2], [3, 4, 5]],
/// );
/// let done = separate_coincident(&mut bowtie);
/// assert_eq!((done.moved, done.still_coincident), (2, 0));
/// weld_vertices(&mut bowtie);
/// assert_eq!(mesh_topology(&bowtie).non_manifold_vertices, 0);
/// ```
pub fn separate_coincident(mesh: &mut TriangleMesh) -> Separation {
    let groups = coincident_groups(mesh);
    if groups.is_empty() {
        return Separation::default();
    }
    let layout = Layout::new(mesh, groups);
    let class = seam_classes(mesh, &layout);
    let mut moved = 0;
    for g in 0..layout.groups.len() - 1 {
        let members = layout.group(g);
        let mut labels: Vec<u32> = members.iter().map(|&m| class[m as usize]).collect();
        labels.sort_unstable();
        labels.dedup();
        if labels.len() < 2 {
            continue;
        }
        for label in labels {
            let copies: Vec<u32> = members
                .iter()
                .filter(|&&m| class[m as usize] == label)
                .copied()
                .collect();
            moved += move_class(mesh, &layout, &copies);
        }
    }
    Separation {
        moved,
        still_coincident: still_coincident(mesh, &layout, &class),
    }
}

/// A position's key for grouping: its coordinates' bits, `-0.0` as `+0.0`.
type Key = [u32; 3];

/// The [`Key`] of `p`.
fn key(p: Vec3) -> Key {
    p.to_array().map(|x| if x == 0.0 { 0 } else { x.to_bits() })
}

/// The referenced vertices that share their position with another, one group per position,
/// each group ascending and the groups in the order of their first vertex. O(V log V) (one
/// sort of the coordinates' keys).
fn coincident_groups(mesh: &TriangleMesh) -> Vec<Vec<u32>> {
    let mut used = vec![false; mesh.positions.len()];
    for t in &mesh.triangles {
        for &v in t {
            used[v as usize] = true;
        }
    }
    let mut at: Vec<(Key, u32)> = (0..mesh.positions.len())
        .filter(|&v| used[v])
        .map(|v| (key(mesh.positions[v]), v as u32))
        .collect();
    at.sort_unstable();
    let mut groups: Vec<Vec<u32>> = at
        .chunk_by(|x, y| x.0 == y.0)
        .filter(|run| run.len() > 1)
        .map(|run| run.iter().map(|&(_, v)| v).collect())
        .collect();
    groups.sort_unstable_by_key(|g| g[0]);
    groups
}

/// The coincident vertices ("members") numbered group by group, with their triangles.
struct Layout {
    /// The members' vertices, group after group.
    vertices: Vec<u32>,
    /// Where each group starts in `vertices`, and the end (one more than the groups).
    groups: Vec<usize>,
    /// Each vertex's member number, `u32::MAX` for the others.
    member: Vec<u32>,
    /// Each member's group.
    group_of: Vec<u32>,
    /// Each member's triangles.
    fan: Vec<Vec<u32>>,
}

impl Layout {
    /// The layout of `groups` in `mesh`: O(V + F).
    fn new(mesh: &TriangleMesh, groups: Vec<Vec<u32>>) -> Layout {
        let mut member = vec![u32::MAX; mesh.positions.len()];
        let (mut vertices, mut starts, mut group_of) = (Vec::new(), vec![0], Vec::new());
        for (g, group) in groups.iter().enumerate() {
            for &v in group {
                member[v as usize] = vertices.len() as u32;
                vertices.push(v);
                group_of.push(g as u32);
            }
            starts.push(vertices.len());
        }
        let mut fan = vec![Vec::new(); vertices.len()];
        for (t, tri) in mesh.triangles.iter().enumerate() {
            for &v in tri {
                if let Some(f) = fan.get_mut(member[v as usize] as usize) {
                    f.push(t as u32);
                }
            }
        }
        Layout {
            vertices,
            groups: starts,
            member,
            group_of,
            fan,
        }
    }

    /// Group `g`'s member numbers.
    fn group(&self, g: usize) -> Vec<u32> {
        (self.groups[g] as u32..self.groups[g + 1] as u32).collect()
    }

    /// Vertex `v`'s class label in `class` as a weld after the moves sees it: its member's
    /// label, or above every label for a vertex outside the groups (a class of its own).
    fn label(&self, class: &[u32], v: u32) -> u64 {
        match self.member[v as usize] {
            u32::MAX => (1u64 << 32) | v as u64,
            m => class[m as usize] as u64,
        }
    }

    /// Whether vertex `v` shares its position with another.
    fn is_member(&self, v: u32) -> bool {
        self.member[v as usize] != u32::MAX
    }
}

/// Each member's class label (the smallest member number of its class): members joined by a
/// seam a weld closes (module docs) share one. Where moving the classes as units would put more
/// than two triangles on one edge of the welded mesh, or two wound the same way (a seam on the
/// positions of another edge, or joined through other edges), the seams at that edge's classes
/// are given up and the classes joined again. O(F) expected a round; each round but the last
/// gives up a seam.
fn seam_classes(mesh: &TriangleMesh, layout: &Layout) -> Vec<u32> {
    let mut seams = clean_seams(mesh, layout);
    loop {
        let mut class: Vec<u32> = (0..layout.vertices.len() as u32).collect();
        for &[a, b, c, d] in &seams {
            join(&mut class, layout, a, d);
            join(&mut class, layout, b, c);
        }
        let crowded = crowded(mesh, layout, &class);
        let label = |v: u32| layout.label(&class, v);
        let before = seams.len();
        seams.retain(|&[a, b, _, _]| !crowded.contains(&label(a)) && !crowded.contains(&label(b)));
        if seams.len() == before {
            return class;
        }
    }
}

/// The seams a weld closes: pairs of edges `a → b`, `c → d` between members, `a` at `d`'s
/// position and `b` at `c`'s, alone on these positions (each of one triangle). O(F) expected.
fn clean_seams(mesh: &TriangleMesh, layout: &Layout) -> Vec<[u32; 4]> {
    let at = |v: u32| key(mesh.positions[v as usize]);
    let mut uses: HashMap<(Key, Key), Vec<[u32; 2]>> = HashMap::new();
    for tri in &mesh.triangles {
        for i in 0..3 {
            let (a, b) = (tri[i], tri[(i + 1) % 3]);
            if layout.is_member(a) && layout.is_member(b) && at(a) != at(b) {
                let (p, q) = (at(a), at(b));
                uses.entry((p.min(q), p.max(q))).or_default().push([a, b]);
            }
        }
    }
    let mut seams: Vec<[u32; 4]> = uses
        .into_values()
        .filter_map(|edges| match edges.as_slice() {
            &[[a, b], [c, d]] if at(a) == at(d) && (c, d) != (b, a) => Some([a, b, c, d]),
            _ => None,
        })
        .collect();
    seams.sort_unstable();
    seams
}

/// The class labels at an edge of the welded mesh (classes moved as units, every other vertex
/// on its own) with more than two triangles or two wound the same way. O(F) expected.
fn crowded(mesh: &TriangleMesh, layout: &Layout, class: &[u32]) -> HashSet<u64> {
    let label = |v: u32| layout.label(class, v);
    let mut uses: HashMap<(u64, u64), Vec<(u64, u64)>> = HashMap::new();
    for tri in &mesh.triangles {
        for i in 0..3 {
            let (a, b) = (tri[i], tri[(i + 1) % 3]);
            if layout.is_member(a) || layout.is_member(b) {
                let (x, y) = (label(a), label(b));
                uses.entry((x.min(y), x.max(y))).or_default().push((x, y));
            }
        }
    }
    uses.values()
        .filter(|u| u.len() > 2 || (u.len() == 2 && u[0] == u[1]))
        .flat_map(|u| [u[0].0, u[0].1])
        .collect()
}

/// Puts the classes of vertices `u` and `w` (members of one group) together under the
/// smaller label. O(group size).
fn join(class: &mut [u32], layout: &Layout, u: u32, w: u32) {
    let (mu, mw) = (layout.member[u as usize], layout.member[w as usize]);
    let (old, new) = {
        let (x, y) = (class[mu as usize], class[mw as usize]);
        (x.max(y), x.min(y))
    };
    for m in layout.group(layout.group_of[mu as usize] as usize) {
        if class[m as usize] == old {
            class[m as usize] = new;
        }
    }
}

/// Moves the members `copies` (one class, all at one position) by one step into their joint
/// fan (module docs); returns how many moved (all or none).
fn move_class(mesh: &mut TriangleMesh, layout: &Layout, copies: &[u32]) -> usize {
    let vertices: Vec<u32> = copies
        .iter()
        .map(|&m| layout.vertices[m as usize])
        .collect();
    let p = mesh.positions[vertices[0] as usize];
    let fan: Vec<u32> = copies
        .iter()
        .flat_map(|&m| layout.fan[m as usize].iter().copied())
        .collect();
    let Some((direction, height)) = step_of(mesh, p, &fan) else {
        return 0;
    };
    let at = p.as_dvec3();
    let floor = 8.0 * f32::EPSILON as f64 * p.abs().max_element() as f64;
    let length = (STEP * height).max(floor).min(MOST * height);
    let to = (at + direction * length).as_vec3();
    if key(to) == key(p) || (to.as_dvec3() - at).length() > 2.0 * MOST * height {
        return 0;
    }
    for &v in &vertices {
        mesh.positions[v as usize] = to;
    }
    vertices.len()
}

/// The unit direction into the fan `fan` of the vertices at `p`, and the fan's smallest height
/// over an opposite edge (module docs); `None` for a fan without area. O(fan).
fn step_of(mesh: &TriangleMesh, p: Vec3, fan: &[u32]) -> Option<(DVec3, f64)> {
    let at = p.as_dvec3();
    let here = key(p);
    let (mut centre, mut normal, mut size) = (DVec3::ZERO, DVec3::ZERO, 0.0);
    let (mut height, mut count) = (f64::INFINITY, 0);
    for &t in fan {
        let tri = mesh.triangles[t as usize];
        let corners = tri.map(|v| mesh.positions[v as usize]);
        let mut at_p = (0..3).filter(|&i| key(corners[i]) == here);
        let (Some(i), None) = (at_p.next(), at_p.next()) else {
            continue;
        };
        let a = corners[(i + 1) % 3].as_dvec3() - at;
        let b = corners[(i + 2) % 3].as_dvec3() - at;
        let n = a.cross(b);
        let base = (b - a).length();
        if n.length() == 0.0 || base == 0.0 {
            continue;
        }
        height = height.min(n.length() / base);
        centre += (a + b) / 3.0;
        size += ((a + b) / 3.0).length();
        normal += n;
        count += 1;
    }
    if count == 0 {
        return None;
    }
    let (centre, size) = (centre / count as f64, size / count as f64);
    let direction = if centre.length() > 1e-3 * size {
        centre.normalize()
    } else if normal.length() > 0.0 {
        -normal.normalize()
    } else {
        return None;
    };
    Some((direction, height))
}

/// Referenced vertices that share their position with one of another class after the moves
/// (a vertex outside the groups is a class of its own). O(V log V).
fn still_coincident(mesh: &TriangleMesh, layout: &Layout, class: &[u32]) -> usize {
    let label = |v: u32| layout.label(class, v);
    coincident_groups(mesh)
        .into_iter()
        .filter(|g| g.iter().any(|&v| label(v) != label(g[0])))
        .map(|g| g.len())
        .sum()
}

#[cfg(test)]
mod tests {
    use voxlod_core::glam::Vec3;
    use voxlod_core::weld::weld_vertices;
    use voxlod_testkit::shapes::{append, unit_cube};

    use crate::candidate::{Candidate, Method};

    /// A candidate of two cubes touching at (1, 1, 1): one vertex cut into two copies, both
    /// moved, and welding its mesh by position finds nothing to join.
    #[test]
    fn a_candidate_of_two_touching_cubes_welds_into_two_cubes() {
        let mut pair = unit_cube();
        let mut other = unit_cube();
        other.positions.iter_mut().for_each(|p| *p += Vec3::ONE);
        append(&mut pair, &other);
        weld_vertices(&mut pair);
        let c = Candidate::new(Method::Collapse, pair);
        assert_eq!((c.cut_vertices, c.separated_vertices), (1, 2));
        assert!(c.topology.is_closed_manifold() && c.topology.components == 2);
        let mut welded = c.mesh.clone();
        assert_eq!(weld_vertices(&mut welded).vertices_after, 16);
    }
}
