//! Whether two triangles of a mesh cross each other: the predicates behind the cleaning's
//! guard (voxlod-contouring), the whole-mesh count [`crate::crossing_pairs`] and the quadric
//! stage's refusal of folds (voxlod-quadric), kept here so that each of them, one stage or
//! another, asks the same question (so that no level crosses itself).
//!
//! Beyond the paper. Two questions, by the signs of `f64` orientation determinants:
//!
//! - **May they meet** ([`triangles_meet`], the guard's): an edge of either, not incident to a
//!   vertex they share, meets the other, a zero sign counting as meeting (a guard refuses what
//!   it cannot rule out). A folded fan around a shared vertex counts and two triangles along a
//!   shared edge do not. Near-coplanar neighbours, such as the strips of a flat face whose
//!   corners lie in one plane up to `f32` rounding, give signs of pure rounding and often
//!   "meet": right for a guard, wrong for a count.
//! - **Do they cross** ([`triangles_cross`], the count's): an edge of either, not incident to a
//!   shared vertex, properly crosses the other, every sign certain (outside Shewchuk's static
//!   error bound of the determinant, so that it is the exact sign for the `f64` corners;
//!   touching is not crossing); or they lie in one plane and overlap with positive area
//!   ([`coplanar_overlap`]: a flat region folded onto itself, as a collapse can leave on a CAD
//!   part's faces): in the plane's two dominant axes, a shared edge with both third corners on
//!   one side, overlapping wedges at a shared corner, or else a proper edge crossing or a
//!   corner strictly inside the other. Coplanarity allows the rounding of the `f64`
//!   determinant.
//!
//! Cost: O(1) per pair, a few dozen flops; pairs whose boxes lie apart by more than a margin
//! (far above the determinants' rounding) are ruled out first, then pairs of which one
//! triangle lies certainly on one side of the other's plane (one plane, three determinants).

use glam::DVec3;

/// Triangles `a` (vertex ids `ia`) and `b` (ids `ib`) cross: an edge of either, not incident
/// to a vertex they share, properly crosses the other, or they overlap in one plane
/// ([`coplanar_overlap`]); module docs. Triangles whose boxes lie apart by more than `margin`
/// do not cross.
///
/// ```
/// use voxlod_core::crossings::triangles_cross;
/// use voxlod_core::glam::DVec3;
///
/// let flat = [DVec3::ZERO, DVec3::new(2.0, 0.0, 0.0), DVec3::new(0.0, 2.0, 0.0)];
/// let through = [DVec3::new(0.5, 0.5, -1.0), DVec3::new(0.5, 0.5, 1.0), DVec3::splat(3.0)];
/// assert!(triangles_cross(flat, [0, 1, 2], through, [3, 4, 5], 1e-9));
/// let above = through.map(|p| p + DVec3::new(0.0, 0.0, 5.0));
/// assert!(!triangles_cross(flat, [0, 1, 2], above, [3, 4, 5], 1e-9));
/// // Touching is not crossing: a corner on the other triangle.
/// let touching = [DVec3::new(0.5, 0.5, 0.0), DVec3::new(0.5, 0.5, 1.0), DVec3::splat(3.0)];
/// assert!(!triangles_cross(flat, [0, 1, 2], touching, [3, 4, 5], 1e-9));
/// ```
pub fn triangles_cross(
    a: [DVec3; 3],
    ia: [u32; 3],
    b: [DVec3; 3],
    ib: [u32; 3],
    margin: f64,
) -> bool {
    if boxes_apart(bounds(a), bounds(b), margin) {
        return false;
    }
    // A triangle whose unshared corners all lie certainly on one side of the other's plane
    // meets that plane at shared corners only: no edge of either crosses the other. An
    // unshared corner of `b` certainly off `a`'s plane is outside the rounding that
    // `coplanar_overlap` allows (a quarter of the certain bound): they are not coplanar.
    let b_sides = sides(b, ib, a, ia);
    if on_one_side(b_sides) {
        return false;
    }
    let flat = b_sides.iter().flatten().all(|&s| s == 0);
    let a_sides = sides(a, ia, b, ib);
    if on_one_side(a_sides) {
        return flat && coplanar_overlap(a, ia, b, ib);
    }
    edges_cross(a, a_sides, b)
        || edges_cross(b, b_sides, a)
        || (flat && coplanar_overlap(a, ia, b, ib))
}

