//! Levels of detail by triangle budget that hold on any input: for each budget, a portfolio of
//! candidate levels made by different methods, and the one measured closest to the input that
//! keeps every promise of the chain.
//!
//! He, Hong, Kaufman, Varshney and Wang (1995, §5) propose the voxel method as a first step
//! that removes what a budget cannot afford (small parts, thin walls, handles), followed by a
//! geometric simplification that spends the triangles. Where the budget does afford the
//! input's topology, the input's own quadric collapse is usually closer than any filtered
//! level; where the input has no inside (an open sheet), the solid's filter erases it. So no
//! single method answers every budget of every input. This crate makes several and measures
//! them (our addition to the paper):
//!
//! - **the input's collapse** ([`Method::Collapse`]): meshoptimizer `simplify` as gltfpack runs
//!   it, with its checked form ([`Method::CollapseKept`]) where it broke a promise (an open
//!   input's holes may close in it; where the plain one only crossed, the plain one made in
//!   two steps as well, [`Method::CollapseInTwoSteps`]), and `simplifySloppy` ([`Method::Sloppy`]),
//!   which competes where its result keeps the promises;
//! - **voxel levels** ([`Method::Voxel`], module `voxel`): the input's solid filtered (§2–3),
//!   contoured (§4) at three isodensities and collapsed to the budget (§5), at small budgets
//!   the finest grid's levels also collapsed in two stages with a fit to the input between,
//!   the closest fitted back to the input's surface (crate `voxlod-fit`); for a surface that
//!   is not closed, a **shell** around it ([`Method::Shell`], module `shell`), which follows
//!   sheets the solid's filter would erase;
//! - **a plate's mid-surface** ([`Method::Plate`], module [`plate`]): where every part of a
//!   closed input is a plate far thinner than its size, one side moved to the mid-surface,
//!   collapsed as a sheet (its border free, and with vertices locked along it at about the
//!   sheet's edge length) and thickened again: its two sides cannot cross, where any collapse
//!   of the closed plate passes them through each other and no voxel grid sees an inside. One
//!   that keeps every promise close enough stands in for the plain collapse: no voxel search
//!   and no checked collapse (which stalls on a plate) for that budget;
//! - **the level above** ([`Method::Above`]): the next larger budget's level collapsed further,
//!   and beside it that budget's runner-up, the closest candidate of the other lineage (a voxel
//!   level where the level is a collapse of the input, or the reverse: [`select::Chosen`]), so
//!   that a lineage that lost at a large budget but collapses closer is there at the small ones;
//! - **the level below** ([`Method::Below`], module `below`): where the choice left a budget's
//!   level farther from the input than the next smaller budget's, that level with its edges
//!   split to the budget and fitted replaces it, where it keeps every promise and is closer;
//! - **parts** (module `restore`): where a candidate lost small parts of the input, a twin with
//!   them back beside it as tetrahedra; for a many-part input whose parts the budget cannot all
//!   carry, the input's collapse with its small parts stood in for by tetrahedra.
//!
//! Every candidate is cut into an oriented manifold where a collapse pinched it
//! ([`voxlod_core::manifold`]), so that a collapse that touched two sheets together can still
//! keep the promises.
//!
//! **Promises** ([`Promise`]): every level is a manifold, consistently oriented, closed where the
//! input is, with no more handles than the level above it (the genus never rises along the
//! chain), no crossing triangles, and its budget's triangles within 10 %. The choice
//! ([`select`]) keeps the candidate with the smallest measured two-sided Hausdorff distance
//! among those that keep them; its mean distance must also stay within 1.25 times the input's
//! collapse's. Once the chain is chosen, a level that is a collapse of the input, with at most
//! a tenth of its triangles, is fitted to the input (crate `voxlod-fit`), where the fit keeps
//! every promise and measures no farther. Where a promise ruled out a closer candidate, the
//! report says which and what it cost ([`RuledOut`]). A budget always gets a level: where no candidate keeps every promise,
//! the one giving up the least is kept, with a warning.
//!
//! **Fast by design.** Every budget's candidates are made at once, on all cores; a budget whose
//! plain collapse keeps every promise and is closer than half the voxel it affords
//! ([`VOXEL_WORTH`]; a quarter, [`VOXEL_WORTH_SMALL`], at budgets up to [`SMALL_BUDGET`],
//! where a fitted voxel level often comes closer) is not searched with voxels at all;
//! candidates are ranked by a quick measurement that stops as soon as one is clearly farther,
//! and only the closest few are measured carefully (near ties again with twice the samples); a budget's checked collapse
//! starts from a larger budget's collapse where one kept the promises; a level is fitted to the
//! input while the next budget is chosen (module `collapse_fits`). Large inputs skip what
//! costs seconds and rarely wins there: the checked collapse above [`KEPT_AT_MOST`] triangles
//! where the plain one broke the topology, or only crossed below a larger budget's collapse
//! (and else with [`KEPT_ATTEMPTS_LARGE`] passes), voxel levels above [`LARGE_VOXEL`]
//! triangles where the input's collapse only came out cut open.
//!
//! ```
//! use voxlod_budget::{levels, PortfolioOptions, Method};
//!
//! let torus = voxlod_testkit::shapes::torus(96, 48, 1.0, 0.3);
//! let run = levels(&torus, &PortfolioOptions::for_triangles(&[2000, 300]))?;
//! for level in &run.levels {
//!     let r = &level.report;
//!     assert!((r.triangles as f64 - r.budget as f64).abs() <= 0.1 * r.budget as f64);
//!     assert_eq!((r.genus, r.boundary_loops), (Some(1), 0));
//! }
//! // A smooth torus at a budget it affords: its own collapse is the closest.
//! assert_eq!(run.levels[0].report.method, Method::Collapse);
//! # Ok::<(), voxlod_budget::BudgetError>(())
//! ```

