//! The one error type of the renderer.

use thiserror::Error;

/// Why an image could not be made.
#[derive(Debug, Error)]
pub enum RenderError {
    #[error("the view direction has zero length")]
    ZeroViewDirection,
    #[error("the view direction {0} is not finite")]
    NonFiniteView(String),
    #[error("image size {0}x{1}: both sides must be between 1 and 16384 pixels")]
    BadSize(u32, u32),
    #[error("supersampling {0}x{0}: choose 1 to 32")]
    BadSupersample(u32),
    #[error("nothing to draw: the scene has no finite geometry")]
    EmptyScene,
    #[error("invalid input: {0}")]
    Invalid(String),
    #[error("cannot encode the PNG: {0}")]
    Png(String),
    #[error(transparent)]
    Core(#[from] voxlod_core::CoreError),
}
