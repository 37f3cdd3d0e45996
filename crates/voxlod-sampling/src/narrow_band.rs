//! The filtered density of paper §2, equation 1, computed only in a narrow band of bricks
//! around the surface and stored as a [`BrickVolume`].
//!
//! A sample farther than the support radius R from every crossing of the surface with the
//! quadrature lattice sees only inside or only outside: its filtered density is exactly 1 or 0
//! (the paper's observation that the filter then has nothing to smooth; the line kernel is
//! normalised so that the dense sampler also gives exactly 1.0 and 0.0 there). So:
//!
//! 1. the lattice crossings of the three families are found as for the dense sampler
//!    ([`crate::density`]), including the majority vote of a mesh with holes;
//! 2. every brick within `R + 2` samples (Chebyshev distance) of a crossing is a **band
//!    brick**; the two extra samples cover the neighbours that marching cubes reads for a
//!    vertex's gradient, so every vertex and normal depends on band samples only;
//! 3. every other brick gets one value, 1 inside and 0 outside, decided by the parity of the
//!    crossings before its first sample on its x row (the same crossings the density uses);
//! 4. each band brick is integrated exactly as [`crate::filtered_density`] integrates its
//!    samples: the same line kernel, the same per-family blend with the same f32 rounding of
//!    the partial sums, only with each row cut to the brick. The values agree with the dense
//!    sampler's to a few units in the last place of f64 before the final rounding to f32.
//!
//! Beyond the paper (which samples a dense grid), and what makes a mesh at 2048³ fit: memory is
//! the lattice (4 bytes per line and per crossing, which grows as N²), 8 bytes per brick, and
//! `4 B³` bytes per band brick, which grows with the surface's area; the leaves are checked
//! against the budget, in terms of the band, before they are allocated. Before any of it, the
//! plan states a level's peak with [`band_estimate`]: for a mesh, the band is bounded by the
//! bricks its triangles' boxes reach ([`crate::band_cover`]), and the mesh marching cubes makes
//! is counted per band brick.
//!
//! **Cost.** O(crossings) to find the band, then per band brick and family O(B² · lines in the
//! kernel pattern + B³): the per-row overhead of the dense sampler is paid per brick row.

use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;
use serde::Serialize;
use voxlod_core::bricks::brick_origin;
use voxlod_core::{memory, BrickVolume, Grid};

use crate::density::{lattice_crossings, DensityOptions, DensityReport, Rows};
use crate::lattice::LineCrossings;
use crate::line_kernel::LineKernel;
use crate::pyramid::LevelEstimate;
use crate::solid::Solid;
use crate::SamplingError;

/// Samples beyond the support radius that the band keeps, for marching cubes' gradients.
const GRADIENT_MARGIN: f64 = 2.0;

/// How to store the band.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct NarrowBandOptions {
    /// Side of a brick in samples: 8 or 16.
    pub brick_size: usize,
}

impl Default for NarrowBandOptions {
    /// Bricks of 8³ (OpenVDB's leaf size): the thinnest band.
    fn default() -> Self {
        NarrowBandOptions {
            brick_size: BrickVolume::DEFAULT_BRICK_SIZE,
        }
    }
}

impl NarrowBandOptions {
    /// Bricks of 16³: a thicker band, less per-brick overhead.
    pub fn large_bricks() -> Self {
        NarrowBandOptions { brick_size: 16 }
    }
}

/// What the band held.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct BandReport {
    /// Bricks of the grid.
    pub bricks: usize,
    /// Bricks within reach of the surface, stored densely.
    pub band_bricks: usize,
    /// Bytes of the brick volume.
    pub bytes: u64,
}

/// Bytes the narrow band needs before its band is known: the lattice (offsets and about two
/// crossings per line, as [`crate::density::estimated_bytes`] counts them) and the brick index.
pub fn lattice_estimated_bytes(grid: &Grid, lines_per_voxel: usize, brick_size: usize) -> u64 {
    let q = lines_per_voxel as u64;
    let l = |a: usize| (grid.dims[a] as u64 - 1) * q + 1;
    let lines = l(0) * l(1) + l(1) * l(2) + l(2) * l(0);
    lines
        .saturating_mul(8)
        .saturating_add(BrickVolume::estimated_bytes(grid, brick_size, 0))
}

