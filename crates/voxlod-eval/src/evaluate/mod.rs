//! Evaluation of every simplifier of the project on one mesh: for each method and each triangle
//! budget, the level closest to the budget, how far its surface lies from the input, and what it
//! did to the topology. The result is the error-against-triangles curve of each method, which
//! [`plot`] draws and [`report`] writes up.
//!
//! The methods ([`Method`]) are controlled by a parameter, not by a triangle count: the voxel
//! pipeline by its resolution (samples across the longest side, [`voxlod::lod`]), the clustering
//! baselines by their cells across the longest side. [`evaluate`] finds, for each budget, the
//! parameter whose output is nearest the budget: a search on the parameter in log–log space
//! (triangle counts grow about as the square of either parameter), interpolating between the
//! nearest trials below and above the budget, until a trial lands within
//! [`EvaluateOptions::tolerance`] of it or [`EvaluateOptions::max_trials`] runs were spent. Every
//! trial of a method is kept, so each budget's search starts from what the earlier ones learnt;
//! typically one to three runs per budget.
//!
//! The error of a level is the two-sided surface distance to the input
//! ([`voxlod::metrics::mesh_distance`]: Hausdorff, mean and RMS over area-uniform samples of both
//! surfaces), given absolutely and as a fraction of the **input's** bounding-box diagonal (the
//! same unit for every level and method, unlike `voxlod compare`, whose unit is the box of both
//! meshes). Only triangles are measured: the dangling edges and isolated points that clustering
//! leaves are counted in the report but have no area to sample.
//!
//! Cost: the voxel trials dominate (a filtered density at the trial's resolution, then marching
//! cubes; about 0.2 s at resolution 64 on the bunny); clustering trials take milliseconds. Then
//! one distance measurement per kept level (two BVH builds, `2 × samples` queries). The
//! measured levels are kept in memory for the caller to write.
//!
//! Each level is also compared with the input in image space when [`EvaluateOptions::images`]
//! asks for it: the share of differing silhouette pixels over a set of views ([`images`]).
//!
//! Simplification envelopes (Varshney et al. 1995) are controlled by ε, a continuous parameter
//! (given as a percentage of the input's diagonal) under which triangle counts fall: the search
//! steps on a geometric grid of ε (ratio 2^¼), with the same interpolation. Each trial simplifies
//! the input itself with [`EnvelopeOptions::tight`]. The envelope needs a consistently oriented
//! manifold; an input that is not one is cut into one first ([`repair_for_envelope`]), and
//! [`Curve::notes`] says what that changed. An input that cannot be made one is listed in
//! [`Evaluation::omitted`] and the other methods go on.
//!
//! The voxel pipeline followed by envelopes ([`Method::VoxelEnvelope`]) is the use the voxel
//! paper proposes for itself (§5): filter away the small features and the genus, then let a
//! topology-preserving simplifier remove the triangles marching cubes spends on flat regions.
//! Its parameter is the resolution; ε is one voxel of it. Resolutions above 256 are not tried
//! (the envelope of a few million triangles takes minutes).

pub mod images;
pub mod plot;
pub mod report;

pub use images::{ImageDifference, ImageOptions, SilhouetteReference};

use std::time::Instant;

use serde::Serialize;
use voxlod::clustering::{
    low_tan, rossignac_borrel, ClusterOptions, ClusteringError, FloatingCellOptions,
};
use voxlod::core::{mesh_topology, PolyMesh, TriangleMesh};
use voxlod::envelope::{check_manifold, repair_for_envelope};
use voxlod::envelope::{simplify_envelope, EnvelopeError, EnvelopeOptions, Epsilon};
use voxlod::metrics::{mesh_distance, welded_mesh_report, DistanceOptions, MetricsError};
use voxlod::render::RenderError;
use voxlod::sampling::{Filter, MeshSolid, PyramidOptions, SamplingError};

use voxlod::lod::{build_level, plan, LodError, LodOptions, LodSource};

