//! [`labels()`]: crate `voxlod-pyramid`'s label maps job with the facade's error.

use crate::error::Error;
use voxlod_core::Volume;
use voxlod_pyramid::{labels::LabelMeshes, labels::LabelOptions, ProgressFn};

/// Every label of a label map meshed with its levels, as [`voxlod_pyramid::labels::labels`].
pub fn labels(
    map: &Volume,
    options: &LabelOptions,
    progress: &ProgressFn,
) -> Result<LabelMeshes, Error> {
    Ok(voxlod_pyramid::labels::labels(map, options, progress)?)
}
