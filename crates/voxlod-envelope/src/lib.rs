//! Simplification envelopes (Varshney, Agarwal, Brooks, Wright and Weber, "Generating levels of
//! detail for large-scale polygonal models", 1995): levels of detail in which every point of the
//! output lies within ε of the input and every point of the input within ε of the output, with
//! the input's topology (genus, components, border loops) and a subset of its vertices.
//!
//! The pipeline of one level:
//!
//! 1. [`offsets`]: the two offset surfaces P(+ε) and P(−ε), each vertex's ε shrunk where a full
//!    offset would leave its own triangles' Voronoi regions (§4.3, tested with a BVH instead of
//!    the paper's octree) and, our addition, wherever the offsets still cross themselves.
//! 2. [`removal`]: vertex removal between the offsets (§7), in the greedy order of §6.2–6.3:
//!    remove a vertex, retriangulate its hole from its neighbours ([`retriangulate`]), keep the
//!    result only if no new triangle touches either offset ([`obstacles`], [`geometry`]), the
//!    mesh stays a manifold of the same topology and nothing folds over.
//! 3. A series ([`envelope_series`]): level i simplifies level i − 1 (Table 2), with ε growing.
//!    Every level's offsets are built around the **input**, so level i is within its own ε of the
//!    input, not of level i − 1 (the paper does not say which; errors do not add up this way).
//!
//! Options (§6.5): edges sharper than a dihedral angle kept ([`features`]), and boxes with their
//! own ε ([`RegionEpsilon`]). The input must be a consistently oriented manifold ([`manifold`]:
//! the check names the offending edges; [`repair_for_envelope`] cuts a mesh into one).
//!
//! Deviations from the paper: border vertices are kept, so the border is exact (the paper
//! assumes closed objects); vertex normals are angle-weighted, and can be smoothed; the
//! offsets are checked for crossings after the Voronoi limit, and can be limited by that check
//! alone ([`EnvelopeOptions::tight`] does both, with the smallest-deviation-first order); new
//! triangles are also checked against the current mesh; the candidate-triangle
//! set-partition variant of §5–6.1 is not built (its vertex-removal variant is what the paper's
//! results use); §6.4's α(1 + lg d) is estimated for the vertex-removal greedy.
//!
//! Cost, per level: the offsets take one closest-point query per vertex and side (more where the
//! Voronoi limit bisects) and a few rounds of triangle queries over the 2F offset triangles; the
//! removals take O(k³) planning per attempt, a BVH query per proposed triangle against the
//! offsets and one against the current mesh, in parallel batches. Memory: O(V + F), with three
//! BVHs (the two offsets, the current mesh) beside the input's closest-point BVH. The bunny
//! (69,451 triangles) takes a few seconds at 1 % on two cores (figures in BENCHMARKS.md).

mod base;
pub mod checks;
pub mod epsilon;
pub mod error;
pub mod features;
pub mod geometry;
mod live;
pub mod manifold;
pub mod obstacles;
pub mod offsets;
pub mod removal;
pub mod retriangulate;

use std::ops::ControlFlow;
use std::time::Instant;

use serde::Serialize;
use voxlod_core::{mesh_topology, Topology, TriangleMesh};
use voxlod_metrics::{mesh_distance, DistanceOptions};

pub use checks::self_intersections;
pub use epsilon::{Epsilon, RegionEpsilon};
pub use error::EnvelopeError;
pub use manifold::{
    check_manifold, manifold_problems, repair_for_envelope, ManifoldProblems, ManifoldRepair,
};
pub use offsets::{OffsetReport, OffsetRule};
pub use removal::{RemovalOrder, RemovalReport, MAX_VALENCE};

use base::Base;
use offsets::Offsets;
use removal::{RemovalSettings, Work};

/// How to simplify.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EnvelopeOptions {
    /// Which removal to try first (§6.2–6.3).
    pub order: RemovalOrder,
    /// How the offsets' ε is limited (§4.3).
    pub offsets: OffsetRule,
    /// Rounds of smoothing of the vertex normals along which the offsets go (0: the raw
    /// normals, as the paper).
    pub normal_smoothing: usize,
    /// Keep every edge whose dihedral angle exceeds this many degrees (§6.5).
    pub keep_sharp: Option<f64>,
    /// Boxes with their own ε, as a multiple of the level's (§6.5).
    pub regions: Vec<RegionEpsilon>,
    /// Smallest aspect ratio of a new triangle (1 for equilateral, 0 allows slivers).
    pub min_aspect: f64,
    /// Vertices with more neighbours are kept (at most [`MAX_VALENCE`]).
    pub max_valence: usize,
    /// Points per side for measuring each level's two-sided distance to the input (0: do not
    /// measure).
    pub measure_samples: usize,
}

impl Default for EnvelopeOptions {
    /// The paper's method: coverage order, Voronoi-limited offsets; no edges kept; triangles of
    /// aspect ratio ≥ 0.05; valence ≤ 16; each level measured with 100 000 points per side.
    fn default() -> Self {
        EnvelopeOptions {
            order: RemovalOrder::Coverage,
            offsets: OffsetRule::Voronoi,
            normal_smoothing: 0,
            keep_sharp: None,
            regions: Vec::new(),
            min_aspect: 0.05,
            max_valence: 16,
            measure_samples: 100_000,
        }
    }
}

