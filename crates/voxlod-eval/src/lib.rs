//! Measurement that is not the product: how voxlod and the baselines compare, and how close we
//! come to the voxel paper (He, Hong, Kaufman, Varshney, Wang 1995).
//!
//! - [`evaluate`]: every simplifier on one mesh, error against triangle count, with plots and a
//!   written report (`voxlod evaluate`).
//! - [`paper_tables`]: the paper's three results tables (§4), regenerated (`voxlod demo` and the
//!   workspace's `table*` examples).
//! - [`antialias`]: the paper's antialiasing claim (§3, Figure 7) measured in images.
//!
//! Built on the facade `voxlod`; nothing in the library depends on this crate.

pub mod antialias;
pub mod evaluate;
pub mod paper_tables;
