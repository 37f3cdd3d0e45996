//! Triangles on a grid of samples with exact coverage and f64 depth, for the visibility test:
//! unlike [`crate::raster`], it tells whether a sample lies strictly inside a triangle or on its
//! boundary, and gives the depth in f64 on the same snapped geometry that decides coverage.
//!
//! Corners are snapped to 1/256 of a sample, so a corner shared by several triangles lands on
//! the same lattice point in all of them; the edge functions are exact integers at the sample
//! centres. The depth at a sample is the barycentric mean of the corners' depths with weights
//! `E_k / 2·area` (both exact integers in f64), so two triangles sharing an edge give the same
//! depth on it up to one rounding of the scene's depth.
//!
//! Cost: O(1) setup, then O(1) per row of the triangle's clipped box (the span of its row, in
//! integers) and per sample it covers.

/// Sub-sample positions per sample side: corners snap to 1/256 of a sample.
const SUB: i64 = 256;

/// A corner on the grid: x and y in 1/[`SUB`] of a sample, and depth.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct GridPoint {
    x: i64,
    y: i64,
    z: f64,
}

impl GridPoint {
    /// The point at `x`, `y` samples from the grid's corner (sample centres at half-integers)
    /// and depth `z`, snapped to the lattice. Coordinates must be within a few million samples.
    pub(super) fn snap(x: f64, y: f64, z: f64) -> GridPoint {
        let s = SUB as f64;
        GridPoint {
            x: (x * s).round() as i64,
            y: (y * s).round() as i64,
            z,
        }
    }
}

/// A snapped triangle, counter-clockwise in the lattice's orientation.
pub(super) struct SnappedTriangle {
    p: [GridPoint; 3],
    /// Twice the area in lattice units, positive.
    area2: i64,
}

impl SnappedTriangle {
    /// The triangle of three snapped corners; `None` when they are collinear.
    pub(super) fn new(corners: [GridPoint; 3]) -> Option<SnappedTriangle> {
        let [a, b, c] = corners;
        let area2 = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
        match area2.signum() {
            0 => None,
            1 => Some(SnappedTriangle { p: corners, area2 }),
            _ => Some(SnappedTriangle {
                p: [a, c, b],
                area2: -area2,
            }),
        }
    }

    /// Calls `visit(index, depth, strictly_inside)` for every sample of the `side × side` grid
    /// (index `y · side + x`) whose centre lies in the closed triangle; `strictly_inside` is
    /// false for a centre on an edge or a corner.
    pub(super) fn for_each_sample(&self, side: usize, mut visit: impl FnMut(usize, f64, bool)) {
        let Some((x0, x1, y0, y1)) = self.sample_box(side) else {
            return;
        };
        let p = &self.p;
        // E_k(P) = a_k P.x + b_k P.y + c_k: edge k runs from corner k+1 to corner k+2.
        let (mut a, mut b, mut c) = ([0i64; 3], [0i64; 3], [0i64; 3]);
        for k in 0..3 {
            let (s, e) = (p[(k + 1) % 3], p[(k + 2) % 3]);
            let (dx, dy) = (e.x - s.x, e.y - s.y);
            a[k] = -dy;
            b[k] = dx;
            c[k] = dy * s.x - dx * s.y;
        }
        let centre = |i: i64| i * SUB + SUB / 2;
        let inv = 1.0 / self.area2 as f64;
        let z = [p[0].z, p[1].z, p[2].z];
        for y in y0..=y1 {
            let rest = [0, 1, 2].map(|k| b[k] * centre(y) + c[k]);
            let Some((xa, xb)) = row_span(&a, &rest, x0, x1) else {
                continue;
            };
            let row = y as usize * side;
            let mut e = [0, 1, 2].map(|k| a[k] * centre(xa) + rest[k]);
            for x in xa..=xb {
                if e[0] >= 0 && e[1] >= 0 && e[2] >= 0 {
                    let w = e.map(|v| v as f64);
                    let depth = (w[0] * z[0] + w[1] * z[1] + w[2] * z[2]) * inv;
                    visit(row + x as usize, depth, e[0] > 0 && e[1] > 0 && e[2] > 0);
                }
                for k in 0..3 {
                    e[k] += a[k] * SUB;
                }
            }
        }
    }

    /// The samples (first x, last x, first y, last y) whose centres lie in the triangle's box,
    /// clipped to the grid; `None` when none do.
    fn sample_box(&self, side: usize) -> Option<(i64, i64, i64, i64)> {
        let p = &self.p;
        let (min_x, max_x) = (p.iter().map(|q| q.x).min()?, p.iter().map(|q| q.x).max()?);
        let (min_y, max_y) = (p.iter().map(|q| q.y).min()?, p.iter().map(|q| q.y).max()?);
        let first = |m: i64| (m - SUB / 2 + SUB - 1).div_euclid(SUB).max(0);
        let last = |m: i64| (m - SUB / 2).div_euclid(SUB).min(side as i64 - 1);
        let (x0, x1, y0, y1) = (first(min_x), last(max_x), first(min_y), last(max_y));
        (x0 <= x1 && y0 <= y1).then_some((x0, x1, y0, y1))
    }
}