impl EnvelopeOptions {
    /// The default: the paper's order and offsets.
    pub fn paper() -> Self {
        EnvelopeOptions::default()
    }

    /// As [`paper`](Self::paper) but without measuring the result (for timing and pipelines).
    pub fn unmeasured() -> Self {
        EnvelopeOptions {
            measure_samples: 0,
            ..Default::default()
        }
    }

    /// Offsets shrunk only where they really cross (less cautious than §4.3).
    pub fn less_cautious() -> Self {
        EnvelopeOptions {
            offsets: OffsetRule::CrossingsOnly,
            ..Default::default()
        }
    }

    /// Our best: offsets along normals smoothed 20 rounds and shrunk only where they cross,
    /// removals with the smallest deviation first. Same guarantees as the paper's method, far
    /// fewer triangles at coarse levels, and faster.
    pub fn tight() -> Self {
        EnvelopeOptions {
            order: RemovalOrder::Deviation,
            offsets: OffsetRule::CrossingsOnly,
            normal_smoothing: 20,
            ..Default::default()
        }
    }

    pub fn with_keep_sharp(mut self, degrees: f64) -> Self {
        self.keep_sharp = Some(degrees);
        self
    }

    pub fn with_order(mut self, order: RemovalOrder) -> Self {
        self.order = order;
        self
    }

    pub fn with_regions(mut self, regions: Vec<RegionEpsilon>) -> Self {
        self.regions = regions;
        self
    }

    pub fn with_normal_smoothing(mut self, rounds: usize) -> Self {
        self.normal_smoothing = rounds;
        self
    }

    pub fn with_measure_samples(mut self, samples: usize) -> Self {
        self.measure_samples = samples;
        self
    }

    fn check(&self) -> Result<(), EnvelopeError> {
        if !(0.0..1.0).contains(&self.min_aspect) {
            return Err(EnvelopeError::InvalidOption {
                what: "the smallest aspect ratio",
                expected: "in [0, 1)",
                value: self.min_aspect,
            });
        }
        if self.normal_smoothing > 1000 {
            return Err(EnvelopeError::InvalidOption {
                what: "the rounds of normal smoothing",
                expected: "at most 1000",
                value: self.normal_smoothing as f64,
            });
        }
        if !(3..=MAX_VALENCE).contains(&self.max_valence) {
            return Err(EnvelopeError::InvalidOption {
                what: "the largest valence",
                expected: "between 3 and 32",
                value: self.max_valence as f64,
            });
        }
        if let Some(d) = self.keep_sharp {
            if !(d > 0.0 && d < 180.0) {
                return Err(EnvelopeError::InvalidOption {
                    what: "the sharp-edge angle",
                    expected: "between 0 and 180 degrees",
                    value: d,
                });
            }
        }
        Ok(())
    }
}

/// The two-sided distance of a level to the input, measured by sampling both surfaces.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct MeasuredDistance {
    /// Largest sampled distance, either way: a lower bound of the Hausdorff distance.
    pub hausdorff: f64,
    /// `hausdorff / ε`: at most 1 when the guarantee holds.
    pub hausdorff_over_epsilon: f64,
    pub mean: f64,
    pub samples_per_side: usize,
    pub seconds: f64,
}

/// The figures of one level.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EnvelopeReport {
    /// 0 for the first (finest) level.
    pub level: usize,
    /// ε as given.
    pub epsilon_given: Epsilon,
    /// ε in the mesh's units, and as a fraction of the bounding-box diagonal.
    pub epsilon: f64,
    pub epsilon_fraction: f64,
    pub input_triangles: usize,
    pub triangles: usize,
    pub vertices: usize,
    /// Triangles removed, in percent of the input's (cumulative, as in the paper's Table 2).
    pub reduction_percent: f64,
    /// Wall time of this level: offsets and removals (level 0 also checks and prepares the
    /// input), without measuring.
    pub seconds: f64,
    pub offsets: OffsetReport,
    pub removal: RemovalReport,
    /// §6.4: α(1 + lg d); the optimum has at least `triangles / quality_factor` triangles.
    pub quality_factor: f64,
    pub topology: Topology,
    pub distance: Option<MeasuredDistance>,
}

/// One level of detail.
#[derive(Clone, Debug)]
pub struct EnvelopeLevel {
    /// The simplified mesh: a subset of the input's vertices (with their normals, or
    /// angle-weighted normals when the input has none).
    pub mesh: TriangleMesh,
    /// For each vertex of `mesh`, the input vertex it is (increasing).
    pub vertex_map: Vec<u32>,
    pub report: EnvelopeReport,
}

/// Simplifies `mesh` within `epsilon` (one level).
pub fn simplify_envelope(
    mesh: &TriangleMesh,
    epsilon: Epsilon,
    options: &EnvelopeOptions,
) -> Result<EnvelopeLevel, EnvelopeError> {
    let mut levels = envelope_series(mesh, &[epsilon], options)?;
    Ok(levels.remove(0))
}

