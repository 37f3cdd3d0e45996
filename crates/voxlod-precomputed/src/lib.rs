//! Neuroglancer "precomputed" segmentation layers with multi-resolution meshes.
//!
//! [`write_layer`] writes, from a label map and each label's finest mesh, a folder that
//! neuroglancer opens as a segmentation layer and cloud-volume reads back:
//!
//! - `info`: the layer (`type` segmentation, one scale, raw encoding, `"mesh": "mesh"`;
//!   neuroglancer's `volume.md`), and the labels in raw chunks `x0-x1_y0-y1_z0-z1` under the
//!   scale's key (`volume.rs`);
//! - `mesh/info`: `neuroglancer_multilod_draco` with the vertex quantization bits, the
//!   transform from the stored model space (voxels) to nanometres, and the sharding when
//!   sharded (`meshes.md`);
//! - per label, the manifest `<id>.index` (the octree of fragments per level of detail) and the
//!   fragment data `<id>` (Draco meshes, `draco.rs`), or all labels in `<shard>.shard` files
//!   (`neuroglancer_uint64_sharded_v1`, `sharded.md`, `sharding.rs`) when there are many.
//!
//! # How the levels of detail are made
//! Two ways, as the caller chooses:
//!
//! - [`write_layer`], from each label's finest mesh: level k is made from level k − 1
//!   (`lods.rs`), not by the paper's filter pyramid. Level 0 is the given mesh cut on the
//!   octree's finest grid (`cut.rs`); level k simplifies each node of level k − 1 separately
//!   with its boundary locked (meshoptimizer, about a quarter of the triangles) and gathers the
//!   eight children of each level-k node. Neuroglancer draws a level-k node next to finer
//!   nodes, hiding the eighths of it they cover; the seams are on the level-(k − 1) grid
//!   planes, so a level must keep the finer levels' cross-sections there for no crack to open.
//!   Locked boundaries keep them exactly (the same vertices), and they make every level-k node
//!   split by the 2 × 2 × 2 grid with no triangle across it, as the format requires.
//! - [`write_layer_filtered`], from one mesh per level: the paper's filter pyramid (He et al.
//!   1995 §2–4), level k of the layer being the pyramid's level k, each cut on the grid of its
//!   nodes' eighths (`filtered.rs`). The fragments of a level meet exactly; consecutive levels
//!   are different surfaces (smoother, with fewer handles), which meet on a coarse node's
//!   face only up to their distance there (module `filtered`).

//! # Same triangles, same bytes
//! A layer's files depend on each label's set of triangles and the options, not on the order
//! of the mesh's vertices or triangles, on a triangle's first corner, on a vertex or a triangle
//! being given several times, or on the number of threads (`canonical.rs`): a label's
//! triangles gathered from blocks of a map write the same layer as the mesh of the whole map.
//!
//! # Coordinates
//! The stored model space is neuroglancer's voxel space: voxel `(i, j, k)` of the map is the
//! unit cube at `voxel_offset + (i, j, k)`, `voxel_offset = round(origin / spacing)`, so a
//! world point `w` is stored at `(w − origin) / spacing + voxel_offset + ½`; the mesh `info`'s
//! transform scales by the resolution (`spacing × nanometres_per_unit`) to nanometres.
//! Neuroglancer's voxel offset is an integer, so the layer keeps the map's origin up to that
//! rounding and the half voxel between a voxel's corner and its centre; labels and meshes stay
//! registered to each other exactly. Fragments are quantized on one grid per level shared by
//! all nodes (`quantize.rs`), so a vertex on a face between two nodes of a level has the same
//! integers in both. Oblique maps are refused: precomputed volumes are axis-aligned.

pub mod canonical;
pub mod compressed_segmentation;
pub mod cut;
pub mod draco;
pub mod error;
pub mod filtered;
pub mod layer;
pub mod lods;
pub mod manifest;
pub mod morton;
pub mod quantize;
pub mod read;
pub mod read_volume;
pub mod sharding;
pub mod volume;

