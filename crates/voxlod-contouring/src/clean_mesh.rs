//! Cleaning a marching-cubes level: no needle, sliver or zero-area triangles, and none of the
//! self-intersections they cause, while the mesh stays closed, manifold and oriented.
//!
//! Beyond the paper (He et al. 1995, §2, contour with plain marching cubes). Where the surface
//! passes close to a grid sample, marching cubes puts several vertices within a tiny fraction of
//! a cell of that sample, on the edges that meet there, and joins them with triangles of area
//! 1e-12 to 1e-6 whose normals are noise; rounded to `f32`, neighbouring slivers can cross.
//! The classic fix snaps such vertices onto the sample; we get the same effect on the mesh:
//!
//! 1. *Collapse short edges*, shortest first: an edge shorter than
//!    [`CleanOptions::min_edge`] cells merges its two vertices at its midpoint, if the **link
//!    condition** holds (the two vertices' common neighbours are exactly the two vertices
//!    opposite the edge, so the mesh stays a closed 2-manifold; Dey, Edelsbrunner et al. 1999),
//!    the component is more than a tetrahedron, and no surviving triangle around it turns over
//!    (its normal keeps a positive component along the neighbourhood's area-weighted normal);
//!    where the midpoint would turn one over, either end is tried. Each vertex moves at most
//!    once per pass, by at most the threshold.
//! 2. *Flip caps*: a triangle still below [`CleanOptions::min_area`] cells² (one corner close to
//!    the opposite edge, no short edge to collapse) has that longest edge flipped when the new
//!    edge is not already in the mesh, neither new triangle turns over, and the smaller quality
//!    of the pair improves; where no flip is allowed, its shortest edge that may be collapsed
//!    as in 1 is, whatever its length; and where none may (a near-pinch, where the link
//!    condition fails), one of its corners moves to the centroid of its neighbours if that
//!    turns nothing over and the triangle grows.
//!
//! Every step is also refused when a triangle it makes would meet a triangle nearby (two sheets
//! of a thin part can lie closer than a step moves a vertex), by the guard in `local_crossings.rs`.
//!
//! Passes repeat until nothing changes (at most [`CleanOptions::max_passes`]). These tests are
//! local, and a component so small that every edge is short has no inside for them to protect:
//! the octahedron marching cubes makes around one sample barely above the isodensity (as at a
//! coarse level of thingi10k-138207) collapses to a tetrahedron, and relaxing one corner of that
//! to the centroid of the others flattens it to zero volume, outward or inward by rounding.
//! So, last, every component whose enclosed volume fell below a quarter of the raw one, or
//! changed sign, gets its raw triangles back (it stays as marching cubes made it). Then dead
//! triangles and vertices are dropped. Orientation is kept by construction: collapses rename a
//! vertex inside oriented triangles, flips replace two oriented triangles by two oriented ones.
//! Normals: a merged vertex takes the normalised mean of the two.
//!
//! Cost: O(F log F) per pass for sorting the candidate edges, O(1) per collapse or flip on a
//! marching-cubes mesh (valences are small).

use glam::{DVec3, Vec3};
use serde::Serialize;
use thiserror::Error;
use voxlod_core::{memory, CoreError, TriangleMesh};

use crate::local_crossings::{triangles_meet, Buckets};

/// A component whose enclosed volume cleaning shrank below this fraction of the raw one (or
/// turned over) is given back its raw triangles (see `restore_flattened`).
const MIN_VOLUME_KEPT: f64 = 0.25;

/// How [`clean_mesh`] cleans.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct CleanOptions {
    /// Edges shorter than this many cells are collapsed.
    pub min_edge: f64,
    /// Triangles smaller than this many square cells are fixed.
    pub min_area: f64,
    /// Passes of both steps at most.
    pub max_passes: usize,
}

