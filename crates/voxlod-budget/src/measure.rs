//! Two-sided distances between a candidate and the input ([`Measure`]), as the portfolio
//! weighs them: sampled Hausdorff distance (the largest distance found from points of either
//! surface to the other) and mean distance (over the area samples of both).
//!
//! The input's side is built once per run: its closest-point structure, and two sets of points
//! on it, a quick set and a careful set, each stratified by area plus one vertex of every
//! connected part (area samples can miss a tiny part altogether, and a tiny part lost far from
//! the rest sets the Hausdorff distance). Where only the seen surface is measured (module
//! `visible`), the sets keep only the points a view sees. A candidate's side is its own
//! closest-point structure, its area samples and its vertices (a vertex moved off the surface
//! is where its side's largest distance lies; at most as many as area samples, every k-th
//! beyond). Points and vertices count in the Hausdorff distances only.
//!
//! **Shape and parts.** The largest distance over the area samples and the candidate's
//! vertices is the candidate's *shape* distance; with the input's part points too, its
//! Hausdorff distance. The choice ranks by shape: where every candidate loses the same speck
//! far from the rest (a CT surface's stray voxels), the Hausdorff distances all equal the
//! speck's and say nothing about the shapes.
//!
//! **Early rejection.** A quick measurement is given a limit, the shape distance that already
//! rules the candidate out; it stops as soon as one point is farther, so a candidate far from
//! the input costs a fraction of its queries.
//!
//! Cost per candidate: its BVH (O(F log F) for its F triangles) and `2 × samples + V`
//! closest-point queries, O(log) each, on all threads.

use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;
use serde::Serialize;
use voxlod_core::glam::DVec3;
use voxlod_core::TriangleMesh;
use voxlod_fit::{fit_with, FitOptions, Fitted};
use voxlod_metrics::spatial_order::z_order;
use voxlod_metrics::{MeshDistance, QueryHint, SamplingOptions, SurfaceSampler};
use voxlod_render::SilhouetteReference;

use crate::input::Input;
use crate::visible::seen_only;
use crate::BudgetError;

/// Views of the silhouettes [`Measure::silhouette`] compares (the octant diagonals and the
/// axes, as `voxlod evaluate` draws them).
pub const VIEWS: usize = 14;
/// Pixels a side of each of those views.
pub const SIZE: u32 = 256;

/// A sampled two-sided distance, in mesh units.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Distance {
    /// The largest distance found, either way, the input's part points included.
    pub hausdorff: f64,
    /// The largest distance over the area samples and the candidate's vertices (module docs).
    pub shape: f64,
    /// The mean over the area samples of both sides.
    pub mean: f64,
}

/// How densely a measurement samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Care {
    /// The quick set: ranks every candidate.
    Quick,
    /// The careful set: decides between the closest and is reported.
    Careful,
    /// [`PRECISE_FACTOR`] times the careful set's samples: settles near ties between the
    /// closest two.
    Precise,
}

/// The precise set has this many times the careful set's samples: near ties are within a few
/// per cent, so a wrong pick costs little, and five times cost up to half a second a chain on
/// inputs with many ties (one level of 130 in the corpus chose differently, 3 % farther).
pub const PRECISE_FACTOR: usize = 2;

/// The input's side of every measurement (module docs).
pub struct Measure<'a> {
    closest: MeshDistance,
    quick: Points,
    careful: Points,
    /// The precise set, drawn on first use from `sampler` with `precise_samples` area samples
    /// and the part points.
    precise: std::sync::OnceLock<Points>,
    sampler: SurfaceSampler<'a>,
    precise_samples: usize,
    part_points: Vec<DVec3>,
    /// The input, whose silhouettes are drawn on first use (module `outline`).
    input_mesh: &'a TriangleMesh,
    outline: std::sync::OnceLock<Option<SilhouetteReference>>,
}

/// Points on one surface: area samples (mean, shape and Hausdorff), extra points (shape and
/// Hausdorff: a candidate's vertices) and part points (Hausdorff only: the input's parts),
/// each list in Z-order for coherent queries.
struct Points {
    area: Vec<DVec3>,
    extra: Vec<DVec3>,
    parts: Vec<DVec3>,
}

/// A fit's samples per vertex of the level fitted ([`Measure::fit_samples`]). On the budget
/// bench's 93 inputs, with collapse levels fitted too (as first tried: inside the choice,
/// without module `chain`'s share cap), fits on the whole careful set (10 000 points) cost 9 %
/// more CPU than no such fits; on 8 per vertex and at least the quick fit's 5 000, 2–5 %, and
/// the levels measure as close (377 levels: geometric mean of the Hausdorff ratios 0.997). A
/// floor of 2 000 costs nothing more, but puts the sphereflake's level at 300 a quarter
/// farther.
pub const FIT_SAMPLES_PER_VERTEX: usize = 8;

/// The most parts given a point of their own.
const PART_POINTS: usize = 10_000;

