//! The terms of the budget search ([`crate::budget`]), apart from it so that the options
//! ([`crate::LodOptions`]) can name them: what a run is asked ([`ErrorTarget`],
//! [`Then`], the budgets' check) and what it reports per level ([`Stage`], [`BudgetLevel`]).

use std::fmt;
use std::str::FromStr;

use serde::Serialize;

use crate::error::{InvalidOption, PyramidError};

/// A budget's level may miss it by this fraction, counted in triangles as the portfolio counts
/// it ([`voxlod_budget::within_budget`]).
pub use voxlod_budget::BUDGET_TOLERANCE;

/// An error target: a distance in the input's units, or a fraction of its box's diagonal.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(rename_all = "kebab-case", tag = "unit", content = "value")]
pub enum ErrorTarget {
    /// A distance.
    Distance(f64),
    /// A fraction of the bounding-box diagonal (`0.005` is 0.5 %).
    Fraction(f64),
}

impl ErrorTarget {
    /// The target in mesh units, for an object whose box has diagonal `diagonal`.
    pub fn distance(self, diagonal: f64) -> f64 {
        match self {
            ErrorTarget::Distance(d) => d,
            ErrorTarget::Fraction(f) => f * diagonal,
        }
    }
}

impl FromStr for ErrorTarget {
    type Err = String;

    /// `0.5` (a distance) or `0.5%` (of the diagonal); positive and finite.
    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let t = text.trim();
        let (number, percent) = match t.strip_suffix('%') {
            Some(n) => (n.trim(), true),
            None => (t, false),
        };
        match number.parse::<f64>() {
            Ok(x) if x > 0.0 && x.is_finite() => Ok(if percent {
                ErrorTarget::Fraction(x / 100.0)
            } else {
                ErrorTarget::Distance(x)
            }),
            _ => Err(format!(
                "'{text}': the error must be a positive distance (0.5) or percentage of the \
                 bounding-box diagonal (0.5%)"
            )),
        }
    }
}

impl fmt::Display for ErrorTarget {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ErrorTarget::Distance(d) => write!(f, "{d}"),
            ErrorTarget::Fraction(x) => write!(f, "{}%", x * 100.0),
        }
    }
}

/// The geometric stage after the voxel stage.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Then {
    /// The quadric stage, and the envelopes where it stalls above the budget (module docs,
    /// step 3), keeping whichever is measured closer to the input.
    #[default]
    Auto,
    /// Simplification envelopes (tight preset), ε searched for the budget.
    Envelope,
    /// meshoptimizer's quadric collapse, topology kept.
    Quadric,
    /// None: the marching-cubes level nearest the budget.
    None,
}

impl FromStr for Then {
    type Err = String;

    fn from_str(text: &str) -> Result<Self, Self::Err> {
        match text.trim() {
            "auto" => Ok(Then::Auto),
            "envelope" => Ok(Then::Envelope),
            "quadric" => Ok(Then::Quadric),
            "none" => Ok(Then::None),
            other => Err(format!(
                "'{other}': expected auto, envelope, quadric or none"
            )),
        }
    }
}

/// The stage that made a level.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Stage {
    /// Marching cubes alone.
    Voxel,
    /// Then meshoptimizer's quadric collapse.
    Quadric,
    /// Then simplification envelopes.
    Envelope,
    /// meshoptimizer's quadric collapse of the input mesh itself: the budget affords the
    /// input's genus and components, so the voxel stage had nothing to remove (module docs,
    /// step 0).
    InputQuadric,
}