impl Default for CleanOptions {
    /// Collapse edges under a tenth of a cell, fix triangles under a thousandth of a cell².
    fn default() -> Self {
        CleanOptions {
            min_edge: 0.1,
            min_area: 1e-3,
            max_passes: 6,
        }
    }
}

impl CleanOptions {
    /// Only the degenerate: edges under a thousandth of a cell, areas under 1e-6 cells².
    pub fn degenerate_only() -> Self {
        CleanOptions {
            min_edge: 1e-3,
            min_area: 1e-6,
            ..Default::default()
        }
    }
}

/// What [`clean_mesh`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct CleanReport {
    /// Edges collapsed (short ones, and those of small triangles).
    pub collapsed_edges: usize,
    /// Longest edges of small triangles flipped.
    pub flipped_edges: usize,
    /// Corners of small triangles moved to the centroid of their neighbours.
    pub relaxed_vertices: usize,
    /// Triangles fewer than the input.
    pub removed_triangles: usize,
    /// Vertices fewer than the input.
    pub removed_vertices: usize,
    /// Triangles still below `min_area` (where neither fix was allowed).
    pub small_triangles_left: usize,
    /// Components given back their raw triangles because cleaning flattened them.
    pub restored_components: usize,
    /// Passes run.
    pub passes: usize,
}

/// Why a mesh could not be cleaned.
#[derive(Debug, Error)]
pub enum CleanError {
    #[error("the cell size {0} is not a positive number")]
    /// The cell size is not finite and positive.
    BadCell(f64),
    #[error(transparent)]
    /// The mesh is invalid, or too big for memory.
    Mesh(#[from] CoreError),
}

/// The mesh being cleaned: triangles with a live flag, and each vertex's triangles (lazily
/// pruned of dead ones).
struct Work {
    positions: Vec<DVec3>,
    normals: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    alive: Vec<bool>,
    around: Vec<Vec<u32>>,
    /// Moved or merged in this pass.
    touched: Vec<bool>,
    buckets: Buckets,
}

impl Work {
    fn new(mesh: &TriangleMesh, cell: f64) -> Work {
        let mut around = vec![Vec::new(); mesh.positions.len()];
        for (t, tri) in mesh.triangles.iter().enumerate() {
            for &v in tri {
                around[v as usize].push(t as u32);
            }
        }
        let corners = (0..mesh.triangles.len()).map(|t| mesh.corners(t));
        Work {
            buckets: Buckets::new(cell, corners),
            positions: mesh.positions.iter().map(|p| p.as_dvec3()).collect(),
            normals: mesh.normals.clone(),
            triangles: mesh.triangles.clone(),
            alive: vec![true; mesh.triangles.len()],
            around,
            touched: vec![false; mesh.positions.len()],
        }
    }

    /// Live triangles around `v`.
    fn fan(&self, v: u32) -> impl Iterator<Item = u32> + '_ {
        self.around[v as usize]
            .iter()
            .copied()
            .filter(|&t| self.alive[t as usize])
    }

    /// Neighbours of `v` (sorted, unique).
    fn neighbours(&self, v: u32) -> Vec<u32> {
        let mut n: Vec<u32> = self
            .fan(v)
            .flat_map(|t| self.triangles[t as usize])
            .filter(|&w| w != v)
            .collect();
        n.sort_unstable();
        n.dedup();
        n
    }

    /// Twice the area vector of triangle `t`, with vertex `moved` (if any) at `to`.
    fn normal(&self, t: u32, moved: &[u32], to: DVec3) -> DVec3 {
        let p = self.triangles[t as usize].map(|v| {
            if moved.contains(&v) {
                to
            } else {
                self.positions[v as usize]
            }
        });
        (p[1] - p[0]).cross(p[2] - p[0])
    }

    fn area(&self, t: u32) -> f64 {
        0.5 * self.normal(t, &[], DVec3::ZERO).length()
    }

