//! The levels of detail of one label: an octree of mesh pieces, level k made from level k − 1.
//!
//! Level 0 is the label's mesh cut on the grid of level-0 nodes (`cut.rs`). Level k ≥ 1 is made
//! node by node from level k − 1: each level-(k − 1) node's piece is simplified by
//! meshoptimizer with its boundary locked (`LockBorder`: the vertices on the node's faces, where
//! the cut opened the mesh, neither move nor go), to about `ratio` of its triangles within an
//! error of `2^k` voxels, and the eight children of a level-k node together make that node.
//! Triangles the simplification lays back to back are dropped in pairs; a level that would
//! leave the label no triangle holds the finer level's pieces as they are
//! ([`Octree::carried`]).
//! Locking the boundary keeps, on every level-(k − 1) plane, the very vertices and edges of the
//! finer levels, and those planes are where neuroglancer puts a coarse node's eighths beside
//! finer nodes: no crack opens between levels, and no level-k triangle crosses the 2 × 2 × 2
//! split of its node (`meshes.md`). Vertices are never created after the cut, only dropped, so
//! all levels index one vertex array.
//!
//! The octree is a function of the label's set of triangles: the mesh is welded into a
//! canonical order before the cut, the vertices renumbered in position order after it, and
//! each node's piece handed to meshoptimizer on its own vertices (`canonical.rs`), so the same
//! triangles in another order, or split between blocks with their shared vertices repeated,
//! give the same octree, whatever the number of threads.
//!
//! Cost: a sort of the vertices and one of the triangles, the cut, then one simplification
//! per node and level (meshoptimizer is about O(n log n) in the piece's triangles; the nodes of
//! a level run in parallel); memory: the vertices and each level's triangles.

use std::collections::BTreeMap;

use meshopt::{SimplifyOptions, VertexDataAdapter};
use rayon::prelude::*;
use voxlod_core::glam::DVec3;
use voxlod_core::memory;

use crate::canonical::{self, Compactor};
use crate::cut::cut_to_cells;
use crate::morton;
use crate::PrecomputedError;

/// One node of a level: its grid position and its triangles (indices into
/// [`Octree::positions`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Node {
    /// Grid position at its level.
    pub position: [u32; 3],
    /// Its triangles, counter-clockwise from outside.
    pub triangles: Vec<[u32; 3]>,
    /// Above level 0, where each child's simplified piece ends in `triangles`: (child position
    /// one level down, end index), in the order the children were gathered.
    pub parts: Vec<([u32; 3], usize)>,
}

/// A label's octree: levels of nodes in Morton order over one vertex array.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Octree {
    /// Vertices in the stored model space.
    pub positions: Vec<DVec3>,
    /// Corner of node (0, 0, 0) at every level.
    pub grid_origin: DVec3,
    /// Size of a level-0 node.
    pub chunk: DVec3,
    /// Per level, the nodes keyed (and so ordered) by their Morton code. Every node of level
    /// k < last has its parent in level k + 1, possibly with no triangle.
    pub levels: Vec<BTreeMap<u128, Node>>,
    /// Per level, whether it holds the finer level's pieces as they are, because simplifying
    /// them left the label no triangle at all (a label smaller than the level's error).
    pub carried: Vec<bool>,
}

/// How a label's octree is built.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OctreeOptions {
    /// Corner of node (0, 0, 0): at or below every vertex.
    pub grid_origin: DVec3,
    /// Size of a level-0 node.
    pub chunk: DVec3,
    /// Number of levels, at least 1.
    pub lods: usize,
    /// Fraction of a node's triangles kept from one level to the next.
    pub ratio: f64,
}

/// Builds the octree of a mesh given in the stored model space (vertices with the same
/// position are merged first, unused ones dropped). The octree depends on the set of triangles,
/// not on the order of the vertices, of the triangles or of their corners (`canonical.rs`): its
/// vertices are in position order, each level-0 node's triangles rotated and sorted, and each
/// node simplified on its own vertices in position order. Fails, naming the reason, if the
/// memory limit refuses the work or a node falls beyond the grid's 32-bit positions.
pub fn build(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    options: &OctreeOptions,
) -> Result<Octree, PrecomputedError> {
    memory::check_allocation(
        "a label's octree",
        octree_bytes(positions.len(), triangles.len(), options.lods),
    )?;
    build_unchecked(positions, triangles, options)
}

/// An upper estimate of the memory [`build`] takes for a mesh of this size.
pub fn octree_bytes(vertices: usize, triangles: usize, lods: usize) -> u64 {
    // Vertices: the input, the welded ones (the cut adds a few percent) and their sort keys.
    // Triangles: at the peak, the level-0 pieces with their cells and sort keys (68 bytes a
    // piece, a few percent more pieces than triangles), the welded triangles and the levels.
    memory::bytes_of::<DVec3>(vertices * 3)
        + memory::bytes_of::<([u64; 3], u32)>(vertices)
        + memory::bytes_of::<[u32; 3]>(triangles * (lods + 7))
}

