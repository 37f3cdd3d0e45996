//! What a run reports: per level ([`BudgetLevel`]) the method and measures of the level, every
//! candidate ([`CandidateReport`]) and the closer candidates a promise ruled out
//! ([`RuledOut`]); for the run, the input's figures ([`InputReport`]).

use serde::Serialize;

use crate::candidate::{Candidate, Fill, Method};
use crate::input::{Input, Preparation};
use crate::promises::Promise;

/// One budget's level, reported.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BudgetLevel {
    /// The triangle budget.
    pub budget: usize,
    /// Triangles of the level.
    pub triangles: usize,
    /// The method that made it.
    pub method: Method,
    /// The voxel resolution (samples across the longest side) of a voxel or shell level.
    pub resolution: Option<usize>,
    /// The isodensity it was contoured at.
    pub iso: Option<f32>,
    /// Whether its voxel level was collapsed in two stages with a fit to the input between
    /// (module `voxel`, `staged`).
    pub staged: bool,
    /// Whether its vertices were fitted to the input.
    pub fitted_to_input: bool,
    /// Parts of the voxel level that the quadric stage dropped for the budget.
    pub parts_dropped: usize,
    /// Lost parts of the input put back beside the level (module `restore`).
    pub parts_restored: usize,
    /// What of the input's inside was filled before sampling the level.
    pub fill: Fill,
    /// Two-sided Hausdorff distance to the input (careful samples), mesh units.
    pub hausdorff: f64,
    /// Two-sided mean distance to the input, mesh units.
    pub mean_distance: f64,
    /// `hausdorff` over the input's bounding-box diagonal.
    pub hausdorff_fraction: f64,
    /// The largest distance over the area samples and the level's vertices, without the
    /// input's part points (module docs of `measure`): how far its shape is off, apart from
    /// specks it lost.
    pub shape_distance: f64,
    /// Genus (handles), when the level is an oriented manifold.
    pub genus: Option<i64>,
    /// Connected components.
    pub components: usize,
    /// Boundary loops (0: closed).
    pub boundary_loops: usize,
    /// Handles of the input the level no longer has, when both genera are known.
    pub handles_removed: Option<i64>,
    /// Crossing triangle pairs: 0 unless a warning says no candidate was free of them, or the
    /// input crosses itself as much (its crossings license a level's), or the level is a new
    /// surface whose crossings a warning names ([`crate::PortfolioOptions::remesh`]).
    pub self_intersections: usize,
    /// The larger budget whose level this one was collapsed from ([`Method::Above`]).
    pub simplified_from: Option<usize>,
    /// Every candidate of this budget.
    pub candidates: Vec<CandidateReport>,
    /// Candidates measured closer than the level that a promise ruled out.
    pub ruled_out: Vec<RuledOut>,
    /// What the level gave up, where no candidate kept every promise.
    pub note: Option<String>,
    /// Where the level was chosen for its outline rather than as the closest (module
    /// `outline`): its silhouette difference and the input's plain collapse's.
    pub outline: Option<Outline>,
    /// Seconds spent on this budget's candidates and choice.
    pub seconds: f64,
}

/// Silhouette differences from the input (crate `voxlod-render`'s, 14 views of 256² pixels,
/// as `voxlod evaluate` reports them) of a level chosen for its outline and of the input's
/// plain collapse at its budget.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Outline {
    /// The level's.
    pub silhouette_difference: f64,
    /// The input's plain collapse's (meshoptimizer `simplify`, as gltfpack runs it).
    pub collapse_silhouette_difference: f64,
}

/// One candidate, reported.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CandidateReport {
    /// Its method, resolution and isodensity.
    pub candidate: String,
    /// Triangles.
    pub triangles: usize,
    /// Quick shape distance (`None`: not measured, or rejected early as far off).
    pub shape: Option<f64>,
    /// Careful Hausdorff distance, for the finalists.
    pub careful_hausdorff: Option<f64>,
    /// Careful mean distance, for the finalists.
    pub careful_mean: Option<f64>,
    /// The promises it broke.
    pub broken: Vec<Promise>,
}

impl CandidateReport {
    /// The report of `c`, which broke `broken`.
    pub fn of(c: &Candidate, broken: &[Promise]) -> CandidateReport {
        CandidateReport {
            candidate: c.label(),
            triangles: c.triangles(),
            shape: c.quick.map(|d| d.shape),
            careful_hausdorff: c.careful.map(|d| d.hausdorff),
            careful_mean: c.careful.map(|d| d.mean),
            broken: broken.to_vec(),
        }
    }
}

/// A candidate closer than the level that a promise ruled out, and what keeping the promise
/// cost.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RuledOut {
    /// Its method, resolution and isodensity.
    pub candidate: String,
    /// The promises it broke.
    pub broken: Vec<Promise>,
    /// Its quick shape distance (module docs of `measure`).
    pub shape: f64,
    /// The level's shape distance over its own: what the promises cost.
    pub cost: f64,
}

/// The input as the run saw it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct InputReport {
    /// Triangles and vertices after preparation.
    pub triangles: usize,
    /// See [`InputReport::triangles`].
    pub vertices: usize,
    /// Genus, when an oriented manifold.
    pub genus: Option<i64>,
    /// Connected components.
    pub components: usize,
    /// Boundary loops.
    pub boundary_loops: usize,
    /// Whether it is a closed, oriented manifold (so are its levels).
    pub closed: bool,
    /// Its box's diagonal.
    pub diagonal: f64,
    /// What preparing it changed.
    pub preparation: Preparation,
    /// Parts no view saw, dropped ([`crate::PortfolioOptions::drop_hidden`]).
    pub hidden_parts: usize,
    /// Triangles of the parts kept that no view saw: left out of measuring.
    pub hidden_triangles: usize,
}

impl InputReport {
    /// The report of `input`.
    pub fn of(input: &Input) -> InputReport {
        InputReport {
            triangles: input.mesh.triangle_count(),
            vertices: input.mesh.vertex_count(),
            genus: input.topology.genus,
            components: input.topology.components,
            boundary_loops: input.topology.boundary_loops,
            closed: input.is_closed(),
            diagonal: input.diagonal,
            preparation: input.preparation,
            hidden_parts: input.seen.as_ref().map_or(0, |s| s.hidden_parts),
            hidden_triangles: (input.seen.as_ref())
                .map_or(0, |s| s.mask.iter().filter(|&&m| !m).count()),
        }
    }
}
