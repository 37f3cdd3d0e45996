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
//!
//! # Example
//!
//! A torus of 48 × 24 quads (2 304 triangles, genus 1) at 1 % and then 4 % of its diagonal:
//! each level has fewer triangles than the one before, stays a closed, consistently oriented
//! manifold of genus 1, keeps only input vertices, and is measured within its ε.
//!
//! ```
//! use glam::Vec3;
//! use voxlod_core::{mesh_topology, TriangleMesh};
//! use voxlod_envelope::{envelope_series, EnvelopeOptions, Epsilon};
//!
//! let (n, m) = (48u32, 24u32);
//! let tau = std::f32::consts::TAU;
//! let mut positions = Vec::new();
//! for i in 0..n {
//!     for j in 0..m {
//!         let (u, v) = (tau * i as f32 / n as f32, tau * j as f32 / m as f32);
//!         let r = 1.0 + 0.4 * v.cos();
//!         positions.push(Vec3::new(r * u.cos(), r * u.sin(), 0.4 * v.sin()));
//!     }
//! }
//! let id = |i: u32, j: u32| (i % n) * m + j % m;
//! let mut triangles = Vec::new();
//! for i in 0..n {
//!     for j in 0..m {
//!         triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
//!         triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
//!     }
//! }
//! let torus = TriangleMesh::new(positions, triangles);
//!
//! let options = EnvelopeOptions::paper().with_measure_samples(20_000);
//! let epsilons = [Epsilon::percent(1.0), Epsilon::percent(4.0)];
//! let levels = envelope_series(&torus, &epsilons, &options)?;
//! assert!(levels[0].mesh.triangles.len() < torus.triangles.len());
//! assert!(levels[1].mesh.triangles.len() < levels[0].mesh.triangles.len());
//! for level in &levels {
//!     let topology = mesh_topology(&level.mesh);
//!     assert!(topology.is_closed_manifold() && topology.is_consistently_oriented());
//!     assert_eq!(topology.genus, Some(1));
//!     for (kept, &input) in level.mesh.positions.iter().zip(&level.vertex_map) {
//!         assert_eq!(*kept, torus.positions[input as usize]);
//!     }
//!     let distance = level.report.distance.expect("measured");
//!     assert!(distance.hausdorff <= level.report.epsilon * (1.0 + 1e-9));
//! }
//! # Ok::<(), voxlod_envelope::EnvelopeError>(())
//! ```

#![warn(missing_docs)]

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
pub use error::{EnvelopeError, ManifoldProblems};
pub use manifold::{check_manifold, manifold_problems, repair_for_envelope, ManifoldRepair};
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

    /// The same, keeping every edge sharper than `degrees` (§6.5).
    pub fn with_keep_sharp(mut self, degrees: f64) -> Self {
        self.keep_sharp = Some(degrees);
        self
    }

    /// The same with another removal order.
    pub fn with_order(mut self, order: RemovalOrder) -> Self {
        self.order = order;
        self
    }

    /// The same with these boxes of their own ε (§6.5).
    pub fn with_regions(mut self, regions: Vec<RegionEpsilon>) -> Self {
        self.regions = regions;
        self
    }

    /// The same with `rounds` of normal smoothing.
    pub fn with_normal_smoothing(mut self, rounds: usize) -> Self {
        self.normal_smoothing = rounds;
        self
    }

    /// The same, measuring each level with `samples` points per side (0: not at all).
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
    /// Mean sampled distance, both ways.
    pub mean: f64,
    /// Points sampled on each surface.
    pub samples_per_side: usize,
    /// Wall time of the measuring.
    pub seconds: f64,
}

/// The figures of one level.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EnvelopeReport {
    /// 0 for the first (finest) level.
    pub level: usize,
    /// ε as given.
    pub epsilon_given: Epsilon,
    /// ε in the mesh's units.
    pub epsilon: f64,
    /// ε as a fraction of the bounding-box diagonal.
    pub epsilon_fraction: f64,
    /// Triangles of the input.
    pub input_triangles: usize,
    /// Triangles of this level.
    pub triangles: usize,
    /// Vertices of this level.
    pub vertices: usize,
    /// Triangles removed, in percent of the input's (cumulative, as in the paper's Table 2).
    pub reduction_percent: f64,
    /// Wall time of this level: offsets and removals (level 0 also checks and prepares the
    /// input), without measuring.
    pub seconds: f64,
    /// How the offsets' ε were limited.
    pub offsets: OffsetReport,
    /// What the removals did.
    pub removal: RemovalReport,
    /// §6.4: α(1 + lg d); the optimum has at least `triangles / quality_factor` triangles.
    pub quality_factor: f64,
    /// Topology of this level (the input's, by construction).
    pub topology: Topology,
    /// The measured distance to the input, when the options ask for it.
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
    /// The level's figures.
    pub report: EnvelopeReport,
}