/// [`build`] without asking the memory limit (the caller has asked for the whole job).
pub(crate) fn build_unchecked(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    options: &OctreeOptions,
) -> Result<Octree, PrecomputedError> {
    let (mut welded, triangles) = canonical::weld(positions, triangles);
    let sorted = welded.len();
    let pieces = cut_to_cells(&mut welded, &triangles, options.grid_origin, options.chunk);
    drop(triangles);
    let (cells, mut pieces): (Vec<[i64; 3]>, Vec<[u32; 3]>) = pieces.into_iter().unzip();
    canonical::renumber_by_position(&mut welded, sorted, &mut pieces);
    let level0 = level_zero(&cells, &pieces)?;
    let mut octree = Octree {
        positions: welded,
        grid_origin: options.grid_origin,
        chunk: options.chunk,
        levels: vec![level0],
        carried: vec![false],
    };
    let relative: Vec<[f32; 3]> = octree
        .positions
        .iter()
        .map(|p| (*p - options.grid_origin).as_vec3().to_array())
        .collect();
    for lod in 1..options.lods {
        let finer = &octree.levels[lod - 1];
        let next = coarser(finer, &relative, options.ratio, lod)?;
        let emptied = next.values().all(|n| n.triangles.is_empty());
        let next = match emptied {
            true => gathered_parts(finer, finer.values().map(|c| c.triangles.clone()).collect()),
            false => next,
        };
        octree.levels.push(next);
        octree.carried.push(emptied);
    }
    Ok(octree)
}

/// The level-0 nodes: the cut's pieces grouped by cell, in Morton order, each node's triangles
/// sorted.
pub(crate) fn level_zero(
    cells: &[[i64; 3]],
    pieces: &[[u32; 3]],
) -> Result<BTreeMap<u128, Node>, PrecomputedError> {
    let mut keyed: Vec<(u128, [u32; 3])> = Vec::with_capacity(pieces.len());
    for (cell, t) in cells.iter().zip(pieces) {
        keyed.push((morton::code(node_position(*cell)?), *t));
    }
    keyed.sort_unstable();
    let mut level0: BTreeMap<u128, Node> = BTreeMap::new();
    for group in keyed.chunk_by(|a, b| a.0 == b.0) {
        let node = Node {
            position: morton::decode(group[0].0),
            triangles: group.iter().map(|g| g.1).collect(),
            parts: Vec::new(),
        };
        level0.insert(group[0].0, node);
    }
    Ok(level0)
}

/// A cell index as a node position, or the reason it is not one.
pub(crate) fn node_position(cell: [i64; 3]) -> Result<[u32; 3], PrecomputedError> {
    let mut out = [0u32; 3];
    for a in 0..3 {
        out[a] = u32::try_from(cell[a]).map_err(|_| PrecomputedError::Mesh {
            label: 0,
            reason: format!("octree node {cell:?} is outside the grid's 32-bit positions"),
        })?;
    }
    Ok(out)
}

/// Nodes handed to one task when a level's nodes are simplified or encoded in parallel: each
/// task sets up scratch memory of one mark per vertex of the label.
pub(crate) const NODES_PER_TASK: usize = 32;

/// Level `lod` from the level below: each node simplified with its boundary locked (in
/// parallel; each node's result depends on that node alone), then the eight children of each
/// new node gathered in Morton order ([`gathered_parts`]).
fn coarser(
    finer: &BTreeMap<u128, Node>,
    relative: &[[f32; 3]],
    ratio: f64,
    lod: usize,
) -> Result<BTreeMap<u128, Node>, PrecomputedError> {
    let error = (1u64 << lod) as f32;
    let children: Vec<&Node> = finer.values().collect();
    let kept: Vec<Vec<[u32; 3]>> = children
        .par_iter()
        .with_min_len(NODES_PER_TASK)
        .map_init(
            || Simplifier::new(relative, ratio),
            |simplifier, child| simplifier.simplify(&child.triangles, error),
        )
        .collect::<Result<_, _>>()?;
    Ok(gathered_parts(finer, kept))
}

/// The coarser level whose nodes gather, as their parts, the pieces `kept` of the finer
/// level's nodes (one per node, in the finer level's order).
fn gathered_parts(finer: &BTreeMap<u128, Node>, kept: Vec<Vec<[u32; 3]>>) -> BTreeMap<u128, Node> {
    let children = finer.values();
    let mut out: BTreeMap<u128, Node> = BTreeMap::new();
    for (child, kept) in children.zip(kept) {
        let position = child.position.map(|c| c >> 1);
        let node = out.entry(morton::code(position)).or_insert_with(|| Node {
            position,
            ..Node::default()
        });
        node.triangles.extend(kept);
        node.parts.push((child.position, node.triangles.len()));
    }
    out
}

