//! Surface-to-surface distance between two meshes: two-sided Hausdorff, mean and RMS distance.
//!
//! Each surface is sampled area-uniformly ([`crate::surface_sampling`]) and every sample's
//! distance to the other mesh is measured exactly ([`crate::closest_point`]). The one-sided
//! figures describe one direction; the two-sided ones pool both directions: the Hausdorff
//! distance is the larger one-sided maximum, the mean and RMS run over all samples of both
//! sides (with equal sample counts, the average of the one-sided means). Sampling finds a
//! lower bound of the true Hausdorff distance, which it approaches as samples increase.
//!
//! Every figure is also given as a fraction of the diagonal of the bounding box that encloses
//! *both* meshes, so that the report does not change when the meshes swap places.
//!
//! Cost: two BVH builds, O(F log F) each, then per side S samples drawn, sorted in Z-order
//! (O(S log S)) and queried (about O(log F) each), spread over the rayon threads. Memory: the
//! two BVHs, the cumulative areas, and at most [`SAMPLE_BLOCK`] samples at a time. The result
//! is deterministic for a given seed, whatever the thread count.

use std::fmt;
use std::time::Instant;

use glam::DVec3;
use rayon::prelude::*;
use serde::Serialize;
use voxlod_core::TriangleMesh;

use crate::closest_point::{MeshDistance, QueryHint, QUERY_CHUNK};
use crate::error::MetricsError;
use crate::spatial_order::z_order;
use crate::surface_sampling::{
    check_sample_count, SampleLayout, SamplingOptions, SurfaceSampler, DEFAULT_SEED,
};

/// How densely to sample the two surfaces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DistanceOptions {
    /// Points drawn on each of the two surfaces.
    pub samples_per_side: usize,
    /// Seed of the first surface's samples; the second surface's use the next seed.
    pub seed: u64,
    /// How the samples share out each surface.
    pub layout: SampleLayout,
}

impl Default for DistanceOptions {
    fn default() -> Self {
        DistanceOptions::standard()
    }
}

impl DistanceOptions {
    /// 10 000 samples per side: a quick look, in milliseconds for small meshes.
    pub fn quick() -> Self {
        DistanceOptions::for_samples(10_000)
    }

    /// 100 000 samples per side (the default).
    pub fn standard() -> Self {
        DistanceOptions::for_samples(100_000)
    }

    /// 1 000 000 samples per side: for final figures and meshes of a million triangles.
    pub fn precise() -> Self {
        DistanceOptions::for_samples(1_000_000)
    }

    /// `samples_per_side` stratified samples per side from the default seed.
    pub fn for_samples(samples_per_side: usize) -> Self {
        DistanceOptions {
            samples_per_side,
            seed: DEFAULT_SEED,
            layout: SampleLayout::Stratified,
        }
    }

    fn sampling(&self, side: u64) -> SamplingOptions {
        SamplingOptions {
            samples: self.samples_per_side,
            seed: self.seed.wrapping_add(side),
            layout: self.layout,
        }
    }
}

/// Distances from the samples of one surface to the other mesh.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct OneSidedDistance {
    /// Largest sample distance (the one-sided Hausdorff distance, as sampled).
    pub max: f64,
    /// Mean sample distance.
    pub mean: f64,
    /// Root mean square sample distance.
    pub rms: f64,
    /// Samples drawn on the surface.
    pub samples: usize,
}

/// Two-sided distances between two meshes (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct DistanceReport {
    /// Larger of the two one-sided maxima.
    pub hausdorff: f64,
    /// Mean distance over the samples of both sides.
    pub mean: f64,
    /// Root mean square distance over the samples of both sides.
    pub rms: f64,
    /// `hausdorff` divided by `diagonal` (0 when the diagonal is 0).
    pub hausdorff_fraction: f64,
    /// `mean` divided by `diagonal`.
    pub mean_fraction: f64,
    /// `rms` divided by `diagonal`.
    pub rms_fraction: f64,
    /// Samples drawn on each side.
    pub samples: usize,
    /// Diagonal of the box enclosing both meshes, the unit of the `_fraction` figures.
    pub diagonal: f64,
    /// Wall-clock time of the whole measurement (BVH builds, sampling and queries).
    pub seconds: f64,
    /// From the samples of the first mesh to the second mesh.
    pub first_to_second: OneSidedDistance,
    /// From the samples of the second mesh to the first mesh.
    pub second_to_first: OneSidedDistance,
}