/// The certain side (+1, -1, or 0 where the rounding leaves it open) of each corner of `p`
/// (vertex ids `ip`) not shared with triangle `t` (ids `it`) of `t`'s plane; `None` for a
/// shared corner. The plane and its rounding bound are found once for the three (the
/// determinants [`certain_side`] computes).
fn sides(p: [DVec3; 3], ip: [u32; 3], t: [DVec3; 3], it: [u32; 3]) -> [Option<i8>; 3] {
    let (u, v) = (t[1] - t[0], t[2] - t[0]);
    let normal = u.cross(v);
    let scale = DVec3::new(
        (u.y * v.z).abs() + (u.z * v.y).abs(),
        (u.z * v.x).abs() + (u.x * v.z).abs(),
        (u.x * v.y).abs() + (u.y * v.x).abs(),
    );
    let side = |k: usize| {
        let w = p[k] - t[0];
        (!it.contains(&ip[k])).then(|| certain(normal.dot(w), scale.dot(w.abs())))
    };
    [side(0), side(1), side(2)]
}

/// Some corner is unshared, and every unshared corner lies certainly on the same side.
fn on_one_side(sides: [Option<i8>; 3]) -> bool {
    let mut free = sides.iter().flatten();
    free.next()
        .is_some_and(|&first| first != 0 && free.all(|&s| s == first))
}

/// An edge of triangle `p` between two unshared corners (their `sides` of `t`'s plane, from
/// [`sides`]) properly crosses triangle `t`, every sign certain.
fn edges_cross(p: [DVec3; 3], sides: [Option<i8>; 3], t: [DVec3; 3]) -> bool {
    (0..3).any(|k| {
        let l = (k + 1) % 3;
        match (sides[k], sides[l]) {
            (Some(x), Some(y)) => x * y < 0 && line_through(p[k], p[l], t),
            _ => false,
        }
    })
}

/// The line through `p` and `q` certainly passes through the inside of triangle `t`: the three
/// edge orientations certain and equal.
fn line_through(p: DVec3, q: DVec3, t: [DVec3; 3]) -> bool {
    let e = [
        certain_side(p, q, t[0], t[1]),
        certain_side(p, q, t[1], t[2]),
        certain_side(p, q, t[2], t[0]),
    ];
    e[0] != 0 && e[0] == e[1] && e[1] == e[2]
}

/// The sign of the volume of the tetrahedron `a b c d` (+1 or -1) when the `f64` determinant
/// lies outside its rounding (Shewchuk's static bound, about 7ε times the permanent, taken
/// as 16ε: the differences are exact for corners read from `f32`), else 0.
fn certain_side(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> i8 {
    let (u, v, w) = (b - a, c - a, d - a);
    let permanent = ((u.y * v.z).abs() + (u.z * v.y).abs()) * w.x.abs()
        + ((u.z * v.x).abs() + (u.x * v.z).abs()) * w.y.abs()
        + ((u.x * v.y).abs() + (u.y * v.x).abs()) * w.z.abs();
    certain(u.cross(v).dot(w), permanent)
}

/// The sign of determinant `det` whose permanent is `permanent`: +1 or -1 outside the static
/// bound, else 0.
fn certain(det: f64, permanent: f64) -> i8 {
    let bound = 16.0 * f64::EPSILON * permanent;
    if det > bound {
        1
    } else if det < -bound {
        -1
    } else {
        0
    }
}

/// The smallest and the largest corner of a triangle's box.
pub fn bounds(p: [DVec3; 3]) -> (DVec3, DVec3) {
    (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]))
}

