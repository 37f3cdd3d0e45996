//! Triangulating one polygon face by ear clipping.
//!
//! A face of an OBJ, OFF, PLY or VTK file may have any number of corners and need not be
//! convex; a fan from its first corner is then wrong (triangles fold outside the face). We
//! project the polygon onto the plane of its Newell normal, where it winds counter-clockwise,
//! and repeatedly cut off an *ear*: three consecutive corners that turn left and whose triangle
//! contains no other corner. Every ear keeps the polygon's winding, so the triangles face the
//! way the polygon did.
//!
//! Cost: the textbook method tests every corner against every candidate ear, O(n²) for n
//! corners (a 200,000-corner face took minutes). Here only the corners that can block an ear,
//! the reflex ones, are kept, in a uniform grid of about one cell per corner (`reflex_grid.rs`;
//! Mapbox's earcut has the same idea with a z-order hash), and an ear test looks only at the
//! cells its triangle crosses. Corners on a straight line are set aside and put back at the end
//! (`ring.rs`), and the search steps back after a cut only where the new ear is small. Measured
//! work per corner (cells and corners looked at): a comb 7, a spiral band 27, at every size
//! from 10³ to 4·10⁵ corners; a star, whose every spike spans half the face, about 0.7·√n.
//! The work is capped at n·(32 + 2√n) + 4·10⁶; a face that exceeds it (a self-intersecting or
//! adversarial one) has the rest of its ring split as a fan, so that no face holds the reader
//! up.
//!
//! Real files hold faces that are not simple polygons: repeated corners, corners on a straight
//! line, slight non-planarity, self-intersections. When no proper ear exists we relax the test
//! step by step (corners on the ear's boundary allowed, then the most convex corner taken
//! regardless), so the result always has exactly n − 2 triangles, never panics, and is exact
//! for every simple polygon. Degenerate triangles that a degenerate face forces are kept: the
//! readers do not repair (see `voxlod_core::repair`).

mod reflex_grid;
mod ring;

use std::collections::HashMap;

use glam::{DVec2, DVec3};
use ring::Ring;

/// The Newell normal of a closed polygon: twice its vector area, robust to non-planarity.
/// Zero for a polygon without area.
pub fn newell_normal(points: &[DVec3]) -> DVec3 {
    let n = points.len();
    let mut normal = DVec3::ZERO;
    if n < 3 {
        return normal;
    }
    // Relative to the first corner, for precision far from the origin.
    let base = points[0];
    for i in 0..n {
        let a = points[i] - base;
        let b = points[(i + 1) % n] - base;
        normal += DVec3::new(
            (a.y - b.y) * (a.z + b.z),
            (a.z - b.z) * (a.x + b.x),
            (a.x - b.x) * (a.y + b.y),
        );
    }
    normal
}

/// Splits a polygon into `n - 2` triangles of indices into `points`, winding as the polygon
/// does. Fewer than three points give no triangle.
pub fn triangulate(points: &[DVec3]) -> Vec<[usize; 3]> {
    let n = points.len();
    if n < 3 {
        return Vec::new();
    }
    if n == 3 {
        return vec![[0, 1, 2]];
    }
    let normal = newell_normal(points);
    let length = normal.length();
    if !(length.is_finite() && length > 0.0) {
        // No area (or non-finite coordinates): any split is as good as any other.
        return (1..n - 1).map(|i| [0, i, i + 1]).collect();
    }
    let w = normal / length;
    // An orthonormal basis (u, v) of the plane with u × v = w: the polygon winds
    // counter-clockwise in it.
    let u = w.any_orthonormal_vector();
    let v = w.cross(u);
    let base = points[0];
    let flat: Vec<DVec2> = points
        .iter()
        .map(|&p| {
            let d = p - base;
            DVec2::new(d.dot(u), d.dot(v))
        })
        .collect();
    clip_ears(&flat)
}

/// Twice the signed area of triangle (a, b, c): positive when it turns left.
#[inline]
fn turn(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    (b - a).perp_dot(c - b)
}

/// How strictly a candidate ear must be free of other corners.
#[derive(Clone, Copy, PartialEq)]
enum Rule {
    /// Convex, and no other corner inside or on the boundary: the textbook ear.
    Strict,
    /// Convex, and no other corner strictly inside (corners on its edges allowed).
    Relaxed,
}

