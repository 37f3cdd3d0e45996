//! Evaluation of every simplifier of the project on one mesh: for each method and each triangle
//! budget, the level closest to the budget, how far its surface lies from the input, and what it
//! did to the topology. The result is the error-against-triangles curve of each method, which
//! [`plot`] draws and [`report`] writes up.
//!
//! The pieces, one file each:
//!
//! - the methods ([`crate::methods`]): each behind the [`Simplifier`](crate::methods::Simplifier)
//!   trait, controlled by a parameter, not by a triangle count (the voxel pipeline by its
//!   resolution, [`voxlod::lod`]; the clustering baselines by their cells across the longest
//!   side; simplification envelopes by ε);
//! - the budget search (`search.rs`): for each budget, the parameter whose output is nearest
//!   it, searched in log–log space until a trial lands within [`EvaluateOptions::tolerance`] of
//!   it or [`EvaluateOptions::max_trials`] runs were spent; typically one to three runs per
//!   budget;
//! - the measuring (`measure.rs`): the two-sided surface distance of each kept level to the
//!   input ([`voxlod::metrics::mesh_distance`]: Hausdorff, mean and RMS over area-uniform
//!   samples of both surfaces), given absolutely and as a fraction of the **input's**
//!   bounding-box diagonal (the same unit for every level and method, unlike `voxlod compare`,
//!   whose unit is the box of both meshes), its topology, and when [`EvaluateOptions::images`]
//!   asks for it the share of differing silhouette pixels over a set of views ([`images`]);
//! - [`plot`] and [`report`]: the chart and the Markdown write-up.
//!
//! Simplification envelopes need a consistently oriented manifold; an input that is not one is
//! cut into one first ([`voxlod::envelope::repair_for_envelope`]), and [`Curve::notes`] says
//! what that changed. An input that cannot be made one is listed in [`Evaluation::omitted`] and
//! the other methods go on.
//!
//! Cost: the voxel trials dominate (a filtered density at the trial's resolution, then marching
//! cubes; about 0.2 s at resolution 64 on the bunny), then the envelope trials; clustering
//! trials take milliseconds. Then one distance measurement per kept level (two BVH builds,
//! `2 × samples` queries). The measured levels are kept in memory for the caller to write.
//!
//! # Example
//!
//! Two methods on a small torus, one budget:
//!
//! ```
//! use voxlod::metrics::DistanceOptions;
//! use voxlod_eval::evaluate::{evaluate, Budgets, EvaluateOptions, ImageOptions, Method};
//!
//! # let mesh = voxlod_testkit::shapes::torus(48, 24, 2.0, 0.7);
//! // `mesh`: a torus of 2304 triangles (or any mesh, say from `voxlod::io::read_mesh`).
//! let options = EvaluateOptions {
//!     methods: vec!["voxel-hypercone".parse()?, "rossignac-borrel".parse()?],
//!     budgets: Budgets::Explicit(vec![400]),
//!     distance: DistanceOptions::with_samples(2_000),
//!     images: ImageOptions::off(),
//!     ..EvaluateOptions::quick()
//! };
//! let evaluation = evaluate(&mesh, &options, |_, _| {})?;
//! for curve in &evaluation.curves {
//!     let point = &curve.points[0];
//!     // Within the quick options' 20 % of the budget, and close to the input.
//!     assert!(point.triangles.abs_diff(400) <= 80, "{}: {}", curve.method, point.triangles);
//!     assert!(point.hausdorff_fraction < 0.1);
//! }
//! // The voxel level of a torus is a closed manifold of genus 1.
//! assert_eq!(evaluation.curves[0].method, Method::ALL[0]);
//! assert_eq!(evaluation.curves[0].points[0].genus, Some(1));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod measure;
mod search;

pub mod images;
pub mod plot;
pub mod report;

pub use crate::methods::{Method, RunFailure};
pub use images::{ImageDifference, ImageOptions, SilhouetteReference};

use std::time::Instant;

use serde::Serialize;
use voxlod::core::{PolyMesh, TriangleMesh};
use voxlod::metrics::{DistanceOptions, MetricsError};
use voxlod::render::RenderError;
use voxlod::sampling::SamplingError;

use crate::methods::{MethodInput, Needs};
use measure::{summarise_input, Measurer};
use search::method_curve;

