//! Refusing folds: a meshoptimizer pass must not make two triangles cross (no level
//! crosses itself). Where two sheets lie closer than the collapses reach,
//! meshoptimizer's quadric collapse can pull a vertex of one sheet through the other; its
//! error estimate sees only the planes of the vertex's own neighbourhood. Our addition,
//! neither the paper's (He et al. 1995, §5 leaves the geometric stage open) nor meshoptimizer's.
//!
//! [`Folds::check`] counts the pairs of a pass's result that cross ([`crossing_pairs`], the
//! whole-mesh count of voxlod-core) and refuses the pass when there are more than in the mesh
//! before it (the input's count, usually 0, or the last accepted step's). The pairs it blames
//! are those with at least one new triangle, not one of the mesh before the pass (a pass
//! keeps the vertex buffer and moves no vertex, so a triangle with the same three vertices is
//! the same triangle, and a pair of unchanged triangles crossed before the pass too: an
//! input's own crossings are not the pass's doing). [`lock_around`] then locks every vertex
//! of the mesh before the pass inside the boxes of those triangles, each grown by half its longest side (the vertex that collapsed onto a
//! crossing triangle's corner lay within about one side of it), so that the next pass leaves
//! that neighbourhood as it was and spends its collapses elsewhere; unless that would lock
//! more than a sixteenth of the triangle count in vertices (a pass that folded much of the
//! mesh, as a hollow ball's thin wall at a small budget), where the ratchet asks for less
//! instead.
//!
//! Cost: [`Folds::check`] is one [`crossing_pairs`], O(F) on all threads, and only when some
//! pair crosses a hash set of the earlier triangles and, once, the count of the input's
//! pairs; [`lock_around`] puts the grown boxes on a grid of cells as large as the largest,
//! O(V + C) for C boxes of similar size.

use rustc_hash::{FxHashMap as HashMap, FxHashSet as HashSet};

use voxlod_core::crossings::bounds;
use voxlod_core::glam::DVec3;
use voxlod_core::{crossing_pairs, TriangleMesh};

/// The crossing pairs a ratchet's accepted meshes have, counted when first needed.
#[derive(Default)]
pub(crate) struct Folds {
    /// Crossing pairs of the last accepted mesh (the input at first), once counted.
    accepted: Option<usize>,
}

impl Folds {
    /// Whether the pass from `before` (the last accepted mesh) to `after`, over the same
    /// vertices, made no more crossing pairs than `before` has: `Ok` (and `after` is taken as
    /// the accepted mesh), or the triangles of `after` (ascending, each once) in a crossing pair
    /// with at least one triangle that `before` does not have.
    pub(crate) fn check(
        &mut self,
        before: &TriangleMesh,
        after: &TriangleMesh,
    ) -> Result<(), Vec<u32>> {
        let pairs = crossing_pairs(after);
        if pairs.is_empty() {
            self.accepted = Some(0);
            return Ok(());
        }
        let key = |t: [u32; 3]| {
            let mut t = t;
            t.sort_unstable();
            t
        };
        let earlier: HashSet<[u32; 3]> = before.triangles.iter().map(|&t| key(t)).collect();
        let is_new = |t: u32| !earlier.contains(&key(after.triangles[t as usize]));
        let mut crossing: Vec<u32> = (pairs.iter())
            .filter(|&&(s, t)| is_new(s) || is_new(t))
            .flat_map(|&(s, t)| [s, t])
            .collect();
        // Pairs of unchanged triangles crossed before as well; only new pairs can add to the
        // count, and only then is `before`'s needed.
        let had = match crossing.is_empty() {
            true => pairs.len(),
            false => *(self.accepted).get_or_insert_with(|| crossing_pairs(before).len()),
        };
        if pairs.len() <= had {
            self.accepted = Some(pairs.len());
            return Ok(());
        }
        crossing.sort_unstable();
        crossing.dedup();
        Err(crossing)
    }
}

/// Locks the vertices of `before`'s triangles that lie inside the box of one of `after`'s
/// triangles `crossing`, grown by half its longest side (module docs); whether any vertex was
/// newly locked. `before` and `after` share their vertex buffer.
pub(crate) fn lock_around(
    before: &TriangleMesh,
    after: &TriangleMesh,
    crossing: &[u32],
    locked: &mut [bool],
) -> bool {
    let boxes: Vec<(DVec3, DVec3)> = crossing
        .iter()
        .map(|&t| {
            let (lo, hi) = bounds(after.corners(t as usize));
            let grow = DVec3::splat(0.5 * (hi - lo).max_element());
            (lo - grow, hi + grow)
        })
        .collect();
    let Some(cell) = boxes
        .iter()
        .map(|(lo, hi)| (*hi - *lo).max_element())
        .reduce(f64::max)
    else {
        return false;
    };
    if !(cell.is_finite() && cell > 0.0) {
        return false;
    }
    let key = |p: DVec3| (p / cell).floor().as_i64vec3().to_array();
    let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::default();
    for (b, (lo, hi)) in boxes.iter().enumerate() {
        let (a, z) = (key(*lo), key(*hi));
        for x in a[0]..=z[0] {
            for y in a[1]..=z[1] {
                for w in a[2]..=z[2] {
                    grid.entry([x, y, w]).or_default().push(b as u32);
                }
            }
        }
    }
    let inside = |p: DVec3| {
        grid.get(&key(p)).is_some_and(|list| {
            (list.iter()).any(|&b| {
                let (lo, hi) = boxes[b as usize];
                p.cmpge(lo).all() && p.cmple(hi).all()
            })
        })
    };
    let mut fresh: Vec<u32> = (before.triangles.as_flattened().iter().copied())
        .filter(|&v| !locked[v as usize] && inside(before.positions[v as usize].as_dvec3()))
        .collect();
    fresh.sort_unstable();
    fresh.dedup();
    if fresh.is_empty() || fresh.len() > before.triangles.len() / LOCK_SHARE {
        return false;
    }
    for v in fresh {
        locked[v as usize] = true;
    }
    true
}

/// A fold's locks may take at most a triangle count's share of vertices (about
/// `2 / LOCK_SHARE` of a closed mesh's): where a pass folded much of the mesh, locking it
/// would leave nothing to collapse, and asking for less (the ratchet's halving) does better.
const LOCK_SHARE: usize = 16;