/// What the budget pipeline did for one level.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BudgetLevel {
    /// The triangle budget (`None` for an error target alone).
    pub budget: Option<usize>,
    /// The error target in mesh units, if one was given.
    pub error_target: Option<f64>,
    /// The voxel resolution chosen (for [`Stage::InputQuadric`], the resolution whose level
    /// showed that the budget affords the input's topology).
    pub resolution: usize,
    /// Triangles of that resolution's marching-cubes level (after cutting caps).
    pub voxel_triangles: usize,
    /// Cap triangles cut away over the input's holes.
    pub caps_cut: usize,
    /// The stage that made the level.
    pub stage: Stage,
    /// The final stage's own error bound in mesh units: meshoptimizer's estimate (quadric), ε
    /// (envelope), or half a voxel (marching cubes' placement of the surface).
    pub error_bound: f64,
    /// Two-sided Hausdorff and mean distance to the input mesh (`None` without one).
    pub hausdorff: Option<f64>,
    /// See [`BudgetLevel::hausdorff`].
    pub mean_distance: Option<f64>,
    /// The silhouette difference from the input over 14 views (share of the covered pixels
    /// covered by one of the two alone), measured where levels of the input as given and with
    /// its cavities filled competed (module docs of `budget/silhouettes`); `None` elsewhere.
    pub silhouette_difference: Option<f64>,
    /// Triangles of the level.
    pub triangles: usize,
    /// Genus, components and boundary loops of the level.
    pub genus: Option<i64>,
    /// See [`BudgetLevel::genus`].
    pub components: usize,
    /// See [`BudgetLevel::genus`].
    pub boundary_loops: usize,
    /// Handles of the input that the level no longer has (input genus − level genus), when
    /// both are known.
    pub handles_removed: Option<i64>,
    /// Components of the voxel level that the quadric stage dropped, the smallest first,
    /// because the budget could not carry them all (module docs, step 3).
    pub parts_dropped: usize,
    /// The isodensity of the voxel level (0.5 follows a solid's surface; the dilated levels'
    /// lower one keeps thin parts that 0.5 erases, module docs step 1).
    pub iso: f32,
    /// Cavities of the input (closed shells bounding voids in its material) filled before
    /// sampling, when the filled input gave the closer level (module docs of `budget/filled`);
    /// 0 when the input was sampled as given.
    pub cavities_filled: usize,
    /// Detached parts of the input (closed, genus 0, apart from the level) restored beside the
    /// level as their own collapse (module docs of `budget/detached`).
    pub parts_restored: usize,
    /// In a chain of budgets, the larger budget whose level this one was simplified from
    /// (quadric, topology kept), because its own search found no level within 10 % of the
    /// budget with no more handles than that level (module docs of `budget/genus_cap`).
    pub simplified_from: Option<usize>,
    /// Whether the level's voxel level was collapsed in two stages with a fit to the input
    /// between (a portfolio level: `voxlod_budget::BudgetLevel::staged`).
    pub staged: bool,
    /// Whether the level's vertices were fitted to the input surface (step 7 of
    /// [`crate::budget`], module docs of `budget/fit`): only where that measured closer.
    pub fitted_to_input: bool,
    /// Pairs of the level's triangles that cross ([`voxlod_contouring::crossing_pairs`]): the
    /// quadric collapse refuses to fold one sheet through another, but an input that crosses
    /// itself, or another stage, can leave some. The search prefers candidates without (module
    /// docs, step 4), and where every candidate had some, a warning names them; a mesh's
    /// portfolio keeps no more than its input has.
    pub self_intersections: usize,
    /// Candidates (resolution and stage) built and measured.
    pub candidates: usize,
    /// For a mesh input, the portfolio's method that made the level (crate voxlod-budget);
    /// `None` for a volume's levels.
    pub method: Option<voxlod_budget::Method>,
    /// The largest distance without the input's part points: how far the shape is off apart
    /// from specks it lost (mesh inputs).
    pub shape_distance: Option<f64>,
    /// Candidates measured closer than the level that a promise ruled out, and what keeping
    /// the promise cost (mesh inputs).
    pub ruled_out: Vec<voxlod_budget::RuledOut>,
    /// Every candidate of the portfolio, measured and checked (mesh inputs).
    pub portfolio: Vec<voxlod_budget::CandidateReport>,
    /// Why the level misses its budget by more than 10 %, or what else to know.
    pub note: Option<String>,
    /// Time of this budget's search.
    pub seconds: f64,
}

/// Refuses budgets no closed surface can meet.
pub(crate) fn check_budgets(budgets: &[usize]) -> Result<(), PyramidError> {
    if budgets.is_empty() {
        return Err(InvalidOption::new("triangles", "[]", "give at least one budget").into());
    }
    if let Some(&b) = budgets.iter().find(|&&b| b < 4) {
        let problem =
            "a closed surface needs at least 4 triangles (a tetrahedron); ask for 4 or more";
        return Err(InvalidOption::new("triangles", b, problem).into());
    }
    Ok(())
}
