//! The pairs of a mesh's triangles that cross each other: a whole-mesh count of what the
//! cleaning's guard refuses to make (issue 12, item 6: levels without self-intersections).
//!
//! Beyond the paper. Two triangles cross when an edge of either, not incident to a vertex they
//! share, meets the other ([`crate::local_crossings`]'s test on orientation signs, so a folded
//! fan around a shared vertex counts and two triangles along a shared edge do not), or when
//! they lie in one plane and overlap with positive area (a flat region folded onto itself, as
//! a collapse can leave on a CAD part's faces): in the plane's two dominant axes, a shared
//! edge with both third corners on one side, overlapping wedges at a shared corner, or else a
//! proper edge crossing or a corner strictly inside the other. Coplanarity allows the rounding
//! of the `f64` determinant (Shewchuk's static bound). Used to report and avoid what a
//! geometric stage did to a cleaned level (the quadric collapse can fold one sheet through
//! another where two lie close).
//!
//! Cost: the triangles' boxes on a grid of cells of their mean longest side, O(F), then the
//! exact test for each pair of triangles that share a cell and whose boxes meet, on all
//! threads. Memory: about 40 bytes per triangle.

use std::collections::HashMap;

use glam::DVec3;
use rayon::prelude::*;
use voxlod_core::TriangleMesh;

use crate::local_crossings::triangles_meet;

/// Every pair `(s, t)`, `s < t`, of `mesh`'s triangles that cross (module docs), ascending.
///
/// ```
/// use voxlod_contouring::crossing_pairs;
/// use voxlod_core::{glam::Vec3, TriangleMesh};
///
/// // Two triangles, one through the other.
/// let mesh = TriangleMesh::new(
///     vec![
///         Vec3::new(0.0, 0.0, 0.0), Vec3::new(2.0, 0.0, 0.0), Vec3::new(0.0, 2.0, 0.0),
///         Vec3::new(0.5, 0.5, -1.0), Vec3::new(0.5, 0.5, 1.0), Vec3::new(3.0, 3.0, 0.0),
///     ],
///     vec![[0, 1, 2], [3, 4, 5]],
/// );
/// assert_eq!(crossing_pairs(&mesh), vec![(0, 1)]);
/// ```
pub fn crossing_pairs(mesh: &TriangleMesh) -> Vec<(u32, u32)> {
    let count = mesh.triangles.len();
    if count < 2 {
        return Vec::new();
    }
    let corners: Vec<[DVec3; 3]> = (0..count).map(|t| mesh.corners(t)).collect();
    let cell = cell_size(&corners, mesh.bounds().diagonal());
    let margin = cell * 0.5e-6;
    let mut cells: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
    for (t, c) in corners.iter().enumerate() {
        let (lo, hi) = box_of(c);
        let (a, b) = (key(lo - margin, cell), key(hi + margin, cell));
        for x in a[0]..=b[0] {
            for y in a[1]..=b[1] {
                for z in a[2]..=b[2] {
                    cells.entry([x, y, z]).or_default().push(t as u32);
                }
            }
        }
    }
    let lists: Vec<Vec<u32>> = cells.into_values().filter(|l| l.len() > 1).collect();
    let mut pairs: Vec<(u32, u32)> = lists
        .par_iter()
        .flat_map_iter(|list| {
            let corners = &corners;
            list.iter().enumerate().flat_map(move |(k, &s)| {
                list[k + 1..].iter().filter_map(move |&t| {
                    let (s, t) = (s.min(t), s.max(t));
                    let (a, b) = (s as usize, t as usize);
                    let (ta, tb) = (mesh.triangles[a], mesh.triangles[b]);
                    let meet = triangles_meet(corners[a], ta, corners[b], tb, margin)
                        || coplanar_overlap(corners[a], ta, corners[b], tb);
                    meet.then_some((s, t))
                })
            })
        })
        .collect();
    pairs.par_sort_unstable();
    pairs.dedup();
    pairs
}

