//! Checking a drawing order: no triangle may be drawn before a triangle that lies behind it.
//!
//! Every pair of triangles whose projections overlap (by more than a small fraction of the
//! smaller one's area) is found through a grid of bins over the image plane; for each, the depth
//! difference of the two planes is evaluated at every corner of the overlap polygon. If it has one
//! sign everywhere, one triangle is behind the other there and must come first in the order; if
//! the sign changes, the triangles cross in 3-D, no order is right, and the pair is counted apart.
//!
//! This is independent of how the order was made (it knows nothing of cells) and costs
//! O(Σ pairs per bin): for surfaces of small triangles, about the depth complexity squared per
//! bin. Bins run in parallel.

use glam::{DVec2, DVec3, UVec2, Vec3};
use rayon::prelude::*;
use serde::Serialize;

use crate::geometry::{clip, Projected, Projector};
use crate::order::View;
use crate::LayersError;

/// What [`check_order`] found.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct OrderCheck {
    /// Triangles in the mesh.
    pub triangles: usize,
    /// Pairs whose projections overlap and that do not cross: the ones with a right order.
    pub overlapping_pairs: u64,
    /// Of those, pairs drawn in the wrong order.
    pub violations: u64,
    /// Pairs that cross in 3-D (no order is right for them).
    pub crossing_pairs: u64,
}

/// Overlaps smaller than this fraction of the smaller triangle's projected area are not checked.
pub const CHECK_OVERLAP: f64 = 1e-6;

/// Checks `order` (a permutation of the triangles) for `view`.
///
/// # Example
///
/// Two stacked triangles seen from above: drawing the lower one first is right, the other way
/// round is one violation.
///
/// ```
/// use glam::{DVec3, Vec3};
/// use voxlod_layers::{check_order, View};
///
/// let corners = |z| [Vec3::new(0.0, 0.0, z), Vec3::new(1.0, 0.0, z), Vec3::new(0.0, 1.0, z)];
/// let positions = [corners(0.0), corners(1.0)].concat();
/// let triangles = [[0, 1, 2], [3, 4, 5]];
/// let view = View::Orthographic { direction: DVec3::new(0.1, 0.05, -1.0) };
/// let right = check_order(&positions, &triangles, &[0, 1], &view)?;
/// assert_eq!((right.overlapping_pairs, right.violations), (1, 0));
/// let wrong = check_order(&positions, &triangles, &[1, 0], &view)?;
/// assert_eq!(wrong.violations, 1);
/// # Ok::<(), voxlod_layers::LayersError>(())
/// ```
pub fn check_order(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    order: &[u32],
    view: &View,
) -> Result<OrderCheck, LayersError> {
    view.check()?;
    let rank = ranks(order, triangles.len())?;
    let projector = projector_for(view, positions)?;
    let projected: Vec<Option<Projected>> = triangles
        .par_iter()
        .map(|t| Projected::new(&projector, t.map(|v| positions[v as usize].as_dvec3())))
        .collect();
    let live: Vec<u32> = (0..triangles.len() as u32)
        .filter(|&t| projected[t as usize].is_some_and(|p| p.area2 != 0.0))
        .collect();
    let mut check = OrderCheck {
        triangles: triangles.len(),
        ..Default::default()
    };
    if live.is_empty() {
        return Ok(check);
    }
    let p = |t: u32| projected[t as usize].as_ref().expect("live");
    let bins = Bins::new(&live, p);
    let (start, members) = bins.members(&live, p);
    let totals = (0..bins.count())
        .into_par_iter()
        .map(|b| {
            let list = &members[start[b] as usize..start[b + 1] as usize];
            bins.check_pairs(b, list, &projector, &rank, p)
        })
        .reduce(|| (0, 0, 0), |x, y| (x.0 + y.0, x.1 + y.1, x.2 + y.2));
    check.overlapping_pairs = totals.0;
    check.violations = totals.1;
    check.crossing_pairs = totals.2;
    Ok(check)
}

