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

use glam::{DVec3, Vec3};
use rayon::prelude::*;
use serde::Serialize;

use crate::geometry::{clip, Projected, Projector};
use crate::order::View;
use crate::LayersError;

/// What [`check_order`] found.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct OrderCheck {
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
pub fn check_order(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    order: &[u32],
    view: &View,
) -> Result<OrderCheck, LayersError> {
    view.check()?;
    if order.len() != triangles.len() {
        return Err(LayersError::Invalid(format!(
            "the order lists {} triangles of {}",
            order.len(),
            triangles.len()
        )));
    }
    let mut rank = vec![u32::MAX; triangles.len()];
    for (i, &t) in order.iter().enumerate() {
        if t as usize >= triangles.len() || rank[t as usize] != u32::MAX {
            return Err(LayersError::Invalid(format!(
                "the order is not a permutation (triangle {t} at {i})"
            )));
        }
        rank[t as usize] = i as u32;
    }
    let projector = match *view {
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
    };
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
    // Bins twice the mean triangle extent, at most 2048 per side.
    let (mut lo, mut hi) = (p(live[0]).min, p(live[0]).max);
    let mut extent = 0.0;
    for &t in &live {
        lo = lo.min(p(t).min);
        hi = hi.max(p(t).max);
        extent += (p(t).max - p(t).min).max_element();
    }
    let size = (2.0 * extent / live.len() as f64)
        .max((hi - lo).max_element() / 2048.0)
        .max(1e-300);
    let nb = ((hi - lo) / size).floor().as_uvec2() + 1;
    let bin = |x: f64, y: f64| {
        let i = (((x - lo.x) / size) as u32).min(nb.x - 1);
        let j = (((y - lo.y) / size) as u32).min(nb.y - 1);
        (i, j)
    };
    let mut count = vec![0u32; (nb.x * nb.y) as usize + 1];
    let span = |t: u32| {
        let (i0, j0) = bin(p(t).min.x, p(t).min.y);
        let (i1, j1) = bin(p(t).max.x, p(t).max.y);
        (i0, j0, i1, j1)
    };
    for &t in &live {
        let (i0, j0, i1, j1) = span(t);
        for j in j0..=j1 {
            for i in i0..=i1 {
                count[(j * nb.x + i) as usize + 1] += 1;
            }
        }
    }
    for b in 0..count.len() - 1 {
        count[b + 1] += count[b];
    }
    let mut fill = count.clone();
    let mut members = vec![0u32; count[count.len() - 1] as usize];
    for &t in &live {
        let (i0, j0, i1, j1) = span(t);
        for j in j0..=j1 {
            for i in i0..=i1 {
                let b = (j * nb.x + i) as usize;
                members[fill[b] as usize] = t;
                fill[b] += 1;
            }
        }
    }
    let totals = (0..(nb.x * nb.y) as usize)
        .into_par_iter()
        .map(|b| {
            let list = &members[count[b] as usize..count[b + 1] as usize];
            let (bi, bj) = ((b as u32) % nb.x, (b as u32) / nb.x);
            let mut c = (0u64, 0u64, 0u64);
            for (n, &s) in list.iter().enumerate() {
                for &t in &list[n + 1..] {
                    let (a, b2) = (p(s), p(t));
                    if !a.boxes_overlap(b2) {
                        continue;
                    }
                    // Check each pair once: in the bin of its boxes' common lower corner.
                    if bin(a.min.x.max(b2.min.x), a.min.y.max(b2.min.y)) != (bi, bj) {
                        continue;
                    }
                    match compare(&projector, a, b2) {
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
        })
        .reduce(|| (0, 0, 0), |x, y| (x.0 + y.0, x.1 + y.1, x.2 + y.2));
    check.overlapping_pairs = totals.0;
    check.violations = totals.1;
    check.crossing_pairs = totals.2;
    Ok(check)
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
