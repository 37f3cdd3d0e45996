//! The sampled two-sided Hausdorff and mean distance between a candidate and the input mesh
//! (step 4 of [`crate::budget`]): the input's samples and closest-point structure are built once
//! per run; each candidate costs its own structure and 2 × [`SEARCH_SAMPLES`] queries.

use voxlod_core::TriangleMesh;
use voxlod_metrics::{
    one_sided_distance, DistanceOptions, MeshDistance, SamplingOptions, SurfaceSampler,
};

use super::SEARCH_SAMPLES;

/// A sampled two-sided distance.
#[derive(Clone, Copy, Debug)]
pub(super) struct Measured {
    pub(super) hausdorff: f64,
    pub(super) mean: f64,
}

/// The input mesh's samples and closest-point structure, built once per run, so that each
/// candidate's two-sided distance costs only its own structure and the queries.
pub(super) struct InputMeasure<'a> {
    sampler: SurfaceSampler<'a>,
    closest: MeshDistance,
}

impl<'a> InputMeasure<'a> {
    pub(super) fn new(input: &'a TriangleMesh) -> Option<Self> {
        Some(InputMeasure {
            sampler: SurfaceSampler::new(input).ok()?,
            closest: MeshDistance::new(input).ok()?,
        })
    }

    /// Two-sided distance between the input and `mesh`, [`SEARCH_SAMPLES`] a side.
    pub(super) fn measure(&self, mesh: &TriangleMesh) -> Option<Measured> {
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
