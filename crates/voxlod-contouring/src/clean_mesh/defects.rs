//! The candidates of [`super::clean_mesh`]'s passes (short edges, small triangles) found by one
//! scan of the whole mesh at the start, and after that only among the candidates of the last
//! scan and the triangles changed since, so that a pass costs what its defects cost, not the
//! mesh.
//!
//! Beyond the paper. A triangle's edges and area change only when a step renames one of its
//! corners or moves one (a collapse, a flip, a relaxed corner), and every such step re-buckets
//! the triangle for the crossing guard: [`super::work::Work::rebucket`] notes it (module
//! `changes`). A triangle never comes back to life during the passes. So an edge or triangle
//! that is a candidate now either was one at the last scan or belongs to a triangle noted
//! since, and re-testing those two sets gives exactly the whole scan's list, in the same order:
//! edges by length, ties by the slot (3 · triangle + corner) where the whole scan meets them first;
//! triangles in ascending order. The whole scans are kept as the reference (`Scan::Whole`).
//! Cost: O(F) once, then O(K log K) per pass for K candidates and changed triangles. Memory:
//! one byte per triangle for the notes, four per changed triangle and eight per candidate.

use rayon::prelude::*;
use voxlod_core::TriangleMesh;

use super::changes::{FOR_EDGES, FOR_SMALL};
use super::work::{Surface, Work};

/// How the candidates of each pass are found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Scan {
    /// The whole mesh scanned before every pass: the reference.
    Whole,
    /// The last candidates and the triangles changed since (see the module documentation).
    Changed,
}

/// A short edge: its length, and its slot `3 · triangle + corner` (the edge runs from that
/// corner to the next, the smaller vertex first).
type Edge = (f64, u64);

/// The candidates found by the last scans.
pub(super) struct Defects {
    scan: Scan,
    /// Slots of the edges short at the last scan, ascending.
    edges: Vec<u64>,
    /// Triangles small at the last scan, ascending.
    small: Vec<u32>,
}

impl Defects {
    /// The short edges and small triangles of `work` (one scan of the whole mesh for both).
    /// With [`Scan::Whole`], nothing is scanned here: every pass scans the whole mesh.
    pub(super) fn new(work: &Work, min_edge: f64, min_area: f64, scan: Scan) -> Defects {
        if scan == Scan::Whole {
            let (edges, small) = (Vec::new(), Vec::new());
            return Defects { scan, edges, small };
        }
        let surface = &work.surface;
        let found: Vec<(u32, u8)> = (0..surface.triangles.len() as u32)
            .into_par_iter()
            .filter_map(|t| {
                let edges =
                    (0..3).fold(0u8, |m, k| m | (short(surface, t, k, min_edge) as u8) << k);
                let small = (small(surface, t, min_area) as u8) << 3;
                (edges | small != 0).then_some((t, edges | small))
            })
            .collect();
        let edges = (found.iter())
            .flat_map(|&(t, m)| {
                (0..3)
                    .filter(move |k| m & (1 << k) != 0)
                    .map(move |k| slot(t, k))
            })
            .collect();
        let small = (found.iter().filter(|f| f.1 & 8 != 0))
            .map(|f| f.0)
            .collect();
        Defects { scan, edges, small }
    }

    /// The edges shorter than `limit`, shortest first, ties in the order of their slots, as
    /// `(length, a, b)` with `a < b`.
    pub(super) fn short_edges(&mut self, work: &mut Work, limit: f64) -> Vec<(f64, u32, u32)> {
        let changed = work.changes.take(FOR_EDGES);
        let surface = &work.surface;
        let test = |s: u64| {
            let (t, k) = ((s / 3) as u32, (s % 3) as usize);
            short(surface, t, k, limit).then(|| (edge_length(surface, t, k), s))
        };
        let mut edges: Vec<Edge> = match self.scan {
            Scan::Whole => (0..slot(surface.triangles.len() as u32, 0))
                .into_par_iter()
                .filter_map(test)
                .collect(),
            Scan::Changed => {
                let mut slots = std::mem::take(&mut self.edges);
                slots.extend(
                    changed
                        .iter()
                        .flat_map(|&t| (0..3).map(move |k| slot(t, k))),
                );
                slots.par_sort_unstable();
                slots.dedup();
                slots.into_par_iter().filter_map(test).collect()
            }
        };
        edges.par_sort_unstable_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        if self.scan == Scan::Changed {
            self.edges = edges.iter().map(|e| e.1).collect();
            self.edges.par_sort_unstable();
        }
        (edges.into_iter())
            .map(|(length, s)| {
                let tri = surface.triangles[(s / 3) as usize];
                let k = (s % 3) as usize;
                (length, tri[k], tri[(k + 1) % 3])
            })
            .collect()
    }

    /// The live triangles smaller than `limit`, ascending.
    pub(super) fn small_triangles(&mut self, work: &mut Work, limit: f64) -> Vec<u32> {
        let changed = work.changes.take(FOR_SMALL);
        let surface = &work.surface;
        let test = |&t: &u32| small(surface, t, limit);
        let found: Vec<u32> = match self.scan {
            Scan::Whole => (0..surface.triangles.len() as u32)
                .into_par_iter()
                .filter(test)
                .collect(),
            Scan::Changed => {
                let mut candidates = std::mem::take(&mut self.small);
                candidates.extend(changed);
                candidates.par_sort_unstable();
                candidates.dedup();
                candidates.into_par_iter().filter(test).collect()
            }
        };
        if self.scan == Scan::Changed {
            self.small.clone_from(&found);
        }
        found
    }
}

/// Whether `mesh`, as given, has an edge shorter than `min_edge` or a triangle smaller than
/// `min_area`: whether [`Defects::new`] would find anything on it (the same `f64` arithmetic on
/// the same positions), without setting up the cleaning's lists. One parallel read of the
/// triangles, stopping at the first defect.
pub(super) fn any_defect(mesh: &TriangleMesh, min_edge: f64, min_area: f64) -> bool {
    (0..mesh.triangles.len()).into_par_iter().any(|t| {
        let p = mesh.corners(t);
        let short = (0..3).any(|k| p[k].distance(p[(k + 1) % 3]) < min_edge);
        short || 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length() < min_area
    })
}

fn slot(t: u32, k: usize) -> u64 {
    3 * t as u64 + k as u64
}

fn edge_length(surface: &Surface, t: u32, k: usize) -> f64 {
    let tri = surface.triangles[t as usize];
    let (a, b) = (tri[k], tri[(k + 1) % 3]);
    surface.positions[a as usize].distance(surface.positions[b as usize])
}

/// Edge `k` of live triangle `t` runs from the smaller vertex and is shorter than `limit`.
fn short(surface: &Surface, t: u32, k: usize, limit: f64) -> bool {
    let tri = surface.triangles[t as usize];
    let live = surface.alive[t as usize] && tri[k] < tri[(k + 1) % 3];
    live && edge_length(surface, t, k) < limit
}

/// Triangle `t` is live and smaller than `limit`.
fn small(surface: &Surface, t: u32, limit: f64) -> bool {
    surface.alive[t as usize] && surface.area(t) < limit
}
