//! The pyramid driver of voxlod (He, Hong, Kaufman, Varshney, Wang 1995): a source's levels of
//! detail by resolution, each filtered from the original object (§2) and contoured by marching
//! cubes (§4), with what the facade's `lod` call adds around it.
//!
//! - **Sources** ([`Source`]): a mesh (through a BVH), a solid, a scan thresholded or filtered
//!   directly, or a scan read block by block ([`blockwise`]); [`Source::prepare`] checks it and
//!   chooses the route ([`Route`]). A scan file is opened whole or blockwise by [`Scan`].
//! - **Levels** ([`lod()`], [`lod_with`]): the resolutions planned and checked against the
//!   memory limit, levels sampled ahead on all cores, the genus kept from rising along the
//!   chain ([`voxlod_sampling::monotone_level`]), each level cleaned and, on request,
//!   simplified within ε by simplification envelopes ([`ThenEnvelope`]); one level at a time
//!   with [`lod::plan`] and [`lod::build_level`].
//! - **The finest resolution** ([`finest`]): given, or chosen from a triangle count.
//! - **Levels by triangle budget or error** ([`lod_by_budget`], [`BudgetOptions`]): for a
//!   mesh, the portfolio of crate `voxlod-budget`; for a scan, and for an error target, the
//!   voxel-first search of §5 ([`budget`]: a voxel level, then the geometric stage).
//! - **Label maps** ([`labels`]): each label's indicator through the same pyramid.
//! - **One proxy for a whole scene** ([`proxy()`]): the scene's union as new closed levels by
//!   budget, each baked with one material and one texture set (crate `voxlod-bake`).
//! - **One filtered volume** ([`voxelize()`]).
//! - Progress and cancellation ([`ProgressFn`], [`Control`]) and the crate's error
//!   ([`PyramidError`], with [`ErrorClass`]).
//!
//! Cost: each level is dominated by its sampling (crate `voxlod-sampling`), linear in the grid's
//! samples plus the lattice lines' crossings, then marching cubes, linear in the samples.

#![warn(missing_docs)]

mod asset_lod;
pub mod blockwise;
pub mod budget;
mod budget_options;
mod budget_terms;
mod by_budget;
mod caps;
pub mod error;
pub mod finest;
pub mod labels;
mod levels;
pub mod lod;
mod lod_options;
pub mod progress;
mod proxy;
pub mod scan;
pub mod source;
mod then_envelope;
mod voxelize;

pub use asset_lod::{asset_lod, asset_lod_by_budget, AssetLod, AssetLodLevel};
pub use budget_options::BudgetOptions;
pub use by_budget::{lod_by_budget, lod_by_budget_with};
pub use error::{ErrorClass, InvalidOption, PyramidError};
pub use finest::Finest;
pub use levels::{lod, lod_with};
pub use lod::LodLevel;
pub use lod_options::{Lod, LodOptions};
pub use progress::{run_to_end, Control, Event, Progress, ProgressFn, Tracker};
pub use proxy::{proxy, proxy_with, Proxy, ProxyLevel, ProxyOptions};
pub use scan::{BlockwiseReason, Scan};
pub use source::{iso_outside_data, Prepared, Route, ScanRoute, Source};
pub use then_envelope::{EnvelopeStep, LevelEpsilon, ThenEnvelope};
pub use voxelize::{voxelize, VoxelizeOptions, Voxelized};
