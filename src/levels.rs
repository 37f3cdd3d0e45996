//! The pyramid's one-call jobs with the facade's error: [`lod()`], [`lod_with`] and
//! [`voxelize()`] call crate `voxlod-pyramid` (its docs say what they do and cost) and turn its
//! error into [`Error`].

use crate::error::Error;
use voxlod_pyramid::{Lod, LodOptions, ProgressFn, Source, VoxelizeOptions, Voxelized};

/// Levels of detail of `source` (He et al. 1995 §2, §4; by triangle budget or error, §5), as
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

/// One level's filtered density as a volume, as [`voxlod_pyramid::voxelize()`].
pub fn voxelize(source: &Source, options: &VoxelizeOptions) -> Result<Voxelized, Error> {
    Ok(voxlod_pyramid::voxelize(source, options)?)
}
