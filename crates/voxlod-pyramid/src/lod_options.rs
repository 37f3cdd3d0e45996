//! What [`crate::lod`] is asked ([`LodOptions`]: the pyramid, the isodensity, the steps beyond
//! the paper) and what it and [`crate::lod_by_budget`] return ([`Lod`]: the levels and their
//! reports), with the options' presets and their checks before any work (cost: none beyond the
//! checks). Levels by budget have options of their own ([`crate::BudgetOptions`]).

use serde::Serialize;
use voxlod_contouring::CleanOptions;
use voxlod_core::Frame;
use voxlod_sampling::{Filter, MeshPreparation, MonotoneOptions, PyramidOptions};

use crate::budget_terms::BudgetLevel;
use crate::error::{InvalidOption, PyramidError};
use crate::finest::{Finest, FinestChoice};
use crate::lod::LodLevel;
use crate::source::Route;
use crate::then_envelope::ThenEnvelope;

/// Options of [`crate::lod`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LodOptions {
    /// Resolutions (one per level), filter, radius in voxels of each level, quadrature.
    pub pyramid: PyramidOptions,
    /// The isodensity of the surfaces: `None` is 0.5 for meshes, thresholded volumes and
    /// solids (it must lie strictly between 0 and 1); a volume filtered directly needs one in
    /// its own units.
    pub iso: Option<f32>,
    /// Gradient normals on the level meshes.
    pub normals: bool,
    /// Then simplify each level by simplification envelopes within ε.
    pub then_envelope: Option<ThenEnvelope>,
    /// How the finest resolution is chosen: by default, for a mesh, from the input's triangle
    /// count (at most `pyramid`'s finest, [`crate::finest`]); [`Finest::Given`] takes `pyramid`
    /// as it is.
    pub finest: Finest,
    /// Keep the genus from rising along the chain (beyond the paper,
    /// [`voxlod_sampling::monotone_topology`]): a thin wall closes up instead of perforating.
    /// For a scan filtered directly, filled cavities get the data's largest value. `None` gives
    /// the plain pyramid.
    pub monotone: Option<MonotoneOptions>,
    /// Clean each level: no sliver, needle or zero-area triangle and no self-intersection,
    /// closed and manifold kept (beyond the paper, [`voxlod_contouring::clean_mesh()`]). `None`
    /// keeps plain marching cubes.
    pub clean: Option<CleanOptions>,
    /// The anatomical frame of the level meshes of a scan (`Frame::Lps`, `Frame::Ras`): `None`
    /// keeps the scan's own. Refused for a source without a frame ([`crate::Source::to_frame`]).
    pub frame: Option<Frame>,
}

impl Default for LodOptions {
    /// Six levels, halving, from 256 samples or, for a mesh, from the resolution at which the
    /// finest level has no more triangles than the input; hyper-cone filter of one voxel,
    /// isodensity 0.5, with normals, genus that never rises, cleaned levels, no envelope step.
    fn default() -> Self {
        LodOptions {
            pyramid: PyramidOptions::default(),
            iso: None,
            normals: true,
            then_envelope: None,
            finest: Finest::InputTriangles,
            monotone: Some(MonotoneOptions::default()),
            clean: Some(CleanOptions::default()),
            frame: None,
        }
    }
}

impl LodOptions {
    /// `levels` levels from `resolution` samples, halving each time, with `filter`.
    pub fn halving(resolution: usize, levels: usize, filter: Filter) -> Self {
        LodOptions {
            pyramid: PyramidOptions::halving(resolution, levels, filter),
            finest: Finest::Given,
            ..Default::default()
        }
    }

    /// The paper's Table 1: the Gaussian at 200, 100, 50, 30, 15 and 5, isodensity 0.5, plain
    /// marching cubes (the paper's method, whose counts Table 1 gives).
    pub fn paper_table1() -> Self {
        LodOptions {
            pyramid: PyramidOptions::paper_table1(),
            finest: Finest::Given,
            monotone: None,
            clean: None,
            ..Default::default()
        }
    }

    /// A quick look: four levels from 64 samples, hyper-cone.
    pub fn preview() -> Self {
        LodOptions::halving(64, 4, Filter::Hypercone)
    }

    /// These options with the isodensity `iso`.
    pub fn with_iso(self, iso: f32) -> Self {
        LodOptions {
            iso: Some(iso),
            ..self
        }
    }

    /// These options with the envelope step (He et al. §5 suggest one voxel:
    /// `ThenEnvelope::voxels(1.0)`).
    pub fn with_then_envelope(self, step: ThenEnvelope) -> Self {
        LodOptions {
            then_envelope: Some(step),
            ..self
        }
    }

    /// Refuses options out of their range before any work.
    pub(crate) fn check(&self) -> Result<(), PyramidError> {
        let p = &self.pyramid;
        if p.resolutions.is_empty() {
            return Err(InvalidOption::new("resolutions", "[]", "give at least one level").into());
        }
        if let Some(level) = p.resolutions.iter().position(|&r| r == 0) {
            let problem = format!("level {level} has resolution 0; resolutions are at least 1");
            return Err(InvalidOption::new("resolutions", list(&p.resolutions), problem).into());
        }
        if !(p.radius_voxels.is_finite() && p.radius_voxels > 0.0) {
            let problem = "the filter radius must be a positive number of voxels";
            return Err(InvalidOption::new("radius_voxels", p.radius_voxels, problem).into());
        }
        if p.lines_per_radius == 0 {
            let problem = "at least one quadrature line per filter radius";
            return Err(InvalidOption::new("lines_per_radius", 0, problem).into());
        }
        Ok(())
    }
}

fn list(values: &[usize]) -> String {
    let items: Vec<String> = values.iter().map(|v| v.to_string()).collect();
    items.join(",")
}

/// The levels of detail, finest first.
#[derive(Clone, Debug)]
pub struct Lod {
    /// One per resolution, finest first; a level the filter removed has an empty mesh.
    pub levels: Vec<LodLevel>,
    /// How the source entered the pipeline.
    pub route: Route,
    /// What the preparation of a mesh source did: welding, degenerate and duplicate triangles
    /// dropped, holes closed.
    pub preparation: Option<MeshPreparation>,
    /// The isodensity used.
    pub iso: f32,
    /// Empty levels, a threshold at or below every sample: each in one line.
    pub warnings: Vec<String>,
    /// Per level, what the budget pipeline did ([`crate::lod_by_budget`]; empty from [`crate::lod`]).
    pub budgets: Vec<BudgetLevel>,
    /// How the finest resolution was chosen from a mesh's triangle count
    /// ([`LodOptions::finest`]); `None` when the pyramid was taken as given.
    pub finest: Option<FinestChoice>,
    /// Wall time of the whole call.
    pub seconds: f64,
}
