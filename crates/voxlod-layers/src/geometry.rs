//! Small exact-enough geometry for visibility ordering: projecting triangles along a view
//! (orthographic or from an eye), clipping one projected triangle by another, and comparing
//! the depths of two triangles along the ray through a point of their common projection.
//!
//! Two triangles that do not cross in 3-D and whose projections overlap are in a fixed
//! front/back relation over the whole overlap (the depth difference is affine there and has no
//! zero), so one interior point of the overlap decides it. Cost: O(1) per pair.

use glam::{DVec2, DVec3};

/// How points map to the image plane: along `direction` (orthographic), or from `eye` through a
/// plane perpendicular to `direction` (perspective; points must lie in front of the eye).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Projector {
    /// The eye of a perspective projection; `None` for orthographic.
    pub eye: Option<DVec3>,
    /// Unit view direction (eye to scene).
    pub direction: DVec3,
    u: DVec3,
    v: DVec3,
}

impl Projector {
    /// Orthographic along `direction` (need not be normalised, must not be zero).
    pub fn orthographic(direction: DVec3) -> Projector {
        Self::build(None, direction)
    }

    /// From `eye`, with image plane perpendicular to `direction`.
    pub fn perspective(eye: DVec3, direction: DVec3) -> Projector {
        Self::build(Some(eye), direction)
    }

    fn build(eye: Option<DVec3>, direction: DVec3) -> Projector {
        let d = direction.normalize();
        debug_assert!(d.is_finite(), "zero view direction");
        let helper = if d.x.abs() < 0.6 {
            DVec3::X
        } else if d.y.abs() < 0.6 {
            DVec3::Y
        } else {
            DVec3::Z
        };
        let u = d.cross(helper).normalize();
        let v = d.cross(u);
        Projector {
            eye,
            direction: d,
            u,
            v,
        }
    }

    /// Image-plane coordinates and depth (distance along the view for orthographic, along the
    /// ray from the eye for perspective); `None` for a point not in front of the eye.
    #[inline]
    pub fn project(&self, p: DVec3) -> Option<(DVec2, f64)> {
        match self.eye {
            None => Some((
                DVec2::new(p.dot(self.u), p.dot(self.v)),
                p.dot(self.direction),
            )),
            Some(e) => {
                let r = p - e;
                let z = r.dot(self.direction);
                if z.is_nan() || z <= 1e-12 * r.length() {
                    return None;
                }
                Some((DVec2::new(r.dot(self.u) / z, r.dot(self.v) / z), r.length()))
            }
        }
    }

    /// Ray parameter at which the ray through image point `q` meets the plane `n · x = c`
    /// (larger is farther); `None` when the ray runs along the plane.
    #[inline]
    pub fn depth_on_plane(&self, q: DVec2, n: DVec3, c: f64) -> Option<f64> {
        let (origin, dir) = match self.eye {
            None => (q.x * self.u + q.y * self.v, self.direction),
            Some(e) => (e, self.direction + q.x * self.u + q.y * self.v),
        };
        let den = n.dot(dir);
        let t = (c - n.dot(origin)) / den;
        (den.abs() > 1e-300 && t.is_finite()).then_some(t)
    }
}

/// A triangle prepared for pair tests: its projection, projected box and plane.
#[derive(Clone, Copy, Debug)]
pub struct Projected {
    /// The corners on the image plane.
    pub corners: [DVec2; 3],
    /// Lower corner of the projected box.
    pub min: DVec2,
    /// Upper corner of the projected box.
    pub max: DVec2,
    /// Twice the signed projected area.
    pub area2: f64,
    /// The plane's normal (not normalised: the cross product of two edges).
    pub normal: DVec3,
    /// The plane is `normal · x = offset`.
    pub offset: f64,
    /// Depth of the centroid.
    pub depth: f64,
    /// Smallest depth of a corner.
    pub depth_min: f64,
    /// Largest depth of a corner.
    pub depth_max: f64,
    /// The corners in the world.
    pub world: [DVec3; 3],
    /// Positive on the eye's side of the plane: `n · x − offset` times this is positive for
    /// points on the side of the eye.
    pub eye_sign: f64,
    /// Distances `n · x − offset` below this count as on the plane.
    pub plane_tol: f64,
}

