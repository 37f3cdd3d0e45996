//! What [`crate::lod_by_budget`] is asked ([`BudgetOptions`]): levels chosen by triangle count
//! or by an error target, the voxel method first and a geometric method after (He et al. 1995
//! §5), for any source, with its presets and the checks made before any work.
//!
//! A mesh's budgets with the quadric stage go to the portfolio of crate `voxlod-budget`
//! ([`voxlod_budget::PortfolioOptions`], built here from these options); volumes, an error
//! target alone, and the envelope or no geometric stage go to the voxel-first search of
//! [`crate::budget`]. The options that one road does not use are named in the run's warnings.

use serde::Serialize;
use voxlod_core::{Frame, TriangleMesh};
use voxlod_fit::FitOptions;
use voxlod_sampling::{DensityOptions, Filter, PyramidOptions};

use crate::budget_terms::{check_budgets, ErrorTarget, Then};
use crate::error::{InvalidOption, PyramidError};
use crate::source::Source;

/// Options of [`crate::lod_by_budget`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BudgetOptions {
    /// The triangle budgets, one level each, in the order given. Empty with `error` set: one
    /// level within the error target.
    pub triangles: Vec<usize>,
    /// An error target: with budgets, the bound of every level's geometric stage; alone, one
    /// level within it.
    pub error: Option<ErrorTarget>,
    /// The geometric stage after the voxel stage.
    pub then: Then,
    /// The low-pass filter of the voxel levels (He et al. 1995 §3).
    pub filter: Filter,
    /// The filter's support radius in voxels of each voxel level (the paper uses 1). The
    /// portfolio of a mesh uses 1 and warns about another value.
    pub radius_voxels: f64,
    /// Quadrature lines per support radius ([`DensityOptions`]). The portfolio of a mesh uses
    /// the default and warns about another value.
    pub lines_per_radius: usize,
    /// The isodensity of the voxel levels: `None` is 0.5 for meshes, thresholded volumes and
    /// solids; a volume filtered directly needs one in its own units. The portfolio of a mesh
    /// chooses its own and warns when one is given.
    pub iso: Option<f32>,
    /// Per-vertex normals on the levels (area-weighted where the stage made none).
    pub normals: bool,
    /// No level has more handles than the level of the next larger budget (beyond the paper:
    /// the genus never rises along the chain).
    pub monotone: bool,
    /// Every level closed, an open input's holes capped; by default a level is open where the
    /// input is, the caps that sampling puts over its holes cut away.
    pub closed: bool,
    /// The levels' vertices fitted to the input, kept only where that measures closer (beyond
    /// the paper, crate `voxlod-fit`); `None` leaves each level as its geometric stage made it.
    pub fit: Option<FitOptions>,
    /// CPU seconds (all threads; [`voxlod_core::cpu_clock`]) the voxel-first search may spend
    /// per budget and isodensity after its first candidate (`f64::INFINITY`: all of them, `0`:
    /// the first only). CPU time, not wall time, so that a busy machine gives the same levels.
    pub time_cap: f64,
    /// The anatomical frame of the levels of a scan (`Frame::Lps`, `Frame::Ras`): `None` keeps
    /// the scan's own. Refused for a source without a frame ([`Source::to_frame`]).
    pub frame: Option<Frame>,
}

impl Default for BudgetOptions {
    /// No budget yet ([`BudgetOptions::for_triangles`], [`BudgetOptions::for_error`]), the
    /// automatic geometric stage, the hyper-cone of one voxel, normals, the genus never rising,
    /// open where the input is open, the quick fit on (`FitOptions::quick`, the options the
    /// portfolio's benchmark and targets are measured with), one CPU second per search.
    fn default() -> Self {
        BudgetOptions {
            triangles: Vec::new(),
            error: None,
            then: Then::Auto,
            filter: Filter::Hypercone,
            radius_voxels: 1.0,
            lines_per_radius: DensityOptions::DEFAULT_LINES_PER_RADIUS,
            iso: None,
            normals: true,
            monotone: true,
            closed: false,
            fit: Some(FitOptions::quick()),
            time_cap: 1.0,
            frame: None,
        }
    }
}

impl BudgetOptions {
    /// One level per triangle count in `budgets`, in that order:
    ///
    /// ```
    /// # fn main() -> Result<(), voxlod_pyramid::PyramidError> {
    /// # let mesh = voxlod_testkit::shapes::torus(64, 32, 2.0, 0.7);
    /// // `mesh`: a closed torus of 4 096 triangles (or any mesh from `voxlod::read_mesh`).
    /// use voxlod_pyramid::{lod_by_budget, BudgetOptions, Source};
    /// let lod = lod_by_budget(&Source::Mesh(&mesh), &BudgetOptions::for_triangles(&[1000, 250]))?;
    /// for (level, report) in lod.levels.iter().zip(&lod.budgets) {
    ///     let miss = level.mesh.triangle_count() as f64 / report.budget.unwrap() as f64 - 1.0;
    ///     assert!(miss.abs() <= 0.1 && level.topology.is_closed_manifold());
    /// }
    /// # Ok(())
    /// # }
    /// ```
    pub fn for_triangles(budgets: &[usize]) -> Self {
        BudgetOptions {
            triangles: budgets.to_vec(),
            ..Default::default()
        }
    }

