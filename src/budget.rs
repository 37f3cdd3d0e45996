//! Levels by triangle budget or by error target: the voxel method first, then a geometric
//! simplifier, as the paper proposes (He et al. 1995, §5: the voxel method removes the small
//! features and holes, a geometric method then spends the triangles where the shape needs them).
//!
//! For each budget `B` of [`crate::LodOptions::triangles`], on its own:
//!
//! 0. **What the budget affords.** The marching-cubes level with about `B` triangles shows what
//!    topology `B` triangles can carry. When it has no fewer handles and components than the
//!    input mesh, the voxel stage has nothing to remove, and the geometric stage runs on the
//!    input itself (quadric collapse, topology kept, [`Stage::InputQuadric`]): a filtered level
//!    would only add the filter's smoothing to the error (measured on the bunny, rocker arm and
//!    fandisk: the input's collapse is two to ten times closer than any voxel level's). If that
//!    collapse reaches the budget, it is the level; if not (it stalls above it), it stays a
//!    candidate of the search below. This shortcut is our addition to §5, which always filters.
//! 1. **Resolution.** The finest voxel resolution whose marching-cubes level has about
//!    `4 B` triangles: what the budget cannot afford (handles, thin parts, small pieces below a
//!    voxel) is filtered away there, and the geometric stage gets room to choose. Found by
//!    probing: from the resolution that [`voxlod_contouring::triangle_estimate`] predicts from
//!    the input mesh (32 for a volume), each try scales the resolution by `√(wanted / got)`
//!    (marching cubes' count grows as the resolution squared), until the count is within 25 %,
//!    at most five tries. A level that vanished (a sheet thinner than a voxel) sends the search
//!    to twice the resolution, with a warning. **Dilated levels** (our addition to §4, which
//!    contours at 0.5): with a mesh input and the default isodensity, the same search runs on
//!    levels contoured at 0.25 and 0.15 ([`DILATED_ISO_FRACTIONS`] of 0.5), each finding its
//!    own resolution, where a part thinner than the filter still leaves a surface: the thin
//!    skull of a CT bone surface, which 0.5 erases at the coarse resolutions a small budget
//!    affords, closes up into a thicker shell instead of vanishing (a slab of thickness `t`
//!    under the hyper-cone of radius `R` peaks at a density of about `t / R`, so 0.25 keeps
//!    slabs half as thick as 0.5 does, 0.15 slabs a third as thick). The price is one-sided: a
//!    flat surface moves outwards by 0.27 `R` at 0.25 and 0.40 `R` at 0.15 (where the density
//!    of a half-space under the hyper-cone falls that low), which the measured distances of
//!    step 4 weigh against what the 0.5 level lost: the candidates of all three compete there.
//! 2. **Openings.** An open mesh input keeps its openings: the caps that sampling put over its
//!    holes are cut away from the level ([`crate::caps`]), unless
//!    [`crate::LodOptions::closed`] asks for watertight levels.
//! 3. **Geometric stage** ([`Then`]): meshoptimizer's quadric collapse with the topology kept
//!    (voxlod-quadric); where it stalls more than 10 % above the budget because the level has
//!    more components than the budget can carry, the smallest components (by bounding-box
//!    diagonal) are dropped until it fits ([`voxlod_quadric::simplify_dropping_parts`], reported
//!    as [`BudgetLevel::parts_dropped`]): the paper's point that the voxel method may drop small
//!    parts, carried into the geometric stage (our addition), so that a finer level that still
//!    holds the large parts' shape can compete with a coarser one that filtered everything; or simplification envelopes (voxlod-envelope, `tight` preset, ε searched
//!    for the count), or none. [`Then::Auto`] runs the quadric stage, and the envelopes only on
//!    a level where the quadric stage stalls above the budget: measured on the bunny's chain,
//!    the envelopes cost 10 to 300 times the quadric stage's time and were closer to the input
//!    only once, at the largest budget, where the input's own collapse (step 0) is closer
//!    still.
//! 4. **Search.** Within [`crate::LodOptions::time_cap`] seconds per budget and isodensity
//!    (counted after the probes for its first resolution), the neighbouring resolutions (about
//!    `8 B` and `2 B` triangles) are tried too, and the candidate within 10 % of the budget
//!    with the smallest measured two-sided Hausdorff distance to the input is kept (without a
//!    mesh input, the first within 10 %). Distances are sampled (10 000
//!    points a side) against the input's closest-point structure, built once per run.
//!
//! **Independence.** A budget's level depends on that budget and the options alone, never on
//! the other budgets of the run: each search starts from nothing, and levels built for one
//! budget are reused by another only because building them again would give the same level.
//! The time cap charges a reused level its original building time, so it stops a search at the
//! same candidate whatever ran before (up to the machine's timing noise).
//!
//! **Error target.** With [`crate::LodOptions::error`] and no budgets, one level: the resolution
//! whose voxel is the error, then the quadric stage within the error; with budgets too, the
//! error bounds every geometric stage.
//!
//! Every level is within 10 % of its budget or its report says why not
//! ([`BudgetLevel::note`]). Cost: per budget and isodensity (three with the dilated levels),
//! one to five samplings (the finest dominates, O(N³)), marching cubes, one to four geometric
//! stages (each up to four quadric runs when parts are dropped) and a distance measurement
//! each; when the budget affords the input's topology, one small sampling and one collapse of
//! the input, O(F log F).

