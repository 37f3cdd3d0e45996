//! The pyramid's error: every stage crate's error it meets, wrapped with `#[from]`, plus its
//! own (an invalid option, a volume without a surface at the requested iso value, a computed
//! surface beyond 32-bit coordinates, cancellation), and [`PyramidError::class`], the kind of
//! failure that decides what a caller does next (the command line's exit status); the
//! functions [`core_class`] … [`budget_class`] give the class of each stage's error, for the
//! facade's error too.
//!
//! Messages are one line. Where a message names an option it writes the option's field name
//! in backticks (`` `iso` 1.5: … ``), so that a front end can show its own spelling (the command
//! line shows `--iso 1.5: …`).

use std::fmt;
use std::path::Path;

use serde::Serialize;
use voxlod_budget::BudgetError;
use voxlod_contouring::{CleanError, ContourError};
use voxlod_core::validate::MeshDefect;
use voxlod_core::CoreError;
use voxlod_envelope::EnvelopeError;
use voxlod_io::{IoError, IoErrorKind};
use voxlod_metrics::MetricsError;
use voxlod_render::RenderError;
use voxlod_sampling::{MonotoneError, SamplingError};

use crate::lod::LodError;

/// The kind of a failure, for exit codes and for deciding whether to retry.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ErrorClass {
    /// The call is wrong: an option out of range, an output that would replace an input.
    Usage,
    /// The input cannot be processed as asked: a malformed file, a broken mesh, data that has
    /// no surface at the requested iso value.
    BadInput,
    /// The work would not fit in the memory voxlod allows itself (`VOXLOD_MAX_MEMORY`), or in
    /// the 32-bit indices of a mesh.
    TooLarge,
    /// A file could not be opened, read, written or renamed.
    Io,
    /// The caller stopped the work through the progress callback.
    Cancelled,
}

/// An option that is out of its range: the option (a field name), the value
/// given and what is wrong with it.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("`{option}` {value}: {problem}")]
pub struct InvalidOption {
    /// The option's field name, e.g. `iso`, `resolution`, `keep_sharp`.
    pub option: &'static str,
    /// The value given, as written.
    pub value: String,
    /// What is wrong with it, and what would be right.
    pub problem: String,
}

impl InvalidOption {
    /// `option` with `value` is wrong because of `problem`.
    pub fn new(
        option: &'static str,
        value: impl fmt::Display,
        problem: impl Into<String>,
    ) -> InvalidOption {
        InvalidOption {
            option,
            value: value.to_string(),
            problem: problem.into(),
        }
    }
}

