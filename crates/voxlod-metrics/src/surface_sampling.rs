//! Area-uniform random points on a triangle mesh.
//!
//! A triangle is picked with probability proportional to its area by a binary search of the
//! cumulative areas, then a point is drawn uniformly inside it (with `s = √r₁`, the point
//! `(1 − s)·a + s(1 − r₂)·b + s·r₂·c`). Sample `i` draws its random numbers from its own
//! PCG generator seeded from `(seed, i)`, so the samples are the same however many threads
//! draw them, and any one of them can be drawn alone.
//!
//! [`SampleLayout::Stratified`] (the default) gives sample `i` of `n` the cumulative-area value
//! `(i + ξ)/n · A`: each sample is uniform within its own `1/n` share of the surface. Every
//! sample still lands on a surface element with probability proportional to its area, so the
//! mean of any function over the samples is unbiased, with less variance than independent
//! draws and no large unsampled patches. The samples come out in triangle order, which keeps
//! queries made from them coherent. [`SampleLayout::Independent`] draws i.i.d. points instead.
//!
//! The search is guided (the cutpoint method): a table of F entries holds the triangle at
//! each multiple of `total/F` of the cumulative area, so a search only looks between two
//! neighbouring entries — usually one or two triangles, at worst a binary search of them.
//!
//! Cost: O(F) to sum the areas and fill the table (12 bytes per triangle), then O(1) expected
//! per sample (O(log F) at worst).

use glam::DVec3;
use rand::Rng;
use rand_pcg::Pcg64Mcg;
use rayon::prelude::*;
use voxlod_core::TriangleMesh;

use crate::error::{check_mesh, MetricsError};

/// The most samples drawn on one surface: 10⁸, a hundred times the count that gives final
/// figures, and about a minute of work per surface. A larger count is refused rather than left
/// to run for hours.
pub const MAX_SAMPLES: usize = 100_000_000;

/// Refuses a sample count of zero or above [`MAX_SAMPLES`].
pub(crate) fn check_sample_count(samples: usize) -> Result<(), MetricsError> {
    if samples == 0 {
        return Err(MetricsError::NoSamples);
    }
    check_sample_ceiling(samples)
}

/// Refuses a sample count above [`MAX_SAMPLES`].
pub(crate) fn check_sample_ceiling(samples: usize) -> Result<(), MetricsError> {
    if samples > MAX_SAMPLES {
        return Err(MetricsError::TooManySamples {
            requested: samples,
            max: MAX_SAMPLES,
        });
    }
    Ok(())
}

/// How the samples share out the surface (see the module documentation).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SampleLayout {
    /// Sample `i` of `n` lies in the `i`-th `1/n` of the cumulative area.
    #[default]
    Stratified,
    /// Independent, identically distributed area-uniform points.
    Independent,
}

/// How many samples to draw, from which seed, laid out how.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SamplingOptions {
    /// Points to draw.
    pub samples: usize,
    /// Seed of the random generator: the same seed gives the same points.
    pub seed: u64,
    /// How the points share out the surface.
    pub layout: SampleLayout,
}

impl Default for SamplingOptions {
    fn default() -> Self {
        SamplingOptions {
            samples: 100_000,
            seed: DEFAULT_SEED,
            layout: SampleLayout::Stratified,
        }
    }
}

impl SamplingOptions {
    /// `samples` stratified points from the default seed.
    pub fn for_samples(samples: usize) -> Self {
        SamplingOptions {
            samples,
            ..Default::default()
        }
    }
}

/// The seed used unless another is given.
pub const DEFAULT_SEED: u64 = 0x766f_786c_6f64; // "voxlod"

/// A point on the surface and the triangle it lies on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceSample {
    /// The point, in the mesh's coordinates.
    pub point: DVec3,
    /// Index of the triangle it lies on.
    pub triangle: u32,
}

/// A mesh prepared for area-uniform sampling: its cumulative triangle areas.
pub struct SurfaceSampler<'a> {
    mesh: &'a TriangleMesh,
    /// `cumulative_area[t]` is the area of triangles `0..=t`.
    cumulative_area: Vec<f64>,
    /// The last triangle with positive area, for a target rounded up to the total.
    last_with_area: usize,
    /// `guide[g]` is the triangle that holds the cumulative area `g/G · total` (G = the guide's
    /// length): a search for a target only has to look between two neighbouring entries.
    guide: Vec<u32>,
}