/// A series of levels, level i simplifying level i − 1 with its own ε (paper Table 2).
pub fn envelope_series(
    mesh: &TriangleMesh,
    epsilons: &[Epsilon],
    options: &EnvelopeOptions,
) -> Result<Vec<EnvelopeLevel>, EnvelopeError> {
    let mut levels = Vec::with_capacity(epsilons.len());
    envelope_series_with(mesh, epsilons, options, |level| {
        levels.push(level);
    })?;
    Ok(levels)
}

/// [`envelope_series`], handing each level to `each` as soon as it is made.
pub fn envelope_series_with(
    mesh: &TriangleMesh,
    epsilons: &[Epsilon],
    options: &EnvelopeOptions,
    mut each: impl FnMut(EnvelopeLevel),
) -> Result<(), EnvelopeError> {
    envelope_series_until(mesh, epsilons, options, |level| {
        each(level);
        ControlFlow::Continue(())
    })
}

/// [`envelope_series_with`], stopping before the next level when `each` breaks (so a caller
/// can cancel a long series between levels).
pub fn envelope_series_until(
    mesh: &TriangleMesh,
    epsilons: &[Epsilon],
    options: &EnvelopeOptions,
    mut each: impl FnMut(EnvelopeLevel) -> ControlFlow<()>,
) -> Result<(), EnvelopeError> {
    let start = Instant::now();
    options.check()?;
    if epsilons.is_empty() {
        return Err(EnvelopeError::InvalidOption {
            what: "the number of levels",
            expected: "at least 1",
            value: 0.0,
        });
    }
    for e in epsilons {
        e.check()?;
    }
    let base = Base::new(mesh, options.normal_smoothing)?;
    let n = base.vertex_count();
    let resolved: Vec<f64> = epsilons.iter().map(|e| e.resolve(base.diagonal)).collect();
    for (i, w) in resolved.windows(2).enumerate() {
        if w[1] < w[0] {
            return Err(EnvelopeError::EpsilonNotGrowing {
                level: i + 1,
                epsilon: w[1],
            });
        }
    }
    let scales = epsilon::region_scales(&base.pos, &options.regions);
    let sharp = match options.keep_sharp {
        Some(degrees) => features::sharp_vertices(&base, degrees).0,
        None => vec![false; n],
    };
    let always_fixed: Vec<bool> = (0..n)
        .map(|v| {
            !base.is_used(v) || base.border[v] || sharp[v] || base.normals[v] == glam::DVec3::ZERO
        })
        .collect();
    let mut work = Work::new(&base);
    let mut level_start = start;
    for (index, (&given, &eps)) in epsilons.iter().zip(&resolved).enumerate() {
        let target: Vec<f64> = (0..n)
            .map(|v| {
                if base.is_used(v) {
                    eps * scales[v]
                } else {
                    0.0
                }
            })
            .collect();
        let offsets = Offsets::new(&base, &target, options.offsets)?;
        let envelope = offsets.envelope(&base)?;
        let fixed: Vec<bool> = (0..n)
            .map(|v| always_fixed[v] || offsets.outer[v] <= 0.0 || offsets.inner[v] <= 0.0)
            .collect();
        let removal = work.run(&RemovalSettings {
            target: &target,
            fixed: &fixed,
            envelope: &envelope,
            order: options.order,
            min_aspect: options.min_aspect,
            max_valence: options.max_valence,
        });
        drop(envelope);
        let (out, vertex_map) = work.snapshot(mesh);
        let seconds = level_start.elapsed().as_secs_f64();
        let distance = if options.measure_samples > 0 {
            let t = Instant::now();
            let d = mesh_distance(
                mesh,
                &out,
                &DistanceOptions::with_samples(options.measure_samples),
            )?;
            Some(MeasuredDistance {
                hausdorff: d.hausdorff,
                hausdorff_over_epsilon: d.hausdorff / eps,
                mean: d.mean,
                samples_per_side: options.measure_samples,
                seconds: t.elapsed().as_secs_f64(),
            })
        } else {
            None
        };
        let d = removal.max_cover.max(1) as f64;
        let report = EnvelopeReport {
            level: index,
            epsilon_given: given,
            epsilon: eps,
            epsilon_fraction: eps / base.diagonal,
            input_triangles: mesh.triangles.len(),
            triangles: out.triangles.len(),
            vertices: out.positions.len(),
            reduction_percent: 100.0
                * (1.0 - out.triangles.len() as f64 / mesh.triangles.len() as f64),
            seconds,
            offsets: offsets.report.clone(),
            quality_factor: removal.alpha * (1.0 + d.log2()),
            removal,
            topology: mesh_topology(&out),
            distance,
        };
        debug_assert_eq!(work.triangle_count(), out.triangles.len());
        let level = EnvelopeLevel {
            mesh: out,
            vertex_map,
            report,
        };
        if each(level).is_break() {
            break;
        }
        level_start = Instant::now();
    }
    Ok(())
}
