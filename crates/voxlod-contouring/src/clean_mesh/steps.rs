//! The cleaning steps of [`super::clean_mesh`], each split in two: a decision that only reads
//! the mesh (and notes the guard's buckets it read, so that decisions can be made in parallel
//! and checked before they are applied in order), and the edit that applies it.

use glam::DVec3;

use super::work::{KeyBox, Work};

/// An edit decided on.
#[derive(Clone, Copy, Debug)]
pub(super) enum Step {
    /// Merge `b` into `a` at `to`.
    Collapse { a: u32, b: u32, to: DVec3 },
    /// Triangle `t` (`a b c`, longest edge `ab`) and `u` (`b a d`) become `c a d` and `c d b`.
    Flip {
        t: u32,
        u: u32,
        a: u32,
        b: u32,
        c: u32,
        d: u32,
    },
    /// Move `v` to `to`.
    Relax { v: u32, to: DVec3 },
}

/// Where edge `ab` collapses to, if it may: its midpoint, or else either end (see the module
/// documentation of `clean_mesh`).
pub(super) fn decide_collapse(work: &Work, a: u32, b: u32, reads: &mut KeyBox) -> Option<DVec3> {
    if work.touched[a as usize] || work.touched[b as usize] {
        return None;
    }
    let shared = shared_triangles(work, a, b);
    if shared.len() != 2 || !link_condition(work, a, b, &shared) {
        return None;
    }
    let (pa, pb) = (work.position(a), work.position(b));
    let mut ring: Vec<u32> = work.fan(a).chain(work.fan(b)).collect();
    ring.sort_unstable();
    ring.dedup();
    let mut allowed = |to: DVec3| {
        let proposed: Vec<_> = (ring.iter())
            .filter(|t| !shared.contains(t))
            .map(|&t| work.moved(t, &[a, b], a, to))
            .collect();
        !turns_over(work, &[a, b], to, &shared) && !work.crosses(&proposed, &ring, reads)
    };
    [0.5 * (pa + pb), pa, pb]
        .into_iter()
        .find(|&to| allowed(to))
}

/// The live triangles on edge `ab`.
fn shared_triangles(work: &Work, a: u32, b: u32) -> Vec<u32> {
    work.fan(a)
        .filter(|&t| work.surface.triangles[t as usize].contains(&b))
        .collect()
}

