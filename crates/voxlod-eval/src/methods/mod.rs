//! The simplification methods the evaluation compares, each behind one trait, [`Simplifier`]:
//! its name in reports, the name and search space of the one parameter that controls it, and a
//! run at a given value of that parameter. [`Method`] is the handle that options, command lines
//! and reports use; [`Method::ALL`] lists the methods of the project.
//!
//! | method | file | parameter |
//! |---|---|---|
//! | voxel pipeline, hyper-cone filter (He et al. 1995, §2, equation 3) | `voxel_filter.rs` | resolution |
//! | voxel pipeline, truncated Gaussian (§2) | `voxel_filter.rs` | resolution |
//! | vertex clustering (Rossignac and Borrel 1993) | `rossignac_borrel.rs` | cells |
//! | floating-cell clustering (Low and Tan 1997) | `low_tan.rs` | cells |
//! | simplification envelopes (Varshney et al.) | `envelope.rs` | ε in % of the diagonal |
//! | voxel pipeline, then envelopes within one voxel (§5) | `voxel_envelope.rs` | resolution |
//! | voxel resolution for the budget, then a geometric stage (§5) | `budget_pipeline.rs` | target triangles |
//! | meshoptimizer `simplify`, quadric collapse (reference) | `meshopt_simplify.rs` | target triangles |
//! | meshoptimizer `simplifySloppy`, clustering (reference) | `meshopt_sloppy.rs` | target triangles |
//!
//! **Adding a method**: a file here with a unit struct that implements [`Simplifier`], its `mod`
//! line below (and a `pub use` line if callers should name the struct), and one line in
//! [`Method::ALL`]. The budget search, the measuring, the command line's `--methods`, the reports
//! and the chart take it from there. A method of your own can also be evaluated without touching
//! this crate: [`Method::new`] wraps any `&'static dyn Simplifier`.
//!
//! What the methods need made from the input once ([`Needs`]: the input as a solid, or as a
//! consistently oriented manifold) is made by [`MethodInput::prepare`] and shared by all of
//! them. Cost: that of the methods; see each file.

mod budget_pipeline;
mod clustering;
mod envelope;
mod input;
mod low_tan;
mod meshopt_simplify;
mod meshopt_sloppy;
mod rossignac_borrel;
mod voxel;
mod voxel_envelope;
mod voxel_filter;

pub use budget_pipeline::BudgetPipeline;
pub use envelope::Envelope;
pub use input::{MethodInput, Needs};
pub use low_tan::LowTan;
pub use meshopt_simplify::MeshoptSimplify;
pub use meshopt_sloppy::MeshoptSloppy;
pub use rossignac_borrel::RossignacBorrel;
pub use voxel_envelope::VoxelEnvelope;
pub use voxel_filter::{VoxelFilter, VOXEL_GAUSSIAN, VOXEL_HYPERCONE};

use serde::Serialize;
use voxlod::clustering::ClusteringError;
use voxlod::core::PolyMesh;
use voxlod::envelope::{EnvelopeError, ManifoldProblems};
use voxlod::lod::LodError;
use voxlod_quadric::QuadricError;

