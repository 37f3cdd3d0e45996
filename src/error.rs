//! The one error of the facade: every stage crate's error, wrapped with `#[from]` (the
//! pyramid's own failures as [`Error::Pyramid`], what it passes on from the stages as the
//! stages' variants), an invalid option, a cancellation, and [`Error::class`], the kind of
//! failure that decides what a caller does next (the command line's exit status).
//!
//! Messages are one line. Where a message names an option of a facade call it writes the
//! option's field name in backticks (`` `iso` 1.5: … ``), so that a front end can show its own
//! spelling (the command line shows `--iso 1.5: …`).

use std::path::Path;

use voxlod_budget::BudgetError;
use voxlod_clustering::ClusteringError;
use voxlod_contouring::ContourError;
use voxlod_core::CoreError;
use voxlod_envelope::EnvelopeError;
use voxlod_gltf::GltfError;
use voxlod_io::IoError;
use voxlod_labels::LabelsError;
use voxlod_layers::LayersError;
use voxlod_metrics::MetricsError;
use voxlod_precomputed::PrecomputedError as Precomputed;
use voxlod_pyramid::error::{
    budget_class, contour_class, core_class, envelope_class, io_class, metrics_class, render_class,
    sampling_class,
};
use voxlod_pyramid::lod::LodError;
use voxlod_pyramid::{ErrorClass, InvalidOption, PyramidError};
use voxlod_render::RenderError;
use voxlod_sampling::SamplingError;

