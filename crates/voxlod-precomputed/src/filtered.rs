//! The levels of detail of one label from given meshes, one per level: the paper's filter
//! pyramid (He et al. 1995 §2–4, each level filtered from the original at half the resolution
//! of the one before), rather than each level simplified from the finer one (`lods.rs`).
//!
//! Level k's mesh is cut on the grid of its nodes' eighths (`cut.rs`, cells of
//! `chunk · 2^(k − 1)` for k ≥ 1, of `chunk` for level 0), so that no triangle crosses the
//! 2 × 2 × 2 split of its node (`meshes.md`), and the pieces are gathered into their nodes.
//! Within a level, the cut puts the same vertex on both sides of a node's face, and one
//! quantization lattice per level keeps it the same integers in both fragments: no crack
//! opens between the fragments of a level.
//!
//! **Between levels** the surfaces are the pyramid's own: a coarser level is a different,
//! smoother surface, not the finer one with vertices taken away, so where neuroglancer draws a
//! level-k node's eighths beside finer nodes, the two surfaces meet on the node's face only up
//! to their distance there: within the filters' radii where both levels have the part (the
//! filter moves a surface by less than its radius), the whole cross-section where the coarser
//! level lost a part thinner than its filter. Simplifying each level from the finer one with
//! the seams locked (`lods.rs`) closes that seam, at the price of the pyramid's topology and
//! smoothing.
//!
//! Every node of a level below the last has its parent in the next level (an empty node where
//! the coarser surface has nothing there, as where a thin part vanished); a coarser node may
//! have eighths without a finer node (where the coarser surface reaches beyond the finer one),
//! which neuroglancer draws from the coarser level.
//!
//! Cost per level: the weld and cut of its mesh (sorts of its vertices and triangles); the
//! vertices of all levels in one array, level after level.

use std::collections::BTreeMap;

use voxlod_core::glam::DVec3;

use crate::canonical;
use crate::cut::cut_to_cells;
use crate::lods::{level_zero, node_position, Node, Octree, OctreeOptions};
use crate::morton;
use crate::PrecomputedError;

/// One level's mesh, in the stored model space.
pub struct LevelMesh<'a> {
    /// Its vertices.
    pub positions: &'a [DVec3],
    /// Its triangles, counter-clockwise from outside.
    pub triangles: &'a [[u32; 3]],
}

/// The octree of a label whose level k is `levels[k]` (module docs). `options.lods` must equal
/// the number of levels and `options.grid_origin` be at or below every vertex of every level;
/// `options.ratio` is not used. Depends on each level's set of triangles only, as
/// [`crate::lods::build`] does (`canonical.rs`). Fails, naming the reason, if a node falls
/// beyond the grid's 32-bit positions.
pub fn build_filtered(
    levels: &[LevelMesh],
    options: &OctreeOptions,
) -> Result<Octree, PrecomputedError> {
    if levels.len() != options.lods || levels.is_empty() {
        return Err(PrecomputedError::Mesh {
            label: 0,
            reason: format!(
                "{} meshes given for {} levels of detail",
                levels.len(),
                options.lods
            ),
        });
    }
    let mut octree = Octree {
        positions: Vec::new(),
        grid_origin: options.grid_origin,
        chunk: options.chunk,
        levels: Vec::with_capacity(levels.len()),
        carried: vec![false; levels.len()],
    };
    for (k, level) in levels.iter().enumerate() {
        // Level 0 is cut on its nodes, a coarser level on its nodes' eighths.
        let eighths = if k == 0 { 1 } else { 1u64 << (k - 1) };
        let cell = options.chunk * eighths as f64;
        let (cells, pieces) = cut_level(level, options.grid_origin, cell, &mut octree.positions);
        let nodes = match k {
            0 => level_zero(&cells, &pieces)?,
            _ => gathered(&cells, &pieces)?,
        };
        octree.levels.push(nodes);
    }
    with_parents(&mut octree.levels);
    Ok(octree)
}

/// The level's mesh welded, cut on cells of `cell` from `origin` and renumbered in position
/// order, its vertices appended to `positions`: each piece's cell and its triangle (indices
/// into `positions`).
fn cut_level(
    level: &LevelMesh,
    origin: DVec3,
    cell: DVec3,
    positions: &mut Vec<DVec3>,
) -> (Vec<[i64; 3]>, Vec<[u32; 3]>) {
    let (mut welded, triangles) = canonical::weld(level.positions, level.triangles);
    let sorted = welded.len();
    let pieces = cut_to_cells(&mut welded, &triangles, origin, cell);
    let (cells, mut pieces): (Vec<[i64; 3]>, Vec<[u32; 3]>) = pieces.into_iter().unzip();
    canonical::renumber_by_position(&mut welded, sorted, &mut pieces);
    let offset = positions.len() as u32;
    for t in pieces.iter_mut() {
        *t = t.map(|v| v + offset);
    }
    positions.extend(welded);
    (cells, pieces)
}

/// A coarser level's nodes from its pieces cut on the eighths' grid: each node's triangles
/// grouped by eighth in Morton order, each eighth's sorted, with `parts` saying where each
/// eighth's triangles end.
fn gathered(
    cells: &[[i64; 3]],
    pieces: &[[u32; 3]],
) -> Result<BTreeMap<u128, Node>, PrecomputedError> {
    let mut keyed: Vec<(u128, u128, [u32; 3])> = Vec::with_capacity(pieces.len());
    for (cell, t) in cells.iter().zip(pieces) {
        let eighth = node_position(*cell)?;
        let parent = eighth.map(|c| c >> 1);
        keyed.push((morton::code(parent), morton::code(eighth), *t));
    }
    keyed.sort_unstable();
    let mut nodes: BTreeMap<u128, Node> = BTreeMap::new();
    for group in keyed.chunk_by(|a, b| a.0 == b.0) {
        let mut node = Node {
            position: morton::decode(group[0].0),
            ..Node::default()
        };
        for eighth in group.chunk_by(|a, b| a.1 == b.1) {
            node.triangles.extend(eighth.iter().map(|e| e.2));
            node.parts
                .push((morton::decode(eighth[0].1), node.triangles.len()));
        }
        nodes.insert(group[0].0, node);
    }
    Ok(nodes)
}

/// Every node of a level below the last given its parent in the next level, an empty node
/// where that level has none.
fn with_parents(levels: &mut [BTreeMap<u128, Node>]) {
    for k in 1..levels.len() {
        let parents: Vec<[u32; 3]> = (levels[k - 1].values())
            .map(|n| n.position.map(|c| c >> 1))
            .collect();
        for position in parents {
            levels[k]
                .entry(morton::code(position))
                .or_insert_with(|| Node {
                    position,
                    ..Node::default()
                });
        }
    }
}
