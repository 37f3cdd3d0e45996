//! voxlod: levels of detail from polygon meshes and scanned volumes, by voxel filtering and
//! marching cubes (He, Hong, Kaufman, Varshney, Wang 1995), with the classic baselines beside it.
//!
//! This facade re-exports the stage crates, whose dependencies point one way:
//! `core ← io`, `core ← sampling ← contouring`, and the command line on top.
//!
//! | stage | crate | what |
//! |---|---|---|
//! | types | [`core`] | meshes, grids, volumes, topology, memory budget |
//! | files | [`io`] | OBJ, PLY, STL, OFF, VTK meshes; NRRD, VTI, NIfTI, MetaImage, raw volumes |
//! | sampling | [`sampling`] | inside tests, hyper-cone and Gaussian filters, the pyramid |
//! | contouring | [`contouring`] | table-driven marching cubes |
//! | measurement | [`metrics`], [`evaluate`], [`paper_tables`] | distances and mesh health; every method against the input; the paper's tables |

pub mod commands;
pub mod evaluate;
pub mod lod;
pub mod paper_tables;

pub use voxlod_contouring as contouring;
pub use voxlod_core as core;
pub use voxlod_io as io;
pub use voxlod_metrics as metrics;
pub use voxlod_sampling as sampling;