impl Projected {
    /// `None` when a corner is not in front of the eye.
    pub fn new(projector: &Projector, p: [DVec3; 3]) -> Option<Projected> {
        let a = projector.project(p[0])?;
        let b = projector.project(p[1])?;
        let c = projector.project(p[2])?;
        let corners = [a.0, b.0, c.0];
        let normal = (p[1] - p[0]).cross(p[2] - p[0]);
        let centroid = (p[0] + p[1] + p[2]) / 3.0;
        let depth = projector
            .project(centroid)
            .map_or((a.1 + b.1 + c.1) / 3.0, |x| x.1);
        let offset = normal.dot(p[0]);
        let eye_sign = match projector.eye {
            None => -normal.dot(projector.direction),
            Some(e) => normal.dot(e) - offset,
        };
        let scale = p[0].abs().max_element()
            + (p[1] - p[0]).abs().max_element()
            + (p[2] - p[0]).abs().max_element();
        Some(Projected {
            depth_min: a.1.min(b.1).min(c.1),
            depth_max: a.1.max(b.1).max(c.1),
            plane_tol: 1e-9 * normal.length() * scale,
            world: p,
            eye_sign: if eye_sign > 0.0 {
                1.0
            } else if eye_sign < 0.0 {
                -1.0
            } else {
                0.0
            },
            corners,
            min: a.0.min(b.0).min(c.0),
            max: a.0.max(b.0).max(c.0),
            area2: (corners[1] - corners[0]).perp_dot(corners[2] - corners[0]),
            normal,
            offset,
            depth,
        })
    }

    /// Whether the projected boxes overlap (touching does not count).
    #[inline]
    pub fn boxes_overlap(&self, other: &Projected) -> bool {
        self.min.x < other.max.x
            && other.min.x < self.max.x
            && self.min.y < other.max.y
            && other.min.y < self.max.y
    }
}

/// A convex polygon of at most 9 corners (a triangle clipped by three half-planes).
#[derive(Clone, Copy, Debug)]
pub struct Polygon {
    /// The corners, counter-clockwise; only the first `len` are used.
    pub corners: [DVec2; 9],
    /// How many corners the polygon has.
    pub len: usize,
}

impl Polygon {
    /// The signed area (positive counter-clockwise).
    pub fn area(&self) -> f64 {
        let mut a = 0.0;
        for i in 0..self.len {
            a += self.corners[i].perp_dot(self.corners[(i + 1) % self.len]);
        }
        0.5 * a
    }

    /// The centroid of the corners (inside, the polygon being convex).
    pub fn centre(&self) -> DVec2 {
        self.corners[..self.len].iter().copied().sum::<DVec2>() / self.len as f64
    }
}

/// The intersection of two projected triangles (either orientation), as a counter-clockwise
/// convex polygon (possibly empty).
pub fn clip(a: &[DVec2; 3], b: &[DVec2; 3]) -> Polygon {
    let ccw = |t: &[DVec2; 3]| {
        if (t[1] - t[0]).perp_dot(t[2] - t[0]) < 0.0 {
            [t[0], t[2], t[1]]
        } else {
            *t
        }
    };
    let a = ccw(a);
    let b = ccw(b);
    let mut poly = Polygon {
        corners: [DVec2::ZERO; 9],
        len: 3,
    };
    poly.corners[..3].copy_from_slice(&a);
    for e in 0..3 {
        let (p, q) = (b[e], b[(e + 1) % 3]);
        let edge = q - p;
        let side = |x: DVec2| edge.perp_dot(x - p);
        let mut out = Polygon {
            corners: [DVec2::ZERO; 9],
            len: 0,
        };
        for i in 0..poly.len {
            let cur = poly.corners[i];
            let nxt = poly.corners[(i + 1) % poly.len];
            let (sc, sn) = (side(cur), side(nxt));
            if sc >= 0.0 {
                push(&mut out, cur);
            }
            if (sc >= 0.0) != (sn >= 0.0) {
                let t = sc / (sc - sn);
                push(&mut out, cur + (nxt - cur) * t);
            }
        }
        poly = out;
        if poly.len < 3 {
            poly.len = 0;
            break;
        }
    }
    poly
}

#[inline]
fn push(p: &mut Polygon, x: DVec2) {
    if p.len < p.corners.len() {
        p.corners[p.len] = x;
        p.len += 1;
    }
}

/// Where the corners of `q` lie with respect to the plane of `p`, seen from the eye.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Side {
    /// All on the eye's side (corners on the plane allowed).
    Front,
    /// All on the far side.
    Back,
    /// All on the plane.
    On,
    Mixed,
}