/// A simplification method controlled by one number: the evaluation searches that number for
/// each triangle budget ([`crate::evaluate`]) and measures what [`Simplifier::run`] makes.
///
/// # Example
///
/// A method of one's own, evaluated beside Rossignac–Borrel: keep every `n`-th triangle of the
/// input (triangle counts fall as `1/n`).
///
/// ```
/// use voxlod::core::{PolyMesh, TriangleMesh};
/// use voxlod_eval::evaluate::{evaluate, Budgets, EvaluateOptions, ImageOptions, Method};
/// use voxlod_eval::methods::{
///     MethodInput, ParameterGrid, RunFailure, SearchLimits, SearchSpace, Simplifier,
/// };
/// use voxlod::metrics::DistanceOptions;
///
/// struct EveryNth;
///
/// impl Simplifier for EveryNth {
///     fn name(&self) -> &'static str { "every-nth" }
///     fn description(&self) -> &'static str { "every n-th triangle of the input" }
///     fn parameter_name(&self) -> &'static str { "n" }
///     fn search_space(&self, _: &SearchLimits) -> SearchSpace {
///         SearchSpace { lowest: 1.0, highest: 1000.0, first: 4.0, first_at_budget: false,
///                       exponent: -1.0, grid: ParameterGrid::Integers }
///     }
///     fn run(&self, input: &MethodInput, n: f64) -> Result<PolyMesh, RunFailure> {
///         let mesh = input.mesh();
///         let kept = mesh.triangles.iter().step_by(n as usize).copied().collect();
///         Ok(PolyMesh::from(TriangleMesh::new(mesh.positions.clone(), kept)))
///     }
/// }
///
/// # let mesh = voxlod_testkit::shapes::torus(32, 16, 2.0, 0.7);
/// // `mesh`: a torus of 1024 triangles (or any mesh, say from `voxlod::io::read_mesh`).
/// let options = EvaluateOptions {
///     methods: vec![Method::new(&EveryNth), "rossignac-borrel".parse()?],
///     budgets: Budgets::Explicit(vec![256]),
///     distance: DistanceOptions::for_samples(2_000),
///     images: ImageOptions::off(),
///     ..EvaluateOptions::quick()
/// };
/// let evaluation = evaluate(&mesh, &options, |_, _| {})?;
/// let mine = &evaluation.curves[0];
/// assert_eq!(mine.method.name(), "every-nth");
/// assert_eq!(mine.points[0].parameter, 4.0); // 1024 / 4: the budget exactly
/// assert_eq!(mine.points[0].triangles, 256);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub trait Simplifier: Sync {
    /// The name on the command line and in reports (`voxel-hypercone`, `envelope`, …).
    fn name(&self) -> &'static str;

    /// What the method is and where it comes from, in words, for reports (an evaluation that
    /// leaves the method out says so with this).
    fn description(&self) -> &'static str;

    /// What the parameter is (`resolution`, `cells`, `epsilon-percent`): a report's column.
    fn parameter_name(&self) -> &'static str;

    /// The values the budget search may try within `limits`, and how triangle counts follow
    /// them.
    fn search_space(&self, limits: &SearchLimits) -> SearchSpace;

    /// What the method needs made from the input before its first run (nothing by default).
    fn needs(&self) -> Needs {
        Needs::default()
    }

    /// The method's level at `parameter` (a value of its [`Simplifier::search_space`]): its
    /// triangles and, for clustering, the dangling edges and isolated points it left.
    fn run(&self, input: &MethodInput, parameter: f64) -> Result<PolyMesh, RunFailure>;
}

/// The bounds an evaluation sets on every method's search (from its options,
/// `EvaluateOptions::search_limits`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SearchLimits {
    /// Highest voxel resolution tried.
    pub max_resolution: usize,
    /// Most clustering cells tried along the longest side.
    pub max_cells: u32,
}

/// The range of a method's parameter, the values the search steps through, and how triangle
/// counts grow with it. The search interpolates in log–log space between trials (see
/// [`crate::evaluate`]), so only the sign and rough size of [`SearchSpace::exponent`] matter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SearchSpace {
    /// The smallest value tried.
    pub lowest: f64,
    /// The largest value tried.
    pub highest: f64,
    /// The first value tried when nothing is known yet.
    pub first: f64,
    /// The parameter is the triangle count asked for (meshoptimizer's target, the budget
    /// pipeline's budget): a budget's search tries the budget itself first, so that its level
    /// is the one the method gives for that budget when it lands within the tolerance.
    pub first_at_budget: bool,
    /// Triangle counts grow about as `parameter^exponent` (negative: they fall as it grows).
    pub exponent: f64,
    /// Whole numbers or a geometric grid.
    pub grid: ParameterGrid,
}

/// The values a parameter takes, numbered: the search steps from one to the next.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ParameterGrid {
    /// Whole numbers (resolutions, cell counts): step `k` is the value `k`.
    Integers,
    /// Continuous parameters, log-spaced: step `k` is `ratio^k`.
    Geometric {
        /// The ratio of neighbouring values, above 1.
        ratio: f64,
    },
}

impl SearchSpace {
    /// The step nearest `x`, within the range.
    pub fn step_of(&self, x: f64) -> i64 {
        let x = x.clamp(self.lowest, self.highest);
        match self.grid {
            ParameterGrid::Integers => x.round() as i64,
            ParameterGrid::Geometric { ratio } => (x.ln() / ratio.ln()).round() as i64,
        }
    }