/// A simplification method the evaluation can run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// The voxel pipeline (paper §2) with the hyper-cone filter of equation 3.
    VoxelHypercone,
    /// The voxel pipeline with the truncated Gaussian (σ = R/3).
    VoxelGaussian,
    /// Uniform-grid vertex clustering, weighted centres of mass (Rossignac and Borrel 1993).
    RossignacBorrel,
    /// Floating-cell weight-controlled clustering (Low and Tan), without thick edges.
    LowTan,
    /// Simplification envelopes (Varshney et al. 1995), vertex removal between the offsets,
    /// [`EnvelopeOptions::tight`].
    Envelope,
    /// The paper's proposal (§5): the voxel pipeline with the hyper-cone, then each level
    /// simplified by envelopes within one voxel of that level, keeping the genus the filter
    /// made.
    VoxelEnvelope,
}

impl Method {
    /// Every method, in the order reports list them.
    pub const ALL: [Method; 6] = [
        Method::VoxelHypercone,
        Method::VoxelGaussian,
        Method::RossignacBorrel,
        Method::LowTan,
        Method::Envelope,
        Method::VoxelEnvelope,
    ];

    /// The name used on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            Method::VoxelHypercone => "voxel-hypercone",
            Method::VoxelGaussian => "voxel-gaussian",
            Method::RossignacBorrel => "rossignac-borrel",
            Method::LowTan => "low-tan",
            Method::Envelope => "envelope",
            Method::VoxelEnvelope => "voxel-envelope",
        }
    }

    /// What the method's parameter is.
    pub fn parameter_name(self) -> &'static str {
        match self {
            Method::VoxelHypercone | Method::VoxelGaussian | Method::VoxelEnvelope => "resolution",
            Method::RossignacBorrel | Method::LowTan => "cells",
            Method::Envelope => "epsilon-percent",
        }
    }

    fn is_voxel(self) -> bool {
        matches!(
            self,
            Method::VoxelHypercone | Method::VoxelGaussian | Method::VoxelEnvelope
        )
    }

    /// The range and growth of the parameter, for the budget search.
    fn control(self, options: &EvaluateOptions) -> Control {
        match self {
            Method::VoxelHypercone | Method::VoxelGaussian => Control {
                lowest: 2.0,
                highest: options.max_resolution as f64,
                first: 64.0,
                exponent: 2.0,
                grid: Grid::Integers,
            },
            Method::RossignacBorrel | Method::LowTan => Control {
                lowest: 1.0,
                highest: options.max_cells as f64,
                first: 64.0,
                exponent: 2.0,
                grid: Grid::Integers,
            },
            // Envelope levels within one voxel keep about a twentieth of marching cubes'
            // triangles; above 256 the envelope of millions of triangles costs minutes.
            Method::VoxelEnvelope => Control {
                lowest: 4.0,
                highest: options.max_resolution.min(256) as f64,
                first: 128.0,
                exponent: 2.0,
                grid: Grid::Integers,
            },
            // ε in percent of the diagonal; on smooth surfaces triangles fall about as 1/ε.
            Method::Envelope => Control {
                lowest: 0.005,
                highest: 25.0,
                first: 1.0,
                exponent: -1.0,
                grid: Grid::Geometric {
                    ratio: 2f64.powf(0.25),
                },
            },
        }
    }
}

impl std::str::FromStr for Method {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Method::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| {
                let names: Vec<&str> = Method::ALL.iter().map(|m| m.name()).collect();
                format!(
                    "unknown method '{s}' (expected one of {})",
                    names.join(", ")
                )
            })
    }
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Which triangle counts to aim at.
#[derive(Clone, Debug, PartialEq)]
pub enum Budgets {
    /// Half the input's triangles, then halving `count` times in all, stopping before `smallest`.
    Halving { count: usize, smallest: usize },
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
    pub methods: Vec<Method>,
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
    pub vertices: usize,
    pub triangles: usize,
    pub area: f64,
    /// Diagonal of the input's bounding box: the unit of every `_fraction`.
    pub diagonal: f64,
    /// Topology after welding coincident vertices.
    pub components: usize,
    pub boundary_loops: usize,
    pub genus: Option<i64>,
    pub closed_manifold: bool,
}

