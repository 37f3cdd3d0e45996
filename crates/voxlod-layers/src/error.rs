//! The one error type of the crate: what went wrong, in one line that names the problem.

use thiserror::Error;
use voxlod_contouring::ContourError;
use voxlod_core::CoreError;
use voxlod_sampling::SamplingError;

/// Why layers could not be planned, extracted, ordered or exported.
#[derive(Debug, Error)]
pub enum LayersError {
    /// An error bound ε that is zero, negative or not finite.
    #[error("the error bound must be a positive number, got {0}")]
    NonPositiveError(f64),
    /// An ε so small that even the most layers allowed do not reach it.
    #[error(
        "the error bound {bound} needs more than {max} layers: with {max} the optimal error is \
         still {achieved:.6}; choose a larger bound"
    )]
    TooManyLayers {
        /// The ε asked for.
        bound: f64,
        /// The most layers allowed.
        max: usize,
        /// The optimal error with that many.
        achieved: f64,
    },
    /// No layer has a triangle.
    #[error("the filtered volume is empty: no layer has a triangle (the object does not reach any sample, or the volume holds no density between 0 and 1)")]
    EmptyVolume,
    /// A view direction of zero length (or an eye at the scene's centre).
    #[error("the view direction has zero length")]
    ZeroViewDirection,
    /// A view direction or eye with a NaN or infinite component (as written).
    #[error("the view is not finite: {0}")]
    NonFiniteView(String),
    /// Layers, cells, orders or palettes that do not fit together (what is wrong).
    #[error("invalid layered mesh: {0}")]
    Invalid(String),
    /// A glTF file that cannot be read or written (what is wrong, and where).
    #[error("invalid glTF file: {0}")]
    Gltf(String),
    /// Marching cubes refused the volume.
    #[error(transparent)]
    Contour(#[from] ContourError),
    /// Filtering the solid failed.
    #[error(transparent)]
    Sampling(#[from] SamplingError),
    /// The memory limit's refusal, or another core error.
    #[error(transparent)]
    Core(#[from] CoreError),
    /// Drawing the preview failed.
    #[error(transparent)]
    Render(#[from] voxlod_render::RenderError),
    /// Baking an asset's looks onto the layers failed (a memory refusal is [`Self::Core`]).
    #[error(transparent)]
    Bake(voxlod_bake::BakeError),
    /// Reading or writing a file failed.
    #[error(transparent)]
    Io(#[from] voxlod_io::IoError),
}