fn side(p: &Projected, q: &Projected) -> Side {
    if p.eye_sign == 0.0 {
        return Side::Mixed;
    }
    let tol = p.plane_tol;
    let (mut front, mut back) = (false, false);
    for c in &q.world {
        let s = (p.normal.dot(*c) - p.offset) * p.eye_sign;
        front |= s > tol;
        back |= s < -tol;
    }
    match (front, back) {
        (true, false) => Side::Front,
        (false, true) => Side::Back,
        (false, false) => Side::On,
        (true, true) => Side::Mixed,
    }
}

/// Whether two projected triangles overlap with some area (separating axis test on the six
/// edge normals; touching counts as apart).
pub fn projections_overlap(a: &Projected, b: &Projected) -> bool {
    let extent = (a.max - a.min).max(b.max - b.min).max_element();
    let tol = 1e-9 * extent;
    !separated_by_edges(a, b, tol) && !separated_by_edges(b, a, tol)
}

/// Whether an edge normal of `t` separates it from `o`. Along the normal of edge (p, q), `t`
/// spans from the edge to its third corner; `o` must lie wholly beyond the edge.
#[inline]
fn separated_by_edges(t: &Projected, o: &Projected, tol: f64) -> bool {
    for e in 0..3 {
        let p = t.corners[e];
        let q = t.corners[(e + 1) % 3];
        let r = t.corners[(e + 2) % 3];
        let axis = DVec2::new(p.y - q.y, q.x - p.x);
        let edge = p.dot(axis);
        let third = r.dot(axis) - edge;
        // Slack in the axis' units (|axis| ≤ L1 norm).
        let slack = tol * (axis.x.abs() + axis.y.abs());
        let d = [
            o.corners[0].dot(axis) - edge,
            o.corners[1].dot(axis) - edge,
            o.corners[2].dot(axis) - edge,
        ];
        if third > 0.0 {
            if d[0] <= slack && d[1] <= slack && d[2] <= slack {
                return true;
            }
        } else if third < 0.0 && d[0] >= -slack && d[1] >= -slack && d[2] >= -slack {
            return true;
        }
    }
    false
}

/// [`behind`], faster for the common case: when one triangle lies wholly on one side of the
/// other's plane, the plane says which is behind wherever they overlap, and a separating axis
/// test says whether they overlap; only triangles that straddle each other's planes need the
/// clipped overlap.
pub fn behind_fast(
    projector: &Projector,
    a: &Projected,
    b: &Projected,
    rel_area: f64,
) -> Option<bool> {
    if !a.boxes_overlap(b) {
        return None;
    }
    let relation = match side(b, a) {
        Side::Back => true,
        Side::Front => false,
        Side::On => return None,
        Side::Mixed => match side(a, b) {
            Side::Back => false,
            Side::Front => true,
            Side::On => return None,
            Side::Mixed => return behind(projector, a, b, rel_area),
        },
    };
    projections_overlap(a, b).then_some(relation)
}

/// Whether `b` lies behind `a` somewhere their projections overlap, so that `b` must be drawn
/// first although `a` comes first by centroid depth. Cheap when the answer is no, which is
/// what a good depth sort makes common: disjoint depth ranges or boxes settle it at once, then
/// the planes (`b` wholly in front of `a`'s plane, or `a` wholly behind `b`'s), and only a
/// "yes" from the planes needs the overlap test.
pub fn second_is_behind(
    projector: &Projector,
    a: &Projected,
    b: &Projected,
    rel_area: f64,
) -> bool {
    if a.depth_min >= b.depth_max || !a.boxes_overlap(b) {
        return false;
    }
    match side(a, b) {
        Side::Back => projections_overlap(a, b),
        Side::Front | Side::On => false,
        Side::Mixed => match side(b, a) {
            Side::Front => projections_overlap(a, b),
            Side::Back | Side::On => false,
            Side::Mixed => behind(projector, a, b, rel_area) == Some(false),
        },
    }
}