use std::collections::HashMap;
use std::fmt;
use std::str::FromStr;
use std::sync::Mutex;
use std::time::Instant;

use serde::Serialize;
use voxlod_contouring::triangle_estimate::resolution_for_triangles;
use voxlod_core::weld::weld_vertices;
use voxlod_core::{mesh_topology, Topology, TriangleMesh};
use voxlod_envelope::{simplify_envelope, EnvelopeOptions, Epsilon};
use voxlod_metrics::{
    one_sided_distance, DistanceOptions, MeshDistance, SamplingOptions, SurfaceSampler,
};
use voxlod_quadric::{simplify_dropping_parts, simplify_to_budget, PartsOptions, QuadricOptions};
use voxlod_sampling::PyramidOptions;

use crate::caps::{cut_caps, InputBorder};
use crate::error::{Error, InvalidOption};
use crate::levels::{Lod, LodOptions};
use crate::lod::{build_level, plan, LevelOptions, LodLevel, LodSource};
use crate::progress::{Event, ProgressFn, Tracker};
use crate::source::Source;

/// A budget's level may miss it by this fraction.
pub const BUDGET_TOLERANCE: f64 = 0.10;
/// The marching-cubes level aimed at has this many times the budget's triangles.
const HEADROOM: f64 = 4.0;
/// Resolutions searched: at most this fine (memory is checked as well), at least this coarse.
const FINEST: usize = 512;
const COARSEST: usize = 4;
/// The resolution search stops once a level's count is within this fraction of the wanted one.
const PROBE_TOLERANCE: f64 = 0.25;
/// With a mesh input and the solid's default isodensity, the search also runs on levels
/// contoured at these fractions of it (0.25 and 0.15 for 0.5): module docs, step 1.
const DILATED_ISO_FRACTIONS: [f32; 2] = [0.5, 0.3];
/// Samples per side of the distances measured during the search.
const SEARCH_SAMPLES: usize = 10_000;

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
    /// Candidates (resolution and stage) built and measured.
    pub candidates: usize,
    /// Why the level misses its budget by more than 10 %, or what else to know.
    pub note: Option<String>,
    /// Time of this budget's search.
    pub seconds: f64,
}

/// What the budgets share: the source, the input mesh and its border, levels built so far.
pub(crate) struct BudgetContext<'a> {
    pub(crate) source: &'a LodSource<'a>,
    pub(crate) level_options: LevelOptions,
    pub(crate) input: Option<&'a TriangleMesh>,
    pub(crate) border: Option<InputBorder>,
    /// The input mesh welded, its topology, and its distance measure (with a mesh input).
    welded: Option<(TriangleMesh, Topology)>,
    measure: Option<InputMeasure<'a>>,
    pub(crate) input_genus: Option<i64>,
    pub(crate) then: Then,
    pub(crate) time_cap: f64,
    pub(crate) diagonal: f64,
    /// Whether the dilated levels are searched too (module docs, step 1): with a mesh input and
    /// the solid's default isodensity.
    pub(crate) dilated: bool,
    /// Levels by resolution and isodensity (its bits), with the seconds they took to build.
    levels: Mutex<HashMap<(usize, u32), (LodLevel, f64)>>,
}

/// One candidate for a budget: the level and its report.
struct Candidate {
    mesh: TriangleMesh,
    stage: Stage,
    error_bound: f64,
    distance: Option<Measured>,
    /// Components of the voxel level that the quadric stage dropped.
    parts_dropped: usize,
    /// The isodensity of the voxel level it came from.
    iso: f32,
}

/// A sampled two-sided distance.
#[derive(Clone, Copy, Debug)]
struct Measured {
    hausdorff: f64,
    mean: f64,
}

/// The input mesh's samples and closest-point structure, built once per run, so that each
/// candidate's two-sided distance costs only its own structure and the queries.
struct InputMeasure<'a> {
    sampler: SurfaceSampler<'a>,
    closest: MeshDistance,
}

impl<'a> InputMeasure<'a> {
    fn new(input: &'a TriangleMesh) -> Option<Self> {
        Some(InputMeasure {
            sampler: SurfaceSampler::new(input).ok()?,
            closest: MeshDistance::new(input).ok()?,
        })
    }