/// Simplifies `mesh` within `epsilon` (one level).
///
/// # Errors
///
/// [`EnvelopeError::EmptyMesh`], [`EnvelopeError::IndexOutOfRange`],
/// [`EnvelopeError::NonFiniteCoordinate`] and [`EnvelopeError::NotManifold`] for an input it
/// cannot take (see [`repair_for_envelope`] for the last), [`EnvelopeError::InvalidEpsilon`] and
/// [`EnvelopeError::InvalidOption`] for bad settings.
///
/// # Example
///
/// The icosahedron subdivided three times (1 280 triangles on the unit sphere) within 2 % of
/// its diagonal: far fewer triangles, still a closed sphere, every input vertex within ε.
///
/// ```
/// use voxlod_core::mesh_topology;
/// use voxlod_envelope::{simplify_envelope, EnvelopeOptions, Epsilon};
/// use voxlod_metrics::MeshDistance;
///
/// let sphere = voxlod_testkit::shapes::icosphere(3);
/// let options = EnvelopeOptions::unmeasured();
/// let level = simplify_envelope(&sphere, Epsilon::percent(2.0), &options)?;
/// assert!(level.mesh.triangles.len() < sphere.triangles.len() / 2);
/// let topology = mesh_topology(&level.mesh);
/// assert!(topology.is_closed_manifold());
/// assert_eq!((topology.genus, topology.components), (Some(0), 1));
/// let inputs: Vec<_> = sphere.positions.iter().map(|p| p.as_dvec3()).collect();
/// let distances = MeshDistance::new(&level.mesh)?.distances(&inputs);
/// let farthest = distances.into_iter().fold(0.0, f64::max);
/// assert!(farthest <= level.report.epsilon * (1.0 + 1e-9));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
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
    let resolved: Vec<f64> = epsilons.iter().map(|e| e.resolve(base.diagonal)).collect();
    for (i, w) in resolved.windows(2).enumerate() {
        if w[1] < w[0] {
            return Err(EnvelopeError::EpsilonNotGrowing {
                level: i + 1,
                epsilon: w[1],
            });
        }
    }
    let series = Series {
        mesh,
        options,
        scales: epsilon::region_scales(&base.pos, &options.regions),
        always_fixed: always_fixed(&base, options),
        base: &base,
    };
    let mut work = Work::new(&base);
    let mut level_start = start;
    for (index, (&given, &eps)) in epsilons.iter().zip(&resolved).enumerate() {
        if each(series.level(&mut work, index, (given, eps), level_start)?).is_break() {
            break;
        }
        level_start = Instant::now();
    }
    Ok(())
}

/// The vertices no level may remove: unused, on the border, on a kept sharp edge (§6.5), or
/// without a normal.
fn always_fixed(base: &Base, options: &EnvelopeOptions) -> Vec<bool> {
    let n = base.vertex_count();
    let sharp = match options.keep_sharp {
        Some(degrees) => features::sharp_vertices(base, degrees).0,
        None => vec![false; n],
    };
    (0..n)
        .map(|v| {
            !base.is_used(v) || base.border[v] || sharp[v] || base.normals[v] == glam::DVec3::ZERO
        })
        .collect()
}

/// What every level of one series shares.
struct Series<'a> {
    mesh: &'a TriangleMesh,
    base: &'a Base,
    options: &'a EnvelopeOptions,
    /// Each vertex's ε as a multiple of the level's ([`RegionEpsilon`]).
    scales: Vec<f64>,
    always_fixed: Vec<bool>,
}

impl Series<'_> {
    /// Level `index` of ε `given` (`eps` in mesh units): the offsets around the input, then
    /// removals from the previous level's mesh in `work`; measured if the options ask.
    fn level(
        &self,
        work: &mut Work,
        index: usize,
        (given, eps): (Epsilon, f64),
        level_start: Instant,
    ) -> Result<EnvelopeLevel, EnvelopeError> {
        let (base, options, mesh) = (self.base, self.options, self.mesh);
        let n = base.vertex_count();
        let target: Vec<f64> = (0..n)
            .map(|v| {
                if base.is_used(v) {
                    eps * self.scales[v]
                } else {
                    0.0
                }
            })
            .collect();
        let offsets = Offsets::new(base, &target, options.offsets)?;
        let envelope = offsets.envelope(base)?;
        let fixed: Vec<bool> = (0..n)
            .map(|v| self.always_fixed[v] || offsets.outer[v] <= 0.0 || offsets.inner[v] <= 0.0)
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
        let distance = measure(mesh, &out, eps, options.measure_samples)?;
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
        Ok(EnvelopeLevel {
            mesh: out,
            vertex_map,
            report,
        })
    }
}

/// The two-sided distance between `mesh` and `out` by `samples` points per side; `None` when
/// `samples` is 0.
fn measure(
    mesh: &TriangleMesh,
    out: &TriangleMesh,
    eps: f64,
    samples: usize,
) -> Result<Option<MeasuredDistance>, EnvelopeError> {
    if samples == 0 {
        return Ok(None);
    }
    let t = Instant::now();
    let d = mesh_distance(mesh, out, &DistanceOptions::for_samples(samples))?;
    Ok(Some(MeasuredDistance {
        hausdorff: d.hausdorff,
        hausdorff_over_epsilon: d.hausdorff / eps,
        mean: d.mean,
        samples_per_side: samples,
        seconds: t.elapsed().as_secs_f64(),
    }))
}
