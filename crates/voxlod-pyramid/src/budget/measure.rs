//! The sampled two-sided Hausdorff and mean distance between a candidate and the input mesh
//! (step 4 of [`crate::budget`]): the input's samples and closest-point structure are built once
//! per run; each candidate costs its own structure and 2 × [`SEARCH_SAMPLES`] queries, plus one
//! per connected part of the input (at most [`PART_POINTS`]): samples spread by area can miss
//! a tiny part altogether, and a tiny part lost far from the rest sets the Hausdorff distance
//! (module `detached`).

use voxlod_core::glam::DVec3;
use voxlod_core::TriangleMesh;
use voxlod_fit::{fit_with, FitOptions, Fitted};
use voxlod_metrics::{
    one_sided_distance, DistanceOptions, MeshDistance, SamplingOptions, SurfaceSampler,
};

use super::SEARCH_SAMPLES;

/// A sampled two-sided distance.
#[derive(Clone, Copy, Debug)]
pub(super) struct Measured {
    pub(super) hausdorff: f64,
    /// The Hausdorff distance of the area samples alone, without the parts' own points: how
    /// far the candidate's shape is off, apart from parts it lost.
    pub(super) shape: f64,
    pub(super) mean: f64,
}

/// The input mesh's samples and closest-point structure, built once per run, so that each
/// candidate's two-sided distance costs only its own structure and the queries.
pub(super) struct InputMeasure<'a> {
    sampler: SurfaceSampler<'a>,
    closest: MeshDistance,
    /// A vertex of each connected part of the input (of every `k`-th part beyond
    /// [`PART_POINTS`]).
    part_points: Vec<DVec3>,
}

/// The most parts given a point of their own in the distance from the input.
const PART_POINTS: usize = 10_000;

impl<'a> InputMeasure<'a> {
    /// The measure against `input`, with its parts `parts` (the triangles of each component of
    /// `welded`, the input with coincident vertices merged, so that a triangle soup's parts are
    /// its pieces, not its triangles).
    pub(super) fn new(
        input: &'a TriangleMesh,
        welded: &TriangleMesh,
        parts: &[Vec<u32>],
    ) -> Option<Self> {
        let step = parts.len().div_ceil(PART_POINTS).max(1);
        let part_points = (parts.iter().step_by(step))
            .map(|p| welded.positions[welded.triangles[p[0] as usize][0] as usize].as_dvec3())
            .collect();
        Some(InputMeasure {
            sampler: SurfaceSampler::new(input).ok()?,
            closest: MeshDistance::new(input).ok()?,
            part_points,
        })
    }

    /// Two-sided distance between the input and `mesh`, [`SEARCH_SAMPLES`] a side.
    pub(super) fn measure(&self, mesh: &TriangleMesh) -> Option<Measured> {
        let options = DistanceOptions::for_samples(SEARCH_SAMPLES);
        let sampling = |side: u64| SamplingOptions {
            seed: options.seed.wrapping_add(side),
            ..SamplingOptions::for_samples(SEARCH_SAMPLES)
        };
        let sampler = SurfaceSampler::new(mesh).ok()?;
        let closest = MeshDistance::new(mesh).ok()?;
        let there = one_sided_distance(&self.sampler, &closest, &sampling(0));
        let back = one_sided_distance(&sampler, &self.closest, &sampling(1));
        let parts = closest.distances(&self.part_points).into_iter();
        let shape = there.max.max(back.max);
        Some(Measured {
            hausdorff: shape.max(parts.fold(0.0, f64::max)),
            shape,
            mean: 0.5 * (there.mean + back.mean),
        })
    }

    /// `mesh` fitted to the input (step 7, module `fit`), with the fit's own samples of the
    /// input (its seed, not the distances'), against the input's closest-point structure.
    pub(super) fn fit(&self, mesh: &TriangleMesh, options: &FitOptions) -> Option<Fitted> {
        let sampling = SamplingOptions {
            seed: options.seed,
            ..SamplingOptions::for_samples(options.samples)
        };
        let samples: Vec<DVec3> = (self.sampler.samples(&sampling).ok()?.into_iter())
            .map(|s| s.point)
            .collect();
        fit_with(mesh, &self.closest, &samples, options).ok()
    }
}