/// Any failure of the pyramid driver.
#[derive(Debug, thiserror::Error)]
pub enum PyramidError {
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
    /// Simplification envelopes.
    #[error(transparent)]
    Envelope(#[from] EnvelopeError),
    /// Distances and mesh health.
    #[error(transparent)]
    Metrics(#[from] MetricsError),
    /// Levels by triangle budget.
    #[error(transparent)]
    Budget(#[from] BudgetError),
    /// Baking a proxy's textures.
    #[error(transparent)]
    Bake(#[from] voxlod_bake::BakeError),
    /// An option out of its range.
    #[error(transparent)]
    InvalidOption(#[from] InvalidOption),
    /// A volume filtered directly has no surface at `iso`: every sample is inside (`iso` at or
    /// below the data's minimum) or none is (above its maximum).
    #[error(
        "`iso` {iso} {}. The data runs from {min} to {max}: choose a value above {min} and at \
         most {max}",
        if .iso <= .min {
            "is at or below the data's minimum: every sample is inside (a sample is inside when \
             its value is >= the iso value), so there is no surface"
        } else {
            "is above the data's maximum: no sample reaches it, so nothing is inside and there \
             is no surface"
        }
    )]
    IsoOutsideData {
        /// The iso value asked for.
        iso: f32,
        /// The smallest finite sample.
        min: f32,
        /// The largest finite sample.
        max: f32,
    },
    /// A volume with no finite sample (all NaN or infinite).
    #[error("the volume has no finite samples")]
    NoFiniteSamples,
    /// Filtering the data directly needs the iso value in the data's units.
    #[error("direct filtering needs `iso` in the data's units")]
    IsoRequired,
    /// A scanned volume with no route: neither a threshold nor direct filtering was asked for.
    #[error(
        "a volume needs `threshold` T (inside where the data is >= T) or `direct` (filter the \
         data itself, with `iso` in its units)"
    )]
    NoVolumeRoute,
    /// A scan read blockwise is thresholded; one filtered directly is held whole.
    #[error(
        "`blockwise` reads a scan window by window for `threshold`; `direct` filters the volume \
         held whole"
    )]
    BlockwiseNeedsThreshold,
    /// A file asked to be read blockwise whose samples cannot be read window by window.
    #[error(
        "`blockwise` reads raw files, NRRD with raw encoding and MetaImage with uncompressed \
         data window by window (and Zarr arrays); this file's samples have no random access \
         (compressed, ascii, another format or not a volume): drop `blockwise` to read it whole"
    )]
    NoRandomAccess,
    /// Layered shells need a solid (density 1 inside, 0 outside), not a volume filtered
    /// directly.
    #[error(
        "layers need a solid (density 1 inside, 0 outside): give a mesh, or a volume with a \
         `threshold`"
    )]
    NeedsSolid,
    /// Every level came out empty: the object is thinner than the filter, or encloses nothing.
    #[error(
        "no level has a surface: at every level the filtered density stays below the \
         isodensity {iso}. The object is thinner than the filter (level 0: voxel {voxel_size:.4}, \
         radius {radius:.4}) or encloses no volume; use a higher `resolution`, a smaller \
         `radius_voxels` or a lower `iso`"
    )]
    NoSurface {
        /// The isodensity used.
        iso: f32,
        /// Voxel size of the finest level.
        voxel_size: f64,
        /// Filter radius of the finest level, in world units.
        radius: f64,
    },
    /// A volume's samples reach beyond the range of the 32-bit coordinates of mesh vertices.
    #[error(
        "the samples reach {axis} = {reach:.3e} (origin {}, spacing {}), beyond the ±{:.1e} of \
         32-bit mesh coordinates",
        short_number(*.origin),
        short_number(*.spacing),
        f32::MAX
    )]
    GridBeyondCoordinates {
        /// `x`, `y` or `z`.
        axis: char,
        /// The farthest sample coordinate along it.
        reach: f64,
        /// The grid's origin along it.
        origin: f64,
        /// The grid's spacing along it.
        spacing: f64,
    },
    /// A computed surface has a non-finite vertex or normal: the computation left the range of
    /// 32-bit floats (`cause` says what led there).
    #[error("the computed surface {}; {cause}", computed_defect(.defect))]
    ComputedBeyondRange {
        /// The first non-finite vertex or normal.
        defect: MeshDefect,
        /// What makes the numbers so large.
        cause: &'static str,
    },
    /// A sample of a label map that is not an integer label.
    #[error(
        "sample ({}, {}, {}) holds {value}, which is not an integer label",
        .at[0],
        .at[1],
        .at[2]
    )]
    NotALabel {
        /// Its index along x, y, z.
        at: [usize; 3],
        /// Its value.
        value: f32,
    },
    /// A label map that holds only background (0).
    #[error("the map holds no label other than 0")]
    NoLabels,
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
        source: Box<PyramidError>,
    },
}