/// Triangles marching cubes makes per band brick of 8³, at most: 9.97 M triangles from 125,330
/// band bricks (79.5) on the sphereflake of the peers' kit at 1024, rounded up.
const TRIANGLES_PER_BAND_BRICK: u64 = 80;

/// Bytes per triangle of a mesh from sparse marching cubes while it is made (positions and
/// normals of about half a vertex, the triangle, the vertex table of the brick faces), measured
/// on the same sphereflake and rounded up.
const MESH_BYTES_PER_TRIANGLE: u64 = 64;

/// What the plan expects of a level through the narrow band ([`band_estimate`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BandEstimate {
    /// Bytes at the peak of sampling and contouring, and what they are for.
    pub estimate: LevelEstimate,
    /// Triangles marching cubes is expected to make, at most (0 when the band is not bounded).
    pub triangles: u64,
}

/// What a level of `solid` on `grid` needs through the narrow band, before the lattice is cast:
/// the lattice and brick index ([`lattice_estimated_bytes`]), and, when the solid bounds its
/// band ([`Solid::band_bricks_bound`], a mesh does), the band's leaves and the mesh marching
/// cubes makes of them. `radius_samples` is the filter's support radius in samples.
pub fn band_estimate(
    solid: &dyn Solid,
    grid: &Grid,
    lines_per_voxel: usize,
    radius_samples: f64,
    band: &NarrowBandOptions,
) -> BandEstimate {
    let b = band.brick_size;
    let lattice = lattice_estimated_bytes(grid, lines_per_voxel, b);
    let margin = radius_samples + GRADIENT_MARGIN;
    let Some(leaves) = solid.band_bricks_bound(grid, b, margin) else {
        return BandEstimate {
            estimate: lattice.into(),
            triangles: 0,
        };
    };
    let bricks: u64 = grid.dims.iter().map(|&d| d.div_ceil(b) as u64).product();
    let leaves_bytes = (memory::bytes_of::<f32>(b.pow(3)) + 4).saturating_mul(leaves as u64);
    // Bricks of 16³ hold eight of 8³: as many triangles per sample.
    let triangles = TRIANGLES_PER_BAND_BRICK * (b as u64 / 8).max(1).pow(3) * leaves as u64;
    let mesh = MESH_BYTES_PER_TRIANGLE.saturating_mul(triangles);
    BandEstimate {
        estimate: LevelEstimate {
            // The lattice is freed before marching cubes: the peak is the larger of the two.
            bytes: leaves_bytes
                .saturating_add(lattice.max(mesh))
                .saturating_add(solid.resident_bytes()),
            what: Some(format!(
                "the narrow band of ~{leaves} bricks of {b}³ samples ({:.1}% of the grid), its \
                 lattice, its mesh of ~{triangles} triangles and the input",
                100.0 * leaves as f64 / bricks.max(1) as f64
            )),
        },
        triangles,
    }
}

/// Samples `solid` filtered by `options.filter` on `grid`, densely only in the band of bricks the
/// surface reaches (see the module documentation).
pub fn narrow_band_density(
    solid: &dyn Solid,
    grid: &Grid,
    options: &DensityOptions,
    band: &NarrowBandOptions,
) -> Result<(BrickVolume, DensityReport, BandReport), SamplingError> {
    let b = band.brick_size;
    if !BrickVolume::BRICK_SIZES.contains(&b) {
        return Err(SamplingError::InvalidOption(format!(
            "brick side {b}: must be one of {:?}",
            BrickVolume::BRICK_SIZES
        )));
    }
    let (crossings, kernel, report) = lattice_crossings(solid, grid, options, &|q| {
        lattice_estimated_bytes(grid, q, b)
    })?;
    let brick_dims = grid.dims.map(|d| d.div_ceil(b));
    let bricks: usize = brick_dims.iter().product();
    memory::check_allocation("the brick index", memory::bytes_of::<u64>(bricks))?;
    let mask = band_mask(&crossings, grid, b, kernel.radius + GRADIENT_MARGIN);
    let values = outside_values(&crossings[0], grid, b, &mask);
    let band_bricks = mask.iter().filter(|&&m| m).count();
    let bytes = BrickVolume::estimated_bytes(grid, b, band_bricks);
    memory::check_allocation(
        &format!(
            "the narrow band ({band_bricks} of {bricks} bricks of {b}³ samples, {:.1}% of the grid)",
            100.0 * band_bricks as f64 / bricks.max(1) as f64
        ),
        bytes,
    )?;
    let mut volume = BrickVolume::from_leaves(*grid, b, values, &mask)?;
    drop(mask);
    let leaf_bricks = volume.leaf_bricks().to_vec();
    volume
        .leaves_mut()
        .par_chunks_mut(b * b * b)
        .zip(leaf_bricks)
        .for_each_init(
            || BrickScratch::new(b),
            |scratch, (leaf, brick)| {
                let origin = brick_origin(brick_dims, b, brick as usize);
                scratch.fill(&crossings, &kernel, grid, origin, [0; 3], leaf);
            },
        );
    let band = BandReport {
        bricks,
        band_bricks,
        bytes,
    };
    Ok((volume, report, band))
}

