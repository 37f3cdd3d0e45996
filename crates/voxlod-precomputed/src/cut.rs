//! Cutting a triangle mesh on an axis-aligned grid, so that every triangle lies in one cell
//! (the level-0 nodes of the octree, neuroglancer `meshes.md`).
//!
//! The grid planes are `origin[a] + n · cell[a]`. The mesh is cut one axis at a time: a triangle
//! that spans several slabs of that axis gets a point on each of its edges at each plane the
//! edge crosses strictly (an endpoint on a plane is used as it is), and each slab's part of it,
//! a convex polygon made of the triangle's corners and those points in boundary order, is
//! triangulated as a fan. The point where an edge crosses a plane depends only on the edge's two
//! endpoints, taken in sorted order, and is shared by the two triangles of the edge: the pieces
//! on both sides of a plane meet at exactly the same vertices, and two meshes sharing a surface
//! are cut at the same points. The point's coordinate across the plane is the plane's, exactly.
//! Cost: linear in the triangles and the pieces made; a hash map of the crossings per axis.

use rustc_hash::FxHashMap;
use voxlod_core::glam::DVec3;

/// The position of plane `n` of an axis.
#[inline]
fn plane(origin: f64, cell: f64, n: i64) -> f64 {
    origin + n as f64 * cell
}

/// The slab `s` with `plane(s) <= x < plane(s + 1)`, consistent with [`plane`] at the bounds.
#[inline]
fn slab(origin: f64, cell: f64, x: f64) -> i64 {
    let mut s = ((x - origin) / cell).floor() as i64;
    while x < plane(origin, cell, s) {
        s -= 1;
    }
    while x >= plane(origin, cell, s + 1) {
        s += 1;
    }
    s
}

/// The point where the segment between `p` and `q` crosses coordinate `at` of axis `a`,
/// computed from the endpoints in sorted order so that it does not depend on the edge's
/// direction, with that coordinate set exactly.
fn crossing(p: DVec3, q: DVec3, a: usize, at: f64) -> DVec3 {
    let key = |v: DVec3| v.to_array().map(f64::to_bits);
    let (lo, hi) = if key(p) <= key(q) { (p, q) } else { (q, p) };
    let t = (at - lo[a]) / (hi[a] - lo[a]);
    let mut x = lo + (hi - lo) * t;
    x[a] = at;
    x
}

/// Cuts `triangles` on the planes of axis `a`; new vertices are appended to `positions`.
fn cut_axis(
    positions: &mut Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
    a: usize,
    origin: f64,
    cell: f64,
) -> Vec<[u32; 3]> {
    let mut crossings: FxHashMap<(u32, u32, i64), u32> = FxHashMap::default();
    let mut out = Vec::with_capacity(triangles.len() + triangles.len() / 8);
    let (mut ring, mut piece): (Vec<u32>, Vec<u32>) = (Vec::new(), Vec::new());
    for tri in triangles {
        let c = tri.map(|v| positions[v as usize][a]);
        let (first, last) = slab_range(c, origin, cell);
        if first >= last {
            out.push(tri);
            continue;
        }
        ring.clear();
        for e in 0..3 {
            let (u, v) = (tri[e], tri[(e + 1) % 3]);
            ring.push(u);
            let (cu, cv) = (c[e], c[(e + 1) % 3]);
            let (low, high) = (cu.min(cv), cu.max(cv));
            let (s_lo, s_hi) = (slab(origin, cell, low), slab(origin, cell, high));
            // The planes strictly between the endpoints, from u's side to v's.
            let strictly = |n: &i64| {
                let x = plane(origin, cell, *n);
                x > low && x < high
            };
            let mut add = |n: i64| {
                let key = (u.min(v), u.max(v), n);
                let id = *crossings.entry(key).or_insert_with(|| {
                    let x = crossing(
                        positions[u as usize],
                        positions[v as usize],
                        a,
                        plane(origin, cell, n),
                    );
                    positions.push(x);
                    positions.len() as u32 - 1
                });
                ring.push(id);
            };
            if cu <= cv {
                (s_lo + 1..=s_hi).filter(strictly).for_each(&mut add);
            } else {
                (s_lo + 1..=s_hi).rev().filter(strictly).for_each(&mut add);
            }
        }
        for s in first..=last {
            let (bottom, top) = (plane(origin, cell, s), plane(origin, cell, s + 1));
            piece.clear();
            piece.extend(
                ring.iter()
                    .copied()
                    .filter(|&v| (bottom..=top).contains(&positions[v as usize][a])),
            );
            for i in 1..piece.len().saturating_sub(1) {
                out.push([piece[0], piece[i], piece[i + 1]]);
            }
        }
    }
    out
}

/// The slabs of axis `a` whose interiors a triangle with coordinates `c` reaches: the first
/// and the last (equal for a triangle that crosses no plane of the axis; a triangle flat on a
/// plane is in the slab above it).
#[inline]
fn slab_range(c: [f64; 3], origin: f64, cell: f64) -> (i64, i64) {
    let lo = c[0].min(c[1]).min(c[2]);
    let hi = c[0].max(c[1]).max(c[2]);
    let first = slab(origin, cell, lo);
    let mut last = slab(origin, cell, hi);
    if plane(origin, cell, last) == hi && last > first {
        last -= 1;
    }
    (first, last)
}

/// The cell of a triangle that crosses no grid plane, or `None` if it crosses one.
#[inline]
fn single_cell(t: [u32; 3], positions: &[DVec3], origin: DVec3, cell: DVec3) -> Option<[i64; 3]> {
    let mut out = [0i64; 3];
    for a in 0..3 {
        let c = t.map(|v| positions[v as usize][a]);
        let (first, last) = slab_range(c, origin[a], cell[a]);
        if first < last {
            return None;
        }
        out[a] = first;
    }
    Some(out)
}

