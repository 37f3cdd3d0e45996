//! The geometric predicates the envelope needs: whether two triangles touch, whether a triangle
//! overlaps a box, and the exact distance from a point to a triangle (from voxlod-metrics).
//!
//! All tests are in `f64` and lean towards "touching": a contact within `tol` (a length, in the
//! mesh's units) counts as an intersection. Every caller uses them to refuse something (a new
//! triangle, or an offset that might cross itself), so a doubtful case refuses; no exact
//! arithmetic is needed for the guarantees to hold.
//!
//! Triangle–triangle: two closed triangles meet iff an edge of one meets the other (their common
//! part, when they are not coplanar, is a segment whose ends lie on edges). So six
//! segment–triangle tests, each cut short by the plane-side test of Möller (1997): a segment whose
//! ends lie strictly on one side of the other triangle's plane cannot meet it. A segment lying in
//! the plane (within `tol`) falls back to a test inside the plane. Cost: a few dozen flops when the
//! plane test separates the triangles, about 300 otherwise.
//!
//! Triangle–box: the separating-axis test of Akenine-Möller (2001) with the 13 axes (3 box
//! normals, the triangle normal, 9 edge cross products).

use glam::{DVec3, Vec3A};

pub(crate) use voxlod_metrics::closest_point_on_triangle;

/// Distance from `p` to the closed triangle `t`.
#[inline]
pub(crate) fn point_triangle_distance(p: DVec3, t: &[DVec3; 3]) -> f64 {
    (p - closest_point_on_triangle(p, *t)).length()
}

/// A triangle prepared for many line crossings: its plane and its three inward edge normals.
#[derive(Clone, Copy, Debug)]
pub(crate) struct CrossingTest {
    corner: DVec3,
    /// Unit normal.
    normal: DVec3,
    /// For each edge, a vector in the plane pointing inwards, of the edge's length, and the
    /// edge's start.
    edges: [(DVec3, DVec3); 3],
    /// Contact tolerance times each edge's length.
    slack: [f64; 3],
}

impl CrossingTest {
    /// `None` for a triangle without area.
    pub fn new(t: &[DVec3; 3], tol: f64) -> Option<Self> {
        let n = (t[1] - t[0]).cross(t[2] - t[0]);
        let l = n.length();
        if l == 0.0 {
            return None;
        }
        let normal = n / l;
        let edge = |i: usize| {
            let e = t[(i + 1) % 3] - t[i];
            (normal.cross(e), t[i])
        };
        let slack = |i: usize| tol * (t[(i + 1) % 3] - t[i]).length() * 1.0;
        Some(CrossingTest {
            corner: t[0],
            normal,
            edges: [edge(0), edge(1), edge(2)],
            slack: [slack(0), slack(1), slack(2)],
        })
    }

    /// Where the line `p + s·dir` (`dir` of unit length) crosses the triangle (widened by the
    /// tolerance): `s`, or `None` when it misses or runs parallel to the plane.
    #[inline]
    pub fn line(&self, p: DVec3, dir: DVec3) -> Option<f64> {
        let den = dir.dot(self.normal);
        if den.abs() <= 1e-9 {
            return None;
        }
        let s = (self.corner - p).dot(self.normal) / den;
        let x = p + dir * s;
        (0..3)
            .all(|i| (x - self.edges[i].1).dot(self.edges[i].0) >= -self.slack[i])
            .then_some(s)
    }
}