/// The position of each triangle in `order`; refuses an order that is not a permutation of
/// `0..triangles`.
fn ranks(order: &[u32], triangles: usize) -> Result<Vec<u32>, LayersError> {
    if order.len() != triangles {
        return Err(LayersError::Invalid(format!(
            "the order lists {} triangles of {}",
            order.len(),
            triangles
        )));
    }
    let mut rank = vec![u32::MAX; triangles];
    for (i, &t) in order.iter().enumerate() {
        if t as usize >= triangles || rank[t as usize] != u32::MAX {
            return Err(LayersError::Invalid(format!(
                "the order is not a permutation (triangle {t} at {i})"
            )));
        }
        rank[t as usize] = i as u32;
    }
    Ok(rank)
}

/// The projection of `view`; a perspective view looks from its eye at the vertices' centroid.
fn projector_for(view: &View, positions: &[Vec3]) -> Result<Projector, LayersError> {
    Ok(match *view {
        View::Orthographic { direction } => Projector::orthographic(direction),
        View::Perspective { eye } => {
            let c = positions.iter().map(|p| p.as_dvec3()).sum::<DVec3>()
                / positions.len().max(1) as f64;
            let d = c - eye;
            if d.length_squared() == 0.0 {
                return Err(LayersError::ZeroViewDirection);
            }
            Projector::perspective(eye, d)
        }
    })
}

/// Square bins over the image plane, twice the mean triangle extent, at most 2048 per side.
struct Bins {
    lo: DVec2,
    size: f64,
    nb: UVec2,
}

impl Bins {
    fn new<'a>(live: &[u32], p: impl Fn(u32) -> &'a Projected) -> Bins {
        let (mut lo, mut hi) = (p(live[0]).min, p(live[0]).max);
        let mut extent = 0.0;
        for &t in live {
            lo = lo.min(p(t).min);
            hi = hi.max(p(t).max);
            extent += (p(t).max - p(t).min).max_element();
        }
        let size = (2.0 * extent / live.len() as f64)
            .max((hi - lo).max_element() / 2048.0)
            .max(1e-300);
        let nb = ((hi - lo) / size).floor().as_uvec2() + 1;
        Bins { lo, size, nb }
    }

    fn count(&self) -> usize {
        (self.nb.x * self.nb.y) as usize
    }

    /// The bin (column, row) of a point.
    #[inline]
    fn bin(&self, x: f64, y: f64) -> (u32, u32) {
        let i = (((x - self.lo.x) / self.size) as u32).min(self.nb.x - 1);
        let j = (((y - self.lo.y) / self.size) as u32).min(self.nb.y - 1);
        (i, j)
    }

    /// The bins (first column, first row, last column, last row) a triangle's box touches.
    #[inline]
    fn span(&self, p: &Projected) -> (u32, u32, u32, u32) {
        let (i0, j0) = self.bin(p.min.x, p.min.y);
        let (i1, j1) = self.bin(p.max.x, p.max.y);
        (i0, j0, i1, j1)
    }

    /// The live triangles of each bin (a counting sort): where each bin's list starts (with
    /// the total at the end), and the lists.
    fn members<'a>(&self, live: &[u32], p: impl Fn(u32) -> &'a Projected) -> (Vec<u32>, Vec<u32>) {
        let nx = self.nb.x;
        let mut count = vec![0u32; self.count() + 1];
        for &t in live {
            let (i0, j0, i1, j1) = self.span(p(t));
            for j in j0..=j1 {
                for i in i0..=i1 {
                    count[(j * nx + i) as usize + 1] += 1;
                }
            }
        }
        for b in 0..count.len() - 1 {
            count[b + 1] += count[b];
        }
        let mut fill = count.clone();
        let mut members = vec![0u32; count[count.len() - 1] as usize];
        for &t in live {
            let (i0, j0, i1, j1) = self.span(p(t));
            for j in j0..=j1 {
                for i in i0..=i1 {
                    let b = (j * nx + i) as usize;
                    members[fill[b] as usize] = t;
                    fill[b] += 1;
                }
            }
        }
        (count, members)
    }

    /// The pairs of bin `b`'s triangles `list` that overlap, counted in the bin of their
    /// boxes' common lower corner only: (ordered pairs, violations of `rank`, crossing pairs).
    fn check_pairs<'a>(
        &self,
        b: usize,
        list: &[u32],
        projector: &Projector,
        rank: &[u32],
        p: impl Fn(u32) -> &'a Projected,
    ) -> (u64, u64, u64) {
        let (bi, bj) = ((b as u32) % self.nb.x, (b as u32) / self.nb.x);
        let mut c = (0u64, 0u64, 0u64);
        for (n, &s) in list.iter().enumerate() {
            for &t in &list[n + 1..] {
                let (a, b2) = (p(s), p(t));
                if !a.boxes_overlap(b2) {
                    continue;
                }
                // Check each pair once: in the bin of its boxes' common lower corner.
                if self.bin(a.min.x.max(b2.min.x), a.min.y.max(b2.min.y)) != (bi, bj) {
                    continue;
                }
                match compare(projector, a, b2) {
                    Relation::Apart => {}
                    Relation::Crossing => c.2 += 1,
                    Relation::Behind(first_is_behind) => {
                        c.0 += 1;
                        let (back, front) = if first_is_behind { (s, t) } else { (t, s) };
                        if rank[back as usize] > rank[front as usize] {
                            c.1 += 1;
                        }
                    }
                }
            }
        }
        c
    }
}