    /// One level within `error` of the input.
    pub fn for_error(error: ErrorTarget) -> Self {
        BudgetOptions {
            error: Some(error),
            ..Default::default()
        }
    }

    /// Refuses options out of their range before any work.
    pub fn check(&self) -> Result<(), PyramidError> {
        if self.triangles.is_empty() && self.error.is_none() {
            let problem = "give at least one budget, or an error target";
            return Err(InvalidOption::new("triangles", "[]", problem).into());
        }
        if !self.triangles.is_empty() {
            check_budgets(&self.triangles)?;
        }
        if let Some(e @ (ErrorTarget::Distance(x) | ErrorTarget::Fraction(x))) = self.error {
            if !(x.is_finite() && x > 0.0) {
                let problem = "the error target must be a positive distance or fraction";
                return Err(InvalidOption::new("error", e, problem).into());
            }
        }
        if !(self.radius_voxels.is_finite() && self.radius_voxels > 0.0) {
            let problem = "the filter radius must be a positive number of voxels";
            return Err(InvalidOption::new("radius_voxels", self.radius_voxels, problem).into());
        }
        if self.lines_per_radius == 0 {
            let problem = "at least one quadrature line per filter radius";
            return Err(InvalidOption::new("lines_per_radius", 0, problem).into());
        }
        if self.time_cap.is_nan() || self.time_cap < 0.0 {
            let problem = "the time cap is a number of seconds, zero or more";
            return Err(InvalidOption::new("time_cap", self.time_cap, problem).into());
        }
        Ok(())
    }

    /// Whether the portfolio answers these options for `source`: a mesh, budgets given, and
    /// the quadric stage (or the automatic choice) asked.
    pub(crate) fn uses_portfolio(&self, source: &Source) -> bool {
        matches!(source, Source::Mesh(_))
            && !self.triangles.is_empty()
            && matches!(self.then, Then::Auto | Then::Quadric)
    }

    /// The voxel levels' pyramid: the filter, its radius and quadrature; the resolutions are
    /// chosen per budget.
    pub(crate) fn pyramid(&self) -> PyramidOptions {
        PyramidOptions {
            resolutions: Vec::new(),
            radius_voxels: self.radius_voxels,
            filter: self.filter,
            lines_per_radius: self.lines_per_radius,
        }
    }

    /// The portfolio's options for `mesh`, and a warning for each option the portfolio does
    /// not use.
    pub(crate) fn portfolio(
        &self,
        mesh: &TriangleMesh,
    ) -> (voxlod_budget::PortfolioOptions, Vec<String>) {
        let defaults = BudgetOptions::default();
        let mut warnings = Vec::new();
        let mut unused = |name: &str, given: bool| {
            if given {
                warnings.push(format!(
                    "{name} does not apply to budget levels of a mesh (the portfolio chooses each \
                     level's resolution and isodensity): ignored"
                ));
            }
        };
        unused("iso", self.iso.is_some());
        unused("time_cap", self.time_cap != defaults.time_cap);
        unused("radius", self.radius_voxels != defaults.radius_voxels);
        unused(
            "lines_per_radius",
            self.lines_per_radius != defaults.lines_per_radius,
        );
        let diagonal = mesh.bounds().diagonal();
        let portfolio = voxlod_budget::PortfolioOptions {
            triangles: self.triangles.clone(),
            filter: self.filter,
            monotone: self.monotone,
            closed: self.closed,
            max_error: self.error.map(|e| e.distance(diagonal)),
            fit: self.fit.clone(),
            ..voxlod_budget::PortfolioOptions::default()
        };
        (portfolio, warnings)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn check_refuses_an_empty_job_and_small_budgets() {
        let e = BudgetOptions::default().check().unwrap_err();
        assert!(e.to_string().contains("at least one budget"), "{e}");
        let e = BudgetOptions::for_triangles(&[100, 3]).check().unwrap_err();
        assert!(e.to_string().contains("tetrahedron"), "{e}");
        let e = BudgetOptions::for_error(ErrorTarget::Fraction(-0.1))
            .check()
            .unwrap_err();
        assert!(e.to_string().contains("positive"), "{e}");
        assert!(BudgetOptions::for_error(ErrorTarget::Fraction(0.01))
            .check()
            .is_ok());
    }

    #[test]
    fn portfolio_names_the_options_it_does_not_use() {
        let mesh = voxlod_testkit::shapes::torus(16, 8, 2.0, 0.7);
        let options = BudgetOptions {
            iso: Some(0.3),
            time_cap: 5.0,
            ..BudgetOptions::for_triangles(&[100])
        };
        let (portfolio, warnings) = options.portfolio(&mesh);
        assert_eq!(portfolio.triangles, vec![100]);
        assert_eq!(warnings.len(), 2, "{warnings:?}");
        assert!(warnings[0].starts_with("iso ") && warnings[1].starts_with("time_cap "));
        let (_, none) = BudgetOptions::for_triangles(&[100]).portfolio(&mesh);
        assert!(none.is_empty(), "{none:?}");
    }
}
