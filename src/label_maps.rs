//! The label maps' jobs with the facade's error (crates `voxlod-pyramid` and `voxlod-labels`).

use crate::Error;
use voxlod_core::LabelVolume;
use voxlod_labels::{LabelSurfaces, SurfaceOptions};
use voxlod_pyramid::{labels::LabelMeshes, labels::LabelOptions, ProgressFn};

/// Every label of a label map meshed with its levels, as [`voxlod_pyramid::labels::labels`].
pub fn labels<M: voxlod_pyramid::labels::LabelSource>(
    map: &M,
    options: &LabelOptions,
    progress: &ProgressFn,
) -> Result<LabelMeshes, Error> {
    Ok(voxlod_pyramid::labels::labels(map, options, progress)?)
}

/// Every label of a label map as one closed, outward mesh, as [`voxlod_labels::label_surfaces`].
pub fn label_surfaces(map: &LabelVolume, options: &SurfaceOptions) -> Result<LabelSurfaces, Error> {
    Ok(voxlod_labels::label_surfaces(map, options)?)
}