/// One measured level of one method.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CurvePoint {
    /// The triangle count aimed at.
    pub budget: usize,
    /// The method's parameter that came nearest (resolution or cells).
    pub parameter: f64,
    pub triangles: usize,
    pub vertices: usize,
    /// Clustering only: edges and points left by collapsed triangles (not measured).
    pub dangling_edges: usize,
    pub isolated_points: usize,
    /// Two-sided distances to the input (see the module documentation).
    pub hausdorff: f64,
    pub mean: f64,
    pub rms: f64,
    /// The same, as fractions of the input's diagonal.
    pub hausdorff_fraction: f64,
    pub mean_fraction: f64,
    pub rms_fraction: f64,
    /// The one-sided maxima, as fractions of the input's diagonal: how far the input strays
    /// from the level, and the level from the input (caps over the input's holes show here).
    pub input_to_level_fraction: f64,
    pub level_to_input_fraction: f64,
    pub components: usize,
    pub boundary_loops: usize,
    pub non_manifold_edges: usize,
    pub genus: Option<i64>,
    pub closed_manifold: bool,
    /// Silhouettes against the input's, when images are measured.
    pub image_difference: Option<ImageDifference>,
    /// Time of the run that made this level (without the search's other runs).
    pub simplify_seconds: f64,
    pub distance_seconds: f64,
    pub image_seconds: f64,
    /// The level: triangles, and for clustering its dangling edges and isolated points.
    #[serde(skip)]
    pub level: PolyMesh,
}

/// The curve of one method.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Curve {
    pub method: Method,
    /// `"resolution"`, `"cells"` or `"epsilon-percent"`.
    pub parameter: &'static str,
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
    pub what: String,
    pub reason: String,
}

/// Everything [`evaluate`] found.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Evaluation {
    pub input: InputSummary,
    pub budgets: Vec<usize>,
    pub samples_per_side: usize,
    pub tolerance: f64,
    /// Views and pixels per side of the silhouette difference (0 views: not measured).
    pub image_views: usize,
    pub image_size: u32,
    pub curves: Vec<Curve>,
    pub omitted: Vec<Omission>,
    pub seconds: f64,
}