/// Which triangle counts to aim at.
#[derive(Clone, Debug, PartialEq)]
pub enum Budgets {
    /// Half the input's triangles, then halving `count` times in all, stopping before `smallest`.
    Halving {
        /// How many budgets at most.
        count: usize,
        /// No budget below this many triangles.
        smallest: usize,
    },
    /// These triangle counts.
    Explicit(Vec<usize>),
}

impl Budgets {
    /// The budgets for an input of `triangles` triangles, largest first, without repeats.
    pub fn resolve(&self, triangles: usize) -> Vec<usize> {
        let mut list = match self {
            Budgets::Halving { count, smallest } => {
                let mut list = Vec::new();
                let mut b = triangles / 2;
                while list.len() < *count && b >= (*smallest).max(1) {
                    list.push(b);
                    b /= 2;
                }
                list
            }
            Budgets::Explicit(list) => list.iter().copied().filter(|&b| b > 0).collect(),
        };
        list.sort_unstable_by(|a, b| b.cmp(a));
        list.dedup();
        list
    }
}

/// How to evaluate (see the module documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct EvaluateOptions {
    /// The methods to run, in the order of the report ([`Method::ALL`] by default).
    pub methods: Vec<Method>,
    /// The triangle counts to aim at.
    pub budgets: Budgets,
    /// Samples per surface of each distance measurement.
    pub distance: DistanceOptions,
    /// A trial within this relative distance of its budget ends the search (0.1: ±10 %).
    pub tolerance: f64,
    /// A level further than this factor from its budget (either way) is not kept: the budget
    /// is out of the method's reach (more triangles than clustering can keep, say).
    pub max_miss_factor: f64,
    /// Most runs spent on one budget of one method.
    pub max_trials: usize,
    /// Highest voxel resolution tried.
    pub max_resolution: usize,
    /// Most clustering cells tried along the longest side.
    pub max_cells: u32,
    /// Quadrature lines per filter radius of the voxel pipeline (see `voxlod lod --help`).
    pub lines_per_radius: usize,
    /// The silhouette difference's views and image size.
    pub images: ImageOptions,
}

impl Default for EvaluateOptions {
    fn default() -> Self {
        EvaluateOptions::standard()
    }
}

impl EvaluateOptions {
    /// Every method, eight halving budgets down to 100 triangles, 100 000 samples per side.
    pub fn standard() -> Self {
        EvaluateOptions {
            methods: Method::ALL.to_vec(),
            budgets: Budgets::Halving {
                count: 8,
                smallest: 100,
            },
            distance: DistanceOptions::standard(),
            tolerance: 0.1,
            max_miss_factor: 1.5,
            max_trials: 6,
            max_resolution: 512,
            max_cells: 4096,
            lines_per_radius: 4,
            images: ImageOptions::standard(),
        }
    }

    /// Every method, four budgets, 20 000 samples per side, a looser fit: for tests and a first
    /// look.
    pub fn quick() -> Self {
        EvaluateOptions {
            budgets: Budgets::Halving {
                count: 4,
                smallest: 50,
            },
            distance: DistanceOptions::with_samples(20_000),
            tolerance: 0.2,
            max_trials: 4,
            images: ImageOptions::quick(),
            ..EvaluateOptions::standard()
        }
    }
}

/// The input's figures, for the report.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct InputSummary {
    /// Vertices as given (before welding).
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
}

/// One measured level of one method.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CurvePoint {
    /// The triangle count aimed at.
    pub budget: usize,
    /// The method's parameter that came nearest (resolution or cells).
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
    /// The level: triangles, and for clustering its dangling edges and isolated points.
    #[serde(skip)]
    pub level: PolyMesh,
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
    /// One curve per method run, in the order of [`EvaluateOptions::methods`].
    pub curves: Vec<Curve>,
    /// What was left out, and why.
    pub omitted: Vec<Omission>,
    /// Wall time of the whole evaluation.
    pub seconds: f64,
}