/// Measures how far apart the surfaces of `first` and `second` are.
///
/// Fails when either mesh is empty, invalid, or has no area (the error names which one), when
/// the sample count is zero or above [`crate::surface_sampling::MAX_SAMPLES`], and when a block
/// of samples would not fit in the memory limit.
///
/// Two unit squares a quarter apart: every sample of either lies exactly 0.25 from the other.
///
/// ```
/// use voxlod_core::{glam::Vec3, TriangleMesh};
/// use voxlod_metrics::{mesh_distance, DistanceOptions};
///
/// let square = |z: f32| {
///     let corners = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
///     let positions = corners.iter().map(|&[x, y]| Vec3::new(x, y, z)).collect();
///     TriangleMesh::new(positions, vec![[0, 1, 2], [0, 2, 3]])
/// };
/// let report = mesh_distance(&square(0.0), &square(0.25), &DistanceOptions::for_samples(1000))?;
/// for d in [report.hausdorff, report.mean, report.rms] {
///     assert!((d - 0.25).abs() < 1e-6);
/// }
/// assert!((report.diagonal - 2.0625f64.sqrt()).abs() < 1e-6);
/// assert!((report.hausdorff_fraction - 0.25 / report.diagonal).abs() < 1e-9);
/// assert_eq!(report.first_to_second.samples, 1000);
/// # Ok::<(), voxlod_metrics::MetricsError>(())
/// ```
pub fn mesh_distance(
    first: &TriangleMesh,
    second: &TriangleMesh,
    options: &DistanceOptions,
) -> Result<DistanceReport, MetricsError> {
    let start = Instant::now();
    check_sample_count(options.samples_per_side)?;
    let first_sampler = SurfaceSampler::new(first).map_err(|e| e.in_mesh("first"))?;
    let second_sampler = SurfaceSampler::new(second).map_err(|e| e.in_mesh("second"))?;
    let (first_bvh, second_bvh) = rayon::join(
        || MeshDistance::new(first).map_err(|e| e.in_mesh("first")),
        || MeshDistance::new(second).map_err(|e| e.in_mesh("second")),
    );
    let (first_bvh, second_bvh) = (first_bvh?, second_bvh?);
    let block = options.samples_per_side.min(SAMPLE_BLOCK);
    voxlod_core::memory::check_allocation(
        &format!("a block of {block} distance samples"),
        voxlod_core::memory::bytes_of::<[u8; SAMPLE_BYTES]>(block),
    )?;

    let first_to_second = one_sided_distance(&first_sampler, &second_bvh, &options.sampling(0));
    let second_to_first = one_sided_distance(&second_sampler, &first_bvh, &options.sampling(1));

    let diagonal = first.bounds().union(&second.bounds()).diagonal();
    let pooled = first_to_second.pooled_with(&second_to_first);
    let fraction = |x: f64| if diagonal > 0.0 { x / diagonal } else { 0.0 };
    Ok(DistanceReport {
        hausdorff: pooled.max,
        mean: pooled.mean,
        rms: pooled.rms,
        hausdorff_fraction: fraction(pooled.max),
        mean_fraction: fraction(pooled.mean),
        rms_fraction: fraction(pooled.rms),
        samples: options.samples_per_side,
        diagonal,
        seconds: start.elapsed().as_secs_f64(),
        first_to_second,
        second_to_first,
    })
}

/// Distances from the samples `sampling` draws on `from` to the mesh behind `to`.
///
/// Samples are drawn in blocks of [`SAMPLE_BLOCK`]; each block is queried in Z-order (so the
/// speed does not depend on the mesh's triangle order or the sample layout), in fixed chunks
/// spread over the rayon threads, and the chunk sums are added in order: the figures do not
/// depend on the thread count.
pub fn one_sided_distance(
    from: &SurfaceSampler,
    to: &MeshDistance,
    sampling: &SamplingOptions,
) -> OneSidedDistance {
    let n = sampling.samples;
    let mut total = Accumulator::default();
    for block_start in (0..n).step_by(SAMPLE_BLOCK) {
        let block_end = (block_start + SAMPLE_BLOCK).min(n);
        let points: Vec<DVec3> = (block_start..block_end)
            .into_par_iter()
            .map(|i| from.sample(i, sampling).point)
            .collect();
        let order = z_order(&points);
        let chunks: Vec<Accumulator> = order
            .par_chunks(QUERY_CHUNK)
            .map(|indices| {
                let mut acc = Accumulator::default();
                let mut hint = QueryHint::default();
                for &i in indices {
                    acc.add(to.closest_with_hint(points[i as usize], &mut hint).distance);
                }
                acc
            })
            .collect();
        total = chunks.iter().fold(total, |a, b| a.merged(b));
    }
    total.summary()
}