    /// Two-sided distance between the input and `mesh`, [`SEARCH_SAMPLES`] a side.
    fn measure(&self, mesh: &TriangleMesh) -> Option<Measured> {
        let options = DistanceOptions::with_samples(SEARCH_SAMPLES);
        let sampling = |side: u64| SamplingOptions {
            seed: options.seed.wrapping_add(side),
            ..SamplingOptions::with_samples(SEARCH_SAMPLES)
        };
        let sampler = SurfaceSampler::new(mesh).ok()?;
        let closest = MeshDistance::new(mesh).ok()?;
        let there = one_sided_distance(&self.sampler, &closest, &sampling(0));
        let back = one_sided_distance(&sampler, &self.closest, &sampling(1));
        Some(Measured {
            hausdorff: there.max.max(back.max),
            mean: 0.5 * (there.mean + back.mean),
        })
    }
}

impl<'a> BudgetContext<'a> {
    /// The context of a run; `closed` keeps the caps over an open input's holes.
    pub(crate) fn new(
        source: &'a LodSource<'a>,
        level_options: LevelOptions,
        input: Option<&'a TriangleMesh>,
        then: Then,
        closed: bool,
        time_cap: f64,
    ) -> Result<Self, Error> {
        let border = match (input, closed) {
            (Some(mesh), false) => InputBorder::new(mesh)?,
            _ => None,
        };
        let welded = input.map(|m| {
            let mut mesh = m.clone();
            weld_vertices(&mut mesh);
            mesh.remove_unreferenced_vertices();
            let topology = mesh_topology(&mesh);
            (mesh, topology)
        });
        let input_genus = welded.as_ref().and_then(|w| w.1.genus);
        Ok(BudgetContext {
            source,
            level_options,
            input,
            border,
            welded,
            measure: input.and_then(InputMeasure::new),
            input_genus,
            then,
            time_cap,
            diagonal: source.bounds().diagonal(),
            dilated: false,
            levels: Mutex::new(HashMap::new()),
        })
    }

    /// The isodensities each resolution is contoured at: the surface's, then the dilated one.
    fn isos(&self) -> Vec<f32> {
        let surface = self.level_options.iso;
        let dilated = DILATED_ISO_FRACTIONS.map(|f| f * surface);
        std::iter::once(surface)
            .chain(dilated.into_iter().filter(|_| self.dilated))
            .collect()
    }

    /// The marching-cubes level at `resolution` and the seconds it took (built once), at the
    /// surface's isodensity.
    fn level(&self, resolution: usize) -> Result<(LodLevel, f64), Error> {
        self.level_at(resolution, self.level_options.iso)
    }

    /// The marching-cubes level at `resolution` and isodensity `iso`, and the seconds it took
    /// (built once).
    fn level_at(&self, resolution: usize, iso: f32) -> Result<(LodLevel, f64), Error> {
        let key = (resolution, iso.to_bits());
        if let Some(found) = self.levels.lock().expect("not poisoned").get(&key) {
            return Ok(found.clone());
        }
        let start = Instant::now();
        let options = LevelOptions {
            pyramid: PyramidOptions {
                resolutions: vec![resolution],
                ..self.level_options.pyramid.clone()
            },
            iso,
            ..self.level_options.clone()
        };
        let plans = plan(self.source, &options)?;
        let level = build_level(self.source, &plans[0], &options)?;
        let built = (level, start.elapsed().as_secs_f64());
        self.levels
            .lock()
            .expect("not poisoned")
            .insert(key, built.clone());
        Ok(built)
    }

    /// The resolution whose level has about `wanted` triangles (module docs, step 1), the
    /// seconds charged for the probes, and warnings for levels that vanished.
    fn resolution_for(&self, wanted: f64) -> Result<(usize, f64, Vec<String>), Error> {
        self.resolution_for_at(wanted, self.level_options.iso)
    }

    /// [`BudgetContext::resolution_for`] at isodensity `iso`.
    fn resolution_for_at(&self, wanted: f64, iso: f32) -> Result<(usize, f64, Vec<String>), Error> {
        let start = self
            .input
            .and_then(|mesh| resolution_for_triangles(mesh, wanted.round() as usize))
            .unwrap_or(32)
            .clamp(COARSEST, FINEST);
        let (mut resolution, mut charged, mut warnings) = (start, 0.0, Vec::new());
        for _ in 0..5 {
            let (level, seconds) = self.level_at(resolution, iso)?;
            charged += seconds;
            let got = level.mesh.triangle_count();
            let next = if got == 0 {
                warnings.push(format!(
                    "resolution {resolution}: the level vanished (parts thinner than a voxel); \
                     trying {}",
                    (resolution * 2).min(FINEST)
                ));
                resolution * 2
            } else {
                (resolution as f64 * (wanted / got as f64).sqrt()).round() as usize
            };
            let next = next.clamp(COARSEST, FINEST);
            if next == resolution
                || (got > 0 && (got as f64 / wanted - 1.0).abs() < PROBE_TOLERANCE)
            {
                break;
            }
            resolution = next;
        }
        Ok((resolution, charged, warnings))
    }

