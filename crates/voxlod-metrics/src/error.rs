//! The errors the metrics report at the crate boundary, each with a one-line message. Cost:
//! O(1) to build one.

use thiserror::Error;
use voxlod_core::{CoreError, TriangleMesh};

/// Why a measurement could not be made.
#[derive(Debug, Error)]
pub enum MetricsError {
    /// Every triangle is degenerate, so there is no surface to sample.
    #[error("the mesh has no area ({triangles} triangles, all degenerate)")]
    NoArea {
        /// Triangles in the mesh.
        triangles: usize,
    },
    /// Zero samples were asked for.
    #[error("the sample count must be at least 1")]
    NoSamples,
    /// More samples per surface than [`crate::surface_sampling::MAX_SAMPLES`] allows.
    #[error(
        "{requested} samples per surface is more than the {max} allowed: a million already gives \
         final figures, and this many would run for hours"
    )]
    TooManySamples {
        /// Samples asked for.
        requested: usize,
        /// The most allowed.
        max: usize,
    },
    /// An error about one of two meshes measured together.
    #[error("{which} mesh: {source}")]
    InMesh {
        /// Which mesh: "first" or "second".
        which: &'static str,
        /// What is wrong with it.
        source: Box<MetricsError>,
    },
    /// An allocation over the memory limit.
    #[error(transparent)]
    Core(#[from] CoreError),
}

impl MetricsError {
    /// Names the mesh an error came from ("first", "second") when two meshes are measured.
    pub(crate) fn in_mesh(self, which: &'static str) -> MetricsError {
        MetricsError::InMesh {
            which,
            source: Box::new(self),
        }
    }
}

/// Checks what every measurement needs: at least one triangle, vertex indices in range and
/// finite coordinates (for every stored vertex, used or not). Area is checked separately, by
/// the measurements that need it.
pub(crate) fn check_mesh(mesh: &TriangleMesh) -> Result<(), MetricsError> {
    let required = voxlod_core::validate::Requirements::default();
    Ok(voxlod_core::validate::validate_mesh(mesh, &required)?)
}
