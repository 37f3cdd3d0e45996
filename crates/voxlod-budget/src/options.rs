//! [`PortfolioOptions`]: what a run of budgets is asked.

use serde::Serialize;
use voxlod_fit::FitOptions;
use voxlod_sampling::Filter;

use crate::BudgetError;

/// A level may miss its budget by this fraction of it.
pub const BUDGET_TOLERANCE: f64 = 0.10;

/// How [`crate::levels`] runs.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PortfolioOptions {
    /// The triangle budgets, in any order; one level each.
    pub triangles: Vec<usize>,
    /// The low-pass filter of the voxel candidates (He et al. 1995 §3).
    pub filter: Filter,
    /// No level has more handles than the level of the next larger budget (the genus never
    /// rises along the chain). Off, each budget is answered on its own.
    pub monotone: bool,
    /// Every level closed, even where the input is open (its holes capped): the collapse of an
    /// open input then competes only if it is closed. Off (the default), a level is closed
    /// where the input is closed.
    pub closed: bool,
    /// The largest distance, in mesh units, that a level may be from the input, as its
    /// geometric stages estimate it (`None`: the budget alone decides).
    pub max_error: Option<f64>,
    /// Voxel candidates' vertices fitted to the input (crate `voxlod-fit`), kept only where
    /// that measures closer; `None` leaves them as the quadric stage made them.
    pub fit: Option<FitOptions>,
    /// With `fit`, the levels that are collapses of the input fitted to it too, once the chain
    /// is chosen, where that measures no farther. Off where a level's vertices must stay the
    /// input's: an asset's levels never fit them (module `looks`, which makes an asset's
    /// collapse again with its attributes).
    pub fit_collapses: bool,
    /// Every level a new surface around the input (a proxy, to be baked): only voxel, shell
    /// and level-above candidates compete, never the input's own collapse nor its parts stood
    /// in for, so that parts merge, gaps close and what the filter removes stays removed.
    pub remesh: bool,
    /// Parts that no view from a sphere around the input sees are dropped, and candidates are
    /// measured against and fitted to the triangles seen only (module `visible`).
    pub drop_hidden: bool,
    /// Gaps between parts narrower than this (mesh units) closed in every voxel candidate's
    /// solid (a morphological closing, module `voxel`); `None`: only what the filter closes,
    /// gaps under about a voxel.
    pub close_gaps: Option<f64>,
    /// Samples a side of the quick distance that ranks every candidate.
    pub quick_samples: usize,
    /// Samples a side of the careful distance that decides between the closest candidates
    /// and is reported.
    pub careful_samples: usize,
}

impl Default for PortfolioOptions {
    /// No budget yet (see [`PortfolioOptions::for_triangles`]), the hyper-cone, monotone, open
    /// where the input is open, no error limit, the quick fit (of collapses too), 1 000 quick
    /// and 10 000 careful samples a side.
    fn default() -> Self {
        PortfolioOptions {
            triangles: Vec::new(),
            filter: Filter::Hypercone,
            monotone: true,
            closed: false,
            max_error: None,
            fit: Some(FitOptions::quick()),
            fit_collapses: true,
            remesh: false,
            close_gaps: None,
            drop_hidden: false,
            quick_samples: 1_000,
            careful_samples: 10_000,
        }
    }
}

impl PortfolioOptions {
    /// A proxy's levels for `budgets` ([`PortfolioOptions::remesh`]), every level closed, what
    /// is hidden dropped ([`PortfolioOptions::drop_hidden`]).
    pub fn remesh(budgets: &[usize]) -> Self {
        PortfolioOptions {
            remesh: true,
            closed: true,
            drop_hidden: true,
            ..PortfolioOptions::for_triangles(budgets)
        }
    }

    /// The default options for `budgets`.
    pub fn for_triangles(budgets: &[usize]) -> Self {
        PortfolioOptions {
            triangles: budgets.to_vec(),
            ..PortfolioOptions::default()
        }
    }

    /// Refuses what no run can honour: no budget, a budget under 4 (a closed surface needs a
    /// tetrahedron), sample counts of zero, a negative or NaN error limit.
    pub fn check(&self) -> Result<(), BudgetError> {
        if self.triangles.is_empty() {
            return Err(BudgetError::InvalidBudgets(
                "give at least one budget".into(),
            ));
        }
        if let Some(b) = self.triangles.iter().find(|&&b| b < 4) {
            return Err(BudgetError::InvalidBudgets(format!(
                "{b}: a closed surface needs at least 4 triangles (a tetrahedron); ask for 4 or more"
            )));
        }
        if self.quick_samples == 0 || self.careful_samples == 0 {
            return Err(BudgetError::InvalidOption {
                name: "samples",
                problem: "distances need at least one sample a side".into(),
            });
        }
        if let Some(g) = self.close_gaps {
            if !(g.is_finite() && g > 0.0) {
                return Err(BudgetError::InvalidOption {
                    name: "close_gaps",
                    problem: format!("{g}: a gap width must be a positive distance"),
                });
            }
        }
        if let Some(e) = self.max_error {
            if e.is_nan() || e < 0.0 {
                return Err(BudgetError::InvalidOption {
                    name: "max_error",
                    problem: format!("{e}: a distance limit must be zero or positive"),
                });
            }
        }
        Ok(())
    }
}
