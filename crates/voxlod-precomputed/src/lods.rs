//! The levels of detail of one label: an octree of mesh pieces, level k made from level k − 1.
//!
//! Level 0 is the label's mesh cut on the grid of level-0 nodes (`cut.rs`). Level k ≥ 1 is made
//! node by node from level k − 1: each level-(k − 1) node's piece is simplified by
//! meshoptimizer with its boundary locked (`LockBorder`: the vertices on the node's faces, where
//! the cut opened the mesh, neither move nor go), to about `ratio` of its triangles within an
//! error of `2^k` voxels, and the eight children of a level-k node together make that node.
//! Locking the boundary keeps, on every level-(k − 1) plane, the very vertices and edges of the
//! finer levels, and those planes are where neuroglancer puts a coarse node's eighths beside
//! finer nodes: no crack opens between levels, and no level-k triangle crosses the 2 × 2 × 2
//! split of its node (`meshes.md`). Vertices are never created after the cut, only dropped, so
//! all levels index one vertex array.
//!
//! Cost: the cut, then one simplification per node and level (meshoptimizer is about
//! O(n log n) in the piece's triangles); memory: the vertices and each level's triangles.

use std::collections::{BTreeMap, HashMap};

use meshopt::{SimplifyOptions, VertexDataAdapter};
use voxlod_core::glam::DVec3;
use voxlod_core::memory;

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
/// position are merged first). Fails, naming the reason, if the memory limit refuses the work
/// or a node falls beyond the grid's 32-bit positions.
pub fn build(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    options: &OctreeOptions,
) -> Result<Octree, PrecomputedError> {
    memory::check_allocation(
        "a label's octree",
        memory::bytes_of::<DVec3>(positions.len() * 2)
            + memory::bytes_of::<[u32; 3]>(triangles.len() * (options.lods + 2)),
    )?;
    let (mut welded, triangles) = weld(positions, triangles);
    let pieces = cut_to_cells(&mut welded, &triangles, options.grid_origin, options.chunk);
    let mut level0: BTreeMap<u128, Node> = BTreeMap::new();
    for (cell, t) in pieces {
        let position = node_position(cell)?;
        level0
            .entry(morton::code(position))
            .or_insert_with(|| Node {
                position,
                ..Node::default()
            })
            .triangles
            .push(t);
    }
    let mut octree = Octree {
        positions: welded,
        grid_origin: options.grid_origin,
        chunk: options.chunk,
        levels: vec![level0],
    };
    let relative: Vec<[f32; 3]> = octree
        .positions
        .iter()
        .map(|p| (*p - options.grid_origin).as_vec3().to_array())
        .collect();
    let bytes: &[u8] = meshopt::typed_to_bytes(&relative);
    let adapter = VertexDataAdapter::new(bytes, 12, 0).map_err(|e| PrecomputedError::Mesh {
        label: 0,
        reason: format!("meshoptimizer refused the vertices: {e}"),
    })?;
    for lod in 1..options.lods {
        let next = coarser(&octree.levels[lod - 1], &adapter, lod, options.ratio);
        octree.levels.push(next);
    }
    Ok(octree)
}

/// A cell index as a node position, or the reason it is not one.
fn node_position(cell: [i64; 3]) -> Result<[u32; 3], PrecomputedError> {
    let mut out = [0u32; 3];
    for a in 0..3 {
        out[a] = u32::try_from(cell[a]).map_err(|_| PrecomputedError::Mesh {
            label: 0,
            reason: format!("octree node {cell:?} is outside the grid's 32-bit positions"),
        })?;
    }
    Ok(out)
}

/// Merges vertices at the same position (so that cut pieces and simplification see one
/// surface) and drops triangles that then repeat an index.
fn weld(positions: &[DVec3], triangles: &[[u32; 3]]) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let mut first: HashMap<[u64; 3], u32> = HashMap::with_capacity(positions.len());
    let mut out = Vec::with_capacity(positions.len());
    let remap: Vec<u32> = positions
        .iter()
        .map(|p| {
            *first
                .entry(p.to_array().map(f64::to_bits))
                .or_insert_with(|| {
                    out.push(*p);
                    out.len() as u32 - 1
                })
        })
        .collect();
    let triangles = triangles
        .iter()
        .map(|t| t.map(|v| remap[v as usize]))
        .filter(|t| t[0] != t[1] && t[1] != t[2] && t[2] != t[0])
        .collect();
    (out, triangles)
}

/// Level `lod` from the level below: each node simplified with its boundary locked, then the
/// eight children of each new node gathered.
fn coarser(
    finer: &BTreeMap<u128, Node>,
    adapter: &VertexDataAdapter<'_>,
    lod: usize,
    ratio: f64,
) -> BTreeMap<u128, Node> {
    let error = (1u64 << lod) as f32;
    let mut out: BTreeMap<u128, Node> = BTreeMap::new();
    for child in finer.values() {
        let kept = simplify(&child.triangles, adapter, ratio, error);
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

/// One node's piece simplified to about `ratio` of its triangles within `error` (stored
/// units), its boundary locked.
fn simplify(
    triangles: &[[u32; 3]],
    adapter: &VertexDataAdapter<'_>,
    ratio: f64,
    error: f32,
) -> Vec<[u32; 3]> {
    if triangles.is_empty() {
        return Vec::new();
    }
    let indices: Vec<u32> = triangles.iter().flatten().copied().collect();
    let target = 3 * ((triangles.len() as f64 * ratio).ceil() as usize).max(1);
    let options =
        SimplifyOptions::LockBorder | SimplifyOptions::Sparse | SimplifyOptions::ErrorAbsolute;
    let kept = meshopt::simplify(&indices, adapter, target, error, options, None);
    kept.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect()
}
