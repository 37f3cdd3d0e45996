//! The one error type of the renderer.

use thiserror::Error;

/// Why an image could not be made.
#[derive(Debug, Error)]
pub enum RenderError {
    /// A view or light direction of zero length.
    #[error("the view direction has zero length")]
    ZeroViewDirection,
    /// A view or light direction with a NaN or infinite component (as written).
    #[error("the view direction {0} is not finite")]
    NonFiniteView(String),
    /// An image side outside 1 to 16384 pixels (width, height).
    #[error("image size {0}x{1}: both sides must be between 1 and 16384 pixels")]
    BadSize(u32, u32),
    /// Samples per pixel side outside 1 to 32.
    #[error("supersampling {0}x{0}: choose 1 to 32")]
    BadSupersample(u32),
    /// A camera asked to frame an empty or non-finite box.
    #[error("nothing to draw: the scene has no finite geometry")]
    EmptyScene,
    /// A scene item that does not fit together (which item, and what is wrong).
    #[error("invalid input: {0}")]
    Invalid(String),
    /// The PNG encoder's refusal.
    #[error("cannot encode the PNG: {0}")]
    Png(String),
    /// The memory budget's refusal, or another core error.
    #[error(transparent)]
    Core(#[from] voxlod_core::CoreError),
}