#![warn(missing_docs)]

mod below;
mod candidate;
mod chain;
mod collapse;
mod collapse_fits;
mod enclosed;
mod error;
mod grids;
mod input;
pub mod looks;
mod measure;
mod open_parts;
mod options;
mod outline;
pub mod plate;
mod promises;
mod report;
mod restore;
pub mod select;
pub mod separate;
mod shell;
mod shell_density;
mod visible;
mod voxel;

pub use candidate::{Fill, Method};
pub use chain::{
    levels_with, ProgressFn, LARGE_VOXEL, SMALL_BUDGET, VOXEL_WORTH, VOXEL_WORTH_SMALL,
};
pub use collapse::{KEPT_ATTEMPTS, KEPT_ATTEMPTS_LARGE, KEPT_AT_MOST};
pub use error::BudgetError;
pub use input::Preparation;
pub use looks::{asset_levels, AssetBudgeted, AssetLevel, Looks};
pub use measure::Distance;
pub use options::{PortfolioOptions, BUDGET_TOLERANCE};
pub use promises::{within_budget, Promise, MEAN_SLACK};
pub use report::{BudgetLevel, CandidateReport, InputReport, Outline, RuledOut};
pub use voxlod_fit::FitOptions;

use voxlod_core::{Topology, TriangleMesh};

/// One budget's level: the mesh and its report.
#[derive(Clone, Debug)]
pub struct Level {
    /// The level.
    pub mesh: TriangleMesh,
    /// Its topology.
    pub topology: Topology,
    /// What made it and how close it is.
    pub report: BudgetLevel,
}

/// A run of budgets.
#[derive(Clone, Debug)]
pub struct Budgeted {
    /// One level per budget, in the order the budgets were given (a budget given twice gets
    /// the same level twice).
    pub levels: Vec<Level>,
    /// The input as the run saw it.
    pub input: InputReport,
    /// Warnings for the user: what a level gave up, what the input needed.
    pub warnings: Vec<String>,
    /// Wall seconds of each phase.
    pub timings: Timings,
    /// Wall seconds of the whole run.
    pub seconds: f64,
}

/// Wall seconds of a run's phases.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Timings {
    /// Preparing the input.
    pub prepare: f64,
    /// The input's side of the measure beside its collapses for every budget, and deciding
    /// where voxels can do better.
    pub collapses: f64,
    /// The voxel and shell candidates.
    pub voxels: f64,
    /// Measuring, fitting and choosing, from the largest budget down.
    pub choice: f64,
}

/// One level per budget of `options.triangles` from `mesh` (crate docs). Fails on a mesh
/// without triangles or with bad coordinates, on budgets under 4, on work beyond the memory
/// budget, and where no method gave a level at all.
pub fn levels(mesh: &TriangleMesh, options: &PortfolioOptions) -> Result<Budgeted, BudgetError> {
    levels_with(mesh, options, &|_, _| true)
}