/// Triangles `a` and `b` (vertex ids `ia`, `ib`) lie in one plane and overlap with positive
/// area (module docs).
fn coplanar_overlap(a: [DVec3; 3], ia: [u32; 3], b: [DVec3; 3], ib: [u32; 3]) -> bool {
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

/// The grid's cell: the triangles' mean longest side, at least a millionth of the diagonal.
fn cell_size(corners: &[[DVec3; 3]], diagonal: f64) -> f64 {
    let longest = |c: &[DVec3; 3]| {
        let (lo, hi) = box_of(c);
        (hi - lo).max_element()
    };
    let mean = corners.iter().map(longest).sum::<f64>() / corners.len() as f64;
    let cell = mean.max(diagonal * 1e-6);
    if cell.is_finite() && cell > 0.0 {
        cell
    } else {
        1.0
    }
}

fn box_of(c: &[DVec3; 3]) -> (DVec3, DVec3) {
    (c[0].min(c[1]).min(c[2]), c[0].max(c[1]).max(c[2]))
}

fn key(p: DVec3, cell: f64) -> [i64; 3] {
    (p / cell).floor().as_i64vec3().to_array()
}

#[cfg(test)]
mod tests {
    use super::*;
    use voxlod_core::glam::Vec3;
    use voxlod_testkit::intersections::self_intersections;
    use voxlod_testkit::shapes::{append, icosphere_at};

    /// Spheres placed so that some overlap: the pairs are exactly those an independent test
    /// (orientation predicates, voxlod-testkit) finds, and none where the spheres lie apart.
    #[test]
    fn crossing_pairs_are_the_independent_tests_pairs() {
        for (offset, crossing) in [(0.7f32, true), (1.3, true), (2.5, false)] {
            let mut mesh = icosphere_at(3, 1.0, Vec3::ZERO);
            append(
                &mut mesh,
                &icosphere_at(3, 0.8, Vec3::new(offset, 0.1, 0.05)),
            );
            let ours: Vec<(usize, usize)> = crossing_pairs(&mesh)
                .into_iter()
                .map(|(s, t)| (s as usize, t as usize))
                .collect();
            let mut theirs = self_intersections(&mesh);
            theirs.sort_unstable();
            assert_eq!(ours, theirs, "offset {offset}");
            assert_eq!(!ours.is_empty(), crossing, "offset {offset}");
        }
    }

    /// A closed sphere alone has no crossing pair.
    #[test]
    fn a_closed_sphere_has_no_crossing_pair() {
        assert!(crossing_pairs(&icosphere_at(4, 1.0, Vec3::ZERO)).is_empty());
    }

    /// Coplanar pairs in the plane z = 0: apart, overlapping, folded over a shared edge, side
    /// by side along it, overlapping and touching wedges at a shared corner; each decided as the
    /// independent test decides it, and both answers occur.
    #[test]
    fn coplanar_pairs_are_decided_as_the_independent_test_decides() {
        let p = |x: f32, y: f32| Vec3::new(x, y, 0.0);
        let cases: [(Vec<Vec3>, [[u32; 3]; 2], bool); 6] = [
            (
                vec![
                    p(0., 0.),
                    p(1., 0.),
                    p(0., 1.),
                    p(2., 2.),
                    p(3., 2.),
                    p(2., 3.),
                ],
                [[0, 1, 2], [3, 4, 5]],
                false,
            ),
            (
                vec![
                    p(0., 0.),
                    p(2., 0.),
                    p(0., 2.),
                    p(0.5, 0.5),
                    p(3., 0.5),
                    p(0.5, 3.),
                ],
                [[0, 1, 2], [3, 4, 5]],
                true,
            ),
            (
                vec![p(0., 0.), p(2., 0.), p(0., 2.), p(1.5, 1.5)],
                [[0, 1, 2], [1, 3, 2]],
                false,
            ),
            (
                vec![p(0., 0.), p(2., 0.), p(0., 2.), p(0.5, 0.5)],
                [[0, 1, 2], [2, 1, 3]],
                true,
            ),
            (
                vec![p(0., 0.), p(2., 0.), p(0., 2.), p(2., 1.), p(1., 2.)],
                [[0, 1, 2], [0, 3, 4]],
                true,
            ),
            (
                vec![p(0., 0.), p(2., 0.), p(0., 2.), p(-2., 0.)],
                [[0, 1, 2], [0, 2, 3]],
                false,
            ),
        ];
        for (k, (positions, triangles, overlap)) in cases.into_iter().enumerate() {
            let mesh = TriangleMesh::new(positions, triangles.to_vec());
            let ours = !crossing_pairs(&mesh).is_empty();
            let theirs = voxlod_testkit::intersections::triangles_intersect(&mesh, 0, 1);
            assert_eq!((ours, theirs), (overlap, overlap), "case {k}");
        }
    }
}
