//! Levels of detail of an asset with its looks (texture coordinates, colours, normals,
//! materials): the levels of the asset's geometry, each then given the looks.
//!
//! - By triangle budget with the portfolio ([`asset_lod_by_budget`], `then` auto or quadric):
//!   `voxlod_budget::asset_levels`, where a level that is the input's collapse keeps the
//!   input's vertices with their attributes ([`Looks::Kept`]) and every other level takes them
//!   from the nearest input points ([`Looks::Transferred`]).
//! - Every other route (the pyramid by resolution, [`asset_lod`]; an error target or the
//!   envelope stage, [`asset_lod_by_budget`]): the levels of the geometry as
//!   [`crate::lod_with`] or [`crate::lod_by_budget_with`] makes them, each with colours, normals and
//!   materials from the nearest input points, the base colour texture sampled into vertex
//!   colours (`voxlod_asset::transfer`), so that no level of a textured asset comes out grey.
//!
//! Beyond the paper: He et al. (1995) carry positions only.
//! Cost: the route's, plus one nearest-point pass per level (O(V log N)).

use voxlod_asset::{Asset, AssetError};
use voxlod_budget::{asset_levels, Looks};
use voxlod_core::{mesh_topology, CoreError};

use crate::budget_options::BudgetOptions;
use crate::by_budget::{as_lod, lod_by_budget_with};
use crate::error::PyramidError;
use crate::levels::lod_with;
use crate::lod_options::{Lod, LodOptions};
use crate::progress::ProgressFn;
use crate::source::Source;

/// One level of an asset with its looks.
#[derive(Clone, Debug)]
pub struct AssetLodLevel {
    /// The level with its looks; none for a level the filter emptied.
    pub asset: Option<Asset>,
    /// How it got them.
    pub looks: Looks,
}

/// Levels of detail of an asset: the levels' geometry and reports as [`crate::lod_with`] or
/// [`crate::lod_by_budget_with`] gives them, and each level with its looks.
#[derive(Clone, Debug)]
pub struct AssetLod {
    /// The levels' geometry, reports and warnings (the looks' warnings among them).
    pub lod: Lod,
    /// One per level of `lod.levels`, in the same order.
    pub assets: Vec<AssetLodLevel>,
}

/// The pyramid's levels of `asset` for `options` ([`crate::lod_with`] on its geometry), each
/// with the looks of the nearest input points (module docs). Fails as [`crate::lod_with`]
/// does, and on an invalid asset (bad input).
pub fn asset_lod(
    asset: &Asset,
    options: &LodOptions,
    progress: &ProgressFn,
) -> Result<AssetLod, PyramidError> {
    let start = std::time::Instant::now();
    asset.validate().map_err(asset_error)?;
    let geometry = asset.mesh.geometry();
    let lod = lod_with(&Source::Mesh(&geometry), options, progress)?;
    transferred(asset, lod, start)
}

/// The levels of `asset` for the budgets or error target of `options`, each with the asset's
/// looks: kept where a level is the input's collapse, else from the nearest input points
/// (module docs). Fails as [`crate::lod_by_budget_with`] does, and on an invalid asset.
pub fn asset_lod_by_budget(
    asset: &Asset,
    options: &BudgetOptions,
    progress: &ProgressFn,
) -> Result<AssetLod, PyramidError> {
    let start = std::time::Instant::now();
    asset.validate().map_err(asset_error)?;
    let geometry = asset.mesh.geometry();
    let source = Source::Mesh(&geometry);
    if !options.uses_portfolio(&source) {
        let lod = lod_by_budget_with(&source, options, progress)?;
        return transferred(asset, lod, start);
    }
    options.check()?;
    source.to_frame(options.frame)?;
    let (portfolio, mut warnings) = options.portfolio(&geometry);
    let run = asset_levels(asset, &portfolio)?;
    warnings.extend(run.warnings);
    let mut assets = Vec::with_capacity(run.levels.len());
    let mut levels = Vec::with_capacity(run.levels.len());
    for level in run.levels {
        let mesh = level.asset.mesh.geometry();
        levels.push((mesh_topology(&mesh), mesh, level.report));
        assets.push(AssetLodLevel {
            asset: Some(level.asset),
            looks: level.looks,
        });
    }
    let levels = levels.into_iter().map(|(t, m, r)| (m, t, r));
    let mut lod = as_lod(&geometry, levels, &run.input, portfolio.max_error, warnings)?;
    lod.seconds = start.elapsed().as_secs_f64();
    Ok(AssetLod { lod, assets })
}

/// `lod`'s levels of `asset`'s geometry, each with colours, normals and materials from the
/// nearest input points.
fn transferred(
    asset: &Asset,
    mut lod: Lod,
    start: std::time::Instant,
) -> Result<AssetLod, PyramidError> {
    let mut assets = Vec::with_capacity(lod.levels.len());
    for level in &lod.levels {
        let asset = if level.mesh.is_empty() {
            None
        } else {
            let taken = voxlod_asset::transfer(asset, &level.mesh).map_err(asset_error)?;
            lod.warnings.extend(taken.warnings);
            Some(taken.asset)
        };
        assets.push(AssetLodLevel {
            asset,
            looks: Looks::Transferred,
        });
    }
    lod.warnings.dedup();
    lod.seconds = start.elapsed().as_secs_f64();
    Ok(AssetLod { lod, assets })
}

/// An asset's failure as the crate's error: an invalid asset is bad input, a memory refusal
/// keeps its class.
fn asset_error(e: AssetError) -> PyramidError {
    match e {
        AssetError::Core(c) => PyramidError::Core(c),
        other => PyramidError::Core(CoreError::InvalidMesh(format!("the asset: {other}"))),
    }
}