/// Cuts the mesh on the grid of `cell`-sized cells from `origin` and returns each piece with
/// its cell (`floor((centroid − origin) / cell)`, non-negative when `origin` is at or below
/// every vertex; a piece flat on a plane goes to the cell above it). New vertices are appended
/// to `positions`; triangles with a repeated index are dropped. Triangles inside one cell
/// are passed through as they are; only the others are cut, axis by axis.
pub fn cut_to_cells(
    positions: &mut Vec<DVec3>,
    triangles: &[[u32; 3]],
    origin: DVec3,
    cell: DVec3,
) -> Vec<([i64; 3], [u32; 3])> {
    let mut out = Vec::with_capacity(triangles.len() + triangles.len() / 8);
    let mut pieces: Vec<[u32; 3]> = Vec::new();
    for &t in triangles {
        if t[0] == t[1] || t[1] == t[2] || t[2] == t[0] {
            continue;
        }
        match single_cell(t, positions, origin, cell) {
            Some(c) => out.push((c, t)),
            None => pieces.push(t),
        }
    }
    for a in 0..3 {
        pieces = cut_axis(positions, pieces, a, origin[a], cell[a]);
    }
    out.extend(pieces.into_iter().map(|t| {
        let centroid = t
            .iter()
            .map(|&v| positions[v as usize])
            .fold(DVec3::ZERO, |s, p| s + p)
            / 3.0;
        let c = std::array::from_fn(|a| cell_of(t, positions, a, origin[a], cell[a], centroid));
        (c, t)
    }));
    out
}

/// The slab of axis `a` holding a piece: its centroid's, unless rounding put the centroid of a
/// thin piece on a plane that the piece does not cross, then the slab of its lowest corner.
fn cell_of(
    t: [u32; 3],
    positions: &[DVec3],
    a: usize,
    origin: f64,
    cell: f64,
    centroid: DVec3,
) -> i64 {
    let lo = t
        .iter()
        .map(|&v| positions[v as usize][a])
        .fold(f64::INFINITY, f64::min);
    let hi = t
        .iter()
        .map(|&v| positions[v as usize][a])
        .fold(f64::NEG_INFINITY, f64::max);
    let s = slab(origin, cell, centroid[a]);
    if lo == hi || (plane(origin, cell, s) <= lo && hi <= plane(origin, cell, s + 1)) {
        s
    } else {
        slab(origin, cell, lo)
    }
}

#[cfg(test)]
mod tests {
    use std::collections::HashMap;

    use super::*;

    fn area(positions: &[DVec3], pieces: &[([i64; 3], [u32; 3])]) -> f64 {
        pieces
            .iter()
            .map(|(_, t)| {
                let [a, b, c] = t.map(|v| positions[v as usize]);
                (b - a).cross(c - a).length() / 2.0
            })
            .sum()
    }

    #[test]
    fn a_triangle_across_two_planes_is_cut_into_pieces_of_the_same_area() {
        let mut positions = vec![
            DVec3::new(0.5, 0.5, 0.5),
            DVec3::new(2.5, 0.5, 0.5),
            DVec3::new(0.5, 0.9, 0.5),
        ];
        let pieces = cut_to_cells(&mut positions, &[[0, 1, 2]], DVec3::ZERO, DVec3::ONE);
        // Slabs 0 and 1 get quadrilaterals (two triangles each), slab 2 a triangle.
        let cells: Vec<i64> = pieces.iter().map(|(c, _)| c[0]).collect();
        assert_eq!(cells, vec![0, 0, 1, 1, 2]);
        assert!((area(&positions, &pieces) - 0.4).abs() < 1e-12);
        for (c, t) in &pieces {
            for &v in t {
                let x = positions[v as usize].x;
                assert!(x >= c[0] as f64 && x <= c[0] as f64 + 1.0);
            }
        }
    }

    #[test]
    fn the_two_triangles_of_an_edge_share_its_crossing() {
        let mut positions = vec![
            DVec3::new(0.2, 0.2, 0.5),
            DVec3::new(1.7, 0.4, 0.5),
            DVec3::new(0.9, 1.6, 0.5),
            DVec3::new(1.8, 1.9, 0.5),
        ];
        let pieces = cut_to_cells(
            &mut positions,
            &[[0, 1, 2], [2, 1, 3]],
            DVec3::ZERO,
            DVec3::ONE,
        );
        let whole = area(&positions, &[([0; 3], [0, 1, 2]), ([0; 3], [2, 1, 3])]);
        assert!((area(&positions, &pieces) - whole).abs() < 1e-12);
        let mut edges: HashMap<(u32, u32), i32> = HashMap::new();
        for (_, t) in &pieces {
            for e in 0..3 {
                let (u, v) = (t[e], t[(e + 1) % 3]);
                *edges.entry((u.min(v), u.max(v))).or_default() += 1;
            }
        }
        // Every edge is used once or twice, and the edges used once are the quad's outline:
        // their length is its perimeter (a crack or T-junction inside would add to it).
        let mut open = 0.0;
        for (&(u, v), &n) in &edges {
            assert!(n == 1 || n == 2, "edge {u}-{v} used {n} times");
            if n == 1 {
                open += (positions[u as usize] - positions[v as usize]).length();
            }
        }
        let corner = |i: usize| positions[i];
        let perimeter: f64 = [(0, 1), (1, 3), (3, 2), (2, 0)]
            .iter()
            .map(|&(a, b)| (corner(a) - corner(b)).length())
            .sum();
        assert!((open - perimeter).abs() < 1e-12, "{open} vs {perimeter}");
    }
}