/// Which of two projected triangles is behind the other where their projections overlap:
/// `Some(true)` when `a` is behind `b` (draw `a` first), `Some(false)` when `b` is behind `a`,
/// `None` when the projections do not overlap by more than `rel_area` of the smaller one, or
/// the depths are equal there.
pub fn behind(projector: &Projector, a: &Projected, b: &Projected, rel_area: f64) -> Option<bool> {
    if !a.boxes_overlap(b) {
        return None;
    }
    let poly = clip(&a.corners, &b.corners);
    if poly.len < 3 {
        return None;
    }
    let smaller = a.area2.abs().min(b.area2.abs()) * 0.5;
    let area = poly.area();
    if area.is_nan() || area <= rel_area * smaller || smaller <= 0.0 {
        return None;
    }
    let q = poly.centre();
    let ta = projector.depth_on_plane(q, a.normal, a.offset)?;
    let tb = projector.depth_on_plane(q, b.normal, b.offset)?;
    let tol = 1e-9 * (ta.abs() + tb.abs()) + 1e-300;
    if ta > tb + tol {
        Some(true)
    } else if tb > ta + tol {
        Some(false)
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clip_of_overlapping_triangles_has_the_expected_area() {
        let a = [DVec2::new(0., 0.), DVec2::new(2., 0.), DVec2::new(0., 2.)];
        let b = [DVec2::new(0., 0.), DVec2::new(1., 0.), DVec2::new(0., 1.)];
        assert!((clip(&a, &b).area() - 0.5).abs() < 1e-12);
        // Clockwise input is handled.
        let bw = [b[0], b[2], b[1]];
        assert!((clip(&a, &bw).area() - 0.5).abs() < 1e-12);
        // Sharing only an edge: no area.
        let c = [DVec2::new(2., 0.), DVec2::new(0., 2.), DVec2::new(2., 2.)];
        assert!(clip(&a, &c).area().abs() < 1e-12);
        // A hexagon from two opposite triangles.
        let up = [DVec2::new(0., 0.), DVec2::new(3., 0.), DVec2::new(1.5, 3.)];
        let down = [DVec2::new(0., 2.), DVec2::new(1.5, -1.), DVec2::new(3., 2.)];
        let p = clip(&up, &down);
        assert_eq!(p.len, 6);
    }

    #[test]
    fn the_fast_test_agrees_with_the_clipped_one() {
        // Pseudo-random triangle pairs in a unit box, several views.
        let mut seed = 12345u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut decided = 0;
        for view in [
            Projector::orthographic(DVec3::new(0.3, -0.5, 1.0)),
            Projector::perspective(DVec3::new(-3.0, 1.0, -4.0), DVec3::new(3.0, -1.0, 4.5)),
        ] {
            for _ in 0..3000 {
                let mut tri = || {
                    let base = DVec3::new(rnd(), rnd(), rnd());
                    [0, 1, 2].map(|_| base + 0.4 * DVec3::new(rnd(), rnd(), rnd()))
                };
                let (ta, tb) = (tri(), tri());
                let a = Projected::new(&view, ta).unwrap();
                let b = Projected::new(&view, tb).unwrap();
                let slow = behind(&view, &a, &b, 1e-7);
                let fast = behind_fast(&view, &a, &b, 1e-7);
                if slow == Some(false) && clip(&a.corners, &b.corners).area() > 1e-3 {
                    assert!(second_is_behind(&view, &a, &b, 1e-7));
                }
                if slow == Some(true) {
                    assert!(!second_is_behind(&view, &a, &b, 1e-7));
                }
                if let (Some(x), Some(y)) = (slow, fast) {
                    assert_eq!(x, y);
                    decided += 1;
                }
                // Where the clipped test finds a clear overlap, the fast one decides too.
                if slow.is_some() {
                    let poly = clip(&a.corners, &b.corners);
                    if poly.area() > 1e-3 {
                        assert!(fast.is_some());
                    }
                }
            }
        }
        assert!(decided > 300, "{decided}");
    }

    #[test]
    fn behind_follows_the_view() {
        let tri = |z: f64| {
            [
                DVec3::new(0., 0., z),
                DVec3::new(1., 0., z),
                DVec3::new(0., 1., z),
            ]
        };
        for (proj, near_z) in [
            (Projector::orthographic(DVec3::new(0.1, 0.2, 1.0)), 0.0),
            (Projector::orthographic(DVec3::new(0.0, 0.0, -1.0)), 1.0),
            (
                Projector::perspective(DVec3::new(0.2, 0.2, -5.0), DVec3::Z),
                0.0,
            ),
        ] {
            let a = Projected::new(&proj, tri(0.0)).unwrap();
            let b = Projected::new(&proj, tri(1.0)).unwrap();
            let a_behind = behind(&proj, &a, &b, 1e-9).unwrap();
            assert_eq!(a_behind, near_z == 1.0, "{proj:?}");
        }
        // Far apart sideways: no relation.
        let p = Projector::orthographic(DVec3::Z);
        let a = Projected::new(&p, tri(0.0)).unwrap();
        let mut far = tri(1.0);
        for c in &mut far {
            c.x += 5.0;
        }
        let b = Projected::new(&p, far).unwrap();
        assert_eq!(behind(&p, &a, &b, 1e-9), None);
    }
}