/// Ear clipping of a counter-clockwise polygon in the plane.
fn clip_ears(p: &[DVec2]) -> Vec<[usize; 3]> {
    let n = p.len();
    let mut ring = Ring::new(p);
    let mut triangles = Vec::with_capacity(n - 2);
    let mut current = ring.first();
    // Corners examined since the last cut; a full round without an ear calls for a fallback.
    let mut misses = 0;
    while ring.remaining > 3 {
        if ring.work > ring.work_limit {
            ring.fan_rest(current, &mut triangles);
            break;
        }
        let ear = if misses < ring.remaining {
            ring.is_ear(current, Rule::Strict).then_some(current)
        } else {
            // A full round found no textbook ear: the face is not a simple polygon.
            Some(ring.fallback_ear(current))
        };
        match ear {
            Some(b) => {
                let triangle = ring.cut(b);
                triangles.push(triangle);
                misses = 0;
                // Where to look next. Stepping back to `a`, whose ear may just have appeared,
                // zips up long bands in one pass; but where `a`'s new triangle is large it
                // would fan long, costly triangles from one corner, and walking on past `c`
                // (as earcut does) keeps the ears local.
                let a = ring.live(triangle[0]);
                current = if ring.is_small_ear(a) {
                    a
                } else {
                    ring.next[ring.live(triangle[2])]
                };
            }
            None => {
                current = ring.next[current];
                misses += 1;
                ring.work += 1;
            }
        }
    }
    if ring.remaining == 3 {
        let (a, c) = (ring.prev[current], ring.next[current]);
        triangles.push([a, current, c]);
    }
    reinsert_collinear(&mut triangles, &ring.collinear);
    debug_assert_eq!(triangles.len(), n - 2);
    triangles
}