impl From<LodError> for PyramidError {
    fn from(e: LodError) -> PyramidError {
        match e {
            LodError::Sampling(e) => PyramidError::Sampling(e),
            LodError::Contour(e) => PyramidError::Contour(e),
            LodError::Read(e) => PyramidError::Io(e),
            LodError::Clean(CleanError::Mesh(e)) => PyramidError::Core(e),
            LodError::Clean(CleanError::BadCell(cell)) => {
                PyramidError::InvalidOption(InvalidOption {
                    option: "resolution",
                    value: cell.to_string(),
                    problem: "gives a level whose cell size is not a positive number".into(),
                })
            }
            LodError::Monotone(MonotoneError::Sampling(e)) => PyramidError::Sampling(e),
            LodError::Monotone(MonotoneError::Core(e)) => PyramidError::Core(e),
            LodError::Monotone(MonotoneError::NonFiniteIso(iso)) => PyramidError::InvalidOption(
                InvalidOption::new("iso", iso, "must be a finite number"),
            ),
            LodError::Monotone(e @ MonotoneError::Unresolved { .. }) => {
                PyramidError::Sampling(SamplingError::InvalidOption(format!(
                    "keeping the genus from rising failed ({e}); set `monotone` to None for the \
                     plain pyramid"
                )))
            }
        }
    }
}

impl PyramidError {
    /// The error with what it happened to in front, `context: message` (a cancellation stays
    /// as it is).
    pub fn context(self, context: impl Into<String>) -> PyramidError {
        match self {
            PyramidError::Cancelled => PyramidError::Cancelled,
            source => PyramidError::In {
                context: context.into(),
                source: Box::new(source),
            },
        }
    }

    /// The error naming `path`, unless it already names it (file errors do).
    pub fn in_file(self, path: &Path) -> PyramidError {
        match &self {
            PyramidError::Io(e) if e.path == path => self,
            _ => self.context(path.display().to_string()),
        }
    }

    /// The error without the contexts around it.
    pub fn root(&self) -> &PyramidError {
        match self {
            PyramidError::In { source, .. } => source.root(),
            other => other,
        }
    }

    /// What kind of failure this is.
    pub fn class(&self) -> ErrorClass {
        use ErrorClass::*;
        match self {
            PyramidError::Core(e) => core_class(e),
            PyramidError::Io(e) => io_class(e),
            PyramidError::Sampling(e) => sampling_class(e),
            PyramidError::Contour(e) => contour_class(e),
            PyramidError::Envelope(e) => envelope_class(e),
            PyramidError::Metrics(e) => metrics_class(e),
            PyramidError::Budget(e) => budget_class(e),
            PyramidError::Bake(e) => bake_class(e),
            PyramidError::InvalidOption(_)
            | PyramidError::IsoRequired
            | PyramidError::NoVolumeRoute
            | PyramidError::BlockwiseNeedsThreshold
            | PyramidError::NoRandomAccess
            | PyramidError::NeedsSolid => Usage,
            PyramidError::Cancelled => Cancelled,
            PyramidError::In { source, .. } => source.class(),
            PyramidError::IsoOutsideData { .. }
            | PyramidError::NoFiniteSamples
            | PyramidError::NoSurface { .. }
            | PyramidError::GridBeyondCoordinates { .. }
            | PyramidError::ComputedBeyondRange { .. }
            | PyramidError::NotALabel { .. }
            | PyramidError::NoLabels => BadInput,
        }
    }
}

/// The class of a bake's error: the memory limit keeps its class; an invalid source, level or
/// atlas is bad input.
pub fn bake_class(e: &voxlod_bake::BakeError) -> ErrorClass {
    use voxlod_bake::BakeError;
    match e {
        BakeError::Core(e) | BakeError::Asset(voxlod_asset::AssetError::Core(e)) => core_class(e),
        BakeError::Metrics(e) => metrics_class(e),
        _ => ErrorClass::BadInput,
    }
}