    /// Triangle `t` with the vertices in `from` renamed `into`, placed at `to`.
    fn moved(&self, t: u32, from: &[u32], into: u32, to: DVec3) -> ([u32; 3], [DVec3; 3]) {
        let ids = self.triangles[t as usize].map(|v| if from.contains(&v) { into } else { v });
        let at = ids.map(|v| {
            if v == into {
                to
            } else {
                self.positions[v as usize]
            }
        });
        (ids, at)
    }

    /// Some proposed triangle meets another, or a live triangle nearby other than those in
    /// `changing`.
    fn crosses(&self, proposed: &[([u32; 3], [DVec3; 3])], changing: &[u32]) -> bool {
        let margin = self.buckets.margin();
        let among = proposed.iter().enumerate().any(|(k, &(ids, at))| {
            (proposed[k + 1..].iter())
                .any(|&(other, there)| triangles_meet(at, ids, there, other, margin))
        });
        let corners: Vec<[DVec3; 3]> = proposed.iter().map(|&(_, at)| at).collect();
        among
            || self.buckets.any_near(&corners, |k, u| {
                if !self.alive[u as usize] || changing.contains(&u) {
                    return false;
                }
                let other = self.triangles[u as usize];
                let there = other.map(|v| self.positions[v as usize]);
                triangles_meet(proposed[k].1, proposed[k].0, there, other, margin)
            })
    }

    /// Re-buckets the triangles around `v`, and updates their boxes.
    fn rebucket(&mut self, v: u32) {
        let fan: Vec<u32> = self.fan(v).collect();
        for t in fan {
            let c = self.triangles[t as usize].map(|w| self.positions[w as usize]);
            self.buckets.update(t, c);
        }
    }
}

/// The mesh with short edges collapsed and small triangles flipped away. See the module
/// documentation. `cell` is the grid spacing the mesh was contoured at.
pub fn clean_mesh(
    mesh: &TriangleMesh,
    cell: f64,
    options: &CleanOptions,
) -> Result<(TriangleMesh, CleanReport), CleanError> {
    if !(cell.is_finite() && cell > 0.0) {
        return Err(CleanError::BadCell(cell));
    }
    mesh.validate()?;
    memory::check_allocation(
        "cleaning a level",
        memory::bytes_of::<[u64; 8]>(mesh.positions.len() + mesh.triangles.len()),
    )?;
    let mut work = Work::new(mesh, cell);
    let mut report = CleanReport::default();
    let (min_edge, min_area) = (options.min_edge * cell, options.min_area * cell * cell);
    for _ in 0..options.max_passes {
        report.passes += 1;
        work.touched.iter_mut().for_each(|t| *t = false);
        let collapsed = collapse_short_edges(&mut work, min_edge);
        let [flipped, collapsed_small, relaxed] = fix_small_triangles(&mut work, min_area);
        report.collapsed_edges += collapsed + collapsed_small;
        report.flipped_edges += flipped;
        report.relaxed_vertices += relaxed;
        if collapsed + flipped + collapsed_small + relaxed == 0 {
            break;
        }
    }
    report.restored_components = restore_flattened(&mut work, mesh);
    report.small_triangles_left = (0..work.triangles.len() as u32)
        .filter(|&t| work.alive[t as usize] && work.area(t) < min_area)
        .count();
    let cleaned = compact(&work);
    report.removed_triangles = mesh.triangles.len() - cleaned.triangles.len();
    report.removed_vertices = mesh.positions.len() - cleaned.positions.len();
    Ok((cleaned, report))
}

/// Edges shorter than `limit`, shortest first.
fn short_edges(work: &Work, limit: f64) -> Vec<(f64, u32, u32)> {
    let mut edges: Vec<(f64, u32, u32)> = Vec::new();
    for (t, tri) in work.triangles.iter().enumerate() {
        if !work.alive[t] {
            continue;
        }
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            let length = work.positions[a as usize].distance(work.positions[b as usize]);
            if a < b && length < limit {
                edges.push((length, a, b));
            }
        }
    }
    edges.sort_by(|x, y| x.0.total_cmp(&y.0));
    edges
}