/// Whether the closed triangles `a` and `b` share a point, counting contacts within `tol`.
/// A degenerate triangle (no area) is treated as its edges.
pub(crate) fn triangles_intersect(a: &[DVec3; 3], b: &[DVec3; 3], tol: f64) -> bool {
    let na = (a[1] - a[0]).cross(a[2] - a[0]);
    let nb = (b[1] - b[0]).cross(b[2] - b[0]);
    let (la, lb) = (na.length(), nb.length());
    let degenerate = |l: f64, t: &[DVec3; 3]| {
        let longest = (t[1] - t[0])
            .length_squared()
            .max((t[2] - t[1]).length_squared())
            .max((t[0] - t[2]).length_squared());
        l <= 1e-12 * longest || l == 0.0
    };
    let (da, db) = (degenerate(la, a), degenerate(lb, b));
    match (da, db) {
        (true, true) => segments_of_close(a, b, tol),
        (true, false) => edges_hit(a, b, nb / lb, tol),
        (false, true) => edges_hit(b, a, na / la, tol),
        (false, false) => {
            let (ua, ub) = (na / la, nb / lb);
            let dist_a = a.map(|p| (p - b[0]).dot(ub));
            if dist_a.iter().all(|&d| d > tol) || dist_a.iter().all(|&d| d < -tol) {
                return false;
            }
            let dist_b = b.map(|p| (p - a[0]).dot(ua));
            if dist_b.iter().all(|&d| d > tol) || dist_b.iter().all(|&d| d < -tol) {
                return false;
            }
            (0..3).any(|i| {
                let j = (i + 1) % 3;
                segment_hits_triangle(a[i], a[j], dist_a[i], dist_a[j], b, ub, tol)
                    || segment_hits_triangle(b[i], b[j], dist_b[i], dist_b[j], a, ua, tol)
            })
        }
    }
}

/// The edges of the degenerate triangle `seg` against the proper triangle `tri` (unit normal `n`).
fn edges_hit(seg: &[DVec3; 3], tri: &[DVec3; 3], n: DVec3, tol: f64) -> bool {
    let d = seg.map(|p| (p - tri[0]).dot(n));
    (0..3).any(|i| {
        let j = (i + 1) % 3;
        segment_hits_triangle(seg[i], seg[j], d[i], d[j], tri, n, tol)
    })
}

/// Two degenerate triangles: whether any of their edges come within `tol` of each other.
fn segments_of_close(a: &[DVec3; 3], b: &[DVec3; 3], tol: f64) -> bool {
    (0..3).any(|i| {
        (0..3).any(|j| segment_segment_distance(a[i], a[(i + 1) % 3], b[j], b[(j + 1) % 3]) <= tol)
    })
}

/// Whether segment `pq` meets triangle `t` (unit normal `n`), where `dp`, `dq` are the signed
/// distances of `p` and `q` from the triangle's plane.
#[inline]
fn segment_hits_triangle(
    p: DVec3,
    q: DVec3,
    dp: f64,
    dq: f64,
    t: &[DVec3; 3],
    n: DVec3,
    tol: f64,
) -> bool {
    if (dp > tol && dq > tol) || (dp < -tol && dq < -tol) {
        return false;
    }
    if dp.abs() <= tol && dq.abs() <= tol {
        return segment_triangle_in_plane(p, q, t, n, tol);
    }
    // One end is beyond `tol` from the plane, so dp != dq. A crossing outside the segment (both
    // ends on one side, one within `tol`) is clamped to the nearer end.
    let s = (dp / (dp - dq)).clamp(0.0, 1.0);
    point_in_triangle(p + (q - p) * s, t, n, tol)
}

/// Whether `x` (in or near the plane of `t`) lies inside `t`, widened by `tol`.
#[inline]
fn point_in_triangle(x: DVec3, t: &[DVec3; 3], n: DVec3, tol: f64) -> bool {
    (0..3).all(|i| {
        let (u, w) = (t[i], t[(i + 1) % 3]);
        let e = w - u;
        // Signed distance of x from the edge line, positive inside (t is counter-clockwise
        // about n).
        e.cross(x - u).dot(n) >= -tol * e.length()
    })
}

/// Segment `pq` lying in the plane of `t`: an end inside, or a crossing with an edge.
fn segment_triangle_in_plane(p: DVec3, q: DVec3, t: &[DVec3; 3], n: DVec3, tol: f64) -> bool {
    if point_in_triangle(p, t, n, tol) || point_in_triangle(q, t, n, tol) {
        return true;
    }
    (0..3).any(|i| segments_cross_in_plane(p, q, t[i], t[(i + 1) % 3], n, tol))
}