/// Puts back the corners that were taken out of the ring for lying on the straight line
/// between their neighbours `u` and `w`: the one triangle with the edge (u, w) is split in two
/// at the corner, last taken out first (a corner may lie on an edge that itself held another).
/// An edge no triangle has (only after a fallback on a non-simple face) gets a flat triangle,
/// so the count stays n - 2.
fn reinsert_collinear(triangles: &mut Vec<[usize; 3]>, collinear: &[[usize; 3]]) {
    if collinear.is_empty() {
        return;
    }
    let key = |a: usize, b: usize| (a.min(b), a.max(b));
    let mut by_edge: HashMap<(usize, usize), usize> = HashMap::with_capacity(3 * triangles.len());
    for (t, tri) in triangles.iter().enumerate() {
        for k in 0..3 {
            by_edge.insert(key(tri[k], tri[(k + 1) % 3]), t);
        }
    }
    for &[u, v, w] in collinear.iter().rev() {
        let Some(t) = by_edge.remove(&key(u, w)) else {
            triangles.push([u, v, w]);
            continue;
        };
        // Rotate the triangle to [p, q, opposite] with {p, q} = {u, w}, keeping its winding.
        let mut tri = triangles[t];
        while !(tri[2] != u && tri[2] != w) {
            tri.rotate_left(1);
        }
        let [p, q, opposite] = tri;
        triangles[t] = [p, v, opposite];
        triangles.push([v, q, opposite]);
        // The edge (q, opposite) moved to the new triangle.
        let new = triangles.len() - 1;
        by_edge.insert(key(p, v), t);
        by_edge.insert(key(v, q), new);
        by_edge.insert(key(q, opposite), new);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area2(p: &[DVec2]) -> f64 {
        (0..p.len())
            .map(|i| p[i].perp_dot(p[(i + 1) % p.len()]))
            .sum::<f64>()
            / 2.0
    }

    fn inside(poly: &[DVec2], q: DVec2) -> bool {
        // Even-odd rule.
        let mut odd = false;
        let mut j = poly.len() - 1;
        for i in 0..poly.len() {
            let (a, b) = (poly[i], poly[j]);
            if (a.y > q.y) != (b.y > q.y) && q.x < (b.x - a.x) * (q.y - a.y) / (b.y - a.y) + a.x {
                odd = !odd;
            }
            j = i;
        }
        odd
    }

    /// Checks a triangulation of a simple polygon: n - 2 triangles, none inverted, each inside
    /// the polygon, areas adding up to the polygon's.
    fn check_simple(poly: &[DVec2]) {
        let lifted: Vec<DVec3> = poly.iter().map(|p| p.extend(0.0)).collect();
        let tris = triangulate(&lifted);
        assert_eq!(tris.len(), poly.len() - 2);
        let mut total = 0.0;
        for t in &tris {
            let [a, b, c] = t.map(|i| poly[i]);
            let area = turn(a, b, c) / 2.0;
            assert!(area > 0.0, "inverted or flat triangle {t:?}");
            total += area;
            assert!(
                inside(poly, (a + b + c) / 3.0),
                "triangle {t:?} lies outside"
            );
        }
        assert!((total - area2(poly)).abs() < 1e-9 * area2(poly).abs().max(1.0));
    }

    fn v2(x: f64, y: f64) -> DVec2 {
        DVec2::new(x, y)
    }

    #[test]
    fn l_shape_from_every_start() {
        let mut l = vec![
            v2(0., 0.),
            v2(2., 0.),
            v2(2., 1.),
            v2(1., 1.),
            v2(1., 3.),
            v2(0., 3.),
        ];
        // From (0, 0) a fan would do; from (2, 0) it would fold outside.
        for _ in 0..l.len() {
            check_simple(&l);
            l.rotate_left(1);
        }
    }

    #[test]
    fn star() {
        let star: Vec<DVec2> = (0..10)
            .map(|i| {
                let angle = std::f64::consts::PI * i as f64 / 5.0;
                let r = if i % 2 == 0 { 2.0 } else { 0.7 };
                v2(r * angle.cos(), r * angle.sin())
            })
            .collect();
        check_simple(&star);
    }

    #[test]
    fn comb_and_spiral() {
        // A comb with five teeth: many reflex corners in a row.
        let mut comb = vec![v2(0., 0.), v2(10., 0.)];
        for t in (0..5).rev() {
            let x = 2.0 * t as f64;
            comb.extend([
                v2(x + 2.0, 3.0),
                v2(x + 1.5, 3.0),
                v2(x + 1.5, 1.0),
                v2(x + 0.5, 1.0),
            ]);
            comb.push(v2(x + 0.5, 3.0));
            comb.push(v2(x, 3.0));
        }
        comb.dedup();
        check_simple(&comb);
    }

    #[test]
    fn winding_follows_the_polygon_in_any_plane() {
        // An L in a tilted plane, given clockwise as seen from +z.
        let flat = [
            v2(0., 0.),
            v2(0., 3.),
            v2(1., 3.),
            v2(1., 1.),
            v2(2., 1.),
            v2(2., 0.),
        ];
        let (ex, ey) = (DVec3::new(1.0, 0.0, 1.0), DVec3::new(0.0, 1.0, 0.5));
        let pts: Vec<DVec3> = flat
            .iter()
            .map(|p| DVec3::new(5., -2., 7.) + ex * p.x + ey * p.y)
            .collect();
        let normal = newell_normal(&pts);
        let tris = triangulate(&pts);
        assert_eq!(tris.len(), 4);
        let mut area = 0.0;
        for t in &tris {
            let [a, b, c] = t.map(|i| pts[i]);
            let n = (b - a).cross(c - a);
            assert!(n.dot(normal) > 0.0, "triangle {t:?} is inverted");
            area += n.length() / 2.0;
        }
        assert!((area - normal.length() / 2.0).abs() < 1e-9);
    }

    #[test]
    fn degenerate_faces_do_not_panic() {
        let p = |x: f64, y: f64| DVec3::new(x, y, 0.0);
        // A square with a corner in the middle of an edge, and a repeated corner.
        let square = [
            p(0., 0.),
            p(1., 0.),
            p(2., 0.),
            p(2., 2.),
            p(2., 2.),
            p(0., 2.),
        ];
        let tris = triangulate(&square);
        assert_eq!(tris.len(), 4);
        let area: f64 = tris
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| square[i]);
                (b - a).cross(c - a).z / 2.0
            })
            .sum();
        assert!((area - 4.0).abs() < 1e-12);
        // All corners on one line, all identical, non-finite, too few.
        let line: Vec<DVec3> = (0..6).map(|i| p(i as f64, 0.0)).collect();
        assert_eq!(triangulate(&line).len(), 4);
        assert_eq!(triangulate(&[p(1., 1.); 5]).len(), 3);
        assert_eq!(
            triangulate(&[p(0., 0.), p(f64::NAN, 0.), p(1., 1.), p(0., 1.)]).len(),
            2
        );
        assert!(triangulate(&[p(0., 0.), p(1., 0.)]).is_empty());
        // A self-intersecting bow tie still gives n - 2 triangles of valid indices.
        let bow = [p(0., 0.), p(2., 2.), p(2., 0.), p(0., 2.)];
        let tris = triangulate(&bow);
        assert_eq!(tris.len(), 2);
        assert!(tris.iter().flatten().all(|&i| i < 4));
    }

    #[test]
    fn straight_runs_are_put_back_without_flat_triangles() {
        // A 4 x 4 square with a corner at every unit of its edges, and an L whose long edges
        // are runs of straight corners.
        let mut square = Vec::new();
        for i in 0..4 {
            square.push(v2(i as f64, 0.));
        }
        for i in 0..4 {
            square.push(v2(4., i as f64));
        }
        for i in 0..4 {
            square.push(v2(4. - i as f64, 4.));
        }
        for i in 0..4 {
            square.push(v2(0., 4. - i as f64));
        }
        check_simple(&square);
        let half = |i: usize| i as f64 * 0.5;
        let mut l: Vec<DVec2> = (0..10).map(|i| v2(half(i), 0.)).collect();
        l.extend((0..8).map(|i| v2(5. - half(i), 1.)));
        l.extend((0..8).map(|i| v2(1., 1. + half(i))));
        l.extend((0..10).map(|i| v2(0., 5. - half(i))));
        check_simple(&l);
    }

    #[test]
    fn many_reflex_corners() {
        let star: Vec<DVec3> = (0..40)
            .map(|i| {
                let angle = std::f64::consts::TAU * i as f64 / 40.0;
                let r = if i % 2 == 0 {
                    3.0
                } else {
                    1.0 + 0.01 * i as f64
                };
                DVec3::new(r * angle.cos(), r * angle.sin(), 0.0)
            })
            .collect();
        let tris = triangulate(&star);
        assert_eq!(tris.len(), 38);
        for t in &tris {
            assert!(t[0] != t[1] && t[1] != t[2] && t[0] != t[2]);
        }
    }
}
