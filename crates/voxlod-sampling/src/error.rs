use thiserror::Error;
use voxlod_core::CoreError;

/// Why a solid could not be sampled or filtered.
#[derive(Debug, Error)]
pub enum SamplingError {
    #[error("the mesh has no triangles with area")]
    EmptyMesh,
    #[error("the solid is empty: its bounds have no extent")]
    EmptyBounds,
    #[error("invalid option: {0}")]
    InvalidOption(String),
    #[error(transparent)]
    Core(#[from] CoreError),
}