    /// The level at `resolution` and the surface's isodensity with the caps over the input's
    /// holes cut (unless closed).
    fn uncapped(&self, resolution: usize) -> Result<(LodLevel, usize, f64), Error> {
        self.uncapped_at(resolution, self.level_options.iso)
    }

    /// [`BudgetContext::uncapped`] at isodensity `iso`.
    fn uncapped_at(&self, resolution: usize, iso: f32) -> Result<(LodLevel, usize, f64), Error> {
        let (mut level, seconds) = self.level_at(resolution, iso)?;
        let mut cut = 0;
        if let Some(border) = &self.border {
            let (mesh, n) = cut_caps(&level.mesh, border, 0.5 * level.plan.voxel_size);
            level.mesh = mesh;
            level.topology = mesh_topology(&level.mesh);
            cut = n;
        }
        Ok((level, cut, seconds))
    }

    /// Two-sided distance from the input to `mesh`, when there is an input mesh.
    fn measure(&self, mesh: &TriangleMesh) -> Option<Measured> {
        self.measure.as_ref()?.measure(mesh)
    }

    /// The input mesh collapsed towards `budget` when the budget affords the input's topology
    /// (module docs, step 0): the candidate, and the level that showed it.
    fn input_candidate(
        &self,
        budget: usize,
        error: Option<f64>,
    ) -> Result<Option<(Candidate, LodLevel, f64)>, Error> {
        let Some((input, topology)) = &self.welded else {
            return Ok(None);
        };
        // An open input under `closed` would keep its holes: the voxel levels close them.
        let closed_asked = topology.boundary_loops > 0 && self.border.is_none();
        if matches!(self.then, Then::None | Then::Envelope) || closed_asked {
            return Ok(None);
        }
        let (resolution, charged, _) = self.resolution_for(budget as f64)?;
        let (level, _, _) = self.uncapped(resolution)?;
        let t = &level.topology;
        let keeps =
            |level: Option<i64>, input: Option<i64>| level.zip(input).is_some_and(|(l, i)| l >= i);
        let removes_nothing = keeps(t.genus, topology.genus) && t.components >= topology.components;
        if level.mesh.is_empty() || !removes_nothing {
            return Ok(None);
        }
        let options = QuadricOptions::budget(error.unwrap_or(f64::INFINITY));
        let Ok(done) = simplify_to_budget(input, budget, &options) else {
            return Ok(None);
        };
        let candidate = Candidate {
            distance: self.measure(&done.mesh),
            mesh: done.mesh,
            stage: Stage::InputQuadric,
            error_bound: done.error_bound,
            parts_dropped: 0,
            iso: self.level_options.iso,
        };
        Ok(Some((candidate, level, charged)))
    }
}