/// One pass of short-edge collapses; returns how many.
fn collapse_short_edges(work: &mut Work, limit: f64) -> usize {
    short_edges(work, limit)
        .into_iter()
        .filter(|&(_, a, b)| try_collapse(work, a, b))
        .count()
}

/// Collapses edge `ab` at its midpoint, or else at one of its ends, if neither end moved in this pass and the collapse is
/// allowed (see the module documentation).
fn try_collapse(work: &mut Work, a: u32, b: u32) -> bool {
    if work.touched[a as usize] || work.touched[b as usize] {
        return false;
    }
    let shared: Vec<u32> = work
        .fan(a)
        .filter(|&t| work.triangles[t as usize].contains(&b))
        .collect();
    if shared.len() != 2 {
        return false;
    }
    if !link_condition(work, a, b, &shared) {
        return false;
    }
    let (pa, pb) = (work.positions[a as usize], work.positions[b as usize]);
    let mut ring: Vec<u32> = work.fan(a).chain(work.fan(b)).collect();
    ring.sort_unstable();
    ring.dedup();
    let allowed = |to: DVec3| {
        let proposed: Vec<_> = (ring.iter())
            .filter(|t| !shared.contains(t))
            .map(|&t| work.moved(t, &[a, b], a, to))
            .collect();
        !turns_over(work, &[a, b], to, &shared) && !work.crosses(&proposed, &ring)
    };
    let Some(to) = [0.5 * (pa + pb), pa, pb]
        .into_iter()
        .find(|&to| allowed(to))
    else {
        return false;
    };
    merge(work, a, b, to, &shared);
    work.rebucket(a);
    true
}

/// The common neighbours of `a` and `b` are exactly the corners opposite edge `ab`, and there
/// is more around them than a tetrahedron.
fn link_condition(work: &Work, a: u32, b: u32, shared: &[u32]) -> bool {
    let (na, nb) = (work.neighbours(a), work.neighbours(b));
    let common = na.iter().filter(|v| nb.binary_search(v).is_ok()).count();
    let mut opposite: Vec<u32> = shared
        .iter()
        .flat_map(|&t| work.triangles[t as usize])
        .filter(|&v| v != a && v != b)
        .collect();
    opposite.sort_unstable();
    opposite.dedup();
    common == 2 && opposite.len() == 2 && na.len() + nb.len() > 6
}

/// Some triangle around `moved` (other than `skip`) would turn against the neighbourhood's
/// normal, or collapse to nothing, with `moved` at `to`.
fn turns_over(work: &Work, moved: &[u32], to: DVec3, skip: &[u32]) -> bool {
    let mut ring: Vec<u32> = moved.iter().flat_map(|&v| work.fan(v)).collect();
    ring.sort_unstable();
    ring.dedup();
    let average: DVec3 = ring.iter().map(|&t| work.normal(t, &[], to)).sum();
    ring.iter().filter(|t| !skip.contains(t)).any(|&t| {
        let after = work.normal(t, moved, to);
        after.dot(average) <= 0.0 || after.length_squared() == 0.0
    })
}

/// Merges `b` into `a` at `to`; the triangles in `shared` die.
fn merge(work: &mut Work, a: u32, b: u32, to: DVec3, shared: &[u32]) {
    for &t in shared {
        work.alive[t as usize] = false;
    }
    let moved: Vec<u32> = work.fan(b).collect();
    for t in moved {
        for v in work.triangles[t as usize].iter_mut() {
            if *v == b {
                *v = a;
            }
        }
        work.around[a as usize].push(t);
    }
    work.around[b as usize].clear();
    work.positions[a as usize] = to;
    if !work.normals.is_empty() {
        let n = work.normals[a as usize] + work.normals[b as usize];
        work.normals[a as usize] = n.normalize_or(work.normals[a as usize]);
    }
    work.touched[a as usize] = true;
    work.touched[b as usize] = true;
}