/// The sign of `volume`: +1, -1 or 0 (0 for NaN).
fn sign(volume: f64) -> f64 {
    if volume > 0.0 {
        1.0
    } else if volume < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// Sign of the volume of the tetrahedron `a b c d` (+1, -1 or 0).
fn side(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    sign((b - a).cross(c - a).dot(d - a))
}

/// Segment `p q`, whose ends lie on sides `sp` and `sq` of triangle `t`'s plane (`side(t[0],
/// t[1], t[2], ·)`), meets `t` (touching counts).
fn segment_meets(p: DVec3, q: DVec3, (sp, sq): (f64, f64), t: [DVec3; 3]) -> bool {
    if sp * sq > 0.0 {
        return false;
    }
    if sp == 0.0 && sq == 0.0 {
        // Coplanar: leave it to the turn-over test around the change.
        return false;
    }
    let e = [
        side(p, q, t[0], t[1]),
        side(p, q, t[1], t[2]),
        side(p, q, t[2], t[0]),
    ];
    !(e.iter().any(|&s| s > 0.0) && e.iter().any(|&s| s < 0.0))
}

/// An edge of triangle `p` (vertex ids `ip`) not incident to a vertex of `t` (ids `it`) meets
/// triangle `t`. Triangles sharing an edge have no such edge, and nothing is computed; else the
/// sides of `p`'s unshared corners are the determinants [`side`] computes, the plane's normal
/// found once for them.
fn edges_meet(p: [DVec3; 3], ip: [u32; 3], t: [DVec3; 3], it: [u32; 3]) -> bool {
    let (f0, f1, f2) = (
        !it.contains(&ip[0]),
        !it.contains(&ip[1]),
        !it.contains(&ip[2]),
    );
    let (e0, e1, e2) = (f0 && f1, f1 && f2, f2 && f0);
    if !(e0 || e1 || e2) {
        return false;
    }
    let normal = (t[1] - t[0]).cross(t[2] - t[0]);
    // A shared corner's side is never read: no tested edge ends there.
    let side_of = |free: bool, x: DVec3| match free {
        true => sign(normal.dot(x - t[0])),
        false => 0.0,
    };
    let (s0, s1, s2) = (side_of(f0, p[0]), side_of(f1, p[1]), side_of(f2, p[2]));
    (e0 && segment_meets(p[0], p[1], (s0, s1), t))
        || (e1 && segment_meets(p[1], p[2], (s1, s2), t))
        || (e2 && segment_meets(p[2], p[0], (s2, s0), t))
}

/// Two boxes (smallest and largest corners) lie apart along some axis by more than `margin`.
pub fn boxes_apart(
    (a_lo, a_hi): (DVec3, DVec3),
    (b_lo, b_hi): (DVec3, DVec3),
    margin: f64,
) -> bool {
    (a_hi + margin).cmplt(b_lo).any() || (b_hi + margin).cmplt(a_lo).any()
}

/// Triangle `a` (vertex ids `ia`) and triangle `b` (ids `ib`) meet other than at what they
/// share: an edge of either, not incident to a shared vertex, meets the other. Triangles whose
/// boxes lie apart by more than `margin` cannot meet, and are not tested further: the margin
/// (a caller's bucketing picks it, e.g. a millionth of a cell) is far above the rounding of the
/// orientation determinants, so the answer is the full test's.
pub fn triangles_meet(
    a: [DVec3; 3],
    ia: [u32; 3],
    b: [DVec3; 3],
    ib: [u32; 3],
    margin: f64,
) -> bool {
    if boxes_apart(bounds(a), bounds(b), margin) {
        return false;
    }
    edges_meet(a, ia, b, ib) || edges_meet(b, ib, a, ia)
}

/// Triangles `a` and `b` (vertex ids `ia`, `ib`) lie in one plane and overlap with positive
/// area (module docs).
pub fn coplanar_overlap(a: [DVec3; 3], ia: [u32; 3], b: [DVec3; 3], ib: [u32; 3]) -> bool {
    let normal = (a[1] - a[0]).cross(a[2] - a[0]);
    if normal == DVec3::ZERO || !b.iter().all(|&p| in_plane(a, p)) {
        return false;
    }
    let axis = normal.abs().max_position();
    let flat = |p: DVec3| {
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        [p[u], p[v]]
    };
    let (pa, pb) = (a.map(flat), b.map(flat));
    let shared: Vec<(usize, usize)> = (0..3)
        .flat_map(|i| (0..3).map(move |j| (i, j)))
        .filter(|&(i, j)| ia[i] == ib[j])
        .collect();
    match shared.len() {
        0 => apart_overlap(pa, pb),
        1 => wedges_overlap(pa, pb, shared[0]),
        2 => {
            let third = |t: [u32; 3], o: [u32; 3]| (0..3).find(|&k| !o.contains(&t[k]));
            let (Some(i), Some(j)) = (third(ia, ib), third(ib, ia)) else {
                return true;
            };
            let (p, q) = (pa[shared[0].0], pa[shared[1].0]);
            let (x, y) = (orient(p, q, pa[i]), orient(p, q, pb[j]));
            x * y > 0.0
        }
        _ => true,
    }
}

/// Point `p` lies in the plane of `t`, within the rounding of the orientation determinant.
fn in_plane(t: [DVec3; 3], p: DVec3) -> bool {
    let (u, v, w) = (t[1] - t[0], t[2] - t[0], p - t[0]);
    let det = u.cross(v).dot(w);
    let permanent = (u.y * v.z).abs() * w.x.abs()
        + (u.z * v.y).abs() * w.x.abs()
        + (u.z * v.x).abs() * w.y.abs()
        + (u.x * v.z).abs() * w.y.abs()
        + (u.x * v.y).abs() * w.z.abs()
        + (u.y * v.x).abs() * w.z.abs();
    det.abs() <= 8e-16 * permanent
}

/// Twice the signed area of `p q r` in the plane.
fn orient(p: [f64; 2], q: [f64; 2], r: [f64; 2]) -> f64 {
    (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])
}