/// Seeds of the input's and the candidates' samples (apart from the fit's own).
const INPUT_SEED: u64 = 0x6275_6467_6574; // "budget"
const CANDIDATE_SEED: u64 = INPUT_SEED + 1;

impl<'a> Measure<'a> {
    /// The input's side, with `quick` and `careful` area samples. Fails only on the memory
    /// budget (the input is prepared, so it has area).
    pub fn new(input: &'a Input, quick: usize, careful: usize) -> Result<Measure<'a>, BudgetError> {
        let sampler = SurfaceSampler::new(input.measured())?;
        let mesh = &input.mesh;
        // One vertex of each part's first measured triangle (parts none of whose triangles
        // counts have none).
        let firsts: Vec<u32> = (input.parts.iter())
            .filter_map(|p| p.iter().copied().find(|&t| input.is_measured(t)))
            .collect();
        let step = firsts.len().div_ceil(PART_POINTS).max(1);
        let part_points: Vec<DVec3> = (firsts.iter().step_by(step))
            .map(|&t| mesh.positions[mesh.triangles[t as usize][0] as usize].as_dvec3())
            .collect();
        let area = |n: usize| -> Result<Vec<DVec3>, BudgetError> {
            let options = SamplingOptions {
                seed: INPUT_SEED,
                ..SamplingOptions::for_samples(n)
            };
            Ok(sampler
                .samples(&options)?
                .into_iter()
                .map(|s| s.point)
                .collect())
        };
        let precise_samples = PRECISE_FACTOR * careful;
        let precise = std::sync::OnceLock::new();
        let (mut quick, mut careful) = (area(quick)?, area(careful)?);
        // Where only what is seen is measured, the points of the seen triangles that no view
        // sees go (module `visible`): all three sets at once, for one drawing of the views.
        if input.seen.is_some() {
            let mut precise_area = area(precise_samples)?;
            seen_only(input, [&mut quick, &mut careful, &mut precise_area])?;
            let _ = precise.set(Points::ordered(
                precise_area,
                Vec::new(),
                part_points.clone(),
            ));
        }
        Ok(Measure {
            closest: MeshDistance::new(input.measured())?,
            quick: Points::ordered(quick, Vec::new(), part_points.clone()),
            careful: Points::ordered(careful, Vec::new(), part_points.clone()),
            precise,
            sampler,
            precise_samples,
            part_points,
            input_mesh: mesh,
            outline: std::sync::OnceLock::new(),
        })
    }

    /// Makes the input's points of the precise set now, where they are not made yet: before
    /// precise measurements run side by side (the set is made once, and making it uses all
    /// cores).
    pub fn prepare_precise(&self) {
        self.precise.get_or_init(|| self.precise_points());
    }

    /// The input's points of the precise set (an empty set where sampling fails: the input
    /// sampled for the other sets, so it does not).
    fn precise_points(&self) -> Points {
        let options = SamplingOptions {
            seed: INPUT_SEED,
            ..SamplingOptions::for_samples(self.precise_samples)
        };
        let area = (self.sampler.samples(&options))
            .map(|v| v.into_iter().map(|s| s.point).collect())
            .unwrap_or_default();
        Points::ordered(area, Vec::new(), self.part_points.clone())
    }

    /// The silhouette difference between `mesh` and the input (module `outline`: [`VIEWS`]
    /// views of [`SIZE`]² pixels, the input's drawn on first use), or `None` where a view
    /// cannot be drawn. Cost: one render per view, O(T + pixels).
    pub fn silhouette(&self, mesh: &TriangleMesh) -> Option<f64> {
        let reference = self
            .outline
            .get_or_init(|| SilhouetteReference::new(self.input_mesh, VIEWS, SIZE).ok());
        let d = reference.as_ref()?.mesh_difference(mesh).ok()?;
        Some(d.fraction)
    }

    /// The input's closest-point structure (for the fit).
    pub fn input_closest(&self) -> &MeshDistance {
        &self.closest
    }

    /// `mesh`'s vertices moved towards the input (`voxlod_fit::fit_with`, on
    /// [`Measure::fit_samples`]), with its crossing pairs where the fit counted them, where
    /// the fit ran at least one round; `None` where it did not or failed.
    pub fn fitted(&self, mesh: &TriangleMesh, options: &FitOptions) -> Option<Fitted> {
        let samples = self.fit_samples(mesh.vertex_count(), options);
        let done = fit_with(mesh, &self.closest, &samples, options).ok()?;
        (done.iterations > 0).then_some(done)
    }

    /// The input's points a fit of a level with `vertices` vertices is made on: every k-th of
    /// the careful set's area samples (in Z-order, so spread over the whole surface),
    /// [`FIT_SAMPLES_PER_VERTEX`] per vertex, at least `options.samples`, at most the whole set.
    pub fn fit_samples(&self, vertices: usize, options: &FitOptions) -> Vec<DVec3> {
        let area = &self.careful.area;
        let wanted = (FIT_SAMPLES_PER_VERTEX * vertices).max(options.samples);
        let step = area.len().div_ceil(wanted.max(1)).max(1);
        area.iter().step_by(step).copied().collect()
    }

    /// The two-sided distance between `mesh` and the input, or `None` when some point is
    /// farther than `limit` (early rejection; `f64::INFINITY` measures everything) or `mesh`
    /// has no area to sample.
    pub fn distance(&self, mesh: &TriangleMesh, care: Care, limit: f64) -> Option<Distance> {
        let input_points = match care {
            Care::Quick => &self.quick,
            Care::Careful => &self.careful,
            Care::Precise => self.precise.get_or_init(|| self.precise_points()),
        };
        let sampler = SurfaceSampler::new(mesh).ok()?;
        let closest = MeshDistance::new(mesh).ok()?;
        let options = SamplingOptions {
            seed: CANDIDATE_SEED,
            ..SamplingOptions::for_samples(input_points.area.len())
        };
        let area = sampler.samples(&options).ok()?.into_iter().map(|s| s.point);
        // At most as many vertices as area samples, spread over the vertex list.
        let step = mesh
            .positions
            .len()
            .div_ceil(input_points.area.len().max(1))
            .max(1);
        let vertices = mesh
            .positions
            .iter()
            .step_by(step)
            .map(|p| p.as_dvec3())
            .collect();
        let own = Points::ordered(area.collect(), vertices, Vec::new());
        let there = one_side(input_points, &closest, limit)?;
        let back = one_side(&own, &self.closest, limit)?;
        let shape = there.shape.max(back.shape);
        Some(Distance {
            hausdorff: shape.max(there.parts),
            shape,
            mean: 0.5 * (there.mean + back.mean),
        })
    }
}

impl Points {
    fn ordered(area: Vec<DVec3>, extra: Vec<DVec3>, parts: Vec<DVec3>) -> Points {
        let order =
            |p: Vec<DVec3>| -> Vec<DVec3> { z_order(&p).iter().map(|&i| p[i as usize]).collect() };
        Points {
            area: order(area),
            extra: order(extra),
            parts: order(parts),
        }
    }
}

/// The shape distance, the parts' largest distance and the mean, from `points` to `to`.
struct Side {
    shape: f64,
    parts: f64,
    mean: f64,
}

/// Points queried per task, each run starting from the previous answer.
const CHUNK: usize = 512;

/// `points` against `to`; `None` as soon as an area or extra point is farther than `limit`.
fn one_side(points: &Points, to: &MeshDistance, limit: f64) -> Option<Side> {
    let stop = AtomicBool::new(false);
    let run = |list: &[DVec3], limit: f64| -> Vec<(f64, f64)> {
        list.par_chunks(CHUNK)
            .map(|chunk| {
                let (mut max, mut sum) = (0.0f64, 0.0f64);
                let mut hint = QueryHint::default();
                for &p in chunk {
                    if stop.load(Ordering::Relaxed) {
                        break;
                    }
                    let d = to.closest_with_hint(p, &mut hint).distance;
                    if d > limit {
                        stop.store(true, Ordering::Relaxed);
                        break;
                    }
                    max = max.max(d);
                    sum += d;
                }
                (max, sum)
            })
            .collect()
    };
    let area = run(&points.area, limit);
    let extra = run(&points.extra, limit);
    if stop.load(Ordering::Relaxed) {
        return None;
    }
    let parts = run(&points.parts, f64::INFINITY);
    let largest = |l: &[(f64, f64)]| l.iter().fold(0.0f64, |m, c| m.max(c.0));
    let sum: f64 = area.iter().map(|c| c.1).sum();
    Some(Side {
        shape: largest(&area).max(largest(&extra)),
        parts: largest(&parts),
        mean: sum / points.area.len().max(1) as f64,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use voxlod_testkit::shapes::icosphere;

    #[test]
    fn a_fit_takes_every_kth_careful_sample_as_many_as_its_vertices_ask_and_the_options_floor() {
        let input = Input::prepare(&icosphere(3)).unwrap();
        let measure = Measure::new(&input, 500, 10_000).unwrap();
        let options = FitOptions::quick();
        let all = measure.fit_samples(usize::MAX / FIT_SAMPLES_PER_VERTEX, &options);
        assert_eq!(all, measure.careful.area);
        let n = all.len();
        // A small level: the options' 5 000 at least, every second point.
        let small = measure.fit_samples(100, &options);
        assert_eq!(small.len(), n.div_ceil(n.div_ceil(options.samples)));
        assert!(small.len() >= options.samples, "{} of {n}", small.len());
        assert_eq!(small[1], all[n.div_ceil(options.samples)]);
        // A level whose vertices ask for more than the set holds: the whole set.
        assert_eq!(measure.fit_samples(2_000, &options).len(), n);
    }
}