/// Why an evaluation could not be made.
#[derive(Debug, thiserror::Error)]
pub enum EvaluateError {
    /// The input cannot be measured: broken indices or coordinates, or no area.
    #[error("the input mesh: {0}")]
    Input(#[from] MetricsError),
    /// The voxel methods cannot sample the input as a solid.
    #[error("the input mesh cannot be sampled as a solid: {0}")]
    Solid(SamplingError),
    /// [`EvaluateOptions::budgets`] gives no triangle count for this input.
    #[error("no budgets: give at least one triangle count above 0 (the input has {triangles} triangles)")]
    NoBudgets {
        /// The input's triangles.
        triangles: usize,
    },
    /// [`EvaluateOptions::methods`] is empty.
    #[error("no methods to evaluate")]
    NoMethods,
    /// A run of a method failed.
    #[error("{method} at {parameter} {}: {source}", parameter_text(*.value))]
    Run {
        /// The method.
        method: Method,
        /// Its parameter's name.
        parameter: &'static str,
        /// The parameter's value.
        value: f64,
        /// What failed.
        source: RunFailure,
    },
    /// The input's silhouettes cannot be rendered.
    #[error("the input mesh cannot be rendered: {0}")]
    InputRender(RenderError),
    /// A level's silhouettes cannot be rendered.
    #[error("{method} at {parameter} {}: rendering the level: {source}", parameter_text(*.value))]
    Render {
        /// The method.
        method: Method,
        /// Its parameter's name.
        parameter: &'static str,
        /// The parameter's value.
        value: f64,
        /// What failed.
        source: RenderError,
    },
    /// A level's distance to the input cannot be measured.
    #[error("{method} at {parameter} {}: measuring the level: {source}", parameter_text(*.value))]
    Distance {
        /// The method.
        method: Method,
        /// Its parameter's name.
        parameter: &'static str,
        /// The parameter's value.
        value: f64,
        /// What failed.
        source: MetricsError,
    },
}

/// Runs every method of `options` on `mesh` at every budget and measures each level against
/// `mesh`. `on_point` hears of each measured level as soon as it is made (for progress).
///
/// Fails on a mesh that cannot be measured (empty, no area, broken indices or coordinates), a
/// mesh the voxel methods cannot sample, or a run that fails; the error names the method and
/// parameter. A method whose needs the input cannot meet (a manifold for the envelope) is left
/// out and listed in [`Evaluation::omitted`].
pub fn evaluate(
    mesh: &TriangleMesh,
    options: &EvaluateOptions,
    mut on_point: impl FnMut(Method, &CurvePoint),
) -> Result<Evaluation, EvaluateError> {
    let start = Instant::now();
    let input = summarise_input(mesh)?;
    if options.methods.is_empty() {
        return Err(EvaluateError::NoMethods);
    }
    let budgets = options.budgets.resolve(mesh.triangles.len());
    if budgets.is_empty() {
        return Err(EvaluateError::NoBudgets {
            triangles: mesh.triangles.len(),
        });
    }
    let prepared =
        MethodInput::prepare(mesh, Needs::of(&options.methods), options.lines_per_radius)
            .map_err(EvaluateError::Solid)?;
    let silhouettes = if options.images.views > 0 {
        Some(SilhouetteReference::new(mesh, &options.images).map_err(EvaluateError::InputRender)?)
    } else {
        None
    };
    let measurer = Measurer {
        mesh,
        input: &input,
        silhouettes: silhouettes.as_ref(),
        distance: &options.distance,
    };
    let mut omitted: Vec<Omission> = Vec::new();
    let mut curves = Vec::new();
    for &method in &options.methods {
        let needs = method.simplifier().needs();
        if let Some(reason) = prepared.unmet(needs) {
            let what = method.simplifier().description();
            if !omitted.iter().any(|o| o.what == what) {
                omitted.push(Omission {
                    what: what.into(),
                    reason: reason.into(),
                });
            }
            continue;
        }
        let mut curve = method_curve(
            method,
            &prepared,
            &measurer,
            &budgets,
            options,
            &mut on_point,
        )?;
        if needs.manifold {
            curve.notes = prepared.manifold_notes().to_vec();
        }
        curves.push(curve);
    }
    Ok(Evaluation {
        input,
        budgets,
        samples_per_side: options.distance.samples_per_side,
        tolerance: options.tolerance,
        image_views: options.images.views.min(14),
        image_size: options.images.size,
        curves,
        omitted,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// A parameter as a person writes it: whole numbers plain, ε percentages to three places.
pub fn parameter_text(x: f64) -> String {
    if x.fract() == 0.0 {
        format!("{x:.0}")
    } else {
        format!("{x:.3}")
    }
}