/// One flag per brick: within `margin` samples (per axis) of some crossing.
fn band_mask(crossings: &[LineCrossings; 3], grid: &Grid, b: usize, margin: f64) -> Vec<bool> {
    let brick_dims = grid.dims.map(|d| d.div_ceil(b));
    let flags: Vec<AtomicBool> = (0..brick_dims.iter().product::<usize>())
        .map(|_| AtomicBool::new(false))
        .collect();
    for family in crossings {
        let axis = family.family.axis.index();
        let (u, v) = family.family.cross_axes();
        let (u, v) = (u.index(), v.index());
        let q = family.family.lines_per_voxel as f64;
        let (lu, lv) = family.family.line_counts();
        (0..lv).into_par_iter().for_each(|n| {
            for m in 0..lu {
                for &t in family.line(m as isize, n as isize) {
                    let mut p = [0.0; 3];
                    (p[axis], p[u], p[v]) = (t as f64, m as f64 / q, n as f64 / q);
                    mark_box(&flags, brick_dims, grid.dims, b, p, margin);
                }
            }
        });
    }
    flags.into_iter().map(AtomicBool::into_inner).collect()
}

/// Flags every brick holding a sample within `margin` of `p` along each axis.
fn mark_box(
    flags: &[AtomicBool],
    brick_dims: [usize; 3],
    dims: [usize; 3],
    b: usize,
    p: [f64; 3],
    margin: f64,
) {
    let range = |a: usize| {
        let lo = (p[a] - margin).ceil().max(0.0) as usize;
        let hi = ((p[a] + margin).floor().max(0.0) as usize).min(dims[a] - 1);
        (lo.min(dims[a] - 1) / b)..=(hi / b)
    };
    for k in range(2) {
        for j in range(1) {
            for i in range(0) {
                let index = i + brick_dims[0] * (j + brick_dims[1] * k);
                flags[index].store(true, Ordering::Relaxed);
            }
        }
    }
}

/// Per brick: 1 when its first sample is inside (odd number of x-line crossings before it), 0
/// otherwise; the value of every brick outside the band.
fn outside_values(x_lines: &LineCrossings, grid: &Grid, b: usize, mask: &[bool]) -> Vec<f32> {
    let brick_dims = grid.dims.map(|d| d.div_ceil(b));
    let q = x_lines.family.lines_per_voxel;
    (0..mask.len())
        .into_par_iter()
        .map(|brick| {
            if mask[brick] {
                return 0.0;
            }
            let [i, j, k] = brick_origin(brick_dims, b, brick);
            let line = x_lines.line((j * q) as isize, (k * q) as isize);
            let before = line.partition_point(|&t| (t as f64) < i as f64);
            (before % 2) as f32
        })
        .collect()
}

/// One thread's buffers for filling band bricks (also the blockwise threshold route's blocks).
pub(crate) struct BrickScratch {
    b: usize,
    rows: Rows,
    num: Vec<f32>,
    den: Vec<f32>,
}

