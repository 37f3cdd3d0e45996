//! What an evaluation found: the input's figures and, per method, the curve of its measured
//! levels.

use serde::Serialize;
use voxlod::core::PolyMesh;

use super::images::ImageDifference;
use crate::methods::Method;

/// The input's figures, for the report.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct InputSummary {
    /// Vertices as given (before welding; an asset's geometry is welded by position first,
    /// [`super::evaluate_asset`]).
    pub vertices: usize,
    /// Triangles as given.
    pub triangles: usize,
    /// Surface area.
    pub area: f64,
    /// Diagonal of the input's bounding box: the unit of every `_fraction`.
    pub diagonal: f64,
    /// Connected components, after welding coincident vertices (as the rest of the topology).
    pub components: usize,
    /// Closed loops of boundary edges: holes.
    pub boundary_loops: usize,
    /// Genus, when the surface is a closed manifold.
    pub genus: Option<i64>,
    /// Whether the welded input is a closed, consistently oriented manifold.
    pub closed_manifold: bool,
    /// Draw calls of the input as given ([`super::draw_calls`]): one per material its
    /// triangles use; 1 for a mesh without looks.
    pub draw_calls: usize,
}

/// One measured level of one method.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CurvePoint {
    /// The triangle count aimed at.
    pub budget: usize,
    /// The method's parameter that came nearest (resolution or cells; the proxy's budget).
    pub parameter: f64,
    /// Triangles of the level.
    pub triangles: usize,
    /// Vertices of the level, including those only dangling edges and points use.
    pub vertices: usize,
    /// Clustering only: edges left by collapsed triangles (counted, not measured).
    pub dangling_edges: usize,
    /// Clustering only: points left by collapsed triangles (counted, not measured).
    pub isolated_points: usize,
    /// Two-sided Hausdorff distance to the input (the larger one-sided maximum), in the
    /// input's units.
    pub hausdorff: f64,
    /// Mean distance over the samples of both surfaces.
    pub mean: f64,
    /// Root mean square distance over the samples of both surfaces.
    pub rms: f64,
    /// [`CurvePoint::hausdorff`] as a fraction of the input's diagonal.
    pub hausdorff_fraction: f64,
    /// [`CurvePoint::mean`] as a fraction of the input's diagonal.
    pub mean_fraction: f64,
    /// [`CurvePoint::rms`] as a fraction of the input's diagonal.
    pub rms_fraction: f64,
    /// How far the input strays from the level at most, as a fraction of the input's diagonal.
    pub input_to_level_fraction: f64,
    /// How far the level strays from the input at most (caps over the input's holes show
    /// here), as a fraction of the input's diagonal.
    pub level_to_input_fraction: f64,
    /// Connected components of the level's triangles.
    pub components: usize,
    /// Closed loops of boundary edges.
    pub boundary_loops: usize,
    /// Edges with more than two triangles.
    pub non_manifold_edges: usize,
    /// Genus, when the level is a closed manifold.
    pub genus: Option<i64>,
    /// Whether the level is a closed, consistently oriented manifold.
    pub closed_manifold: bool,
    /// Silhouettes against the input's, when images are measured.
    pub image_difference: Option<ImageDifference>,
    /// Time of the run that made this level (without the search's other runs).
    pub simplify_seconds: f64,
    /// Time of the distance measurement.
    pub distance_seconds: f64,
    /// Time of the silhouette difference.
    pub image_seconds: f64,
    /// How the level looks beside an input asset ([`super::evaluate_asset`]): PSNR and SSIM
    /// of their renders ([`crate::appearance`]), the level drawn with looks taken from the
    /// nearest input points ([`voxlod_asset::transfer`]), or for the [`super::PROXY`] with its
    /// own baked textures; `None` for a mesh without looks.
    pub appearance: Option<LevelAppearance>,
    /// Draw calls of the level as it is drawn: 1 for the simplifiers' levels (one mesh whose
    /// looks taken from the input are vertex colours under one material; the untextured
    /// copies of the input's materials that the transfer keeps per triangle carry no colour),
    /// and for the proxy's ([`super::draw_calls`] of its baked level: one material).
    pub draw_calls: usize,
    /// The level: triangles, and for clustering its dangling edges and isolated points.
    #[serde(skip)]
    pub level: PolyMesh,
}

/// The appearance measure of one level (see [`crate::appearance`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct LevelAppearance {
    /// PSNR in dB from the MSE pooled over the views (infinite: identical renders).
    pub psnr: f64,
    /// The mean of the views' SSIM.
    pub ssim: f64,
    /// Time of the renders and, for a level without looks of its own, the transfer of looks.
    pub seconds: f64,
}

/// The curve of one method.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Curve {
    /// The method, written by its name.
    pub method: Method,
    /// `"resolution"`, `"cells"` or `"epsilon-percent"`.
    pub parameter: &'static str,
    /// The measured levels, one per budget kept, in the order of the budgets.
    pub points: Vec<CurvePoint>,
    /// Budgets for which no level was kept, and why.
    pub misses: Vec<String>,
    /// Runs made by the search, over all budgets.
    pub trials: usize,
    /// Wall time of the method's searches and measurements.
    pub seconds: f64,
    /// What was done to the input for this method (the envelope's repair).
    pub notes: Vec<String>,
}

/// A method or measurement the evaluation could not make, and why.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Omission {
    /// The method or measurement, in words.
    pub what: String,
    /// Why it was left out.
    pub reason: String,
}

/// Everything [`evaluate`] found.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Evaluation {
    /// The input's figures.
    pub input: InputSummary,
    /// The budgets aimed at, largest first.
    pub budgets: Vec<usize>,
    /// Samples per surface of each distance measurement.
    pub samples_per_side: usize,
    /// The accepted relative miss of a budget.
    pub tolerance: f64,
    /// Views of the silhouette difference (0: not measured).
    pub image_views: usize,
    /// Pixels per side of each view.
    pub image_size: u32,
    /// Views of the appearance measure (0: not measured, the input has no looks).
    pub appearance_views: usize,
    /// One curve per method run, in the order of [`EvaluateOptions::methods`].
    pub curves: Vec<Curve>,
    /// What was left out, and why.
    pub omitted: Vec<Omission>,
    /// Wall time of the whole evaluation.
    pub seconds: f64,
}