/// 4√3 · area / Σ edge² (1 for equilateral, 0 for degenerate).
fn quality(p: [DVec3; 3]) -> f64 {
    let area2 = (p[1] - p[0]).cross(p[2] - p[0]).length();
    let sum =
        p[0].distance_squared(p[1]) + p[1].distance_squared(p[2]) + p[2].distance_squared(p[0]);
    if sum > 0.0 {
        2.0 * 3f64.sqrt() * area2 / sum
    } else {
        0.0
    }
}

/// How a small triangle was fixed.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Fix {
    Flip,
    Collapse,
    Relax,
}

/// One pass over the triangles below `limit` area; returns how many were fixed in each way
/// (flips, collapses, relaxed corners).
fn fix_small_triangles(work: &mut Work, limit: f64) -> [usize; 3] {
    let mut counts = [0usize; 3];
    for t in 0..work.triangles.len() as u32 {
        if work.alive[t as usize] && work.area(t) < limit {
            match fix_small(work, t) {
                Some(Fix::Flip) => counts[0] += 1,
                Some(Fix::Collapse) => counts[1] += 1,
                Some(Fix::Relax) => counts[2] += 1,
                None => {}
            }
        }
    }
    counts
}

/// Flips triangle `t`'s longest edge, or else collapses its shortest edge that may be, or else
/// relaxes one of its corners.
fn fix_small(work: &mut Work, t: u32) -> Option<Fix> {
    if flip_longest(work, t) {
        return Some(Fix::Flip);
    }
    let tri = work.triangles[t as usize];
    let length = |k: usize| {
        let (a, b) = (tri[k], tri[(k + 1) % 3]);
        work.positions[a as usize].distance(work.positions[b as usize])
    };
    let mut order = [0, 1, 2];
    order.sort_by(|&i, &j| length(i).total_cmp(&length(j)));
    if order
        .into_iter()
        .any(|k| try_collapse(work, tri[k], tri[(k + 1) % 3]))
    {
        return Some(Fix::Collapse);
    }
    tri.into_iter()
        .any(|v| try_relax(work, v, t))
        .then_some(Fix::Relax)
}

/// Moves vertex `v` to the centroid of its neighbours if no triangle around it turns over and
/// triangle `t` grows.
fn try_relax(work: &mut Work, v: u32, t: u32) -> bool {
    if work.touched[v as usize] {
        return false;
    }
    let ring = work.neighbours(v);
    let to = ring
        .iter()
        .map(|&w| work.positions[w as usize])
        .sum::<DVec3>()
        / ring.len() as f64;
    let grows = work.normal(t, &[v], to).length() > 2.0 * work.area(t);
    if !grows || turns_over(work, &[v], to, &[]) {
        return false;
    }
    let fan: Vec<u32> = work.fan(v).collect();
    let proposed: Vec<_> = fan.iter().map(|&u| work.moved(u, &[v], v, to)).collect();
    if work.crosses(&proposed, &fan) {
        return false;
    }
    work.positions[v as usize] = to;
    work.touched[v as usize] = true;
    work.rebucket(v);
    true
}

