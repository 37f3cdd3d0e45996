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

use crate::crossings::{bounds, boxes_apart, triangles_cross};
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
    let grid = Grid::new(&boxes, mesh.bounds().diagonal());
    let margin = grid.margin;
    // The cells of each box's low and high corners (the box grown by the margin).
    let spans: Vec<([u64; 3], [u64; 3])> = (boxes.par_iter())
        .map(|&(lo, hi)| (grid.cell(lo - margin), grid.cell(hi + margin)))
        .collect();
    // Every cell a triangle's box reaches, sorted by cell.
    let mut entries: Vec<(u64, u32)> = (spans.par_iter().enumerate())
        .flat_map_iter(|(t, &(a, b))| {
            let grid = &grid;
            (a[2]..=b[2]).flat_map(move |z| {
                (a[1]..=b[1]).flat_map(move |y| {
                    (a[0]..=b[0]).map(move |x| (grid.index([x, y, z]), t as u32))
                })
            })
        })
        .collect();
    entries.par_sort_unstable_by_key(|e| e.0);
    let lists: Vec<&[(u64, u32)]> = (entries.chunk_by(|x, y| x.0 == y.0))
        .filter(|l| l.len() > 1)
        .collect();
    let member = |t: u32| Member {
        triangle: t,
        low: boxes[t as usize].0,
        high: boxes[t as usize].1,
        low_cell: spans[t as usize].0,
    };
    let cross = |s: u32, t: u32| {
        let (s, t) = (s.min(t), s.max(t));
        let (a, b) = (s as usize, t as usize);
        let (ta, tb) = (mesh.triangles[a], mesh.triangles[b]);
        triangles_cross(corners[a], ta, corners[b], tb, margin).then_some((s, t))
    };
    let mut pairs: Vec<(u32, u32)> = lists
        .par_iter()
        .flat_map_iter(|list| cell_pairs(list, &member, &grid, &cross))
        .collect();
    pairs.par_sort_unstable();
    pairs
}

/// A triangle of a cell's list, with what the pair test reads before the triangles
/// themselves: its box and the cell of the box's low corner. Copied into the list's own
/// memory, so that a list's pairs read no further than it.
#[derive(Clone, Copy, Default)]
struct Member {
    triangle: u32,
    low: DVec3,
    high: DVec3,
    low_cell: [u64; 3],
}

/// The pairs of one cell's triangles (`list`, each read through `member`) that `cross`
/// finds crossing: every pair of a short list; a long one's (a dense tangle of small
/// triangles) swept along x, each triangle tested only against those whose boxes start
/// before its own ends. A pair is tested in one cell only, the one holding the low corner of
/// its boxes' overlap (the larger of their low corners' cells, axis by axis): it lies in both
/// boxes' cells when the boxes are not apart.
fn cell_pairs(
    list: &[(u64, u32)],
    member: &impl Fn(u32) -> Member,
    grid: &Grid,
    cross: &impl Fn(u32, u32) -> Option<(u32, u32)>,
) -> Vec<(u32, u32)> {
    let cell = list[0].0;
    let margin = grid.margin;
    let test = |s: &Member, t: &Member| {
        let (p, q) = (s.low_cell, t.low_cell);
        let home = grid.index([p[0].max(q[0]), p[1].max(q[1]), p[2].max(q[2])]);
        if home != cell || boxes_apart((s.low, s.high), (t.low, t.high), margin) {
            return None;
        }
        cross(s.triangle, t.triangle)
    };
    let mut out = Vec::new();
    if list.len() <= SWEPT {
        let mut members = [Member::default(); SWEPT];
        for (m, &(_, t)) in members.iter_mut().zip(list) {
            *m = member(t);
        }
        let members = &members[..list.len()];
        for (k, s) in members.iter().enumerate() {
            out.extend(members[k + 1..].iter().filter_map(|t| test(s, t)));
        }
        return out;
    }
    let mut members: Vec<Member> = list.iter().map(|&(_, t)| member(t)).collect();
    members.sort_unstable_by(|a, b| a.low.x.total_cmp(&b.low.x));
    for (k, s) in members.iter().enumerate() {
        let end = s.high.x + margin;
        let starting = members[k + 1..].iter().take_while(|t| t.low.x <= end);
        out.extend(starting.filter_map(|t| test(s, t)));
    }
    out
}

/// Cells with more triangles than this are swept rather than tested pair by pair.
const SWEPT: usize = 16;

/// The bucketing grid: cells of [`cell_size`] from the boxes' smallest corner (less a margin),
/// numbered x fastest; at most two million cells a side (cells further out share the last), so
/// that a cell's number fits 64 bits.
struct Grid {
    origin: DVec3,
    cell: f64,
    margin: f64,
    cells: [u64; 3],
}

impl Grid {
    fn new(boxes: &[(DVec3, DVec3)], diagonal: f64) -> Grid {
        let cell = cell_size(boxes, diagonal);
        let margin = cell * 0.5e-6;
        let (lo, hi) = boxes.iter().fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(lo, hi), b| (lo.min(b.0), hi.max(b.1)),
        );
        let origin = lo - 2.0 * margin;
        let span = ((hi + 2.0 * margin - origin) / cell).floor();
        let cells = (span + 1.0)
            .clamp(DVec3::ONE, DVec3::splat(2e6))
            .as_u64vec3();
        Grid {
            origin,
            cell,
            margin,
            cells: cells.to_array(),
        }
    }

    /// The cell holding `p`, axis by axis (clamped to the grid).
    fn cell(&self, p: DVec3) -> [u64; 3] {
        let c = ((p - self.origin) / self.cell).floor().max(DVec3::ZERO);
        let c = c.as_u64vec3().to_array();
        [0, 1, 2].map(|k| c[k].min(self.cells[k] - 1))
    }

    fn index(&self, c: [u64; 3]) -> u64 {
        (c[2] * self.cells[1] + c[1]) * self.cells[0] + c[0]
    }
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