/// Refuses budgets no closed surface can meet.
pub(crate) fn check_budgets(budgets: &[usize]) -> Result<(), Error> {
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

/// The level for `budget` (see the module documentation), with an optional error bound for the
/// geometric stage, and the warnings of its search.
pub(crate) fn budget_level(
    ctx: &BudgetContext,
    budget: usize,
    error: Option<f64>,
) -> Result<(LodLevel, BudgetLevel, Vec<String>), Error> {
    let start = Instant::now();
    let mut best: Option<(Candidate, LodLevel, usize)> = None;
    if let Some((candidate, level, _)) = ctx.input_candidate(budget, error)? {
        if fits(&candidate, budget) && closer_than_voxels(ctx, &candidate, budget) {
            let voxel_triangles = level.mesh.triangle_count();
            return Ok(finish(
                ctx,
                (candidate, level, 0),
                voxel_triangles,
                budget,
                error,
                1,
                start,
                Vec::new(),
            ));
        }
        best = Some((candidate, level, 0));
    }
    let headroom = if ctx.then == Then::None {
        1.0
    } else {
        HEADROOM
    };
    let (first, _, mut warnings) = ctx.resolution_for(headroom * budget as f64)?;
    let tries = search_plan(ctx, first, headroom * budget as f64)?;
    // Seconds charged to each isodensity's search (by its bits) against the time cap: its
    // neighbouring levels and the geometric stages, not the probes for its first resolution.
    let mut charged: HashMap<u32, f64> = HashMap::new();
    let mut tried = usize::from(best.is_some());
    // Per resolution tried, the count of its best candidate (for the bisection below).
    let mut counts: Vec<(usize, usize)> = Vec::new();
    // Isodensities (their bits) with a candidate within 10 % of the budget: each isodensity's
    // coarser levels are tried while it has none, whatever the time.
    let mut fitted_isos: Vec<u32> = Vec::new();
    for &Try {
        resolution,
        iso,
        base,
    } in &tries
    {
        let is_first = resolution == base;
        let fitted = fitted_isos.contains(&iso.to_bits())
            || best
                .as_ref()
                .is_some_and(|b| b.0.stage == Stage::InputQuadric && fits(&b.0, budget));
        let over_time = !is_first
            && charged
                .get(&iso.to_bits())
                .is_some_and(|&c| c >= ctx.time_cap);
        if !is_first && fitted && (over_time || resolution < step_down(base)) {
            continue;
        }
        if over_time && resolution > base {
            continue;
        }
        let stage_start = Instant::now();
        let (level, cut, seconds) = ctx.uncapped_at(resolution, iso)?;
        if level.mesh.is_empty() {
            continue;
        }
        for candidate in stages(ctx, &level, iso, budget, error) {
            tried += 1;
            if iso == ctx.level_options.iso {
                counts.push((resolution, candidate.mesh.triangle_count()));
            }
            if fits(&candidate, budget) {
                fitted_isos.push(iso.to_bits());
            }
            if better(&candidate, best.as_ref().map(|b| &b.0), budget) {
                best = Some((candidate, level.clone(), cut));
            }
        }
        let built = if is_first { 0.0 } else { seconds };
        *charged.entry(iso.to_bits()).or_default() += built + stage_start.elapsed().as_secs_f64();
    }
    tried += bisect(ctx, &mut best, &mut counts, budget, error)?;
    if let Some((stalled, level, cut)) = best.as_ref().filter(|b| !fits(&b.0, budget)) {
        // Then::Auto's envelopes, where the quadric stage stalled on every level (step 3).
        if ctx.then == Then::Auto && ctx.input.is_some() {
            let (level, iso) = (level.clone(), stalled.iso);
            if let Some(candidate) = envelope_candidate(ctx, &level, iso, budget, error) {
                tried += 1;
                if better(&candidate, Some(stalled), budget) {
                    best = Some((candidate, level, *cut));
                }
            }
        }
    }
    let Some(chosen) = best else {
        warnings.push(format!(
            "budget {budget}: every resolution tried vanished; the level is empty"
        ));
        let (level, _) = ctx.level(first)?;
        let report = report(ctx, &level, Some(budget), error, 0, tried, start);
        return Ok((level, report, warnings));
    };
    let voxel_triangles = chosen.1.mesh.triangle_count();
    Ok(finish(
        ctx,
        chosen,
        voxel_triangles,
        budget,
        error,
        tried,
        start,
        warnings,
    ))
}

/// Whether `candidate` (the input's own collapse) is measured closer to the input than half a
/// voxel of the resolution whose marching-cubes level would have `4 B` triangles: the accuracy
/// of that level's surface placement, which a geometric stage on it can only add to, so the
/// voxel search could not be expected to do better (module docs, step 0).
fn closer_than_voxels(ctx: &BudgetContext, candidate: &Candidate, budget: usize) -> bool {
    let (Some(input), Some(distance)) = (ctx.input, &candidate.distance) else {
        return false;
    };
    let Some(resolution) = resolution_for_triangles(input, (HEADROOM * budget as f64) as usize)
    else {
        return false;
    };
    let voxel = ctx.source.bounds().longest_extent() / resolution.clamp(COARSEST, FINEST) as f64;
    distance.hausdorff <= 0.5 * voxel
}

/// The level and report of the chosen candidate (on the level it came from, with the caps cut
/// from that level), and the warnings with the note of a missed budget.
#[allow(clippy::too_many_arguments)]
fn finish(
    ctx: &BudgetContext,
    (chosen, mut level, cut): (Candidate, LodLevel, usize),
    voxel_triangles: usize,
    budget: usize,
    error: Option<f64>,
    tried: usize,
    start: Instant,
    mut warnings: Vec<String>,
) -> (LodLevel, BudgetLevel, Vec<String>) {
    level.mesh = chosen.mesh;
    level.topology = mesh_topology(&level.mesh);
    let cut = if chosen.stage == Stage::InputQuadric {
        0
    } else {
        cut
    };
    let mut report = report(ctx, &level, Some(budget), error, cut, tried, start);
    report.voxel_triangles = voxel_triangles;
    report.stage = chosen.stage;
    report.error_bound = chosen.error_bound;
    report.hausdorff = chosen.distance.as_ref().map(|d| d.hausdorff);
    report.mean_distance = chosen.distance.as_ref().map(|d| d.mean);
    report.parts_dropped = chosen.parts_dropped;
    report.iso = chosen.iso;
    report.note = miss_note(&level.topology, budget);
    if let Some(note) = &report.note {
        warnings.push(format!("budget {budget}: {note}"));
    }
    (level, report, warnings)
}

/// The report of `level` before its stage is known: the voxel level's figures.
fn report(
    ctx: &BudgetContext,
    level: &LodLevel,
    budget: Option<usize>,
    error: Option<f64>,
    caps_cut: usize,
    candidates: usize,
    start: Instant,
) -> BudgetLevel {
    let t = &level.topology;
    BudgetLevel {
        budget,
        error_target: error,
        resolution: level.resolution,
        voxel_triangles: level.mesh.triangle_count(),
        caps_cut,
        stage: Stage::Voxel,
        error_bound: 0.5 * level.plan.voxel_size,
        hausdorff: None,
        mean_distance: None,
        triangles: level.mesh.triangle_count(),
        genus: t.genus,
        components: t.components,
        boundary_loops: t.boundary_loops,
        handles_removed: ctx.input_genus.zip(t.genus).map(|(a, b)| a - b),
        parts_dropped: 0,
        iso: ctx.level_options.iso,
        candidates,
        note: None,
        seconds: start.elapsed().as_secs_f64(),
    }
}

/// Why a level misses its budget by more than 10 %, if it does.
fn miss_note(topology: &Topology, budget: usize) -> Option<String> {
    let got = topology.triangles;
    if (got as f64 / budget as f64 - 1.0).abs() <= BUDGET_TOLERANCE {
        return None;
    }
    Some(if got > budget {
        format!(
            "{got} triangles, more than 10 % over the budget: the level's topology (genus {}, \
             {} components, {} boundary loops) or the error bound stopped the simplification",
            topology.genus.map_or("?".to_string(), |g| g.to_string()),
            topology.components,
            topology.boundary_loops
        )
    } else {
        format!(
            "{got} triangles, more than 10 % under the budget: no voxel resolution up to {FINEST} \
             gives more"
        )
    })
}

/// Whether `candidate` beats `best` for `budget`: within 10 % beats outside; then the smaller
/// measured Hausdorff distance (or, unmeasured, the count nearer the budget).
fn better(candidate: &Candidate, best: Option<&Candidate>, budget: usize) -> bool {
    let Some(best) = best else {
        return true;
    };
    let miss = |c: &Candidate| (c.mesh.triangle_count() as f64 / budget as f64).ln().abs();
    match (fits(candidate, budget), fits(best, budget)) {
        (true, false) => true,
        (false, true) => false,
        (false, false) => miss(candidate) < miss(best),
        (true, true) => match (&candidate.distance, &best.distance) {
            (Some(a), Some(b)) => a.hausdorff < b.hausdorff,
            _ => false,
        },
    }
}

/// While nothing fits the budget: bisects between the finest resolution whose candidate stayed
/// under the budget and the coarsest whose candidate stalled over it (at most four tries: a
/// level's topology, and so where the quadric stage stalls, can change quickly with the
/// resolution). The candidates built.
fn bisect(
    ctx: &BudgetContext,
    best: &mut Option<(Candidate, LodLevel, usize)>,
    counts: &mut Vec<(usize, usize)>,
    budget: usize,
    error: Option<f64>,
) -> Result<usize, Error> {
    let mut tried = 0;
    for _ in 0..4 {
        if best.as_ref().is_none_or(|b| fits(&b.0, budget)) {
            break;
        }
        let under = counts.iter().filter(|c| c.1 < budget).map(|c| c.0).max();
        let over = counts.iter().filter(|c| c.1 > budget).map(|c| c.0).min();
        let (Some(low), Some(high)) = (under, over) else {
            break;
        };
        if high <= low + 1 {
            break;
        }
        let resolution = (low + high) / 2;
        let (level, cut, _) = ctx.uncapped(resolution)?;
        counts.push((resolution, level.mesh.triangle_count()));
        let iso = ctx.level_options.iso;
        for candidate in stages(ctx, &level, iso, budget, error) {
            tried += 1;
            counts.push((resolution, candidate.mesh.triangle_count()));
            if better(&candidate, best.as_ref().map(|b| &b.0), budget) {
                *best = Some((candidate, level.clone(), cut));
            }
        }
    }
    Ok(tried)
}

/// One level of a budget's search: its resolution and isodensity, and the first resolution of
/// that isodensity's search (module docs, steps 1 and 4).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Try {
    resolution: usize,
    iso: f32,
    base: usize,
}

