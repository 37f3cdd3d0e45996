//! [`SamplingError`], what sampling and filtering refuse and why. Cost: O(1).

use thiserror::Error;
use voxlod_core::CoreError;

/// Why a solid could not be sampled or filtered.
#[derive(Debug, Error)]
pub enum SamplingError {
    /// Every triangle of the mesh is degenerate (or there is none): no solid to sample.
    #[error("the mesh has no triangles with area")]
    EmptyMesh,
    /// The solid's box is empty or flat, so no grid can be fitted to it.
    #[error("the solid is empty: its bounds have no extent")]
    EmptyBounds,
    /// An option out of its range (a radius, a resolution), said in words.
    #[error("invalid option: {0}")]
    InvalidOption(String),
    /// An invalid grid, or work that would not fit in the memory limit.
    #[error(transparent)]
    Core(#[from] CoreError),
}
