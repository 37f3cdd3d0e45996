//! The main job in one call: levels of detail of a mesh, a scanned volume or a solid (He, Hong,
//! Kaufman, Varshney, Wang 1995, §2 and §4).
//!
//! [`lod`] prepares the [`Source`] (welding and hole closing for a mesh, the threshold solid
//! for a scan), checks the iso value, plans every level (refusing what would not fit in memory
//! before any work), then samples each level from the original source with its own filter
//! radius, contours it by marching cubes, and, when asked, simplifies it by simplification
//! envelopes ([`LodOptions::then_envelope`]). Every level is a closed, consistently oriented
//! mesh, or empty where the filter removed the whole object (a warning says so). [`lod_with`]
//! reports progress after each step and stops when asked. The levels one at a time are
//! [`crate::lod::plan`] and [`crate::lod::build_level`]. Cost: per level, the sampling (O(N³)
//! samples) and marching cubes (O(N³)); the finest level dominates.

use std::time::Instant;

use serde::Serialize;
use voxlod_core::mesh_topology;
use voxlod_core::validate::{find_defect, Requirements};
use voxlod_sampling::{Filter, LevelPlan, MeshPreparation, PyramidOptions};

use crate::budget::{check_budgets, lod_by_budget, BudgetLevel, ErrorTarget, Then};
use crate::error::{Error, InvalidOption};
use crate::lod::{plan, sample_level, LevelOptions, LodLevel, LodSource};
use crate::progress::{run_to_end, Event, ProgressFn, Tracker};
use crate::source::{Route, Source};
use crate::then_envelope::{simplify_level, ThenEnvelope};

/// Options of [`lod`].
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
    /// Levels by triangle budget, one per count in the order given ([`crate::budget`]): the
    /// resolutions of `pyramid` are then chosen per budget (its filter, radius and quadrature
    /// are used).
    pub triangles: Option<Vec<usize>>,
    /// An error target: with `triangles`, the bound of every level's geometric stage; alone,
    /// one level within it ([`crate::budget`]).
    pub error: Option<ErrorTarget>,
    /// The geometric stage of the budget levels.
    pub then: Then,
    /// Budget levels of an open mesh keep the caps that sampling puts over its holes
    /// (watertight levels); by default the caps are cut away and the openings kept.
    pub closed: bool,
    /// Seconds each budget's search may spend on neighbouring resolutions after its first
    /// candidate (`f64::INFINITY`: all of them, `0`: the first only).
    pub time_cap: f64,
}

impl Default for LodOptions {
    /// Six levels from 256 samples, halving, hyper-cone filter of one voxel, isodensity 0.5,
    /// with normals, no envelope step.
    fn default() -> Self {
        LodOptions {
            pyramid: PyramidOptions::default(),
            iso: None,
            normals: true,
            then_envelope: None,
            triangles: None,
            error: None,
            then: Then::Auto,
            closed: false,
            time_cap: 1.0,
        }
    }
}

impl LodOptions {
    /// One level per triangle count in `budgets`, by the budget pipeline ([`crate::budget`]):
    ///
    /// ```
    /// # fn main() -> Result<(), voxlod::Error> {
    /// # let mesh = voxlod_testkit::shapes::torus(64, 32, 2.0, 0.7);
    /// // `mesh`: a closed torus of 4 096 triangles (or any mesh from `voxlod::read_mesh`).
    /// let lod = voxlod::lod(&voxlod::Source::Mesh(&mesh), &voxlod::LodOptions::budgets(vec![1000, 250]))?;
    /// for (level, report) in lod.levels.iter().zip(&lod.budgets) {
    ///     let miss = level.mesh.triangle_count() as f64 / report.budget.unwrap() as f64 - 1.0;
    ///     assert!(miss.abs() <= 0.1 && level.topology.is_closed_manifold());
    /// }
    /// # Ok(())
    /// # }
    /// ```
    pub fn budgets(triangles: Vec<usize>) -> Self {
        LodOptions {
            triangles: Some(triangles),
            ..Default::default()
        }
    }

    /// `levels` levels from `resolution` samples, halving each time, with `filter`.
    pub fn halving(resolution: usize, levels: usize, filter: Filter) -> Self {
        LodOptions {
            pyramid: PyramidOptions::halving(resolution, levels, filter),
            ..Default::default()
        }
    }