/// The common neighbours of `a` and `b` are exactly the corners opposite edge `ab`, and there
/// is more around them than a tetrahedron.
fn link_condition(work: &Work, a: u32, b: u32, shared: &[u32]) -> bool {
    let (na, nb) = (work.neighbours(a), work.neighbours(b));
    let common = na.iter().filter(|v| nb.binary_search(v).is_ok()).count();
    let mut opposite: Vec<u32> = shared
        .iter()
        .flat_map(|&t| work.surface.triangles[t as usize])
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

/// How small triangle `t` is fixed: its longest edge flipped, or else its shortest edge that
/// may be collapsed, or else one of its corners relaxed; `None` when nothing is allowed.
pub(super) fn decide_fix(work: &Work, t: u32, reads: &mut KeyBox) -> Option<Step> {
    if let Some(flip) = decide_flip(work, t, reads) {
        return Some(flip);
    }
    let tri = work.surface.triangles[t as usize];
    let length = |k: usize| {
        work.position(tri[k])
            .distance(work.position(tri[(k + 1) % 3]))
    };
    let mut order = [0, 1, 2];
    order.sort_by(|&i, &j| length(i).total_cmp(&length(j)));
    for k in order {
        let (a, b) = (tri[k], tri[(k + 1) % 3]);
        if let Some(to) = decide_collapse(work, a, b, reads) {
            return Some(Step::Collapse { a, b, to });
        }
    }
    tri.into_iter()
        .find_map(|v| decide_relax(work, v, t, reads).map(|to| Step::Relax { v, to }))
}

/// Where vertex `v` moves (the centroid of its neighbours) if no triangle around it turns over
/// and triangle `t` grows.
fn decide_relax(work: &Work, v: u32, t: u32, reads: &mut KeyBox) -> Option<DVec3> {
    if work.touched[v as usize] {
        return None;
    }
    let ring = work.neighbours(v);
    let to = ring.iter().map(|&w| work.position(w)).sum::<DVec3>() / ring.len() as f64;
    let grows = work.normal(t, &[v], to).length() > 2.0 * work.area(t);
    if !grows || turns_over(work, &[v], to, &[]) {
        return None;
    }
    let fan: Vec<u32> = work.fan(v).collect();
    let proposed: Vec<_> = fan.iter().map(|&u| work.moved(u, &[v], v, to)).collect();
    (!work.crosses(&proposed, &fan, reads)).then_some(to)
}

/// The flip of triangle `t`'s longest edge, if allowed (see the module documentation of
/// `clean_mesh`).
fn decide_flip(work: &Work, t: u32, reads: &mut KeyBox) -> Option<Step> {
    let tri = work.surface.triangles[t as usize];
    let p = tri.map(|v| work.position(v));
    let k = (0..3)
        .max_by(|&i, &j| {
            let li = p[i].distance_squared(p[(i + 1) % 3]);
            li.total_cmp(&p[j].distance_squared(p[(j + 1) % 3]))
        })
        .unwrap_or(0);
    let (a, b, c) = (tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]);
    // The other triangle on edge ab runs b -> a -> d.
    let (u, d) = work.fan(a).find_map(|u| {
        let o = work.surface.triangles[u as usize];
        (0..3)
            .find(|&i| o[i] == b && o[(i + 1) % 3] == a)
            .map(|i| (u, o[(i + 2) % 3]))
    })?;
    if d == c || work.neighbours(c).binary_search(&d).is_ok() {
        return None;
    }
    let at = |v: u32| work.position(v);
    let (new_t, new_u) = ([c, a, d], [c, d, b]);
    let before = work.normal(t, &[], DVec3::ZERO) + work.normal(u, &[], DVec3::ZERO);
    let n1 = (at(a) - at(c)).cross(at(d) - at(c));
    let n2 = (at(d) - at(c)).cross(at(b) - at(c));
    let old_quality = quality(p).min(quality([at(b), at(a), at(d)]));
    let new_quality = quality([at(c), at(a), at(d)]).min(quality([at(c), at(d), at(b)]));
    if n1.dot(before) <= 0.0 || n2.dot(before) <= 0.0 || new_quality <= old_quality {
        return None;
    }
    let proposed = [(new_t, new_t.map(at)), (new_u, new_u.map(at))];
    if work.crosses(&proposed, &[t, u], reads) {
        return None;
    }
    Some(Step::Flip { t, u, a, b, c, d })
}

/// The live triangles that `step` changes (moves, renames or kills), before it is applied.
pub(super) fn changed_by(work: &Work, step: &Step) -> Vec<u32> {
    match *step {
        Step::Collapse { a, b, .. } => {
            let mut ring: Vec<u32> = work.fan(a).chain(work.fan(b)).collect();
            ring.sort_unstable();
            ring.dedup();
            ring
        }
        Step::Flip { t, u, .. } => vec![t, u],
        Step::Relax { v, .. } => work.fan(v).collect(),
    }
}

/// Applies `step`.
pub(super) fn apply(work: &mut Work, step: Step) {
    match step {
        Step::Collapse { a, b, to } => {
            let shared = shared_triangles(work, a, b);
            merge(work, a, b, to, &shared);
            work.rebucket(a);
        }
        Step::Flip { t, u, a, b, c, d } => {
            work.surface.triangles[t as usize] = [c, a, d];
            work.surface.triangles[u as usize] = [c, d, b];
            work.fans.push(d, t);
            work.fans.push(c, u);
            // a loses u and b loses t.
            work.fans.remove(a, u);
            work.fans.remove(b, t);
            work.rebucket(c);
            work.rebucket(d);
        }
        Step::Relax { v, to } => {
            work.surface.positions[v as usize] = to;
            work.touched[v as usize] = true;
            work.rebucket(v);
        }
    }
}

/// Merges `b` into `a` at `to`; the triangles in `shared` die.
fn merge(work: &mut Work, a: u32, b: u32, to: DVec3, shared: &[u32]) {
    for &t in shared {
        work.surface.alive[t as usize] = false;
    }
    let moved: Vec<u32> = work.fan(b).collect();
    for &t in &moved {
        for v in work.surface.triangles[t as usize].iter_mut() {
            if *v == b {
                *v = a;
            }
        }
    }
    work.fans.extend(a, &moved);
    work.fans.clear(b);
    let surface = &mut work.surface;
    surface.positions[a as usize] = to;
    if !surface.normals.is_empty() {
        let n = surface.normals[a as usize] + surface.normals[b as usize];
        surface.normals[a as usize] = n.normalize_or(surface.normals[a as usize]);
    }
    work.touched[a as usize] = true;
    work.touched[b as usize] = true;
}
