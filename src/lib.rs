//! voxlod: levels of detail from polygon meshes and scanned volumes, by voxel filtering and
//! marching cubes (He, Hong, Kaufman, Varshney, Wang 1995), with the classic baselines beside it.
//!
//! This is the library facade: it re-exports the stage crates, whose dependencies point one
//! way (`core ← io`, `core ← sampling`, `core ← contouring`, `core ← metrics ← clustering,
//! envelope`, `core ← render ← layers`, layers also on io, sampling and contouring), and adds
//! the calls that span stages. The `voxlod` command line (crate `voxlod-cli`) and the
//! measurements (crate `voxlod-eval`) are built on it; it depends on neither.
//!
//! | stage | crate | what |
//! |---|---|---|
//! | types | [`core`] | meshes, grids, volumes, topology, memory budget |
//! | files | [`io`] | OBJ, PLY, STL, OFF, VTK meshes; NRRD, VTI, NIfTI, MetaImage, raw volumes |
//! | sampling | [`sampling`] | inside tests, hyper-cone and Gaussian filters, the pyramid |
//! | contouring | [`contouring`] | table-driven marching cubes |
//! | levels of detail | [`lod`], [`select`] | the pyramid of closed meshes; which level to draw for a pixel size |
//! | layers | [`layers`], [`render`] | multi-layer translucent shells (§3), the software rasterizer |
//! | baselines | [`clustering`], [`envelope`] | vertex clustering; simplification envelopes |
//! | measurement | [`metrics`] | distances and mesh health |

pub mod labels;
pub mod lod;
pub mod select;

pub use voxlod_clustering as clustering;
pub use voxlod_contouring as contouring;
pub use voxlod_core as core;
pub use voxlod_envelope as envelope;
pub use voxlod_io as io;
pub use voxlod_layers as layers;
pub use voxlod_metrics as metrics;
pub use voxlod_render as render;
pub use voxlod_sampling as sampling;