/// Why an evaluation could not be made.
#[derive(Debug, thiserror::Error)]
pub enum EvaluateError {
    #[error("the input mesh: {0}")]
    Input(#[from] MetricsError),
    #[error("the input mesh cannot be sampled as a solid: {0}")]
    Solid(SamplingError),
    #[error("no budgets: give at least one triangle count above 0 (the input has {triangles} triangles)")]
    NoBudgets { triangles: usize },
    #[error("no methods to evaluate")]
    NoMethods,
    #[error("{method} at {parameter} {}: {source}", parameter_text(*.value))]
    Run {
        method: Method,
        parameter: &'static str,
        value: f64,
        source: RunFailure,
    },
    #[error("the input mesh cannot be rendered: {0}")]
    InputRender(RenderError),
    #[error("{method} at {parameter} {}: rendering the level: {source}", parameter_text(*.value))]
    Render {
        method: Method,
        parameter: &'static str,
        value: f64,
        source: RenderError,
    },
    #[error("{method} at {parameter} {}: measuring the level: {source}", parameter_text(*.value))]
    Distance {
        method: Method,
        parameter: &'static str,
        value: f64,
        source: MetricsError,
    },
}

/// Runs every method of `options` on `mesh` at every budget and measures each level against
/// `mesh`. `on_point` hears of each measured level as soon as it is made (for progress).
///
/// Fails on a mesh that cannot be measured (empty, no area, broken indices or coordinates), a
/// mesh the voxel methods cannot sample, or a run that fails; the error names the method and
/// parameter.
pub fn evaluate(
    mesh: &TriangleMesh,
    options: &EvaluateOptions,
    mut on_point: impl FnMut(Method, &CurvePoint),
) -> Result<Evaluation, EvaluateError> {
    let start = Instant::now();
    let health = welded_mesh_report(mesh)?;
    if health.area <= 0.0 {
        return Err(EvaluateError::Input(MetricsError::NoArea {
            triangles: mesh.triangles.len(),
        }));
    }
    if options.methods.is_empty() {
        return Err(EvaluateError::NoMethods);
    }
    let budgets = options.budgets.resolve(mesh.triangles.len());
    if budgets.is_empty() {
        return Err(EvaluateError::NoBudgets {
            triangles: mesh.triangles.len(),
        });
    }
    let input = InputSummary {
        vertices: mesh.positions.len(),
        triangles: mesh.triangles.len(),
        area: health.area,
        diagonal: health.diagonal,
        components: health.topology.components,
        boundary_loops: health.topology.boundary_loops,
        genus: health.topology.genus,
        closed_manifold: health.closed_manifold,
    };
    let solid = if options.methods.iter().any(|m| m.is_voxel()) {
        Some(MeshSolid::new(mesh).map_err(EvaluateError::Solid)?)
    } else {
        None
    };
    let silhouettes = if options.images.views > 0 {
        Some(SilhouetteReference::new(mesh, &options.images).map_err(EvaluateError::InputRender)?)
    } else {
        None
    };
    let mut omitted = Vec::new();
    let mut envelope_notes = Vec::new();
    let envelope_input = if options.methods.contains(&Method::Envelope) {
        match envelope_input(mesh) {
            Ok((input, notes)) => {
                envelope_notes = notes;
                Some(input)
            }
            Err(reason) => {
                omitted.push(Omission {
                    what: "simplification envelopes (Varshney et al. 1995)".into(),
                    reason,
                });
                None
            }
        }
    } else {
        None
    };
    let mut curves = Vec::new();
    for &method in &options.methods {
        if method == Method::Envelope && envelope_input.is_none() {
            continue;
        }
        let runner = Runner {
            method,
            mesh,
            envelope_input: envelope_input.as_deref(),
            solid: solid.as_ref(),
            silhouettes: silhouettes.as_ref(),
            options,
        };
        let mut curve = method_curve(&runner, &budgets, &input, options, &mut on_point)?;
        if method == Method::Envelope {
            curve.notes = std::mem::take(&mut envelope_notes);
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

/// Why one run of a method failed.
#[derive(Debug, thiserror::Error)]
pub enum RunFailure {
    #[error(transparent)]
    Voxel(#[from] LodError),
    #[error(transparent)]
    Clustering(#[from] ClusteringError),
    #[error(transparent)]
    Envelope(#[from] EnvelopeError),
}

/// The mesh the envelope simplifies: the input, or the input cut into a consistently oriented
/// manifold (with a note of what changed); or why neither can be had.
fn envelope_input(
    mesh: &TriangleMesh,
) -> Result<(std::borrow::Cow<'_, TriangleMesh>, Vec<String>), String> {
    let problems = match check_manifold(mesh) {
        Ok(()) => return Ok((std::borrow::Cow::Borrowed(mesh), Vec::new())),
        Err(e) => e.to_string(),
    };
    let (repaired, repair) = repair_for_envelope(mesh);
    match check_manifold(&repaired) {
        Ok(()) => Ok((
            std::borrow::Cow::Owned(repaired),
            vec![format!(
                "The input is not a consistently oriented manifold ({problems}); the envelope \
                 simplified a repaired copy ({repair}) and was measured against the input."
            )],
        )),
        Err(e) => Err(format!(
            "the input is not a manifold even after repair: {e}"
        )),
    }
}

/// One run of a method.
struct Trial {
    /// The parameter's step on its grid, and its value.
    step: i64,
    parameter: f64,
    /// Triangles, and for clustering the dangling edges and isolated points.
    level: PolyMesh,
    seconds: f64,
}

impl Trial {
    fn triangles(&self) -> usize {
        self.level.mesh.triangles.len()
    }
}

/// Runs one method at a given parameter.
struct Runner<'a> {
    method: Method,
    /// The input: what the levels are measured against and clustering simplifies.
    mesh: &'a TriangleMesh,
    /// What the envelope simplifies (see [`envelope_input`]).
    envelope_input: Option<&'a TriangleMesh>,
    solid: Option<&'a MeshSolid>,
    silhouettes: Option<&'a SilhouetteReference>,
    options: &'a EvaluateOptions,
}

impl Runner<'_> {
    fn run(&self, step: i64, parameter: f64) -> Result<Trial, EvaluateError> {
        let start = Instant::now();
        let method = self.method;
        let level = self
            .simplify(parameter)
            .map_err(|source| EvaluateError::Run {
                method,
                parameter: method.parameter_name(),
                value: parameter,
                source,
            })?;
        Ok(Trial {
            step,
            parameter,
            level,
            seconds: start.elapsed().as_secs_f64(),
        })
    }
}

impl Runner<'_> {
    /// The method's level at `parameter`.
    fn simplify(&self, parameter: f64) -> Result<PolyMesh, RunFailure> {
        Ok(match self.method {
            method @ (Method::VoxelHypercone | Method::VoxelGaussian | Method::VoxelEnvelope) => {
                let filter = if method == Method::VoxelGaussian {
                    Filter::GAUSSIAN
                } else {
                    Filter::Hypercone
                };
                let mut pyramid =
                    PyramidOptions::with_resolutions(vec![parameter as usize], filter);
                pyramid.lines_per_radius = self.options.lines_per_radius;
                let lod = LodOptions {
                    pyramid,
                    iso: 0.5,
                    normals: false,
                    ..LodOptions::default()
                };
                let solid = self.solid.expect("the solid is built for voxel methods");
                let source = LodSource::Solid(solid);
                let plans = plan(&source, &lod)?;
                let level = build_level(&source, &plans[0], &lod)?.mesh;
                if method != Method::VoxelEnvelope || level.triangles.is_empty() {
                    return Ok(PolyMesh::from(level));
                }
                let epsilon = Epsilon::Absolute(plans[0].voxel_size);
                let options = EnvelopeOptions::tight().with_measure_samples(0);
                PolyMesh::from(simplify_envelope(&level, epsilon, &options)?.mesh)
            }
            Method::RossignacBorrel => {
                let options = ClusterOptions::smoothing(parameter as u32);
                first_level(rossignac_borrel(self.mesh, &options)?)
            }
            Method::LowTan => {
                let options = FloatingCellOptions::single(parameter as u32).with_thick_edges(false);
                first_level(low_tan(self.mesh, &options)?)
            }
            Method::Envelope => {
                let input = self
                    .envelope_input
                    .expect("the envelope input is prepared for the envelope method");
                let options = EnvelopeOptions::tight().with_measure_samples(0);
                PolyMesh::from(
                    simplify_envelope(input, Epsilon::percent(parameter), &options)?.mesh,
                )
            }
        })
    }
}

/// The one level a single-level clustering run made.
fn first_level(levels: Vec<voxlod::clustering::Level>) -> PolyMesh {
    levels.into_iter().next().expect("one level asked for").mesh
}

/// The range of a method's parameter and how triangle counts grow with it.
#[derive(Clone, Copy, Debug)]
struct Control {
    lowest: f64,
    highest: f64,
    /// The first parameter tried when nothing is known.
    first: f64,
    /// Triangle counts grow about as `parameter^exponent` (negative: they fall as it grows).
    exponent: f64,
    grid: Grid,
}

/// The values a parameter takes, numbered: the search steps from one to the next.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Grid {
    /// Whole numbers: step `k` is the value `k`.
    Integers,
    /// Step `k` is `ratio^k`, for continuous parameters.
    Geometric { ratio: f64 },
}

impl Control {
    /// The step nearest `x`, within the range.
    fn step_of(&self, x: f64) -> i64 {
        let x = x.clamp(self.lowest, self.highest);
        match self.grid {
            Grid::Integers => x.round() as i64,
            Grid::Geometric { ratio } => (x.ln() / ratio.ln()).round() as i64,
        }
    }

    fn value_of(&self, step: i64) -> f64 {
        match self.grid {
            Grid::Integers => step as f64,
            Grid::Geometric { ratio } => ratio.powi(step as i32),
        }
    }

    fn contains(&self, step: i64) -> bool {
        let x = self.value_of(step);
        x >= self.lowest * (1.0 - 1e-12) && x <= self.highest * (1.0 + 1e-12)
    }
}

/// The trials of one method so far.
struct Trials {
    list: Vec<Trial>,
}

impl Trials {
    fn get(&self, step: i64) -> Option<&Trial> {
        self.list.iter().find(|t| t.step == step)
    }

    /// The parameter step to try next for `budget`, or `None` when no untried step can do
    /// better than the trials so far.
    fn next_guess(&self, budget: usize, control: &Control) -> Option<i64> {
        let target = (budget as f64).ln();
        let count = |t: &Trial| t.triangles();
        // The nearest trials with fewer triangles than the budget and with at least as many.
        let below = self
            .list
            .iter()
            .filter(|t| count(t) < budget)
            .max_by_key(|t| (count(t), std::cmp::Reverse(t.step)));
        let above = self
            .list
            .iter()
            .filter(|t| count(t) >= budget)
            .min_by_key(|t| (count(t), t.step));
        let guess = match (below, above) {
            (None, None) => control.first,
            (Some(b), Some(a)) if count(b) > 0 => {
                let (xb, xa) = (b.parameter.ln(), a.parameter.ln());
                let (tb, ta) = ((count(b) as f64).ln(), (count(a) as f64).ln());
                if ta > tb {
                    (xb + (target - tb) * (xa - xb) / (ta - tb)).exp()
                } else {
                    (b.parameter * a.parameter).sqrt()
                }
            }
            (Some(b), Some(a)) => (b.parameter + a.parameter) / 2.0,
            (Some(near), None) | (None, Some(near)) => {
                if count(near) == 0 {
                    near.parameter * 2f64.powf(control.exponent.signum())
                } else {
                    let ratio = budget as f64 / count(near) as f64;
                    near.parameter * ratio.powf(1.0 / control.exponent)
                }
            }
        };
        let mut guess = control.step_of(guess);
        if let Some(tried) = self.get(guess) {
            // Move one step from the tried parameter towards the budget.
            let towards_more = count(tried) < budget;
            guess += if towards_more == (control.exponent > 0.0) {
                1
            } else {
                -1
            };
            // Never cross a tried parameter on the far side of the budget.
            let crosses = match (below, above) {
                (Some(b), Some(a)) => guess <= b.step.min(a.step) || guess >= b.step.max(a.step),
                _ => false,
            };
            if !control.contains(guess) || self.get(guess).is_some() || crosses {
                return None;
            }
        }
        Some(guess)
    }

    /// The trial nearest `budget` in ratio (ties: fewer triangles), among those with triangles.
    fn nearest(&self, budget: usize) -> Option<&Trial> {
        let miss = |t: &Trial| ((t.triangles() as f64) / budget as f64).ln().abs();
        self.list
            .iter()
            .filter(|t| t.triangles() > 0)
            .min_by(|a, b| {
                miss(a)
                    .total_cmp(&miss(b))
                    .then(a.triangles().cmp(&b.triangles()))
            })
    }
}

fn within(triangles: usize, budget: usize, tolerance: f64) -> bool {
    (triangles as f64 / budget as f64 - 1.0).abs() <= tolerance
}

/// Searches each budget, then measures the level kept for it.
fn method_curve(
    runner: &Runner,
    budgets: &[usize],
    input: &InputSummary,
    options: &EvaluateOptions,
    on_point: &mut impl FnMut(Method, &CurvePoint),
) -> Result<Curve, EvaluateError> {
    let start = Instant::now();
    let method = runner.method;
    let control = method.control(options);
    let mut trials = Trials { list: Vec::new() };
    let mut points: Vec<CurvePoint> = Vec::new();
    let mut misses = Vec::new();
    for &budget in budgets {
        for _ in 0..options.max_trials.max(1) {
            if trials
                .nearest(budget)
                .is_some_and(|t| within(t.triangles(), budget, options.tolerance))
            {
                break;
            }
            let Some(step) = trials.next_guess(budget, &control) else {
                break;
            };
            trials.list.push(runner.run(step, control.value_of(step))?);
        }
        let Some(best) = trials.nearest(budget) else {
            misses.push(format!(
                "budget {budget}: no {} gave any triangles",
                method.parameter_name()
            ));
            continue;
        };
        let ratio = best.triangles() as f64 / budget as f64;
        if ratio.ln().abs() > options.max_miss_factor.ln() {
            misses.push(format!(
                "budget {budget}: out of reach; the nearest level has {} triangles ({} {})",
                best.triangles(),
                method.parameter_name(),
                parameter_text(best.parameter)
            ));
            continue;
        }
        if let Some(same) = points.iter().find(|p| p.parameter == best.parameter) {
            misses.push(format!(
                "budget {budget}: the nearest level ({} {}, {} triangles) is the one kept for \
                 budget {}",
                method.parameter_name(),
                parameter_text(best.parameter),
                best.triangles(),
                same.budget
            ));
            continue;
        }
        match measure(runner, best, budget, input, options) {
            Ok(point) => {
                on_point(method, &point);
                points.push(point);
            }
            // A level whose triangles all collapsed to zero area has nothing to sample.
            Err(EvaluateError::Distance {
                source:
                    MetricsError::InMesh {
                        which: "second",
                        source,
                    },
                ..
            }) if matches!(*source, MetricsError::NoArea { .. }) => misses.push(format!(
                "budget {budget}: the nearest level ({} {}) has {} triangles but no area",
                method.parameter_name(),
                parameter_text(best.parameter),
                best.triangles()
            )),
            Err(e) => return Err(e),
        }
    }
    Ok(Curve {
        method,
        parameter: method.parameter_name(),
        points,
        misses,
        trials: trials.list.len(),
        seconds: start.elapsed().as_secs_f64(),
        notes: Vec::new(),
    })
}

/// Distances and topology of a kept level.
fn measure(
    runner: &Runner,
    trial: &Trial,
    budget: usize,
    input: &InputSummary,
    options: &EvaluateOptions,
) -> Result<CurvePoint, EvaluateError> {
    let start = Instant::now();
    let method = runner.method;
    // Vertices that only dangling edges or points use do not belong to the surface.
    let mut surface = trial.level.mesh.clone();
    surface.remove_unreferenced_vertices();
    let distance = mesh_distance(runner.mesh, &surface, &options.distance).map_err(|source| {
        EvaluateError::Distance {
            method,
            parameter: method.parameter_name(),
            value: trial.parameter,
            source,
        }
    })?;
    let distance_seconds = start.elapsed().as_secs_f64();
    let start = Instant::now();
    let image_difference =
        match runner.silhouettes {
            Some(reference) => Some(reference.difference(&trial.level).map_err(|source| {
                EvaluateError::Render {
                    method,
                    parameter: method.parameter_name(),
                    value: trial.parameter,
                    source,
                }
            })?),
            None => None,
        };
    let image_seconds = start.elapsed().as_secs_f64();
    let topology = mesh_topology(&surface);
    let fraction = |x: f64| x / input.diagonal;
    Ok(CurvePoint {
        budget,
        parameter: trial.parameter,
        triangles: trial.triangles(),
        vertices: trial.level.mesh.positions.len(),
        dangling_edges: trial.level.lines.len(),
        isolated_points: trial.level.points.len(),
        hausdorff: distance.hausdorff,
        mean: distance.mean,
        rms: distance.rms,
        hausdorff_fraction: fraction(distance.hausdorff),
        mean_fraction: fraction(distance.mean),
        rms_fraction: fraction(distance.rms),
        input_to_level_fraction: fraction(distance.first_to_second.max),
        level_to_input_fraction: fraction(distance.second_to_first.max),
        components: topology.components,
        boundary_loops: topology.boundary_loops,
        non_manifold_edges: topology.non_manifold_edges,
        genus: topology.genus,
        closed_manifold: topology.is_closed_manifold() && topology.is_consistently_oriented(),
        image_difference,
        simplify_seconds: trial.seconds,
        distance_seconds,
        image_seconds,
        level: trial.level.clone(),
    })
}