/// The class of a stage crate's error.
pub fn budget_class(e: &BudgetError) -> ErrorClass {
    match e {
        BudgetError::Core(e) => core_class(e),
        BudgetError::Sampling(e) => sampling_class(e),
        BudgetError::Metrics(e) => metrics_class(e),
        BudgetError::Render(e) => render_class(e),
        BudgetError::InvalidBudgets(_) | BudgetError::InvalidOption { .. } => ErrorClass::Usage,
        BudgetError::Cancelled => ErrorClass::Cancelled,
        BudgetError::EmptyMesh { .. } | BudgetError::NoLevel { .. } => ErrorClass::BadInput,
    }
}

/// The class of a stage crate's error.
pub fn core_class(e: &CoreError) -> ErrorClass {
    match e {
        CoreError::OutOfMemory { .. } => ErrorClass::TooLarge,
        CoreError::BadMemoryLimit { .. } => ErrorClass::Usage,
        _ => ErrorClass::BadInput,
    }
}

/// The class of a stage crate's error.
pub fn io_class(e: &IoError) -> ErrorClass {
    match e.kind {
        IoErrorKind::Access => ErrorClass::Io,
        IoErrorKind::TooLarge => ErrorClass::TooLarge,
        IoErrorKind::Conflict => ErrorClass::Usage,
        _ => ErrorClass::BadInput,
    }
}

/// The class of a stage crate's error.
pub fn sampling_class(e: &SamplingError) -> ErrorClass {
    match e {
        SamplingError::Core(e) => core_class(e),
        SamplingError::InvalidOption(_) => ErrorClass::Usage,
        _ => ErrorClass::BadInput,
    }
}

/// The class of a stage crate's error.
pub fn contour_class(e: &ContourError) -> ErrorClass {
    match e {
        ContourError::Memory(e) => core_class(e),
        ContourError::NonFiniteIso(_)
        | ContourError::BadClamp(_)
        | ContourError::SampleCount { .. } => ErrorClass::Usage,
        ContourError::TooManyVertices(_) | ContourError::TooManyCells(_) => ErrorClass::TooLarge,
    }
}

/// The class of a stage crate's error.
pub fn envelope_class(e: &EnvelopeError) -> ErrorClass {
    match e {
        EnvelopeError::Core(e) => core_class(e),
        EnvelopeError::Metrics(e) => metrics_class(e),
        EnvelopeError::TooLarge(_) => ErrorClass::TooLarge,
        EnvelopeError::InvalidEpsilon(_)
        | EnvelopeError::EpsilonNotGrowing { .. }
        | EnvelopeError::InvalidOption { .. } => ErrorClass::Usage,
        _ => ErrorClass::BadInput,
    }
}

/// The class of a stage crate's error.
pub fn metrics_class(e: &MetricsError) -> ErrorClass {
    match e {
        MetricsError::Core(e) => core_class(e),
        MetricsError::InMesh { source, .. } => metrics_class(source),
        MetricsError::NoSamples | MetricsError::TooManySamples { .. } => ErrorClass::Usage,
        _ => ErrorClass::BadInput,
    }
}

/// "has a vertex at (x, y, z), beyond the range of 32-bit coordinates", or the normal's words.
fn computed_defect(defect: &MeshDefect) -> String {
    match defect {
        MeshDefect::NonFiniteCoordinate { x, y, z, .. } => {
            format!("has a vertex at ({x}, {y}, {z}), beyond the range of 32-bit coordinates")
        }
        MeshDefect::NonFiniteNormal { .. } => "has a non-finite normal".to_string(),
        other => format!("is broken: {other}"),
    }
}

/// A number as people write it: plain, or in scientific notation when very large or small.
fn short_number(x: f64) -> String {
    if x != 0.0 && !(1e-4..1e6).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// The class of a stage crate's error.
pub fn render_class(e: &RenderError) -> ErrorClass {
    match e {
        RenderError::Core(e) => core_class(e),
        RenderError::ZeroViewDirection
        | RenderError::NonFiniteView(_)
        | RenderError::BadSize(..)
        | RenderError::BadSupersample(_) => ErrorClass::Usage,
        _ => ErrorClass::BadInput,
    }
}