impl BrickScratch {
    pub(crate) fn new(b: usize) -> BrickScratch {
        BrickScratch {
            b,
            rows: Rows::new(b),
            num: vec![0.0; b * b * b],
            den: vec![0.0; b * b * b],
        }
    }

    /// The filtered density of the brick at `origin` into `leaf` (`B³` samples, x fastest; the
    /// samples beyond the grid are left as they are): [`BrickScratch::fill_box`] of the brick.
    pub(crate) fn fill(
        &mut self,
        crossings: &[LineCrossings; 3],
        kernel: &LineKernel,
        grid: &Grid,
        origin: [usize; 3],
        first_line: [usize; 3],
        leaf: &mut [f32],
    ) {
        let b = self.b;
        let ext = [0, 1, 2].map(|a| (grid.dims[a] - origin[a]).min(b));
        let lattice = BoxLattice {
            crossings,
            kernel,
            first_line,
        };
        self.fill_box(&lattice, origin, ext, [b; 3], leaf);
    }

    /// The filtered density of the `ext` samples from `origin` into `out` (an array of `size`
    /// samples, x fastest, `ext` within it), as the dense sampler blends it: x rows set the
    /// weighted sums, y rows add to them in f32, z rows finish in f64. Each row is integrated
    /// over the box's span of it.
    pub(crate) fn fill_box(
        &mut self,
        lattice: &BoxLattice,
        origin: [usize; 3],
        ext: [usize; 3],
        size: [usize; 3],
        out: &mut [f32],
    ) {
        let (crossings, kernel) = (lattice.crossings, lattice.kernel);
        let q = crossings[0].family.lines_per_voxel;
        let longest = ext.into_iter().max().unwrap_or(0);
        if self.rows.density.len() < longest {
            self.rows = Rows::new(longest);
        }
        let samples = size.iter().product();
        if self.num.len() < samples {
            self.num.resize(samples, 0.0);
            self.den.resize(samples, 0.0);
        }
        let at = |i: usize, j: usize, k: usize| i + size[0] * (j + size[1] * k);
        let line = |a: usize, c: usize| ((origin[a] + c - lattice.first_line[a]) * q) as isize;
        let span = |a: usize| origin[a]..origin[a] + ext[a];
        let rows = &mut self.rows;
        for k in 0..ext[2] {
            for j in 0..ext[1] {
                let touched = rows.run(&crossings[0], kernel, line(1, j), line(2, k), span(0));
                for i in 0..ext[0] {
                    let (n, d) = if touched {
                        rows.weighted(i)
                    } else {
                        (0.0, 0.0)
                    };
                    self.num[at(i, j, k)] = n as f32;
                    self.den[at(i, j, k)] = d as f32;
                }
            }
        }
        for k in 0..ext[2] {
            for i in 0..ext[0] {
                if rows.run(&crossings[1], kernel, line(2, k), line(0, i), span(1)) {
                    for j in 0..ext[1] {
                        let (n, d) = rows.weighted(j);
                        self.num[at(i, j, k)] += n as f32;
                        self.den[at(i, j, k)] += d as f32;
                    }
                }
            }
        }
        for j in 0..ext[1] {
            for i in 0..ext[0] {
                let touched = rows.run(&crossings[2], kernel, line(0, i), line(1, j), span(2));
                for k in 0..ext[2] {
                    let (f, w) = if touched {
                        (rows.density[k], rows.weight[k] * rows.weight[k])
                    } else {
                        (0.0, 0.0)
                    };
                    let (n, d) = (self.num[at(i, j, k)], self.den[at(i, j, k)]);
                    let total = d as f64 + w;
                    let value = if total > 0.0 {
                        (n as f64 + w * f) / total
                    } else {
                        f
                    };
                    out[at(i, j, k)] = value as f32;
                }
            }
        }
    }
}

/// The lattice a box is integrated from: the crossings of the three families (a window of the
/// level's lattice whose line (0, 0) is the one through sample `first_line`, per axis, of the
/// level's grid) and the line kernel.
pub(crate) struct BoxLattice<'a> {
    pub(crate) crossings: &'a [LineCrossings; 3],
    pub(crate) kernel: &'a LineKernel,
    pub(crate) first_line: [usize; 3],
}