/// Flips the longest edge of triangle `t` if allowed (see the module documentation).
fn flip_longest(work: &mut Work, t: u32) -> bool {
    let tri = work.triangles[t as usize];
    let p = tri.map(|v| work.positions[v as usize]);
    let k = (0..3)
        .max_by(|&i, &j| {
            let li = p[i].distance_squared(p[(i + 1) % 3]);
            li.total_cmp(&p[j].distance_squared(p[(j + 1) % 3]))
        })
        .unwrap_or(0);
    let (a, b, c) = (tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]);
    // The other triangle on edge ab runs b -> a -> d.
    let Some((u, d)) = work.fan(a).find_map(|u| {
        let o = work.triangles[u as usize];
        (0..3)
            .find(|&i| o[i] == b && o[(i + 1) % 3] == a)
            .map(|i| (u, o[(i + 2) % 3]))
    }) else {
        return false;
    };
    if d == c || work.neighbours(c).binary_search(&d).is_ok() {
        return false;
    }
    let at = |v: u32| work.positions[v as usize];
    let (new_t, new_u) = ([c, a, d], [c, d, b]);
    let before = work.normal(t, &[], DVec3::ZERO) + work.normal(u, &[], DVec3::ZERO);
    let n1 = (at(a) - at(c)).cross(at(d) - at(c));
    let n2 = (at(d) - at(c)).cross(at(b) - at(c));
    let old_quality = quality(p).min(quality([at(b), at(a), at(d)]));
    let new_quality = quality([at(c), at(a), at(d)]).min(quality([at(c), at(d), at(b)]));
    if n1.dot(before) <= 0.0 || n2.dot(before) <= 0.0 || new_quality <= old_quality {
        return false;
    }
    let proposed = [(new_t, new_t.map(at)), (new_u, new_u.map(at))];
    if work.crosses(&proposed, &[t, u]) {
        return false;
    }
    work.triangles[t as usize] = new_t;
    work.triangles[u as usize] = new_u;
    work.around[d as usize].push(t);
    work.around[c as usize].push(u);
    // a loses u and b loses t: prune them from the lists.
    work.around[a as usize].retain(|&x| x != u);
    work.around[b as usize].retain(|&x| x != t);
    work.rebucket(c);
    work.rebucket(d);
    true
}

/// The component of every vertex of `mesh` (through shared triangles); unused vertices get
/// their own.
fn vertex_components(mesh: &TriangleMesh) -> Vec<u32> {
    let n = mesh.positions.len();
    let mut around = vec![Vec::new(); n];
    for (t, tri) in mesh.triangles.iter().enumerate() {
        for &v in tri {
            around[v as usize].push(t);
        }
    }
    let mut label = vec![u32::MAX; n];
    let mut stack = Vec::new();
    for seed in 0..n {
        if label[seed] != u32::MAX {
            continue;
        }
        label[seed] = seed as u32;
        stack.push(seed);
        while let Some(v) = stack.pop() {
            for &t in &around[v] {
                for w in mesh.triangles[t] {
                    if label[w as usize] == u32::MAX {
                        label[w as usize] = seed as u32;
                        stack.push(w as usize);
                    }
                }
            }
        }
    }
    label
}

/// Six times the signed volume enclosed by triangle `p` with the point `origin`.
fn signed_volume6(p: [DVec3; 3], origin: DVec3) -> f64 {
    (p[0] - origin).dot((p[1] - origin).cross(p[2] - origin))
}

/// Gives every component that cleaning flattened or turned over its raw triangles back (see
/// the module documentation); returns how many. Collapses only merge neighbours and flips keep
/// a triangle's slot, so every vertex and triangle slot stays in its raw component.
fn restore_flattened(work: &mut Work, raw: &TriangleMesh) -> usize {
    let label = vertex_components(raw);
    let origin = |l: u32| raw.positions[l as usize].as_dvec3();
    let mut volumes: std::collections::HashMap<u32, (f64, f64)> = Default::default();
    for (t, tri) in raw.triangles.iter().enumerate() {
        let l = label[tri[0] as usize];
        let before = signed_volume6(raw.corners(t), origin(l));
        volumes.entry(l).or_default().0 += before;
        if work.alive[t] {
            let p = work.triangles[t].map(|v| work.positions[v as usize]);
            volumes.entry(l).or_default().1 += signed_volume6(p, origin(l));
        }
    }
    let flattened: std::collections::HashSet<u32> = (volumes.iter())
        .filter(|(_, &(before, after))| after * before.signum() < MIN_VOLUME_KEPT * before.abs())
        .map(|(&l, _)| l)
        .collect();
    for (t, tri) in raw.triangles.iter().enumerate() {
        if !flattened.contains(&label[tri[0] as usize]) {
            continue;
        }
        work.triangles[t] = *tri;
        work.alive[t] = true;
        for &v in tri {
            work.positions[v as usize] = raw.positions[v as usize].as_dvec3();
            if !work.normals.is_empty() {
                work.normals[v as usize] = raw.normals[v as usize];
            }
        }
    }
    flattened.len()
}

