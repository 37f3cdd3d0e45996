//! The pairs of a mesh's triangles that cross each other: a whole-mesh count of what the
//! cleaning's guard refuses to make and what the quadric stage refuses to accept (so that
//! no level crosses itself).
//!
//! Beyond the paper. The pair test is [`crate::crossings::triangles_cross`]: a proper crossing
//! by certain signs, or a coplanar overlap; touching, and the rounding of near-coplanar
//! neighbours, is not crossing (the cleaning's guard, which refuses those too, asks
//! [`crate::crossings::triangles_meet`]). Used to report
//! and avoid what a geometric stage does to a cleaned level (the quadric collapse can fold one
//! sheet through another where two lie close).
//!
//! Cost: the triangles' boxes on a grid of cells of their mean longest side (the cells each
//! box reaches, sorted), O(F log F), then the exact test for each pair of triangles whose
//! boxes meet, in the one cell that holds the low corner of their overlap, on all threads.
//! Memory: about 100 bytes per triangle.

use glam::DVec3;
use rayon::prelude::*;

use crate::crossings::{bounds, triangles_cross};
use crate::TriangleMesh;

/// Every pair `(s, t)`, `s < t`, of `mesh`'s triangles that cross (module docs), ascending.
///
/// ```
/// use voxlod_core::{crossing_pairs, glam::Vec3, TriangleMesh};
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
    let corners: Vec<[DVec3; 3]> = (0..count)
        .into_par_iter()
        .map(|t| mesh.corners(t))
        .collect();
    let boxes: Vec<(DVec3, DVec3)> = corners.par_iter().map(|c| bounds(*c)).collect();
    let cell = cell_size(&boxes, mesh.bounds().diagonal());
    let margin = cell * 0.5e-6;
    // Every cell a triangle's box (grown by the margin) reaches, sorted by cell.
    let mut entries: Vec<([i64; 3], u32)> = (boxes.par_iter().enumerate())
        .flat_map_iter(|(t, &(lo, hi))| {
            let (a, b) = (key(lo - margin, cell), key(hi + margin, cell));
            (a[2]..=b[2]).flat_map(move |z| {
                (a[1]..=b[1]).flat_map(move |y| (a[0]..=b[0]).map(move |x| ([x, y, z], t as u32)))
            })
        })
        .collect();
    entries.par_sort_unstable();
    let lists: Vec<&[([i64; 3], u32)]> = (entries.chunk_by(|x, y| x.0 == y.0))
        .filter(|l| l.len() > 1)
        .collect();
    // A pair is tested in one cell only, the one holding the low corner of its boxes'
    // overlap: it lies in both boxes' cells when the boxes are not apart.
    let home = |a: usize, b: usize| key(boxes[a].0.max(boxes[b].0) - margin, cell);
    let mut pairs: Vec<(u32, u32)> = lists
        .par_iter()
        .flat_map_iter(|list| {
            let (corners, home) = (&corners, &home);
            list.iter()
                .enumerate()
                .flat_map(move |(k, &(cell_key, s))| {
                    list[k + 1..].iter().filter_map(move |&(_, t)| {
                        let (s, t) = (s.min(t), s.max(t));
                        let (a, b) = (s as usize, t as usize);
                        if home(a, b) != cell_key {
                            return None;
                        }
                        let (ta, tb) = (mesh.triangles[a], mesh.triangles[b]);
                        let cross = triangles_cross(corners[a], ta, corners[b], tb, margin);
                        cross.then_some((s, t))
                    })
                })
        })
        .collect();
    pairs.par_sort_unstable();
    pairs
}

/// The grid's cell: the triangles' mean longest side (of their `boxes`), at least a millionth
/// of the diagonal.
fn cell_size(boxes: &[(DVec3, DVec3)], diagonal: f64) -> f64 {
    let mean = boxes
        .iter()
        .map(|(lo, hi)| (*hi - *lo).max_element())
        .sum::<f64>()
        / boxes.len() as f64;
    let cell = mean.max(diagonal * 1e-6);
    if cell.is_finite() && cell > 0.0 {
        cell
    } else {
        1.0
    }
}

fn key(p: DVec3, cell: f64) -> [i64; 3] {
    (p / cell).floor().as_i64vec3().to_array()
}
