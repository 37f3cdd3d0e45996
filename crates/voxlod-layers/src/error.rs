//! The one error type of the crate: what went wrong, in one line that names the problem.

use thiserror::Error;
use voxlod_contouring::ContourError;
use voxlod_core::CoreError;
use voxlod_sampling::SamplingError;

/// Why layers could not be planned, extracted, ordered or exported.
#[derive(Debug, Error)]
pub enum LayersError {
    #[error("the error bound must be a positive number, got {0}")]
    NonPositiveError(f64),
    #[error(
        "the error bound {bound} needs more than {max} layers: with {max} the optimal error is \
         still {achieved:.6}; choose a larger bound"
    )]
    TooManyLayers {
        bound: f64,
        max: usize,
        achieved: f64,
    },
    #[error("the filtered volume is empty: no layer has a triangle (the object does not reach any sample, or the volume holds no density between 0 and 1)")]
    EmptyVolume,
    #[error("the view direction has zero length")]
    ZeroViewDirection,
    #[error("the view is not finite: {0}")]
    NonFiniteView(String),
    #[error("invalid layered mesh: {0}")]
    Invalid(String),
    #[error("invalid glTF file: {0}")]
    Gltf(String),
    #[error(transparent)]
    Contour(#[from] ContourError),
    #[error(transparent)]
    Sampling(#[from] SamplingError),
    #[error(transparent)]
    Core(#[from] CoreError),
    #[error(transparent)]
    Render(#[from] voxlod_render::RenderError),
    #[error(transparent)]
    Io(#[from] voxlod_io::IoError),
}
