//! An independent triangle–triangle intersection test for checking meshes in tests: which
//! pairs of a mesh's triangles cross each other.
//!
//! Written from the predicates up, sharing nothing with the crates under test. Two triangles
//! that share no vertex intersect when an edge of one properly crosses the other (the
//! segment–triangle test by orientation signs, as in Möller 1997 and Guigue–Devillers 2003
//! reduced to orientation predicates), or, coplanar, when their edges cross in the plane or one
//! holds a corner of the other. Triangles sharing one vertex intersect when an edge of one away
//! from the shared vertex crosses the other; triangles sharing an edge when they fold onto each
//! other (coplanar, on the same side of the edge). Orientations are computed in `f64` with a
//! forward error bound: a sign inside the bound counts as zero, so touching is not crossing and
//! a pair is reported only when the crossing is certain. Cost: a uniform grid over the
//! triangles' boxes, then the pairs that share a cell.

use std::collections::HashMap;

use glam::DVec3;
use voxlod_core::TriangleMesh;

/// The sign of the orientation of `d` against the plane of `a, b, c` (+1, −1), or 0 when the
/// `f64` determinant is within its rounding error bound.
pub fn orientation(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> i8 {
    let (u, v, w) = (a - d, b - d, c - d);
    let det = u.x * (v.y * w.z - v.z * w.y)
        + u.y * (v.z * w.x - v.x * w.z)
        + u.z * (v.x * w.y - v.y * w.x);
    let permanent = u.x.abs() * ((v.y * w.z).abs() + (v.z * w.y).abs())
        + u.y.abs() * ((v.z * w.x).abs() + (v.x * w.z).abs())
        + u.z.abs() * ((v.x * w.y).abs() + (v.y * w.x).abs());
    // Shewchuk's bound for this evaluation is about 8ε times the permanent; the differences
    // a - d, b - d, c - d add a little more: 64ε covers both.
    let bound = 64.0 * f64::EPSILON * permanent;
    if det > bound {
        1
    } else if det < -bound {
        -1
    } else {
        0
    }
}

/// Segment `p q` properly crosses triangle `a b c` (not coplanar, not merely touching).
fn segment_crosses(p: DVec3, q: DVec3, [a, b, c]: [DVec3; 3]) -> bool {
    let (sp, sq) = (orientation(a, b, c, p), orientation(a, b, c, q));
    if sp == 0 || sq == 0 || sp == sq {
        return false;
    }
    let s1 = orientation(p, q, a, b);
    let s2 = orientation(p, q, b, c);
    let s3 = orientation(p, q, c, a);
    s1 != 0 && s1 == s2 && s2 == s3
}

/// Coplanar triangles overlapping with positive area, tested in the plane's dominant axes.
fn coplanar_overlap(t: [DVec3; 3], u: [DVec3; 3]) -> bool {
    let n = (t[1] - t[0]).cross(t[2] - t[0]);
    let drop = n.abs().max_position();
    let flat = |p: DVec3| {
        let a = p.to_array();
        let (i, j) = ((drop + 1) % 3, (drop + 2) % 3);
        (a[i], a[j])
    };
    let orient2 = |a: (f64, f64), b: (f64, f64), c: (f64, f64)| -> i8 {
        let det = (b.0 - a.0) * (c.1 - a.1) - (b.1 - a.1) * (c.0 - a.0);
        let bound = 16.0
            * f64::EPSILON
            * ((b.0 - a.0).abs() + (b.1 - a.1).abs())
            * ((c.0 - a.0).abs() + (c.1 - a.1).abs());
        if det > bound {
            1
        } else if det < -bound {
            -1
        } else {
            0
        }
    };
    let (t, u) = (t.map(flat), u.map(flat));
    let crosses = |a, b, c, d| {
        let (o1, o2) = (orient2(a, b, c), orient2(a, b, d));
        let (o3, o4) = (orient2(c, d, a), orient2(c, d, b));
        o1 * o2 < 0 && o3 * o4 < 0
    };
    for i in 0..3 {
        for j in 0..3 {
            if crosses(t[i], t[(i + 1) % 3], u[j], u[(j + 1) % 3]) {
                return true;
            }
        }
    }
    let strictly_inside = |p, s: [(f64, f64); 3]| {
        let o = [
            orient2(s[0], s[1], p),
            orient2(s[1], s[2], p),
            orient2(s[2], s[0], p),
        ];
        o.iter().all(|&x| x == 1) || o.iter().all(|&x| x == -1)
    };
    u.iter().any(|&p| strictly_inside(p, t)) || t.iter().any(|&p| strictly_inside(p, u))
}

/// Whether triangles `i` and `j` of `mesh` intersect other than along what they share.
pub fn triangles_intersect(mesh: &TriangleMesh, i: usize, j: usize) -> bool {
    let (ti, tj) = (mesh.triangles[i], mesh.triangles[j]);
    let (a, b) = (mesh.corners(i), mesh.corners(j));
    let shared: Vec<(usize, usize)> = (0..3)
        .flat_map(|x| (0..3).map(move |y| (x, y)))
        .filter(|&(x, y)| ti[x] == tj[y])
        .collect();
    match shared.len() {
        0 => {
            (0..3).any(|k| segment_crosses(a[k], a[(k + 1) % 3], b))
                || (0..3).any(|k| segment_crosses(b[k], b[(k + 1) % 3], a))
                || (orientation(a[0], a[1], a[2], b[0]) == 0
                    && orientation(a[0], a[1], a[2], b[1]) == 0
                    && orientation(a[0], a[1], a[2], b[2]) == 0
                    && coplanar_overlap(a, b))
        }
        1 => {
            // Only the edge opposite the shared corner can cross the other triangle properly.
            let (x, y) = shared[0];
            segment_crosses(a[(x + 1) % 3], a[(x + 2) % 3], b)
                || segment_crosses(b[(y + 1) % 3], b[(y + 2) % 3], a)
                || (orientation(a[0], a[1], a[2], b[(y + 1) % 3]) == 0
                    && orientation(a[0], a[1], a[2], b[(y + 2) % 3]) == 0
                    && coplanar_overlap(a, b))
        }
        2 => {
            // Folded onto each other: the far corners coplanar with, and on the same side of,
            // the shared edge.
            let (x0, _) = shared[0];
            let (x1, _) = shared[1];
            let far_a = a[3 - x0 - x1];
            let far_b = (0..3).find(|&k| !ti.contains(&tj[k])).map(|k| b[k]);
            far_b.is_some_and(|fb| {
                orientation(a[0], a[1], a[2], fb) == 0 && coplanar_overlap(a, b) && far_a != fb
            })
        }
        _ => false,
    }
}

/// Triangles of `mesh` whose area is under `limit`.
pub fn triangles_smaller_than(mesh: &TriangleMesh, limit: f64) -> usize {
    (0..mesh.triangles.len())
        .filter(|&t| {
            let [a, b, c] = mesh.corners(t);
            0.5 * (b - a).cross(c - a).length() < limit
        })
        .count()
}

/// Every intersecting pair `(i, j)`, `i < j`, of `mesh`'s non-degenerate triangles.
pub fn self_intersections(mesh: &TriangleMesh) -> Vec<(usize, usize)> {
    let n = mesh.triangles.len();
    if n == 0 {
        return Vec::new();
    }
    let bounds = mesh.bounds();
    let boxes: Vec<(DVec3, DVec3)> = (0..n)
        .map(|t| {
            let c = mesh.corners(t);
            (c[0].min(c[1]).min(c[2]), c[0].max(c[1]).max(c[2]))
        })
        .collect();
    let mean_size = boxes
        .iter()
        .map(|(lo, hi)| (*hi - *lo).max_element())
        .sum::<f64>()
        / n as f64;
    let cell = mean_size
        .max(bounds.longest_extent() * 1e-6)
        .max(f64::MIN_POSITIVE);
    let key = |p: DVec3| ((p - bounds.min) / cell).floor().as_ivec3();
    let mut grid: HashMap<glam::IVec3, Vec<usize>> = HashMap::new();
    for (t, (lo, hi)) in boxes.iter().enumerate() {
        let (klo, khi) = (key(*lo), key(*hi));
        for z in klo.z..=khi.z {
            for y in klo.y..=khi.y {
                for x in klo.x..=khi.x {
                    grid.entry(glam::IVec3::new(x, y, z)).or_default().push(t);
                }
            }
        }
    }
    let mut pairs = Vec::new();
    for (cell_key, members) in &grid {
        for (m, &i) in members.iter().enumerate() {
            for &j in &members[m + 1..] {
                let (lo, hi) = (boxes[i].0.max(boxes[j].0), boxes[i].1.min(boxes[j].1));
                // Each overlapping pair is tested once: in the cell of its overlap's low corner.
                if lo.cmpgt(hi).any() || key(lo) != *cell_key {
                    continue;
                }
                if triangles_intersect(mesh, i, j) {
                    pairs.push((i.min(j), i.max(j)));
                }
            }
        }
    }
    pairs.sort_unstable();
    pairs
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn two(a: [Vec3; 3], b: [Vec3; 3]) -> TriangleMesh {
        TriangleMesh::new([a, b].concat(), vec![[0, 1, 2], [3, 4, 5]])
    }

    #[test]
    fn crossing_touching_and_apart() {
        let flat = [Vec3::ZERO, Vec3::X * 2.0, Vec3::Y * 2.0];
        let piercing = [
            Vec3::new(0.5, 0.5, -1.0),
            Vec3::new(0.5, 0.5, 1.0),
            Vec3::new(0.6, 0.4, 1.0),
        ];
        assert_eq!(self_intersections(&two(flat, piercing)), vec![(0, 1)]);
        let above = piercing.map(|p| p + Vec3::Z * 2.5);
        assert!(self_intersections(&two(flat, above)).is_empty());
        // Touching at a point of the plane is not crossing.
        let touching = [
            Vec3::new(0.5, 0.5, 0.0),
            Vec3::new(0.5, 0.5, 1.0),
            Vec3::new(0.6, 0.4, 1.0),
        ];
        assert!(self_intersections(&two(flat, touching)).is_empty());
        // Coplanar overlap.
        let shifted = flat.map(|p| p + Vec3::new(0.3, 0.3, 0.0));
        assert_eq!(self_intersections(&two(flat, shifted)), vec![(0, 1)]);
    }

    #[test]
    fn shared_corners_and_edges() {
        // Sharing vertex 0, the second triangle's far edge pierces the first.
        let positions = vec![
            Vec3::ZERO,
            Vec3::X * 2.0,
            Vec3::Y * 2.0,
            Vec3::new(1.0, 0.5, -1.0),
            Vec3::new(0.5, 1.0, 1.0),
        ];
        let mesh = TriangleMesh::new(positions.clone(), vec![[0, 1, 2], [0, 3, 4]]);
        assert_eq!(self_intersections(&mesh), vec![(0, 1)]);
        // A fan around a shared corner, each pair meeting only there.
        let mesh = TriangleMesh::new(positions.clone(), vec![[0, 1, 2], [0, 3, 1]]);
        assert!(self_intersections(&mesh).is_empty());
        // Sharing an edge and folded flat onto each other.
        let folded = TriangleMesh::new(
            vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(0.5, 0.6, 0.0)],
            vec![[0, 1, 2], [1, 0, 3]],
        );
        assert_eq!(self_intersections(&folded), vec![(0, 1)]);
        let open = TriangleMesh::new(
            vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(0.5, -0.6, 0.0)],
            vec![[0, 1, 2], [1, 0, 3]],
        );
        assert!(self_intersections(&open).is_empty());
    }
}