    /// The parameter's value at `step`.
    pub fn value_of(&self, step: i64) -> f64 {
        match self.grid {
            ParameterGrid::Integers => step as f64,
            ParameterGrid::Geometric { ratio } => ratio.powi(step as i32),
        }
    }

    /// Whether `step`'s value lies in the range.
    pub fn contains(&self, step: i64) -> bool {
        let x = self.value_of(step);
        x >= self.lowest * (1.0 - 1e-12) && x <= self.highest * (1.0 + 1e-12)
    }
}

/// The search space of a method whose parameter is the triangle count it is asked for: whole
/// numbers from 1 to 100 million, counts growing as the parameter, starting at 1 000.
fn target_count_space() -> SearchSpace {
    SearchSpace {
        lowest: 1.0,
        highest: 1e8,
        first: 1000.0,
        first_at_budget: true,
        exponent: 1.0,
        grid: ParameterGrid::Integers,
    }
}

/// Why one run of a method failed.
#[derive(Debug, thiserror::Error)]
pub enum RunFailure {
    /// The voxel pipeline failed (sampling or contouring).
    #[error(transparent)]
    Voxel(#[from] LodError),
    /// A clustering method failed.
    #[error(transparent)]
    Clustering(#[from] ClusteringError),
    /// Simplification envelopes failed.
    #[error(transparent)]
    Envelope(#[from] EnvelopeError),
    /// The budget pipeline failed (the facade's error).
    #[error(transparent)]
    Pipeline(voxlod::Error),
    /// meshoptimizer (or the quadric stage around it) refused the input.
    #[error(transparent)]
    Quadric(#[from] QuadricError),
    /// The method needs something of the input that [`MethodInput::prepare`] was not asked for.
    #[error("the input was not prepared {0} (see Simplifier::needs)")]
    NotPrepared(&'static str),
    /// The method needs a manifold input and the input could not be made one, even repaired.
    #[error("the input is not a manifold even after repair: {}", EnvelopeError::NotManifold(.0.clone()))]
    NotManifold(ManifoldProblems),
}

/// A simplification method, as options, command lines and reports name it: a handle on a
/// [`Simplifier`]. Two handles are equal when their names are; reports write the name.
#[derive(Clone, Copy)]
pub struct Method(&'static dyn Simplifier);

impl Method {
    /// Every method of the project, in the order reports list them (and that gives each its
    /// colour in charts).
    pub const ALL: &'static [Method] = &[
        Method(&VOXEL_HYPERCONE),
        Method(&VOXEL_GAUSSIAN),
        Method(&RossignacBorrel),
        Method(&LowTan),
        Method(&Envelope),
        Method(&VoxelEnvelope),
        Method(&BudgetPipeline),
        Method(&MeshoptSimplify),
        Method(&MeshoptSloppy),
    ];

    /// A handle on any simplifier, one of the list or one of the caller's own.
    pub const fn new(simplifier: &'static dyn Simplifier) -> Method {
        Method(simplifier)
    }

    /// The method itself.
    pub fn simplifier(self) -> &'static dyn Simplifier {
        self.0
    }

    /// The name used on the command line and in reports.
    pub fn name(self) -> &'static str {
        self.0.name()
    }

    /// What the method's parameter is.
    pub fn parameter_name(self) -> &'static str {
        self.0.parameter_name()
    }

    /// The method's place in [`Method::ALL`]; `None` for a method of the caller's own.
    pub fn index(self) -> Option<usize> {
        Method::ALL.iter().position(|&m| m == self)
    }
}

impl PartialEq for Method {
    fn eq(&self, other: &Method) -> bool {
        self.name() == other.name()
    }
}

impl Eq for Method {}

impl std::hash::Hash for Method {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        self.name().hash(state)
    }
}

impl std::fmt::Debug for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_tuple("Method").field(&self.name()).finish()
    }
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl Serialize for Method {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(self.name())
    }
}

impl std::str::FromStr for Method {
    type Err = String;

    /// One of [`Method::ALL`] by its name.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Method::ALL
            .iter()
            .copied()
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
