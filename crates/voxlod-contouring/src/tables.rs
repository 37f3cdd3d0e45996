//! Marching-cubes lookup tables, generated from first principles at first use.
//!
//! Lorensen and Cline (1987), whom the voxel paper's §2 follows, enumerate the 256 ways the
//! eight corners of a cell can lie inside or outside the surface and store, for each, the
//! triangles that separate them. Rather than copy a published table, we derive ours:
//!
//! 1. On every face of the cube, the edges whose corners disagree are joined by segments. A face
//!    with two such edges has one segment. A face with four (the ambiguous saddle, two diagonal
//!    corners inside) has two: we always **separate the inside corners**, cutting each off on its
//!    own. The rule depends on the face's four corners alone, so the two cells sharing a face
//!    always agree and the surface has no cracks.
//! 2. Each segment is oriented so that, seen from outside the cube through its face, the inside
//!    corner lies to its left; following the segments from edge to edge gives closed loops,
//!    each running counter-clockwise around the surface's outer side.
//! 3. Each loop is triangulated by dynamic programming over its triangulations, minimising the
//!    total length of the diagonals measured between edge midpoints, **never** drawing a
//!    diagonal between two edge points that lie on a common face of the cube. Such a diagonal
//!    could also be drawn by the neighbouring cell and would then be shared by four triangles;
//!    without it, every mesh edge is either a face segment (shared by exactly the two cells on
//!    either side of the face) or a diagonal inside one cell (shared by two of its triangles).
//!
//! With one inside rule for samples (`value >= iso`), one vertex per grid edge, and these
//! tables, the output of a surface that does not touch the grid boundary is a closed,
//! consistently oriented 2-manifold. The table test checks steps 1–3 on all 256 cases.
//!
//! Numbering: corner `c` sits at `(c & 1, (c >> 1) & 1, (c >> 2) & 1)`. Edges 0–3 run along x
//! from corners 0, 2, 4, 6; edges 4–7 along y from corners 0, 1, 4, 5; edges 8–11 along z from
//! corners 0, 1, 2, 3. Bit `c` of a case index is set when corner `c` is inside.
//!
//! Cost: the 256 cases are built once, on first use; the tables take a few
//! kilobytes, and a look-up is O(1).

use std::sync::OnceLock;

/// The two corners of each edge, the first being the one with the lower coordinate.
pub const EDGE_CORNERS: [(u8, u8); 12] = [
    (0, 1),
    (2, 3),
    (4, 5),
    (6, 7),
    (0, 2),
    (1, 3),
    (4, 6),
    (5, 7),
    (0, 4),
    (1, 5),
    (2, 6),
    (3, 7),
];

/// The axis (0 = x, 1 = y, 2 = z) each edge runs along.
pub const EDGE_AXIS: [u8; 12] = [0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2];

/// The triangles of every case, as edge numbers.
pub struct Tables {
    /// For each case, up to five triangles; `triangle_count[case]` of them are valid.
    pub triangles: [[[u8; 3]; 5]; 256],
    /// For each case, how many of its five `triangles` are used (0 to 5).
    pub triangle_count: [u8; 256],
    /// For each case, the number of closed loops (separate surface pieces) in the cell.
    pub loop_count: [u8; 256],
}

/// The tables, built on first use (a few microseconds).
pub fn tables() -> &'static Tables {
    static TABLES: OnceLock<Tables> = OnceLock::new();
    TABLES.get_or_init(build_tables)
}

fn corner_position(c: u8) -> [f64; 3] {
    [(c & 1) as f64, ((c >> 1) & 1) as f64, ((c >> 2) & 1) as f64]
}

fn edge_of(a: u8, b: u8) -> u8 {
    let (lo, hi) = (a.min(b), a.max(b));
    EDGE_CORNERS
        .iter()
        .position(|&e| e == (lo, hi))
        .expect("corners of a cube edge") as u8
}

