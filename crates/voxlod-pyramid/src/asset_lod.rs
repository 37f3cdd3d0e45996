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
//! - A level of an asset with a texture that does not keep the input's vertices is baked
//!   instead ([`Looks::Baked`], crate `voxlod-bake`): an atlas and textures cast from the input
//!   (base colour, normals, occlusion-roughness-metallic, emissive), of the input's largest
//!   texture's size (256 to 2048 texels a side), so that it keeps a texture's detail rather
//!   than one colour per vertex. An asset without textures keeps the transferred colours, and
//!   so does a level of more than [`BAKED_AT_MOST`] triangles, whose vertices are dense enough
//!   for colours (on Spot, baking gains 1.7 dB at 90 000 triangles against 3.5 dB at 5 000)
//!   and whose atlas would cost seconds per 10 000 triangles.
//!
//! Beyond the paper: He et al. (1995) carry positions only.
//! Cost: the route's, plus one nearest-point pass per level (O(V log N)).

use voxlod_asset::{Asset, AssetError};
use voxlod_bake::BakeOptions;
use voxlod_budget::{asset_levels, Looks};
use voxlod_core::{mesh_topology, CoreError};

use crate::budget_options::BudgetOptions;
use crate::by_budget::{as_lod, lod_by_budget_with};
use crate::error::PyramidError;
use crate::levels::lod_with;
use crate::lod::LodLevel;
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
    let mut made = transferred(asset, lod, start)?;
    bake_transferred(asset, &mut made)?;
    Ok(made)
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
        let mut made = transferred(asset, lod, start)?;
        bake_transferred(asset, &mut made)?;
        return Ok(made);
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
    let lod = as_lod(&geometry, levels, &run.input, portfolio.max_error, warnings)?;
    let mut made = AssetLod { lod, assets };
    bake_transferred(asset, &mut made)?;
    made.lod.seconds = start.elapsed().as_secs_f64();
    Ok(made)
}

/// The most triangles a level may have to be baked rather than given vertex colours (module
/// docs).
pub const BAKED_AT_MOST: usize = 30_000;

/// Bakes every level of `made` whose looks were transferred, where `asset` has a texture
/// (module docs); the bakes' warnings join the run's.
fn bake_transferred(asset: &Asset, made: &mut AssetLod) -> Result<(), PyramidError> {
    let Some(texels) = texture_side(asset) else {
        return Ok(());
    };
    let baked = |level: &AssetLodLevel, lod_level: &LodLevel| {
        let size = lod_level.mesh.triangle_count();
        (level.looks == Looks::Transferred && size > 0 && size <= BAKED_AT_MOST).then(|| {
            BakeOptions {
                voxel_size: Some(lod_level.plan.voxel_size as f32),
                ..BakeOptions::for_texture(texels)
            }
        })
    };
    let options: Vec<Option<BakeOptions>> = (made.assets.iter().zip(&made.lod.levels))
        .map(|(level, lod_level)| baked(level, lod_level))
        .collect();
    let each: Vec<_> = (made.lod.levels.iter().zip(&options))
        .map(|(l, o)| o.as_ref().map(|o| (&l.mesh, o)))
        .collect();
    let baked = voxlod_bake::bake_levels(asset, &each, &|_| true)?;
    let levels = made.assets.iter_mut().zip(&made.lod.levels);
    for ((level, lod_level), baked) in levels.zip(baked) {
        let Some(baked) = baked else {
            continue;
        };
        let k = lod_level.plan.level;
        let noted = baked.report.warnings.iter();
        made.lod
            .warnings
            .extend(noted.map(|w| format!("level {k}: {w}")));
        level.asset = Some(baked.asset);
        level.looks = Looks::Baked;
    }
    Ok(())
}

/// The side of a baked level's textures: the largest side of the input's base colour and
/// normal textures whose headers read (KTX2 is passed through, never read), within 256 to
/// 2048 texels; `None` for an asset without such a texture. Reads the images' headers only.
fn texture_side(asset: &Asset) -> Option<u32> {
    let slots = asset.materials.iter().flat_map(|m| {
        let slots = [&m.base_color_texture, &m.normal_texture];
        slots.into_iter().flatten()
    });
    let images = slots.filter_map(|slot| asset.images.get(slot.image));
    let sides = images.filter_map(voxlod_asset::texture::dimensions);
    sides.map(|(w, h)| w.max(h).clamp(256, 2048)).max()
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