pub use draco::QuantizedFragment;
pub use error::PrecomputedError;
pub use layer::{write_layer, write_layer_filtered, LabelReport, LayerReport, LodReport};
pub use manifest::Manifest;
pub use read_volume::read_labels;
pub use sharding::{ShardEncoding, ShardHash, ShardingSpec};

/// Whether the meshes go into shard files.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Sharding {
    /// Sharded when there are more than [`SHARDING_THRESHOLD`] labels with meshes.
    #[default]
    Auto,
    /// One manifest and one fragment file per label.
    Never,
    /// Shard files whatever the number of labels.
    Always,
}

/// Above this many meshed labels, [`Sharding::Auto`] shards (per-label files cost a file
/// system entry and a request each).
pub const SHARDING_THRESHOLD: usize = 512;

/// The volume's data type.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LabelType {
    /// `uint32`: the map's labels as they are.
    #[default]
    Uint32,
    /// `uint64`: the same labels widened (for pipelines that expect 64-bit ids).
    Uint64,
}

/// How [`write_layer`] writes a layer.
#[derive(Clone, Debug, PartialEq)]
pub struct PrecomputedOptions {
    /// Levels of detail per label, at least 1 (at most 16).
    pub lods: usize,
    /// Bits per quantized coordinate of a fragment: 10 or 16 (the only values neuroglancer
    /// reads).
    pub quantization_bits: u32,
    /// Chunk size of the volume, in voxels.
    pub chunk: [usize; 3],
    /// Edge of a level-0 octree node, in voxels (a level-k node is `2^k` times as large).
    pub fragment_voxels: usize,
    /// Plain or sharded mesh storage.
    pub sharding: Sharding,
    /// Hash of the sharded layout.
    pub shard_hash: ShardHash,
    /// Encoding of the minishard indices.
    pub minishard_index_encoding: ShardEncoding,
    /// Encoding of the manifests in the shards (fragments are Draco and never compressed).
    pub data_encoding: ShardEncoding,
    /// Size of the map's spacing unit in nanometres: 1 for maps in nm, 1e6 for maps in mm.
    pub nanometres_per_unit: f64,
    /// Data type of the volume.
    pub label_type: LabelType,
    /// Fraction of its triangles each node keeps from one level to the next (0 < r ≤ 1).
    pub lod_ratio: f64,
}

impl Default for PrecomputedOptions {
    fn default() -> Self {
        PrecomputedOptions {
            lods: 3,
            quantization_bits: 16,
            chunk: [64; 3],
            fragment_voxels: 32,
            sharding: Sharding::Auto,
            shard_hash: ShardHash::Murmurhash3X86_128,
            minishard_index_encoding: ShardEncoding::Gzip,
            data_encoding: ShardEncoding::Gzip,
            nanometres_per_unit: 1.0,
            label_type: LabelType::Uint32,
            lod_ratio: 0.25,
        }
    }
}

impl PrecomputedOptions {
    /// Checks every option's range; the message names the option.
    pub fn validate(&self) -> Result<(), PrecomputedError> {
        let bad = |s: String| Err(PrecomputedError::Options(s));
        if !(1..=16).contains(&self.lods) {
            return bad(format!("lods is {}, not 1 to 16", self.lods));
        }
        if self.quantization_bits != 10 && self.quantization_bits != 16 {
            return bad(format!(
                "quantization_bits is {}; neuroglancer reads 10 or 16",
                self.quantization_bits
            ));
        }
        if self.chunk.iter().any(|&c| c == 0 || c > 1 << 12) {
            return bad(format!("chunk {:?} is not 1 to 4096 voxels", self.chunk));
        }
        if self.fragment_voxels == 0 || self.fragment_voxels > 1 << 16 {
            return bad(format!(
                "fragment_voxels is {}, not 1 to 65536",
                self.fragment_voxels
            ));
        }
        if !(self.nanometres_per_unit.is_finite() && self.nanometres_per_unit > 0.0) {
            return bad(format!(
                "nanometres_per_unit is {}, not a positive number",
                self.nanometres_per_unit
            ));
        }
        if !(self.lod_ratio > 0.0 && self.lod_ratio <= 1.0) {
            return bad(format!("lod_ratio is {}, not in (0, 1]", self.lod_ratio));
        }
        Ok(())
    }
}