/// The live triangles and the vertices they use, numbered in order of first use.
fn compact(work: &Work) -> TriangleMesh {
    let mut index = vec![u32::MAX; work.positions.len()];
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    let mut triangles = Vec::new();
    for (t, tri) in work.triangles.iter().enumerate() {
        if !work.alive[t] {
            continue;
        }
        triangles.push(tri.map(|v| {
            if index[v as usize] == u32::MAX {
                index[v as usize] = positions.len() as u32;
                positions.push(work.positions[v as usize].as_vec3());
                if !work.normals.is_empty() {
                    normals.push(work.normals[v as usize]);
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

    /// A regular tetrahedron with one vertex split in two, 1e-4 apart: the short edge sits in
    /// a component that would collapse to a flat pair of triangles, so it stays.
    fn split_tetrahedron() -> TriangleMesh {
        let p = [
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::new(1.0, -1.0, -1.0),
            Vec3::new(-1.0, 1.0, -1.0),
            Vec3::new(-1.0, -1.0, 1.0),
        ];
        TriangleMesh::new(p.to_vec(), vec![[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]])
    }

    #[test]
    fn refuses_a_bad_cell_and_keeps_a_tetrahedron() {
        let mesh = split_tetrahedron();
        assert!(matches!(
            clean_mesh(&mesh, 0.0, &CleanOptions::default()),
            Err(CleanError::BadCell(_))
        ));
        assert!(clean_mesh(&mesh, f64::NAN, &CleanOptions::default()).is_err());
        // Every edge is "short" for a cell of 100, but a tetrahedron has nothing to give.
        let (clean, report) = clean_mesh(&mesh, 100.0, &CleanOptions::default()).unwrap();
        assert_eq!(clean, mesh);
        assert_eq!(report.collapsed_edges, 0);
    }

    #[test]
    fn collapses_a_short_edge_of_an_octahedron() {
        // An octahedron with its +x vertex split into two 1e-3 apart along y (a seventh vertex
        // and two more triangles): the short edge collapses back to the octahedron.
        let mut positions = vec![
            Vec3::new(1.0, -5e-4, 0.0),
            Vec3::new(-1.0, 0.0, 0.0),
            Vec3::Y,
            Vec3::NEG_Y,
            Vec3::Z,
            Vec3::NEG_Z,
        ];
        positions.push(Vec3::new(1.0, 5e-4, 0.0));
        // Vertex 0 = +x (lower), 6 = +x (upper); 0 keeps the -y side, 6 the +y side.
        let triangles = vec![
            [6, 2, 4],
            [2, 6, 5],
            [0, 4, 3],
            [0, 3, 5],
            [1, 4, 2],
            [1, 2, 5],
            [1, 3, 4],
            [1, 5, 3],
            [0, 6, 4],
            [6, 0, 5],
        ];
        let mesh = TriangleMesh::new(positions, triangles);
        let before = voxlod_core::mesh_topology(&mesh);
        assert!(
            before.is_closed_manifold() && before.is_consistently_oriented(),
            "{before:?}"
        );
        let (clean, report) = clean_mesh(&mesh, 1.0, &CleanOptions::default()).unwrap();
        assert_eq!(report.collapsed_edges, 1);
        assert_eq!((clean.positions.len(), clean.triangles.len()), (6, 8));
        let after = voxlod_core::mesh_topology(&clean);
        assert!(after.is_closed_manifold() && after.is_consistently_oriented());
        assert!((clean.signed_volume() - 4.0 / 3.0).abs() < 1e-3);
    }
}