/// The levels a budget's search tries, in order: each isodensity's first resolution (about
/// `wanted` triangles at that isodensity; `first` for the surface's), then their finer and
/// coarser neighbours (about twice and half `wanted`), then, only while nothing fits the
/// budget, coarser levels still (about a quarter and an eighth), with less to keep.
fn search_plan(ctx: &BudgetContext, first: usize, wanted: f64) -> Result<Vec<Try>, Error> {
    let mut bases = vec![(ctx.level_options.iso, first)];
    for iso in ctx.isos().into_iter().skip(1) {
        bases.push((iso, ctx.resolution_for_at(wanted, iso)?.0));
    }
    let mut tries: Vec<Try> = bases
        .iter()
        .map(|&(iso, base)| Try {
            resolution: base,
            iso,
            base,
        })
        .collect();
    if ctx.then == Then::None {
        return Ok(tries);
    }
    for f in [2f64, 0.5, 0.25, 0.125] {
        for &(iso, base) in &bases {
            let resolution = ((base as f64 * f.sqrt()).round() as usize).clamp(COARSEST, FINEST);
            let next = Try {
                resolution,
                iso,
                base,
            };
            if !tries
                .iter()
                .any(|t| t.resolution == resolution && t.iso == iso)
            {
                tries.push(next);
            }
        }
    }
    Ok(tries)
}