impl<'a> SurfaceSampler<'a> {
    /// Sums the triangle areas. Fails on an empty or invalid mesh and on one whose area is zero
    /// (nothing to sample).
    pub fn new(mesh: &'a TriangleMesh) -> Result<SurfaceSampler<'a>, MetricsError> {
        check_mesh(mesh)?;
        let areas: Vec<f64> = (0..mesh.triangles.len())
            .into_par_iter()
            .map(|t| {
                let [a, b, c] = mesh.corners(t);
                0.5 * (b - a).cross(c - a).length()
            })
            .collect();
        let Some(last_with_area) = areas.iter().rposition(|&a| a > 0.0) else {
            return Err(MetricsError::NoArea {
                triangles: mesh.triangles.len(),
            });
        };
        let mut total = 0.0;
        let cumulative_area: Vec<f64> = areas
            .into_iter()
            .map(|a| {
                total += a;
                total
            })
            .collect();
        let guide_len = cumulative_area.len();
        let mut guide = Vec::with_capacity(guide_len);
        let mut t = 0;
        for g in 0..guide_len {
            let target = g as f64 / guide_len as f64 * total;
            while t < last_with_area && cumulative_area[t] <= target {
                t += 1;
            }
            guide.push(t as u32);
        }
        Ok(SurfaceSampler {
            mesh,
            cumulative_area,
            last_with_area,
            guide,
        })
    }

    /// Total area of the mesh.
    pub fn total_area(&self) -> f64 {
        self.cumulative_area.last().copied().unwrap_or(0.0)
    }

    /// Sample `index` of the `options.samples` that `options` describes.
    pub fn sample(&self, index: usize, options: &SamplingOptions) -> SurfaceSample {
        debug_assert!(index < options.samples.max(1));
        let mut rng = sample_rng(options.seed, index as u64);
        let share: f64 = match options.layout {
            SampleLayout::Stratified => {
                (index as f64 + rng.random::<f64>()) / options.samples.max(1) as f64
            }
            SampleLayout::Independent => rng.random::<f64>(),
        };
        let triangle = self.triangle_at(share * self.total_area());
        let [a, b, c] = self.mesh.corners(triangle);
        let s = rng.random::<f64>().sqrt();
        let r = rng.random::<f64>();
        SurfaceSample {
            point: a * (1.0 - s) + b * (s * (1.0 - r)) + c * (s * r),
            triangle: triangle as u32,
        }
    }

    /// All the samples `options` describes, drawn in parallel. Fails on a count above
    /// [`MAX_SAMPLES`], and when they would not fit in the memory limit.
    pub fn samples(&self, options: &SamplingOptions) -> Result<Vec<SurfaceSample>, MetricsError> {
        check_sample_ceiling(options.samples)?;
        voxlod_core::memory::check_allocation(
            &format!("{} surface samples", options.samples),
            voxlod_core::memory::bytes_of::<SurfaceSample>(options.samples),
        )?;
        Ok((0..options.samples)
            .into_par_iter()
            .map(|i| self.sample(i, options))
            .collect())
    }

    /// The triangle whose share of the cumulative area holds `target` (in `[0, total)`);
    /// zero-area triangles own no share and are never returned.
    fn triangle_at(&self, target: f64) -> usize {
        let total = self.total_area();
        let g = ((target / total * self.guide.len() as f64) as usize).min(self.guide.len() - 1);
        // The answer lies between this guide entry and the next; a rounding in the guide may put
        // it one step outside, so widen by one on each side.
        let lo = (self.guide[g] as usize).saturating_sub(1);
        let hi = self
            .guide
            .get(g + 1)
            .map_or(self.cumulative_area.len(), |&t| t as usize + 2)
            .min(self.cumulative_area.len());
        let t = lo + self.cumulative_area[lo..hi].partition_point(|&c| c <= target);
        debug_assert_eq!(
            t.min(self.last_with_area),
            self.cumulative_area
                .partition_point(|&c| c <= target)
                .min(self.last_with_area)
        );
        t.min(self.last_with_area)
    }
}

/// Area-uniform samples of `mesh` (see [`SurfaceSampler`]).
pub fn sample_surface(
    mesh: &TriangleMesh,
    options: &SamplingOptions,
) -> Result<Vec<SurfaceSample>, MetricsError> {
    SurfaceSampler::new(mesh)?.samples(options)
}

/// The generator of sample `index`: a PCG whose 128-bit state comes from mixing the seed and
/// the index (SplitMix64 finaliser), so neighbouring indices get unrelated streams.
fn sample_rng(seed: u64, index: u64) -> Pcg64Mcg {
    let high = splitmix64(seed ^ splitmix64(index));
    let low = splitmix64(high ^ index);
    Pcg64Mcg::new(((high as u128) << 64) | low as u128)
}

fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}