fn edge_midpoint(e: u8) -> [f64; 3] {
    let (a, b) = EDGE_CORNERS[e as usize];
    let (pa, pb) = (corner_position(a), corner_position(b));
    [
        0.5 * (pa[0] + pb[0]),
        0.5 * (pa[1] + pb[1]),
        0.5 * (pa[2] + pb[2]),
    ]
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// A face of the cube: its corners in cyclic order and its outward normal.
struct Face {
    corners: [u8; 4],
    normal: [f64; 3],
}

fn faces() -> Vec<Face> {
    let mut out = Vec::new();
    for axis in 0..3u8 {
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        for side in 0..2u8 {
            let base = side << axis;
            let corners = [base, base | 1 << u, base | 1 << u | 1 << v, base | 1 << v];
            let mut normal = [0.0; 3];
            normal[axis as usize] = if side == 1 { 1.0 } else { -1.0 };
            out.push(Face { corners, normal });
        }
    }
    out
}

/// The edges of the cube that lie on a common face (including an edge with itself).
fn share_face(a: u8, b: u8) -> bool {
    let corners = |e: u8| {
        let (p, q) = EDGE_CORNERS[e as usize];
        [p, q]
    };
    faces().iter().any(|f| {
        corners(a).iter().all(|c| f.corners.contains(c))
            && corners(b).iter().all(|c| f.corners.contains(c))
    })
}

/// Oriented face segments (from edge, to edge) of a case, per step 1 and 2 of the module doc.
pub(crate) fn face_segments(case: u8) -> Vec<(u8, u8)> {
    let inside = |c: u8| (case >> c) & 1 == 1;
    let mut segments = Vec::new();
    for face in faces() {
        let q = face.corners;
        let crossing: Vec<usize> = (0..4)
            .filter(|&i| inside(q[i]) != inside(q[(i + 1) % 4]))
            .collect();
        let mut pairs: Vec<(u8, u8, u8)> = Vec::new(); // (edge, edge, inside corner)
        match crossing.len() {
            0 => {}
            2 => {
                let e0 = edge_of(q[crossing[0]], q[(crossing[0] + 1) % 4]);
                let e1 = edge_of(q[crossing[1]], q[(crossing[1] + 1) % 4]);
                let corner = *q
                    .iter()
                    .find(|&&c| inside(c))
                    .expect("a crossing face has an inside corner");
                pairs.push((e0, e1, corner));
            }
            4 => {
                for i in 0..4 {
                    if inside(q[i]) {
                        let prev = edge_of(q[(i + 3) % 4], q[i]);
                        let next = edge_of(q[i], q[(i + 1) % 4]);
                        pairs.push((prev, next, q[i]));
                    }
                }
            }
            n => unreachable!("a square face has an even number of crossings, got {n}"),
        }
        for (e0, e1, corner) in pairs {
            let (p, r) = (edge_midpoint(e0), edge_midpoint(e1));
            let c = corner_position(corner);
            if dot(cross(sub(r, p), sub(c, p)), face.normal) < 0.0 {
                segments.push((e0, e1));
            } else {
                segments.push((e1, e0));
            }
        }
    }
    segments
}

/// Closed loops of edges, following the oriented segments.
pub(crate) fn loops(case: u8) -> Vec<Vec<u8>> {
    let segments = face_segments(case);
    let mut next = [u8::MAX; 12];
    for &(a, b) in &segments {
        debug_assert_eq!(
            next[a as usize],
            u8::MAX,
            "edge {a} leaves twice in case {case}"
        );
        next[a as usize] = b;
    }
    let mut visited = [false; 12];
    let mut out = Vec::new();
    for start in 0..12u8 {
        if next[start as usize] == u8::MAX || visited[start as usize] {
            continue;
        }
        let mut cycle = Vec::new();
        let mut e = start;
        while !visited[e as usize] {
            visited[e as usize] = true;
            cycle.push(e);
            e = next[e as usize];
        }
        debug_assert_eq!(e, start, "segments of case {case} do not close");
        out.push(cycle);
    }
    out
}

/// Minimum-diagonal-length triangulation of a loop that never joins two edges on a common face.
fn triangulate(cycle: &[u8]) -> Option<Vec<[u8; 3]>> {
    let n = cycle.len();
    let length = |i: usize, k: usize| {
        let d = sub(edge_midpoint(cycle[i]), edge_midpoint(cycle[k]));
        dot(d, d).sqrt()
    };
    let allowed = |i: usize, k: usize| {
        // Sides of the polygon are face segments and always allowed.
        k == i + 1 || (i == 0 && k == n - 1) || !share_face(cycle[i], cycle[k])
    };
    // cost[i][k]: best triangulation of the sub-polygon i..=k (k - i >= 2), diagonal i-k included.
    let mut cost = vec![vec![f64::INFINITY; n]; n];
    let mut split = vec![vec![usize::MAX; n]; n];
    for i in 0..n - 1 {
        cost[i][i + 1] = 0.0;
    }
    for gap in 2..n {
        for i in 0..n - gap {
            let k = i + gap;
            if !allowed(i, k) {
                continue;
            }
            let own = if gap == n - 1 { 0.0 } else { length(i, k) };
            for j in i + 1..k {
                let c = cost[i][j] + cost[j][k] + own;
                if c < cost[i][k] {
                    cost[i][k] = c;
                    split[i][k] = j;
                }
            }
        }
    }
    if !cost[0][n - 1].is_finite() {
        return None;
    }
    let mut out = Vec::new();
    let mut stack = vec![(0, n - 1)];
    while let Some((i, k)) = stack.pop() {
        if k - i < 2 {
            continue;
        }
        let j = split[i][k];
        out.push([cycle[i], cycle[j], cycle[k]]);
        stack.push((i, j));
        stack.push((j, k));
    }
    Some(out)
}

fn build_tables() -> Tables {
    let mut tables = Tables {
        triangles: [[[0; 3]; 5]; 256],
        triangle_count: [0; 256],
        loop_count: [0; 256],
    };
    for case in 0..=255u8 {
        let cycles = loops(case);
        let mut tris = Vec::new();
        for cycle in &cycles {
            tris.extend(triangulate(cycle).unwrap_or_else(|| {
                panic!("case {case}: loop {cycle:?} has no face-free triangulation")
            }));
        }
        assert!(
            tris.len() <= 5,
            "case {case} needs {} triangles",
            tris.len()
        );
        for (slot, t) in tables.triangles[case as usize].iter_mut().zip(&tris) {
            *slot = *t;
        }
        tables.triangle_count[case as usize] = tris.len() as u8;
        tables.loop_count[case as usize] = cycles.len() as u8;
    }
    tables
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn simple_cases_have_the_expected_triangles() {
        let t = tables();
        assert_eq!(t.triangle_count[0], 0);
        assert_eq!(t.triangle_count[255], 0);
        // One corner in or out: one triangle.
        for c in 0..8 {
            assert_eq!(t.triangle_count[1 << c], 1);
            assert_eq!(t.triangle_count[255 ^ (1 << c)], 1);
        }
        // A face's four corners: a quad, two triangles.
        assert_eq!(t.triangle_count[0b0000_1111], 2);
        // Two diagonal corners of a face, separated: two triangles in two loops.
        assert_eq!(t.triangle_count[0b0000_1001], 2);
        assert_eq!(t.loop_count[0b0000_1001], 2);
        // Two opposite corners of the cube: two triangles.
        assert_eq!(t.triangle_count[0b1000_0001], 2);
    }

    #[test]
    fn corner_zero_triangle_faces_away_from_the_corner() {
        let t = tables();
        let [a, b, c] = t.triangles[1][0];
        let (pa, pb, pc) = (edge_midpoint(a), edge_midpoint(b), edge_midpoint(c));
        let n = cross(sub(pb, pa), sub(pc, pa));
        assert!(dot(n, [1.0, 1.0, 1.0]) > 0.0, "normal {n:?}");
    }

    #[test]
    fn every_case_is_a_closed_oriented_disc_set() {
        let t = tables();
        for case in 0..=255usize {
            // Each crossing edge is in exactly one loop, and the triangles of each loop use
            // every loop side once in loop direction and every diagonal twice, once each way.
            let crossing: Vec<u8> = (0..12u8)
                .filter(|&e| {
                    let (a, b) = EDGE_CORNERS[e as usize];
                    ((case >> a) & 1) != ((case >> b) & 1)
                })
                .collect();
            let mut used = [0u8; 12];
            for tri in &t.triangles[case][..t.triangle_count[case] as usize] {
                for &e in tri {
                    used[e as usize] = 1;
                }
            }
            for e in 0..12u8 {
                assert_eq!(
                    used[e as usize] == 1,
                    crossing.contains(&e),
                    "case {case} edge {e}"
                );
            }
            let segments = face_segments(case as u8);
            let mut directed = std::collections::HashMap::new();
            for tri in &t.triangles[case][..t.triangle_count[case] as usize] {
                for i in 0..3 {
                    *directed.entry((tri[i], tri[(i + 1) % 3])).or_insert(0) += 1;
                }
            }
            for (&(a, b), &count) in &directed {
                assert_eq!(
                    count, 1,
                    "case {case}: directed edge {a}->{b} used {count} times"
                );
                let is_side = segments.contains(&(a, b));
                if !is_side {
                    assert!(
                        directed.contains_key(&(b, a)),
                        "case {case}: diagonal {a}-{b} is used one way only"
                    );
                    assert!(
                        !share_face(a, b),
                        "case {case}: diagonal {a}-{b} lies on a face"
                    );
                }
            }
            for &(a, b) in &segments {
                assert!(
                    directed.contains_key(&(a, b)),
                    "case {case}: side {a}->{b} unused"
                );
            }
        }
    }

    #[test]
    fn complementary_cases_have_the_same_segments_reversed_when_unambiguous() {
        // Without an ambiguous face, the complement's surface is the same, reversed.
        for case in 0..=255u8 {
            let ambiguous = faces().iter().any(|f| {
                let q = f.corners;
                let inside = |c: u8| (case >> c) & 1 == 1;
                (0..4)
                    .filter(|&i| inside(q[i]) != inside(q[(i + 1) % 4]))
                    .count()
                    == 4
            });
            if ambiguous {
                continue;
            }
            let mut a = face_segments(case);
            let mut b: Vec<(u8, u8)> = face_segments(!case)
                .into_iter()
                .map(|(x, y)| (y, x))
                .collect();
            a.sort_unstable();
            b.sort_unstable();
            assert_eq!(a, b, "case {case}");
        }
    }
}
