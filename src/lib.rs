//! voxlod: levels of detail from polygon meshes and scanned volumes, by voxel filtering and
//! marching cubes (He, Hong, Kaufman, Varshney, Wang 1995), with the classic baselines beside it.
//!
//! This is the library facade: one call per job, each a free function over data with an options
//! struct (`Default` and named presets), the simple call first and the general form after.
//!
//! ```no_run
//! # fn main() -> Result<(), voxlod::Error> {
//! let mesh = voxlod::read_mesh("bunny.obj")?;
//! let lod = voxlod::lod(&voxlod::Source::Mesh(&mesh), &voxlod::LodOptions::default())?;
//! for level in &lod.levels {
//!     println!("{}: {} triangles", level.resolution, level.mesh.triangle_count());
//! }
//! # Ok(())
//! # }
//! ```
//!
//! | job | call | options |
//! |---|---|---|
//! | files | [`read_mesh`], [`write_mesh`], [`read_volume`], [`write_volume`], [`read_glb`] | |
//! | levels of detail (§2, §4) | [`lod()`], [`lod_with`]; one level at a time: [`lod::plan`], [`lod::build_level`] | [`LodOptions`] |
//! | levels by triangle budget or error (§5) | [`lod_by_budget`], [`lod_by_budget_with`] | [`BudgetOptions`] |
//! | one filtered volume | [`voxelize`] | [`VoxelizeOptions`] |
//! | one baked proxy for a whole scene | [`proxy()`], [`proxy_with`] | [`ProxyOptions`] |
//! | marching cubes on any volume | [`contour`] | [`ContourOptions`] |
//! | layered translucent shells (§3) | [`layers()`], [`layers_with`]; a chain of levels: [`layers_levels`], [`layers_chain`]; files: [`layered_glb`], [`layered_poly_mesh`], [`layered_preview`] | [`LayersOptions`] |
//! | vertex clustering baselines | [`cluster`]; one `.glb` chain: [`cluster_glb`] | [`ClusteringOptions`] |
//! | simplification envelopes | [`envelope()`], [`envelope_with`] | [`EnvelopeSeriesOptions`] |
//! | topology and health | [`inspect`], [`inspect_scene`], [`inspect_file`] | [`InspectOptions`] |
//! | distance between surfaces | [`compare`] | [`CompareOptions`] |
//! | which level for a pixel | [`select()`], [`select_drawn`] | [`SelectOptions`] |
//! | a picture of meshes and shells | [`draw`], [`read_drawable`] | [`DrawOptions`] |
//!
//! Every call returns [`Error`], whose [`Error::class`] says what kind of failure it is. The
//! long calls take a progress callback that can stop them ([`ProgressFn`], [`Control`]).
//!
//! The stage crates are re-exported for the general forms; their dependencies point one way,
//! layer by layer, as ARCHITECTURE.md draws them (`scripts/crate-diagram` makes the drawing,
//! `tests/architecture.rs` checks it).
//! The `voxlod` command line (crate `voxlod-cli`) and the measurements (crate `voxlod-eval`) are
//! built on this crate; it depends on neither.
//!
//! | stage | crate | what |
//! |---|---|---|
//! | types | [`core`] | meshes, grids, volumes, topology, validation, memory budget |
//! | files | [`io`] | OBJ, PLY, STL, OFF, VTK meshes; NRRD, VTI, NIfTI, MetaImage, raw volumes |
//! | sampling | [`sampling`] | inside tests, hyper-cone and Gaussian filters, the pyramid |
//! | contouring | [`contouring`] | table-driven marching cubes |
//! | layers | [`layers`](mod@layers), [`render`](mod@render) | multi-layer translucent shells (§3), the software rasterizer |
//! | baselines | [`clustering`], [`envelope`](mod@envelope) | vertex clustering; simplification envelopes |
//! | measurement | [`metrics`] | distances and mesh health |

#![warn(missing_docs)]

mod cluster;
mod compare;
mod contour;
mod envelope_series;
mod error;
mod files;
mod inspect;
mod label_maps;
mod levels;
mod picture;
pub mod select;
mod shells;

pub use cluster::{cluster, cluster_glb, ClusteringOptions};
pub use compare::{compare, CompareOptions, Comparison};
pub use contour::{contour, Contour, ContourOptions};
pub use envelope_series::{
    check_envelope_options, envelope, envelope_with, EnvelopeSeries, EnvelopeSeriesOptions,
};
pub use error::Error;
pub use files::{
    read_glb, read_mesh, read_mesh_file, read_scene, read_volume, write_mesh, write_volume,
};
pub use inspect::{
    inspect, inspect_file, inspect_scene, FileInspection, InspectOptions, Inspection,
    PartInspection, SceneInspection,
};
pub use label_maps::{label_surfaces, labels};
pub use levels::{lod, lod_by_budget, lod_by_budget_with, lod_glb, lod_with, voxelize};
pub use picture::{
    check_draw_options, draw, read_drawable, view_direction, DrawOptions, Drawable, Drawing,
    SURFACE_COLOR,
};
pub use select::{select, select_drawn, DrawnSelection, SelectOptions, Selection};
pub use shells::{
    check_layers_levels, check_layers_options, layered_glb, layered_poly_mesh, layered_preview,
    layers, layers_chain, layers_levels, layers_radius, layers_with, Layers, LayersChain,
};
pub use voxlod_pyramid::{asset_lod, asset_lod_by_budget, blockwise, budget, finest, labels};
pub use voxlod_pyramid::{
    iso_outside_data, run_to_end, Control, EnvelopeStep, ErrorClass, Event, Finest, InvalidOption,
    LevelEpsilon, Lod, LodLevel, LodOptions, Prepared, Progress, ProgressFn, PyramidError, Route,
    Source, ThenEnvelope, VoxelizeOptions, Voxelized,
};
pub use voxlod_pyramid::{proxy, proxy_with, Proxy, ProxyLevel, ProxyOptions};
pub use voxlod_pyramid::{AssetLod, AssetLodLevel, BudgetOptions};

/// Levels one at a time: [`voxlod_pyramid::lod`].
pub mod lod {
    pub use voxlod_pyramid::lod::*;
}
pub use voxlod_fit::FitOptions;
pub use voxlod_layers::LayersOptions;

pub use voxlod_asset as asset;
pub use voxlod_bake as bake;
pub use voxlod_budget as portfolio;
pub use voxlod_clustering as clustering;
pub use voxlod_contouring as contouring;
pub use voxlod_core as core;
pub use voxlod_envelope as envelope;
pub use voxlod_fit as fit;
pub use voxlod_gltf as gltf;
pub use voxlod_io as io;
pub use voxlod_labels as surfaces;
pub use voxlod_layers as layers;
pub use voxlod_metrics as metrics;
pub use voxlod_precomputed as precomputed;
pub use voxlod_pyramid as pyramid;
pub use voxlod_quadric as quadric;
pub use voxlod_render as render;
pub use voxlod_sampling as sampling;