/// meshoptimizer's simplifier applied to pieces of one vertex array, each on its own vertices.
struct Simplifier<'a> {
    /// Every vertex, relative to the grid's origin.
    relative: &'a [[f32; 3]],
    /// Fraction of a piece's triangles to keep.
    ratio: f64,
    /// The piece's vertices, reused from piece to piece.
    local: Vec<[f32; 3]>,
    /// Puts each piece on its own vertices.
    compactor: Compactor,
}

impl<'a> Simplifier<'a> {
    fn new(relative: &'a [[f32; 3]], ratio: f64) -> Self {
        Simplifier {
            relative,
            ratio,
            local: Vec::new(),
            compactor: Compactor::new(relative.len()),
        }
    }

    /// A piece simplified to about `ratio` of its triangles within `error` (stored units), its
    /// boundary locked; the triangles kept are rotated and sorted. Two triangles that the
    /// simplification laid back to back (a fold of no volume, or a small closed part flattened
    /// within the error) are dropped together, which leaves every edge paired as before. The
    /// piece is handed to meshoptimizer on its own vertices in increasing index order and its
    /// triangles in the order given, so the result depends on the piece alone.
    fn simplify(
        &mut self,
        triangles: &[[u32; 3]],
        error: f32,
    ) -> Result<Vec<[u32; 3]>, PrecomputedError> {
        if triangles.is_empty() {
            return Ok(Vec::new());
        }
        let piece = self.compactor.compact(triangles);
        self.local.clear();
        self.local
            .extend(piece.vertices.iter().map(|&v| self.relative[v as usize]));
        let bytes: &[u8] = meshopt::typed_to_bytes(&self.local);
        let adapter = VertexDataAdapter::new(bytes, 12, 0).map_err(|e| PrecomputedError::Mesh {
            label: 0,
            reason: format!("meshoptimizer refused the vertices: {e}"),
        })?;
        let indices: &[u32] = piece.triangles.as_flattened();
        let target = 3 * ((triangles.len() as f64 * self.ratio).ceil() as usize).max(1);
        let options = SimplifyOptions::LockBorder | SimplifyOptions::ErrorAbsolute;
        let kept = meshopt::simplify(indices, &adapter, target, error, options, None);
        let mut kept: Vec<[u32; 3]> = (kept.chunks_exact(3)).map(|t| [t[0], t[1], t[2]]).collect();
        drop_back_to_back(&mut kept);
        Ok(global(&piece.vertices, &kept))
    }
}

/// Triangles on a piece's own vertices put back on the mesh's, rotated and sorted.
fn global(vertices: &[u32], triangles: &[[u32; 3]]) -> Vec<[u32; 3]> {
    let mut out: Vec<[u32; 3]> = (triangles.iter())
        .map(|t| canonical::rotate(t.map(|v| vertices[v as usize])))
        .collect();
    out.sort_unstable();
    out
}

/// Drops triangles laid back to back: of the triangles on one set of three vertices, as many
/// of each winding as the other winding has are dropped. Every directed edge of a dropped
/// triangle is the reverse of one of its partner's, so the edges left stay paired as they
/// were. Cost: a sort of the triangles.
fn drop_back_to_back(triangles: &mut Vec<[u32; 3]>) {
    let winding = |t: &[u32; 3]| {
        let r = canonical::rotate(*t);
        r[1] < r[2]
    };
    let key = |t: &[u32; 3]| {
        let mut s = *t;
        s.sort_unstable();
        s
    };
    let mut order: Vec<u32> = (0..triangles.len() as u32).collect();
    order.sort_unstable_by_key(|&i| key(&triangles[i as usize]));
    let mut drop = vec![false; triangles.len()];
    let mut any = false;
    for run in order.chunk_by(|&a, &b| key(&triangles[a as usize]) == key(&triangles[b as usize])) {
        if run.len() < 2 {
            continue;
        }
        let (up, down): (Vec<u32>, Vec<u32>) =
            run.iter().partition(|&&i| winding(&triangles[i as usize]));
        for (&a, &b) in up.iter().zip(&down) {
            drop[a as usize] = true;
            drop[b as usize] = true;
            any = true;
        }
    }
    if any {
        let mut i = 0;
        triangles.retain(|_| {
            i += 1;
            !drop[i - 1]
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn back_to_back_pairs_are_dropped_and_the_rest_kept() {
        // A fold (0 1 2 / 0 2 1, the second rotated) beside a triangle on other vertices, a
        // doubled triangle of one winding (kept: no partner), and three on one set (one pair
        // dropped, one left).
        let mut t = vec![
            [0, 1, 2],
            [2, 1, 0],
            [3, 4, 5],
            [6, 7, 8],
            [6, 7, 8],
            [9, 10, 11],
            [11, 10, 9],
            [10, 11, 9],
        ];
        drop_back_to_back(&mut t);
        assert_eq!(t, vec![[3, 4, 5], [6, 7, 8], [6, 7, 8], [10, 11, 9]]);
    }
}