/// The coarsest resolution of the search's regular neighbours (about `2 B` triangles, for a
/// first resolution of about `4 B`); coarser ones are tried only while nothing fits.
fn step_down(first: usize) -> usize {
    ((first as f64 * 0.5f64.sqrt()).round() as usize).clamp(COARSEST, FINEST)
}

/// Whether `candidate` is within 10 % of `budget` (as a ratio, the same above and below).
fn fits(candidate: &Candidate, budget: usize) -> bool {
    let miss = (candidate.mesh.triangle_count() as f64 / budget as f64)
        .ln()
        .abs();
    miss <= (1.0 + BUDGET_TOLERANCE).ln()
}

/// The geometric stages asked for, applied to `level` for `budget`; a stage that fails is
/// left out (the voxel level itself is the candidate of [`Then::None`]; [`Then::Auto`]'s
/// envelopes run after the search, where the quadric stage stalled).
fn stages(
    ctx: &BudgetContext,
    level: &LodLevel,
    iso: f32,
    budget: usize,
    error: Option<f64>,
) -> Vec<Candidate> {
    let mut out = Vec::new();
    let want_quadric = matches!(ctx.then, Then::Auto | Then::Quadric);
    if ctx.then == Then::None {
        out.push(Candidate {
            mesh: level.mesh.clone(),
            stage: Stage::Voxel,
            error_bound: 0.5 * level.plan.voxel_size,
            distance: ctx.measure(&level.mesh),
            parts_dropped: 0,
            iso,
        });
    }
    if want_quadric {
        let options = PartsOptions {
            quadric: QuadricOptions::budget(error.unwrap_or(f64::INFINITY)),
            ..PartsOptions::default()
        };
        if let Ok(done) = simplify_dropping_parts(&level.mesh, budget, &options) {
            out.push(Candidate {
                distance: ctx.measure(&done.simplified.mesh),
                mesh: done.simplified.mesh,
                stage: Stage::Quadric,
                error_bound: done.simplified.error_bound,
                parts_dropped: done.dropped_parts,
                iso,
            });
        }
    }
    if ctx.then == Then::Envelope {
        out.extend(envelope_candidate(ctx, level, iso, budget, error));
    }
    out
}

/// The envelope stage on `level` for `budget`, measured.
fn envelope_candidate(
    ctx: &BudgetContext,
    level: &LodLevel,
    iso: f32,
    budget: usize,
    error: Option<f64>,
) -> Option<Candidate> {
    let (mesh, epsilon) = envelope_to_count(&level.mesh, budget, error, level)?;
    Some(Candidate {
        distance: ctx.measure(&mesh),
        mesh,
        stage: Stage::Envelope,
        error_bound: epsilon,
        parts_dropped: 0,
        iso,
    })
}

/// Simplification envelopes (tight preset) with ε searched so that the count comes near
/// `budget`: ε starts at one voxel and is scaled by the count's ratio to the budget (counts fall
/// about as 1/ε), at most four runs, ε never above `error`. The run nearest the budget and its ε.
fn envelope_to_count(
    mesh: &TriangleMesh,
    budget: usize,
    error: Option<f64>,
    level: &LodLevel,
) -> Option<(TriangleMesh, f64)> {
    let options = EnvelopeOptions::tight().with_measure_samples(0);
    let cap = error.unwrap_or(f64::INFINITY);
    let mut epsilon = level.plan.voxel_size.min(cap);
    let mut best: Option<(TriangleMesh, f64)> = None;
    for _ in 0..4 {
        let done = simplify_envelope(mesh, Epsilon::Absolute(epsilon), &options).ok()?;
        let got = done.mesh.triangle_count().max(1);
        let miss = |n: usize| (n as f64 / budget as f64).ln().abs();
        if best
            .as_ref()
            .is_none_or(|b| miss(got) < miss(b.0.triangle_count()))
        {
            best = Some((done.mesh, epsilon));
        }
        if miss(got) <= (1.0 + BUDGET_TOLERANCE).ln() {
            break;
        }
        let next = (epsilon * got as f64 / budget as f64).min(cap);
        if next == epsilon {
            break;
        }
        epsilon = next;
    }
    best
}