    /// The paper's Table 1: the Gaussian at 200, 100, 50, 30, 15 and 5, isodensity 0.5.
    pub fn paper_table1() -> Self {
        LodOptions {
            pyramid: PyramidOptions::paper_table1(),
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
    fn check(&self) -> Result<(), Error> {
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
        if self.time_cap.is_nan() || self.time_cap < 0.0 {
            let problem = "the time cap is a number of seconds, zero or more";
            return Err(InvalidOption::new("time_cap", self.time_cap, problem).into());
        }
        if self.then_envelope.is_some() && (self.triangles.is_some() || self.error.is_some()) {
            let problem = "the envelope step is part of the budget pipeline; choose it with `then`";
            return Err(InvalidOption::new("then_envelope", "set", problem).into());
        }
        if let Some(budgets) = &self.triangles {
            check_budgets(budgets)?;
        }
        if let Some(e @ (ErrorTarget::Distance(x) | ErrorTarget::Fraction(x))) = self.error {
            if !(x.is_finite() && x > 0.0) {
                let problem = "the error target must be a positive distance or fraction";
                return Err(InvalidOption::new("error", e, problem).into());
            }
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
    /// Per level, what the budget pipeline did (empty unless `triangles` or `error` was set).
    pub budgets: Vec<BudgetLevel>,
    /// Wall time of the whole call.
    pub seconds: f64,
}

/// Levels of detail of `source`, with the defaults of `options`.
///
/// ```
/// # fn main() -> Result<(), voxlod::Error> {
/// use voxlod::sampling::{CsgSolid, Shape};
/// use voxlod::core::glam::DVec3;
/// // A sphere of radius 1 as an implicit solid, three levels from 24 samples.
/// let ball = CsgSolid::new(Shape::sphere(DVec3::ZERO, 1.0))?;
/// let options = voxlod::LodOptions::halving(24, 3, voxlod::sampling::Filter::Hypercone);
/// let lod = voxlod::lod(&voxlod::Source::Solid(&ball), &options)?;
/// assert_eq!(lod.levels.len(), 3);
/// for level in &lod.levels {
///     assert!(level.topology.is_closed_manifold() && level.topology.genus == Some(0));
/// }
/// assert!(lod.levels[2].mesh.triangle_count() < lod.levels[0].mesh.triangle_count());
/// # Ok(())
/// # }
/// ```
pub fn lod(source: &Source, options: &LodOptions) -> Result<Lod, Error> {
    lod_with(source, options, &run_to_end)
}

/// [`lod`], reporting progress to `progress` after each step (a level's sampling, contouring
/// and envelope step) and stopping with [`Error::Cancelled`] when it answers
/// [`crate::Control::Stop`]; a level's failure names the level.
///
/// ```
/// # fn main() -> Result<(), voxlod::Error> {
/// use std::sync::atomic::{AtomicUsize, Ordering};
/// use voxlod::sampling::{CsgSolid, Shape};
/// use voxlod::core::glam::DVec3;
/// let ball = CsgSolid::new(Shape::sphere(DVec3::ZERO, 1.0))?;
/// let options = voxlod::LodOptions::halving(16, 4, voxlod::sampling::Filter::Hypercone);
/// // Stop once the first level is complete.
/// let levels = AtomicUsize::new(0);
/// let stop_after_one = |p: voxlod::Progress| match p.event {
///     voxlod::Event::LodLevel(_) if levels.fetch_add(1, Ordering::Relaxed) == 0 => {
///         voxlod::Control::Stop
///     }
///     _ => voxlod::Control::Continue,
/// };
/// let e = voxlod::lod_with(&voxlod::Source::Solid(&ball), &options, &stop_after_one);
/// assert!(matches!(e, Err(voxlod::Error::Cancelled)));
/// assert_eq!(levels.load(Ordering::Relaxed), 1);
/// # Ok(())
/// # }
/// ```
pub fn lod_with(
    source: &Source,
    options: &LodOptions,
    progress: &ProgressFn,
) -> Result<Lod, Error> {
    let start = Instant::now();
    options.check()?;
    if options.triangles.is_some() || options.error.is_some() {
        return lod_by_budget(source, options, progress);
    }
    let prepared = source.prepare()?;
    let iso = prepared.iso(options.iso)?;
    let level_options = LevelOptions {
        pyramid: options.pyramid.clone(),
        iso,
        normals: options.normals,
        ..LevelOptions::default()
    };
    let lod_source = prepared.lod_source();
    let plans = plan(&lod_source, &level_options)?;
    let steps = if options.then_envelope.is_some() {
        3
    } else {
        2
    };
    let mut tracker = Tracker::start(progress, plans.len() * steps)?;
    let mut warnings = prepared.warnings().to_vec();
    let mut levels = Vec::with_capacity(plans.len());
    for p in &plans {
        let level = one_level(&lod_source, p, &level_options, options, &mut tracker)
            .map_err(|e| e.context(format!("level {}", p.level)))?;
        if level.mesh.is_empty() {
            warnings.push(empty_level_warning(p, iso));
        }
        tracker.ask(Event::LodLevel(&level))?;
        levels.push(level);
    }
    if levels.iter().all(|l| l.mesh.is_empty()) {
        return Err(Error::NoSurface {
            iso,
            voxel_size: plans[0].voxel_size,
            radius: plans[0].radius,
        });
    }
    Ok(Lod {
        levels,
        route: prepared.route(),
        preparation: prepared.preparation().copied(),
        iso,
        warnings,
        budgets: Vec::new(),
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// Samples, contours and (when asked) simplifies one level, checking that its vertices stayed
/// within 32-bit coordinates.
fn one_level(
    source: &LodSource,
    plan: &LevelPlan,
    level_options: &LevelOptions,
    options: &LodOptions,
    tracker: &mut Tracker,
) -> Result<LodLevel, Error> {
    let sampled = sample_level(source, plan, level_options)?;
    tracker.step(plan.level, "sampled")?;
    let mut level = sampled.contour(level_options)?;
    if let Some(defect) = find_defect(&level.mesh, &Requirements::computed()) {
        return Err(Error::ComputedBeyondRange {
            defect,
            cause: "the object's extent or position is too large for 32-bit coordinates",
        });
    }
    tracker.step(plan.level, "contoured")?;
    if let Some(step) = &options.then_envelope {
        let (mesh, report) = simplify_level(&level.mesh, step, plan.voxel_size)
            .map_err(|e| Error::from(e).context("`then_envelope`"))?;
        level.mesh = mesh;
        level.envelope = report;
        level.topology = mesh_topology(&level.mesh);
        tracker.step(plan.level, "simplified")?;
    }
    Ok(level)
}

/// The warning for a level the filter removed.
fn empty_level_warning(plan: &LevelPlan, iso: f32) -> String {
    format!(
        "level {}: the filter of radius {:.4} removed the whole object (no density reaches \
         {iso}); the level is empty. Use fewer levels, or a lower `iso` for parts thinner than a \
         voxel",
        plan.level, plan.radius
    )
}
