//! voxlod level chains as glTF 2.0, for engines and browsers.
//!
//! A chain of levels from the voxel pyramid (He, Hong, Kaufman, Varshney, Wang 1995, §2) is
//! written as one `.glb` whose meshes are chained with `MSFT_lod` from the finest to the
//! coarsest, with `MSFT_screencoverage` computed from the pixel-size rule of `voxlod select`
//! ([`coverage`]), so an engine switches where the paper's selection would. Optionally the
//! geometry is quantized (`KHR_mesh_quantization`) and encoded with meshoptimizer
//! (`EXT_meshopt_compression`), as gltfpack does ([`streams`], [`encode`]); [`decode`] undoes
//! the encoding for readers without a decoder. [`read`] takes any binary glTF file back as one
//! triangle mesh with its parts (the finest level of a chain; the layers and stored orders of a
//! layered file). [`scene`] reads any glTF 2.0 asset (`.gltf` or `.glb`, quantized or
//! meshopt-compressed) as a scene with its looks, a `voxlod_asset::Asset`. [`labels`] writes
//! every structure of a label map in one file, one node per label with its value on each vertex.
//!
//! Beyond the paper: the paper stops at the meshes; the file format and the switching rule are
//! ours. The JSON is built with `gltf-json`; extensions it has no types for are added to the
//! JSON value in one place ([`chain`]'s `finish`).

pub mod chain;
pub mod coverage;
pub mod decode;
pub mod encode;
pub mod error;
mod file;
pub mod labels;
pub mod read;
pub mod scene;
pub mod streams;

pub use chain::{
    chain_document, chain_glb_bytes, declare_lod, to_glb, write_chain_glb, ChainLevel,
    ChainOptions, Compression,
};
pub use coverage::{fitting_coverage, pixel_size_at, screen_coverages, CoverageOptions};
pub use decode::decompress_glb;
pub use error::GltfError;
pub use labels::{labels_glb, LabelMesh};
pub use read::{parse_glb, read_any_glb, read_glb, GlbPart, GlbScene, ORDER_NAMES};
pub use scene::{
    asset_glb, parse_scene, positions_grid, read_scene, AssetGlbOptions, Layout, SceneRead,
};