/// Any failure of a facade call.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// Core types: an invalid grid or mesh, work that would not fit in memory.
    #[error(transparent)]
    Core(#[from] CoreError),
    /// Reading or writing a file.
    #[error(transparent)]
    Io(#[from] IoError),
    /// Inside tests and filtering.
    #[error(transparent)]
    Sampling(#[from] SamplingError),
    /// Marching cubes.
    #[error(transparent)]
    Contour(#[from] ContourError),
    /// Layered shells.
    #[error(transparent)]
    Layers(#[from] LayersError),
    /// Vertex clustering.
    #[error(transparent)]
    Clustering(#[from] ClusteringError),
    /// Simplification envelopes.
    #[error(transparent)]
    Envelope(#[from] EnvelopeError),
    /// Distances and mesh health.
    #[error(transparent)]
    Metrics(#[from] MetricsError),
    /// Label maps meshed without a filter.
    #[error(transparent)]
    Labels(#[from] LabelsError),
    /// Neuroglancer precomputed layers.
    #[error(transparent)]
    Precomputed(#[from] Precomputed),
    /// Levels by triangle budget.
    #[error(transparent)]
    Budget(#[from] BudgetError),
    /// The software rasterizer.
    #[error(transparent)]
    Render(#[from] RenderError),
    /// A glTF file that cannot be read (a corrupt file is bad input) or written.
    #[error(transparent)]
    Gltf(GltfError),
    /// An option out of its range.
    #[error(transparent)]
    InvalidOption(#[from] InvalidOption),
    /// The pyramid driver's own failures: no surface at the iso value, no finite sample, a
    /// grid or surface beyond 32-bit coordinates, a volume where a solid is needed.
    #[error(transparent)]
    Pyramid(PyramidError),
    /// The caller's progress callback asked to stop.
    #[error("stopped by the caller")]
    Cancelled,
    /// An error with what it happened to: a file, a level (`{context}: {source}`).
    #[error("{context}: {source}")]
    In {
        /// The file, the level, the mesh.
        context: String,
        /// What went wrong there.
        #[source]
        source: Box<Error>,
    },
}

impl From<PyramidError> for Error {
    /// The stage errors, options, cancellations and contexts the pyramid passes on become the
    /// facade's own variants; its own failures stay [`Error::Pyramid`].
    fn from(e: PyramidError) -> Error {
        match e {
            PyramidError::Core(e) => Error::Core(e),
            PyramidError::Io(e) => Error::Io(e),
            PyramidError::Sampling(e) => Error::Sampling(e),
            PyramidError::Contour(e) => Error::Contour(e),
            PyramidError::Envelope(e) => Error::Envelope(e),
            PyramidError::Metrics(e) => Error::Metrics(e),
            PyramidError::Budget(e) => Error::Budget(e),
            PyramidError::InvalidOption(e) => Error::InvalidOption(e),
            PyramidError::Cancelled => Error::Cancelled,
            PyramidError::In { context, source } => Error::In {
                context,
                source: Box::new(Error::from(*source)),
            },
            own => Error::Pyramid(own),
        }
    }
}

impl From<GltfError> for Error {
    /// The memory budget's and the files' errors become [`Error::Core`] and [`Error::Io`].
    fn from(e: GltfError) -> Error {
        match e {
            GltfError::Core(e) => Error::Core(e),
            GltfError::Io(e) => Error::Io(e),
            other => Error::Gltf(other),
        }
    }
}

impl From<LodError> for Error {
    fn from(e: LodError) -> Error {
        Error::from(PyramidError::from(e))
    }
}

impl Error {
    /// The error with what it happened to in front, `context: message` (a cancellation stays
    /// as it is).
    pub fn context(self, context: impl Into<String>) -> Error {
        match self {
            Error::Cancelled => Error::Cancelled,
            source => Error::In {
                context: context.into(),
                source: Box::new(source),
            },
        }
    }

    /// The error naming `path`, unless it already names it (file errors do).
    pub fn in_file(self, path: &Path) -> Error {
        match &self {
            Error::Io(e) if e.path == path => self,
            _ => self.context(path.display().to_string()),
        }
    }

    /// The error without the contexts around it.
    pub fn root(&self) -> &Error {
        match self {
            Error::In { source, .. } => source.root(),
            other => other,
        }
    }

    /// What kind of failure this is.
    pub fn class(&self) -> ErrorClass {
        use ErrorClass::*;
        match self {
            Error::Core(e) => core_class(e),
            Error::Io(e) => io_class(e),
            Error::Sampling(e) => sampling_class(e),
            Error::Contour(e) => contour_class(e),
            Error::Layers(e) => layers_class(e),
            Error::Clustering(e) => clustering_class(e),
            Error::Envelope(e) => envelope_class(e),
            Error::Metrics(e) => metrics_class(e),
            Error::Budget(e) => budget_class(e),
            Error::Labels(LabelsError::Core(e)) => core_class(e),
            Error::Labels(LabelsError::Missing(..) | LabelsError::InvalidOption { .. }) => Usage,
            Error::Labels(_) => BadInput,
            Error::Precomputed(Precomputed::Core(e)) => core_class(e),
            Error::Precomputed(Precomputed::Io { .. }) => Io,
            Error::Precomputed(Precomputed::Options(_)) => Usage,
            Error::Precomputed(_) => BadInput,
            Error::Render(e) => render_class(e),
            Error::Gltf(GltfError::Core(e)) => core_class(e),
            Error::Gltf(GltfError::Io(e)) => io_class(e),
            Error::Gltf(GltfError::InvalidParameter { .. }) => Usage,
            Error::Gltf(_) => BadInput,
            Error::InvalidOption(_) => Usage,
            Error::Pyramid(e) => e.class(),
            Error::Cancelled => Cancelled,
            Error::In { source, .. } => source.class(),
        }
    }
}

fn layers_class(e: &LayersError) -> ErrorClass {
    match e {
        LayersError::Core(e) => core_class(e),
        LayersError::Sampling(e) => sampling_class(e),
        LayersError::Contour(e) => contour_class(e),
        LayersError::Render(e) => render_class(e),
        LayersError::Io(e) => io_class(e),
        LayersError::NonPositiveError(_)
        | LayersError::TooManyLayers { .. }
        | LayersError::ZeroViewDirection
        | LayersError::NonFiniteView(_) => ErrorClass::Usage,
        _ => ErrorClass::BadInput,
    }
}

fn clustering_class(e: &ClusteringError) -> ErrorClass {
    match e {
        ClusteringError::Core(e) => core_class(e),
        ClusteringError::TooLarge { .. } => ErrorClass::TooLarge,
        ClusteringError::ZeroCells
        | ClusteringError::TooManyCells { .. }
        | ClusteringError::ZeroLevels
        | ClusteringError::TooManyLevels { .. }
        | ClusteringError::InvalidParameter { .. } => ErrorClass::Usage,
        _ => ErrorClass::BadInput,
    }
}