enum Relation {
    Apart,
    Crossing,
    /// `true` when the first triangle is behind the second.
    Behind(bool),
}

fn compare(projector: &Projector, a: &Projected, b: &Projected) -> Relation {
    let poly = clip(&a.corners, &b.corners);
    let smaller = 0.5 * a.area2.abs().min(b.area2.abs());
    let area = poly.area();
    if poly.len < 3 || area.is_nan() || area <= CHECK_OVERLAP * smaller {
        return Relation::Apart;
    }
    let (mut pos, mut neg) = (false, false);
    for q in &poly.corners[..poly.len] {
        let (Some(ta), Some(tb)) = (
            projector.depth_on_plane(*q, a.normal, a.offset),
            projector.depth_on_plane(*q, b.normal, b.offset),
        ) else {
            return Relation::Apart;
        };
        let tol = 1e-7 * (ta.abs() + tb.abs());
        if ta > tb + tol {
            pos = true;
        } else if tb > ta + tol {
            neg = true;
        }
    }
    match (pos, neg) {
        (true, false) => Relation::Behind(true),
        (false, true) => Relation::Behind(false),
        (true, true) => Relation::Crossing,
        // Touching or coplanar: any order draws the same.
        (false, false) => Relation::Apart,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_a_swapped_pair() {
        // Two stacked squares seen from +z looking down -z (eye above).
        let positions = vec![
            Vec3::new(0., 0., 0.),
            Vec3::new(1., 0., 0.),
            Vec3::new(0., 1., 0.),
            Vec3::new(0., 0., 1.),
            Vec3::new(1., 0., 1.),
            Vec3::new(0., 1., 1.),
        ];
        let tris = vec![[0, 1, 2], [3, 4, 5]];
        let view = View::Orthographic {
            direction: DVec3::new(0.1, 0.05, -1.0),
        };
        let good = check_order(&positions, &tris, &[0, 1], &view).unwrap();
        assert_eq!((good.overlapping_pairs, good.violations), (1, 0));
        let bad = check_order(&positions, &tris, &[1, 0], &view).unwrap();
        assert_eq!((bad.overlapping_pairs, bad.violations), (1, 1));
        // Not a permutation.
        assert!(check_order(&positions, &tris, &[1, 1], &view).is_err());
    }
}