/// Whether segments `ab` and `cd`, both in the plane with unit normal `n`, cross (within `tol`).
fn segments_cross_in_plane(a: DVec3, b: DVec3, c: DVec3, d: DVec3, n: DVec3, tol: f64) -> bool {
    let side = |u: DVec3, w: DVec3, x: DVec3| {
        let e = w - u;
        let l = e.length();
        if l == 0.0 {
            0.0
        } else {
            e.cross(x - u).dot(n) / l
        }
    };
    let (s1, s2) = (side(a, b, c), side(a, b, d));
    let (s3, s4) = (side(c, d, a), side(c, d, b));
    let apart = |x: f64, y: f64| (x > tol && y > tol) || (x < -tol && y < -tol);
    if apart(s1, s2) || apart(s3, s4) {
        return false;
    }
    // Collinear within tol: overlap of the projections on the line, or close ends.
    if s1.abs() <= tol && s2.abs() <= tol {
        return segment_segment_distance(a, b, c, d) <= tol;
    }
    true
}

/// Distance between segments `ab` and `cd`.
pub(crate) fn segment_segment_distance(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    let (u, v, w) = (b - a, d - c, a - c);
    let (aa, bb, cc) = (u.dot(u), u.dot(v), v.dot(v));
    let (dd, ee) = (u.dot(w), v.dot(w));
    let den = aa * cc - bb * bb;
    let point_segment = |p: DVec3, s0: DVec3, s1: DVec3| {
        let e = s1 - s0;
        let l2 = e.length_squared();
        let t = if l2 > 0.0 {
            ((p - s0).dot(e) / l2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (p - (s0 + e * t)).length()
    };
    let mut best = point_segment(a, c, d)
        .min(point_segment(b, c, d))
        .min(point_segment(c, a, b))
        .min(point_segment(d, a, b));
    if den > 1e-18 * aa * cc {
        let s = (bb * ee - cc * dd) / den;
        let t = (aa * ee - bb * dd) / den;
        if (0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&t) {
            best = best.min(((a + u * s) - (c + v * t)).length());
        }
    }
    best
}

/// Whether triangle `t` overlaps the box `[lo, hi]` (separating axes; touching counts).
#[cfg(test)]
pub(crate) fn triangle_overlaps_box(t: &[DVec3; 3], lo: DVec3, hi: DVec3) -> bool {
    TriangleBoxTest::new(t, 0.0).overlaps(Vec3A::from(lo.as_vec3()), Vec3A::from(hi.as_vec3()))
}

/// Lanes of the nine edge–axis cross products, padded to a multiple of four.
const LANES: usize = 12;

/// The separating-axis test of one triangle against many boxes (the nodes of a BVH), with
/// everything that depends on the triangle alone computed once: its box, its plane, and its
/// extent along the nine edge–axis cross products.
///
/// The boxes are the BVH's `f32` boxes, so the test runs in `f32`, lane by lane. It stays
/// conservative (it never calls a touching pair separate): the axes are rounded to `f32` first
/// and the triangle's extent along each rounded axis is computed in `f64` and rounded outwards;
/// a box's half-size is widened by the contact tolerance and by 10⁻⁵ of its centre's and size's
/// magnitude, far more than the rounding of the `f32` sums. A separating axis that is off by a
/// rounding still separates: only the intervals must be right, and they are.
pub(crate) struct TriangleBoxTest {
    lo: Vec3A,
    hi: Vec3A,
    normal: Vec3A,
    /// The triangle's extent along `normal`.
    offsets: (f32, f32),
    ax: [f32; LANES],
    ay: [f32; LANES],
    az: [f32; LANES],
    min: [f32; LANES],
    max: [f32; LANES],
    tol: f32,
}

/// `x` rounded to `f32` towards minus (`down`) or plus infinity.
fn round_f32(x: f64, down: bool) -> f32 {
    let r = x as f32;
    match (down, (r as f64) > x, (r as f64) < x) {
        (true, true, _) => r.next_down(),
        (false, _, true) => r.next_up(),
        _ => r,
    }
}

impl TriangleBoxTest {
    /// The test for triangle `t`, with contacts within `tol` counted as overlaps.
    pub fn new(t: &[DVec3; 3], tol: f64) -> Self {
        let e = [t[1] - t[0], t[2] - t[1], t[0] - t[2]];
        let extent = |axis: DVec3| {
            let p = [axis.dot(t[0]), axis.dot(t[1]), axis.dot(t[2])];
            (
                round_f32(p[0].min(p[1]).min(p[2]), true),
                round_f32(p[0].max(p[1]).max(p[2]), false),
            )
        };
        let normal = e[0].cross(e[1]).as_vec3();
        let mut test = TriangleBoxTest {
            lo: Vec3A::new(
                round_f32(t[0].x.min(t[1].x).min(t[2].x), true),
                round_f32(t[0].y.min(t[1].y).min(t[2].y), true),
                round_f32(t[0].z.min(t[1].z).min(t[2].z), true),
            ),
            hi: Vec3A::new(
                round_f32(t[0].x.max(t[1].x).max(t[2].x), false),
                round_f32(t[0].y.max(t[1].y).max(t[2].y), false),
                round_f32(t[0].z.max(t[1].z).max(t[2].z), false),
            ),
            normal: Vec3A::from(normal),
            offsets: extent(normal.as_dvec3()),
            ax: [0.0; LANES],
            ay: [0.0; LANES],
            az: [0.0; LANES],
            // Padding lanes never separate.
            min: [f32::NEG_INFINITY; LANES],
            max: [f32::INFINITY; LANES],
            tol: tol as f32 * 1.01,
        };
        for (i, edge) in e.iter().enumerate() {
            for (j, axis) in [
                DVec3::new(0.0, -edge.z, edge.y),
                DVec3::new(edge.z, 0.0, -edge.x),
                DVec3::new(-edge.y, edge.x, 0.0),
            ]
            .into_iter()
            .enumerate()
            {
                let axis = axis.as_vec3();
                let k = 3 * i + j;
                (test.ax[k], test.ay[k], test.az[k]) = (axis.x, axis.y, axis.z);
                (test.min[k], test.max[k]) = extent(axis.as_dvec3());
            }
        }
        test
    }

    /// Whether the triangle overlaps the box `[lo, hi]` widened by the tolerance (touching
    /// counts).
    #[inline]
    pub fn overlaps(&self, lo: Vec3A, hi: Vec3A) -> bool {
        let tol = Vec3A::splat(self.tol);
        if self.lo.cmpgt(hi + tol).any() || self.hi.cmplt(lo - tol).any() {
            return false;
        }
        let c = (lo + hi) * 0.5;
        let h0 = (hi - lo) * 0.5;
        let h = h0 + tol + (c.abs() + h0) * 1e-5;
        let pc = self.normal.dot(c);
        let pr = self.normal.abs().dot(h);
        if self.offsets.0 - pc > pr || self.offsets.1 - pc < -pr {
            return false;
        }
        let mut separated = false;
        for k in 0..LANES {
            let ac = self.ax[k] * c.x + self.ay[k] * c.y + self.az[k] * c.z;
            let r = self.ax[k].abs() * h.x + self.ay[k].abs() * h.y + self.az[k].abs() * h.z;
            separated |= (self.min[k] - ac > r) | (self.max[k] - ac < -r);
        }
        !separated
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn d(x: f64, y: f64, z: f64) -> DVec3 {
        DVec3::new(x, y, z)
    }

    const TOL: f64 = 1e-12;

    #[test]
    fn crossing_and_separated_triangles() {
        let a = [d(0., 0., 0.), d(2., 0., 0.), d(0., 2., 0.)];
        // Pierces a's interior.
        let b = [d(0.5, 0.5, -1.), d(0.5, 0.5, 1.), d(1.5, 1.5, 1.)];
        assert!(triangles_intersect(&a, &b, TOL));
        assert!(triangles_intersect(&b, &a, TOL));
        // Same, lifted above a's plane.
        let c = b.map(|p| p + d(0., 0., 1.5));
        assert!(!triangles_intersect(&a, &c, TOL));
        // Beside a, crossing its plane but outside its area.
        let e = b.map(|p| p + d(3., 0., 0.));
        assert!(!triangles_intersect(&a, &e, TOL));
        // Interpenetrating without any vertex inside the other (an edge through the interior).
        let f = [d(-1., 0.5, -1.), d(3., 0.5, -1.), d(1., 0.5, 1.)];
        assert!(triangles_intersect(&a, &f, TOL));
    }

    #[test]
    fn coplanar_cases() {
        let a = [d(0., 0., 0.), d(2., 0., 0.), d(0., 2., 0.)];
        // Overlapping, no vertex of one inside the other? (a star of David style)
        let b = [d(1.5, 1.5, 0.), d(-0.5, 0.5, 0.), d(0.5, -0.5, 0.)];
        assert!(triangles_intersect(&a, &b, TOL));
        // Contained.
        let c = [d(0.1, 0.1, 0.), d(0.5, 0.1, 0.), d(0.1, 0.5, 0.)];
        assert!(triangles_intersect(&a, &c, TOL));
        assert!(triangles_intersect(&c, &a, TOL));
        // Disjoint in the same plane.
        let e = [d(3., 3., 0.), d(4., 3., 0.), d(3., 4., 0.)];
        assert!(!triangles_intersect(&a, &e, TOL));
        // Touching at a vertex counts.
        let f = [d(2., 0., 0.), d(3., 0., 0.), d(3., 1., 0.)];
        assert!(triangles_intersect(&a, &f, TOL));
    }

    #[test]
    fn parallel_planes_and_degenerate() {
        let a = [d(0., 0., 0.), d(1., 0., 0.), d(0., 1., 0.)];
        let b = a.map(|p| p + d(0., 0., 1e-6));
        assert!(!triangles_intersect(&a, &b, 1e-9));
        assert!(triangles_intersect(&a, &b, 1e-5));
        // A degenerate triangle (a segment) piercing a.
        let s = [d(0.2, 0.2, -1.), d(0.2, 0.2, 1.), d(0.2, 0.2, 0.5)];
        assert!(triangles_intersect(&a, &s, TOL));
        assert!(triangles_intersect(&s, &a, TOL));
        let s2 = s.map(|p| p + d(5., 0., 0.));
        assert!(!triangles_intersect(&a, &s2, TOL));
    }

    #[test]
    fn triangle_box_overlap() {
        let lo = d(0., 0., 0.);
        let hi = d(1., 1., 1.);
        assert!(triangle_overlaps_box(
            &[d(0.5, 0.5, 0.5), d(5., 0.5, 0.5), d(0.5, 5., 0.5)],
            lo,
            hi
        ));
        // A big triangle whose box covers the cube but whose plane misses it.
        assert!(!triangle_overlaps_box(
            &[d(3., -5., -5.), d(3., 10., -5.), d(-6., 2., 10.)].map(|p| p + d(0., 0., 0.)),
            d(-10., -10., -10.),
            d(-9., -9., -9.)
        ));
        // The plane x + y + z = 2.9 cuts the unit cube near the far corner.
        let t = [d(2.9, 0., 0.), d(0., 2.9, 0.), d(0., 0., 2.9)];
        assert!(triangle_overlaps_box(&t, lo, hi));
        let t = [d(3.1, 0., 0.), d(0., 3.1, 0.), d(0., 0., 3.1)];
        assert!(!triangle_overlaps_box(&t, lo, hi));
        // Random triangles: a sampled point inside the box implies an overlap.
        let mut seed = 12345u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 4.0 - 1.5
        };
        let mut overlaps = 0;
        for _ in 0..2000 {
            let t = [
                d(next(), next(), next()),
                d(next(), next(), next()),
                d(next(), next(), next()),
            ];
            let reported = triangle_overlaps_box(&t, lo, hi);
            overlaps += reported as usize;
            for i in 0..=20 {
                for j in 0..=20 - i {
                    let (u, v) = (i as f64 / 20.0, j as f64 / 20.0);
                    let p = t[0] + (t[1] - t[0]) * u + (t[2] - t[0]) * v;
                    let inside = p.cmpge(lo).all() && p.cmple(hi).all();
                    assert!(!inside || reported, "{t:?}");
                }
            }
        }
        assert!(overlaps > 100 && overlaps < 1900, "{overlaps}");
    }

    #[test]
    fn segment_distances() {
        let dd = segment_segment_distance(
            d(0., 0., 0.),
            d(1., 0., 0.),
            d(0.5, 1., 1.),
            d(0.5, -1., 1.),
        );
        assert!((dd - 1.0).abs() < 1e-12);
        let dd =
            segment_segment_distance(d(0., 0., 0.), d(1., 0., 0.), d(2., 0., 0.), d(3., 0., 0.));
        assert!((dd - 1.0).abs() < 1e-12);
    }
}