/// Samples held in memory at once by [`one_sided_distance`] (24 bytes each, plus 16 while
/// sorting).
pub const SAMPLE_BLOCK: usize = 1 << 20;

/// Bytes per sample of a block: its point, and its key and index while sorting.
const SAMPLE_BYTES: usize = 24 + 16;

/// Running max, sum and sum of squares of distances.
#[derive(Clone, Copy, Debug, Default)]
struct Accumulator {
    max: f64,
    sum: f64,
    sum_squares: f64,
    count: usize,
}

impl Accumulator {
    fn add(&mut self, d: f64) {
        debug_assert!(d >= 0.0, "distance {d}");
        self.max = self.max.max(d);
        self.sum += d;
        self.sum_squares += d * d;
        self.count += 1;
    }

    fn merged(&self, other: &Accumulator) -> Accumulator {
        Accumulator {
            max: self.max.max(other.max),
            sum: self.sum + other.sum,
            sum_squares: self.sum_squares + other.sum_squares,
            count: self.count + other.count,
        }
    }

    fn summary(&self) -> OneSidedDistance {
        let n = self.count.max(1) as f64;
        OneSidedDistance {
            max: self.max,
            mean: self.sum / n,
            rms: (self.sum_squares / n).sqrt(),
            samples: self.count,
        }
    }
}

impl OneSidedDistance {
    /// Both directions as one population: the larger maximum, means over all samples.
    fn pooled_with(&self, other: &OneSidedDistance) -> OneSidedDistance {
        let (n1, n2) = (self.samples as f64, other.samples as f64);
        let n = (n1 + n2).max(1.0);
        OneSidedDistance {
            max: self.max.max(other.max),
            mean: (self.mean * n1 + other.mean * n2) / n,
            rms: ((self.rms * self.rms * n1 + other.rms * other.rms * n2) / n).sqrt(),
            samples: self.samples + other.samples,
        }
    }
}

impl fmt::Display for DistanceReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let row = |f: &mut fmt::Formatter<'_>, name: &str, value: f64, fraction: f64| {
            writeln!(
                f,
                "{name:<10} {value:>14.6e}   {:>9.5} % of the diagonal",
                100.0 * fraction
            )
        };
        row(f, "hausdorff", self.hausdorff, self.hausdorff_fraction)?;
        row(f, "mean", self.mean, self.mean_fraction)?;
        row(f, "rms", self.rms, self.rms_fraction)?;
        writeln!(
            f,
            "one-sided maxima: first to second {:.6e}, second to first {:.6e}",
            self.first_to_second.max, self.second_to_first.max
        )?;
        write!(
            f,
            "{} samples per side, diagonal {:.6e} (box of both meshes), {:.3} s",
            self.samples, self.diagonal, self.seconds
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface_sampling::{SurfaceSampler, MAX_SAMPLES};
    use voxlod_testkit::shapes::unit_cube;

    #[test]
    fn refuses_sample_counts_that_would_run_for_hours() {
        let cube = unit_cube();
        let options = DistanceOptions::for_samples(100_000_000_000);
        let err = mesh_distance(&cube, &cube, &options).unwrap_err();
        assert!(matches!(
            err,
            MetricsError::TooManySamples {
                requested: 100_000_000_000,
                max: MAX_SAMPLES
            }
        ));
        assert!(err
            .to_string()
            .starts_with("100000000000 samples per surface is more than the 100000000 allowed"));
        let sampler = SurfaceSampler::new(&cube).unwrap();
        let too_many = options.sampling(0);
        assert!(sampler.samples(&too_many).is_err());
        // At the ceiling the count is accepted (checked without drawing them).
        assert!(crate::surface_sampling::check_sample_count(MAX_SAMPLES).is_ok());
    }
}