/// The samples `x` of `x0..=x1` on one row where every edge function
/// `a_k (x·SUB + SUB/2) + rest_k` is at least 0, as an inclusive range; `None` when there are
/// none. Exact in integers: O(1).
fn row_span(a: &[i64; 3], rest: &[i64; 3], x0: i64, x1: i64) -> Option<(i64, i64)> {
    let (mut lo, mut hi) = (x0, x1);
    for k in 0..3 {
        // a (SUB x + SUB/2) + rest ≥ 0  ⟺  (SUB a) x ≥ −rest − (SUB/2) a.
        let (n, d) = (-rest[k] - SUB / 2 * a[k], SUB * a[k]);
        match d.signum() {
            1 => lo = lo.max(ceil_div(n, d)),
            -1 => hi = hi.min(floor_div(n, d)),
            _ if n > 0 => return None,
            _ => {}
        }
    }
    (lo <= hi).then_some((lo, hi))
}

/// ⌊n / d⌋ for d ≠ 0.
fn floor_div(n: i64, d: i64) -> i64 {
    let q = n / d;
    if n % d != 0 && ((n < 0) != (d < 0)) {
        q - 1
    } else {
        q
    }
}

/// ⌈n / d⌉ for d ≠ 0.
fn ceil_div(n: i64, d: i64) -> i64 {
    -floor_div(-n, d)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The samples of a triangle on a grid: (index, depth, strictly inside).
    fn samples(corners: [(f64, f64, f64); 3], side: usize) -> Vec<(usize, f64, bool)> {
        let t = SnappedTriangle::new(corners.map(|(x, y, z)| GridPoint::snap(x, y, z))).unwrap();
        let mut out = Vec::new();
        t.for_each_sample(side, |i, z, strict| out.push((i, z, strict)));
        out
    }

    #[test]
    fn a_square_split_on_its_diagonal_shares_only_the_diagonal_samples() {
        // The square [0, 4]² on a 4×4 grid: sample centres (i + ½, j + ½) are all inside; the
        // diagonal x = y holds the four with i = j, on the boundary of both halves, either way
        // round.
        let (a, b, c, d) = (
            (0.0, 0.0, 1.0),
            (4.0, 0.0, 1.0),
            (4.0, 4.0, 1.0),
            (0.0, 4.0, 1.0),
        );
        let lower = samples([a, b, c], 4);
        let upper = samples([a, d, c], 4);
        assert_eq!(lower.len(), 10);
        assert_eq!(upper.len(), 10);
        let on_diagonal = |s: &[(usize, f64, bool)]| -> Vec<usize> {
            s.iter().filter(|x| !x.2).map(|x| x.0).collect()
        };
        assert_eq!(on_diagonal(&lower), vec![0, 5, 10, 15]);
        assert_eq!(on_diagonal(&upper), vec![0, 5, 10, 15]);
        assert!(lower.iter().chain(&upper).all(|x| x.1 == 1.0));
    }

    #[test]
    fn depth_is_affine_and_collinear_corners_are_refused() {
        // z = x on the triangle (0,0), (8,0), (0,8): the sample (2, 1) has its centre at x = 2.5.
        let s = samples([(0.0, 0.0, 0.0), (8.0, 0.0, 8.0), (0.0, 8.0, 0.0)], 8);
        let at = s.iter().find(|x| x.0 == 8 + 2).unwrap();
        assert!((at.1 - 2.5).abs() < 1e-12 && at.2, "{at:?}");
        // 8·9/2 = 36 centres with i + j ≤ 7 are in the closed triangle; the 8 with i + j = 7
        // lie on the hypotenuse x + y = 8.
        assert_eq!(s.len(), 36);
        assert_eq!(s.iter().filter(|x| !x.2).count(), 8);
        let flat = [(0.0, 0.0, 0.0), (1.0, 1.0, 0.0), (2.0, 2.0, 0.0)];
        assert!(SnappedTriangle::new(flat.map(|(x, y, z)| GridPoint::snap(x, y, z))).is_none());
    }

    #[test]
    fn the_row_spans_visit_exactly_the_centres_in_the_closed_triangle() {
        // Triangles with corners on a coarse lattice (edges through many centres) and
        // anywhere, some reaching off the 12×12 grid, against a test of every centre.
        let mut seed = 12345u64;
        let mut next = |scale: f64| {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 33) as f64 / (1u64 << 31) as f64 * 16.0 - 2.0) * scale
        };
        let mut visited_total = 0;
        for round in 0..400 {
            let coarse = round % 2 == 0;
            let mut corner = || {
                let (x, y) = (next(1.0), next(1.0));
                let q = |v: f64| if coarse { (v * 2.0).round() / 2.0 } else { v };
                GridPoint::snap(q(x), q(y), 1.0)
            };
            let corners = [corner(), corner(), corner()];
            let Some(t) = SnappedTriangle::new(corners) else {
                continue;
            };
            let mut visited = Vec::new();
            t.for_each_sample(12, |i, _, strict| visited.push((i, strict)));
            let side = |o: GridPoint, e: GridPoint, x: i64, y: i64| {
                ((e.x - o.x) * (y - o.y) - (e.y - o.y) * (x - o.x)).signum()
            };
            let mut expected = Vec::new();
            for i in 0..144usize {
                let (x, y) = (
                    (i % 12) as i64 * SUB + SUB / 2,
                    (i / 12) as i64 * SUB + SUB / 2,
                );
                let [a, b, c] = t.p;
                let s = [side(a, b, x, y), side(b, c, x, y), side(c, a, x, y)];
                if s.iter().all(|&v| v >= 0) {
                    expected.push((i, s.iter().all(|&v| v > 0)));
                }
            }
            assert_eq!(visited, expected, "{corners:?}");
            visited_total += visited.len();
        }
        assert!(visited_total > 2000, "{visited_total}");
    }
}
