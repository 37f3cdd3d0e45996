//! The pyramid's one-call jobs with the facade's error: [`lod()`], [`lod_by_budget`] (each with
//! a `_with` form taking progress) and [`voxelize()`] call crate `voxlod-pyramid` (its docs say what they do and cost) and turn its
//! error into [`Error`]; [`lod_glb`] writes the levels as one glTF chain (crate `voxlod-gltf`).

use crate::error::Error;
use voxlod_gltf::{chain_document, to_glb, ChainLevel, ChainOptions};
use voxlod_pyramid::{BudgetOptions, Lod, LodOptions, ProgressFn, Source};
use voxlod_pyramid::{VoxelizeOptions, Voxelized};

/// Levels of detail of `source` by resolution (He et al. 1995 §2, §4), as
/// [`voxlod_pyramid::lod()`].
pub fn lod(source: &Source, options: &LodOptions) -> Result<Lod, Error> {
    Ok(voxlod_pyramid::lod(source, options)?)
}

/// [`lod()`] with a progress callback that can stop the work, as [`voxlod_pyramid::lod_with`].
pub fn lod_with(
    source: &Source,
    options: &LodOptions,
    progress: &ProgressFn,
) -> Result<Lod, Error> {
    Ok(voxlod_pyramid::lod_with(source, options, progress)?)
}

/// Levels of `source` by triangle budget or error target (He et al. 1995 §5), as
/// [`voxlod_pyramid::lod_by_budget`].
pub fn lod_by_budget(source: &Source, options: &BudgetOptions) -> Result<Lod, Error> {
    Ok(voxlod_pyramid::lod_by_budget(source, options)?)
}

/// [`lod_by_budget`] with a progress callback, as [`voxlod_pyramid::lod_by_budget_with`].
pub fn lod_by_budget_with(
    source: &Source,
    options: &BudgetOptions,
    progress: &ProgressFn,
) -> Result<Lod, Error> {
    Ok(voxlod_pyramid::lod_by_budget_with(
        source, options, progress,
    )?)
}

/// One level's filtered density as a volume, as [`voxlod_pyramid::voxelize()`].
pub fn voxelize(source: &Source, options: &VoxelizeOptions) -> Result<Voxelized, Error> {
    Ok(voxlod_pyramid::voxelize(source, options)?)
}

/// `lod`'s levels with a surface as one `.glb` chain ([`voxlod_gltf::chain`]), and its coverages.
pub fn lod_glb(lod: &Lod, options: &ChainOptions) -> Result<(Vec<u8>, Vec<f64>), Error> {
    let levels = lod.levels.iter().filter(|l| !l.mesh.is_empty());
    let chain: Vec<_> =
        (levels.map(|l| ChainLevel::new(l.plan.level, &l.mesh, l.plan.voxel_size))).collect();
    let (doc, bin) = chain_document(&chain, options)?;
    let coverage = doc.pointer("/nodes/0/extras/MSFT_screencoverage");
    let coverage = coverage.and_then(|c| c.as_array()).into_iter().flatten();
    let coverage = coverage.filter_map(|c| c.as_f64()).collect();
    Ok((to_glb(&doc, bin)?, coverage))
}