/// Two plane triangles with no corner in common overlap with positive area: two edges cross
/// properly, or a corner of one lies strictly inside the other.
fn apart_overlap(a: [[f64; 2]; 3], b: [[f64; 2]; 3]) -> bool {
    let crossing = |p: [f64; 2], q: [f64; 2], r: [f64; 2], s: [f64; 2]| {
        orient(p, q, r) * orient(p, q, s) < 0.0 && orient(r, s, p) * orient(r, s, q) < 0.0
    };
    let inside = |t: [[f64; 2]; 3], x: [f64; 2]| {
        let w = [
            orient(t[0], t[1], x),
            orient(t[1], t[2], x),
            orient(t[2], t[0], x),
        ];
        w.iter().all(|&d| d > 0.0) || w.iter().all(|&d| d < 0.0)
    };
    (0..3).any(|i| (0..3).any(|j| crossing(a[i], a[(i + 1) % 3], b[j], b[(j + 1) % 3])))
        || a.iter().any(|&x| inside(b, x))
        || b.iter().any(|&x| inside(a, x))
}

/// Two plane triangles sharing corner `a[i] = b[j]` overlap: their wedges there overlap (a
/// side of one strictly inside the other's wedge, or the same wedge), or their far edges cross.
fn wedges_overlap(a: [[f64; 2]; 3], b: [[f64; 2]; 3], (i, j): (usize, usize)) -> bool {
    let v = a[i];
    let (a1, a2) = (a[(i + 1) % 3], a[(i + 2) % 3]);
    let (b1, b2) = (b[(j + 1) % 3], b[(j + 2) % 3]);
    let within = |u: [f64; 2], w: [f64; 2], d: [f64; 2]| {
        let turn = orient(v, u, w);
        turn != 0.0 && orient(v, u, d) * turn > 0.0 && orient(v, d, w) * turn > 0.0
    };
    let same_ray = |p: [f64; 2], q: [f64; 2]| {
        orient(v, p, q) == 0.0
            && (p[0] - v[0]) * (q[0] - v[0]) + (p[1] - v[1]) * (q[1] - v[1]) > 0.0
    };
    within(a1, a2, b1)
        || within(a1, a2, b2)
        || within(b1, b2, a1)
        || within(b1, b2, a2)
        || (same_ray(a1, b1) && same_ray(a2, b2))
        || (same_ray(a1, b2) && same_ray(a2, b1))
        || apart_overlap([a1, a2, a1], [b1, b2, b1])
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64;

    /// Whether an edge of either triangle, sharing no corner with the other, passes `edge_test`
    /// against it (segment, triangle): the pair tests below, one edge at a time.
    fn any_edge(
        a: [DVec3; 3],
        ia: [u32; 3],
        b: [DVec3; 3],
        ib: [u32; 3],
        edge_test: impl Fn(DVec3, DVec3, [DVec3; 3]) -> bool,
    ) -> bool {
        let edges = |p: [DVec3; 3], ip: [u32; 3], t: [DVec3; 3], it: [u32; 3]| {
            (0..3).any(|k| {
                let l = (k + 1) % 3;
                !it.contains(&ip[k]) && !it.contains(&ip[l]) && edge_test(p[k], p[l], t)
            })
        };
        edges(a, ia, b, ib) || edges(b, ib, a, ia)
    }

    /// The reference for [`triangles_meet`]: each edge's two plane sides by [`side`], one edge
    /// at a time.
    fn meet_edge_by_edge(a: [DVec3; 3], ia: [u32; 3], b: [DVec3; 3], ib: [u32; 3]) -> bool {
        any_edge(a, ia, b, ib, |p, q, t| {
            let sides = (side(t[0], t[1], t[2], p), side(t[0], t[1], t[2], q));
            segment_meets(p, q, sides, t)
        })
    }

    /// Pairs of triangles over a few shared points (on a half-unit lattice, so that corners
    /// often lie exactly in the other's plane or on its edges, or are shared): the plane sides
    /// found once per triangle decide as the edge-by-edge test, and both answers occur.
    #[test]
    fn shared_plane_sides_decide_as_the_edge_by_edge_test() {
        let mut rng = Pcg64::seed_from_u64(14);
        let mut met = [0usize; 2];
        for _ in 0..20_000 {
            let points: Vec<DVec3> = (0..6)
                .map(|_| {
                    let c = [0, 1, 2].map(|_| rng.random_range(0..3) as f64 * 0.5);
                    DVec3::from_array(c) + DVec3::splat(rng.random_range(0..2) as f64 * 1e-3)
                })
                .collect();
            let mut ids = || [0, 1, 2].map(|_| rng.random_range(0..points.len() as u32));
            let (ia, ib) = (ids(), ids());
            let at = |i: [u32; 3]| i.map(|v| points[v as usize]);
            let meets = triangles_meet(at(ia), ia, at(ib), ib, 1e-9);
            let apart = boxes_apart(bounds(at(ia)), bounds(at(ib)), 1e-9);
            assert_eq!(meets, !apart && meet_edge_by_edge(at(ia), ia, at(ib), ib));
            met[meets as usize] += 1;
        }
        assert!(met[0] > 1000 && met[1] > 1000, "{met:?}");
    }

    /// Segment `p q` crosses `t` by [`certain_side`] alone, edge by edge.
    fn cross_edge_by_edge(a: [DVec3; 3], ia: [u32; 3], b: [DVec3; 3], ib: [u32; 3]) -> bool {
        any_edge(a, ia, b, ib, |p, q, t| {
            let (sp, sq) = (
                certain_side(t[0], t[1], t[2], p),
                certain_side(t[0], t[1], t[2], q),
            );
            sp != 0 && sq != 0 && sp != sq && line_through(p, q, t)
        })
    }

    /// The same lattice pairs, and the same pairs with their corners moved by a few units in
    /// the last place (as `f32` rounding leaves the corners of a flat face): the certain
    /// crossing test with the plane found once decides as edge by edge, both answers occur,
    /// a pair that crosses may also meet, and the whole test with its early exit (one
    /// triangle on one side of the other's plane) decides as its parts do.
    #[test]
    fn certain_crossings_decide_as_the_edge_by_edge_test() {
        let mut rng = Pcg64::seed_from_u64(15);
        let mut crossed = [0usize; 2];
        for round in 0..40_000 {
            let points: Vec<DVec3> = (0..6)
                .map(|_| {
                    let c = [0, 1, 2].map(|_| rng.random_range(0..3) as f64 * 0.5);
                    let jitter = [0, 1, 2].map(|_| rng.random_range(-4..=4) as f64 * 1e-15);
                    DVec3::from_array(c) + (round % 2) as f64 * DVec3::from_array(jitter)
                })
                .collect();
            let mut ids = || [0, 1, 2].map(|_| rng.random_range(0..points.len() as u32));
            let (ia, ib) = (ids(), ids());
            let at = |i: [u32; 3]| i.map(|v| points[v as usize]);
            let (a, b) = (at(ia), at(ib));
            let cross =
                edges_cross(a, sides(a, ia, b, ib), b) || edges_cross(b, sides(b, ib, a, ia), a);
            assert_eq!(cross, cross_edge_by_edge(a, ia, b, ib));
            assert!(!cross || triangles_meet(a, ia, b, ib, 1e-9));
            // The early exit of a triangle on one side of the other's plane decides the same.
            let whole = cross || coplanar_overlap(a, ia, b, ib);
            assert_eq!(triangles_cross(a, ia, b, ib, 1e-9), whole);
            crossed[cross as usize] += 1;
        }
        assert!(crossed[0] > 10_000 && crossed[1] > 300, "{crossed:?}");
    }
}