/// The level for an error target alone: the resolution whose voxel is `error`, then the
/// quadric stage within `error`.
pub(crate) fn error_level(
    ctx: &BudgetContext,
    error: f64,
) -> Result<(LodLevel, BudgetLevel, Vec<String>), Error> {
    let start = Instant::now();
    let longest = ctx.source.bounds().longest_extent();
    let resolution = ((longest / error).ceil() as usize).clamp(COARSEST, FINEST);
    let (mut level, cut, _) = ctx.uncapped(resolution)?;
    let mut warnings = Vec::new();
    if level.mesh.is_empty() {
        warnings.push(format!(
            "error {error}: the level at resolution {resolution} vanished (parts thinner than a \
             voxel); the level is empty"
        ));
        let report = report(ctx, &level, None, Some(error), cut, 0, start);
        return Ok((level, report, warnings));
    }
    let voxel_triangles = level.mesh.triangle_count();
    let mut stage = (Stage::Voxel, 0.5 * level.plan.voxel_size);
    if ctx.then != Then::None {
        let options = QuadricOptions::bounded(0.5 * error);
        if let Ok(done) = simplify_to_budget(&level.mesh, 4, &options) {
            level.mesh = done.mesh;
            level.topology = done.topology;
            stage = (Stage::Quadric, done.error_bound);
        }
    }
    let mut report = report(ctx, &level, None, Some(error), cut, 1, start);
    report.voxel_triangles = voxel_triangles;
    (report.stage, report.error_bound) = stage;
    let distance = ctx.measure(&level.mesh);
    report.hausdorff = distance.as_ref().map(|d| d.hausdorff);
    report.mean_distance = distance.as_ref().map(|d| d.mean);
    Ok((level, report, warnings))
}

/// [`crate::lod_with`] for budgets or an error target (the options are checked): one level per
/// budget, in the order given, or one for the error target alone.
pub(crate) fn lod_by_budget(
    source: &Source,
    options: &LodOptions,
    progress: &ProgressFn,
) -> Result<Lod, Error> {
    let start = Instant::now();
    let prepared = source.prepare()?;
    let iso = prepared.iso(options.iso)?;
    let level_options = LevelOptions {
        pyramid: options.pyramid.clone(),
        iso,
        normals: options.normals,
        clean: Some(voxlod_contouring::CleanOptions::default()),
    };
    let lod_source = prepared.lod_source();
    let input = match source {
        Source::Mesh(mesh) => Some(*mesh),
        _ => None,
    };
    let mut ctx = BudgetContext::new(
        &lod_source,
        level_options,
        input,
        options.then,
        options.closed,
        options.time_cap,
    )?;
    ctx.dilated = input.is_some() && options.iso.is_none() && options.then != Then::None;
    let error = options.error.map(|e| e.distance(ctx.diagonal));
    let budgets = options.triangles.clone().unwrap_or_default();
    let mut tracker = Tracker::start(progress, budgets.len().max(1))?;
    let mut warnings = prepared.warnings().to_vec();
    let (mut levels, mut reports) = (Vec::new(), Vec::new());
    let mut done = |level: LodLevel, report, more: Vec<String>, tracker: &mut Tracker| {
        warnings.extend(more);
        tracker.step(levels.len(), "budget level")?;
        tracker.ask(Event::LodLevel(&level))?;
        levels.push(level);
        reports.push(report);
        Ok::<(), Error>(())
    };
    if budgets.is_empty() {
        let (level, report, more) = error_level(&ctx, error.unwrap_or(f64::INFINITY))?;
        done(level, report, more, &mut tracker)?;
    }
    for (i, &budget) in budgets.iter().enumerate() {
        let (level, report, more) = budget_level(&ctx, budget, error)
            .map_err(|e| e.context(format!("budget {budget} (level {i})")))?;
        done(level, report, more, &mut tracker)?;
    }
    Ok(Lod {
        levels,
        route: prepared.route(),
        preparation: prepared.preparation().copied(),
        iso,
        warnings,
        budgets: reports,
        finest: None,
        seconds: start.elapsed().as_secs_f64(),
    })
}
