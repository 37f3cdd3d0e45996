//! The filtered density of paper §2, equation 1: `f = h ∗ S` sampled on a grid.
//!
//! The inside function S is known exactly along the lattice lines of three families (one per
//! axis, [`crate::lattice`]), as lists of crossings. For each family we evaluate equation 1 as a
//! sum over the lines within the support of each sample of the exact integral of the filter over
//! the line's inside spans ([`crate::line_kernel`]): "integrating analytically along the ray of
//! each row". Per row of samples, each span end touches only the few samples within reach of it;
//! the samples whose window lies wholly inside a span get the line's full weight through a
//! difference array. So a family costs O(N³) for the arrays plus O(crossings × pattern lines).
//!
//! **Blending the three families** (beyond the paper). The line integrals are exact along a
//! line, but the sum across lines is a quadrature, and it is poor where the surface runs parallel
//! to the lines: there the inside function steps from line to line. Each family is best where the
//! surface faces its axis. So every family also measures, per sample, how much surface it sees
//! (its crossings within the support, weighted by the filter); the families are averaged with the
//! squares of those weights. For a plane with normal n the weights go as |n_x|, |n_y|, |n_z|,
//! so a plane facing an axis is integrated by that axis alone and a 45° plane by two equally.
//! With four lines per support radius this keeps the half-space profile within 0.01 of equation 5.
//!
//! **Memory.** Two f32 volumes (numerator and weight) besides the crossings.

use std::ops::Range;

use rayon::prelude::*;
use serde::Serialize;
use voxlod_core::disjoint::DisjointSlice;
use voxlod_core::{memory, Axis, Grid, Volume};

use crate::lattice::{LineCrossings, LineFamily};
use crate::line_kernel::{LineKernel, LineProfile};
use crate::majority::{majority_vote, MajorityReport};
use crate::solid::Solid;
use crate::{Filter, SamplingError};

/// How to filter: which filter, its support radius, and the quadrature density.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct DensityOptions {
    /// The low-pass filter h of equation 1.
    pub filter: Filter,
    /// Support radius R in world units.
    pub radius: f64,
    /// Lattice lines per support radius: the cross-section quadrature's resolution.
    pub lines_per_radius: usize,
}

impl DensityOptions {
    /// Four lines per radius: within 0.01 of the analytic half-space profile.
    pub const DEFAULT_LINES_PER_RADIUS: usize = 4;

    /// `filter` with support radius `radius` (world units), four lines per radius.
    pub fn new(filter: Filter, radius: f64) -> DensityOptions {
        DensityOptions {
            filter,
            radius,
            lines_per_radius: Self::DEFAULT_LINES_PER_RADIUS,
        }
    }

    /// Lattice lines per voxel for a grid of `spacing`: enough that lines are at most R/q apart.
    pub fn lines_per_voxel(&self, spacing: f64) -> usize {
        ((self.lines_per_radius as f64 * spacing / self.radius).ceil() as usize).max(1)
    }
}

/// What sampling a solid found and did, for reports.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct DensityReport {
    /// Lattice lines per voxel side, from [`DensityOptions::lines_per_voxel`].
    pub lines_per_voxel: usize,
    /// Lines of the three families together.
    pub lattice_lines: u64,
    /// Surface crossings found along them.
    pub crossings: u64,
    /// Present when the solid's crossings were not exact and a majority vote corrected them.
    pub majority: Option<MajorityReport>,
}

/// Bytes that [`filtered_density`] will allocate for `grid` (crossing storage estimated).
pub fn estimated_bytes(grid: &Grid, lines_per_voxel: usize) -> u64 {
    let q = lines_per_voxel as u64;
    let l = |a: usize| (grid.dims[a] as u64 - 1) * q + 1;
    let lines = l(0) * l(1) + l(1) * l(2) + l(2) * l(0);
    // Offsets (u32 per line, padded to tiles) and about two crossings per line, two volumes.
    lines * 4 * 2 + 2 * 4 * grid.len() as u64
}

/// Samples `solid` filtered by `options.filter` on `grid` (isotropic spacing required): paper
/// §2, equation 1. See the module documentation.
///
/// The filter integrates to one, so the filtered density holds the solid's volume: summed over
/// the samples and times the voxel volume, it gives the ball's `4/3 π r³` back.
///
/// ```
/// use voxlod_core::{glam::DVec3, Grid};
/// use voxlod_sampling::{filtered_density, CsgSolid, DensityOptions, Filter, Shape};
///
/// let ball = CsgSolid::new(Shape::sphere(DVec3::ZERO, 4.0))?;
/// let grid = Grid::new([13, 13, 13], [1.0; 3], [-6.0; 3])?; // samples at -6, -5, …, 6
/// let options = DensityOptions::new(Filter::Hypercone, 1.0); // R = 1 voxel
/// let (density, report) = filtered_density(&ball, &grid, &options)?;
///
/// assert_eq!(density.get(6, 6, 6), 1.0); // the centre: the whole support is inside
/// assert_eq!(density.get(0, 0, 0), 0.0); // a corner of the grid: all outside
/// // On the sphere (x = 4) the density is near the half-space's 1/2 (equation 5), a little
/// // below it since the surface curves away, and the same along every axis.
/// let on_surface = density.get(10, 6, 6);
/// assert!(0.4 < on_surface && on_surface < 0.5);
/// assert!((density.get(6, 6, 10) - on_surface).abs() < 1e-4);
/// // The volume is kept: within 10⁻⁴ of 4/3 π 4³ = 268.08.
/// let mass: f64 = density.as_slice().iter().map(|&v| v as f64).sum();
/// assert!((mass / (4.0 / 3.0 * std::f64::consts::PI * 64.0) - 1.0).abs() < 1e-4);
/// assert_eq!(report.lines_per_voxel, 4);
/// assert!(report.majority.is_none()); // a CSG solid's crossings are exact
/// # Ok::<(), voxlod_sampling::SamplingError>(())
/// ```
pub fn filtered_density(
    solid: &dyn Solid,
    grid: &Grid,
    options: &DensityOptions,
) -> Result<(Volume, DensityReport), SamplingError> {
    let (crossings, kernel, report) =
        lattice_crossings(solid, grid, options, &|q| estimated_bytes(grid, q))?;
    let volume = integrate_families(&crossings, &kernel, grid)?;
    Ok((volume, report))
}

/// The lattice crossings of the three families (majority-voted when the solid is not exact),
/// the line kernel and the report, after checking the options and `estimate(q)` bytes against
/// the memory limit. Shared by [`filtered_density`] and [`crate::narrow_band`].
pub(crate) fn lattice_crossings(
    solid: &dyn Solid,
    grid: &Grid,
    options: &DensityOptions,
    estimate: &dyn Fn(usize) -> u64,
) -> Result<([LineCrossings; 3], LineKernel, DensityReport), SamplingError> {
    let q = check_options(grid, options)?;
    let h = grid.spacing[0];
    memory::check_allocation(
        &format!(
            "sampling a {}x{}x{} grid",
            grid.dims[0], grid.dims[1], grid.dims[2]
        ),
        estimate(q),
    )?;
    let families = [Axis::X, Axis::Y, Axis::Z].map(|a| LineFamily::new(a, *grid, q));
    // On all threads, before the families wait on it.
    solid.prepare();
    // The three families side by side, so that one's sequential gathering of its tiles
    // overlaps another's tiles; the first failure in family order is the one reported.
    let crossings: Vec<Result<LineCrossings, SamplingError>> =
        families.par_iter().map(|f| solid.crossings(f)).collect();
    let crossings: Result<Vec<LineCrossings>, SamplingError> = crossings.into_iter().collect();
    let mut crossings: [LineCrossings; 3] = crossings?.try_into().expect("three families");
    let majority = (!solid.is_exact()).then(|| majority_vote(&mut crossings));
    let kernel = LineKernel::new(options.filter, options.radius / h, q);
    let report = DensityReport {
        lines_per_voxel: q,
        lattice_lines: crossings.iter().map(|c| c.family.line_count() as u64).sum(),
        crossings: crossings.iter().map(|c| c.len() as u64).sum(),
        majority,
    };
    Ok((crossings, kernel, report))
}

/// Checks that `grid` is isotropic and the options usable; the lattice lines per voxel.
pub(crate) fn check_options(grid: &Grid, options: &DensityOptions) -> Result<usize, SamplingError> {
    let h = grid.spacing[0];
    if grid.spacing.iter().any(|s| (s - h).abs() > 1e-9 * h) {
        return Err(SamplingError::InvalidOption(format!(
            "filtered sampling needs an isotropic grid, got spacing {:?}",
            grid.spacing
        )));
    }
    if !(options.radius.is_finite() && options.radius > 0.0) {
        return Err(SamplingError::InvalidOption(format!(
            "the support radius must be positive, got {}",
            options.radius
        )));
    }
    if options.lines_per_radius == 0 {
        return Err(SamplingError::InvalidOption(
            "lines per radius must be at least 1".into(),
        ));
    }
    Ok(options.lines_per_voxel(h))
}

/// Scratch rows for one thread: the density and surface weight of one row of samples.
pub(crate) struct Rows {
    pub(crate) density: Vec<f64>,
    pub(crate) weight: Vec<f64>,
    diff: Vec<f64>,
}

impl Rows {
    pub(crate) fn new(n: usize) -> Rows {
        Rows {
            density: vec![0.0; n],
            weight: vec![0.0; n],
            diff: vec![0.0; n + 1],
        }
    }

    /// Sample `i` of the last row as its blend terms: (w² f, w²).
    #[inline]
    pub(crate) fn weighted(&self, i: usize) -> (f64, f64) {
        let w2 = self.weight[i] * self.weight[i];
        (w2 * self.density[i], w2)
    }

    /// Integrates the samples `range` of the row along line (m0, n0) of a family into
    /// `density[..range.len()]` and `weight[..range.len()]`. False when no line of the pattern
    /// holds a crossing (the row is then empty and the buffers are zero).
    pub(crate) fn run(
        &mut self,
        crossings: &LineCrossings,
        kernel: &LineKernel,
        m0: isize,
        n0: isize,
        range: Range<usize>,
    ) -> bool {
        let n = range.len();
        let (density, weight, diff) = (
            &mut self.density[..n],
            &mut self.weight[..n],
            &mut self.diff[..n + 1],
        );
        density.fill(0.0);
        weight.fill(0.0);
        diff.fill(0.0);
        let (lo, hi) = (range.start as f64, (range.end - 1) as f64);
        let lines = crossings.lookup();
        let mut touched = false;
        for line in &kernel.lines {
            let ts = lines.line(m0 + line.du as isize, n0 + line.dv as isize);
            if ts.is_empty() {
                continue;
            }
            touched = true;
            let profile = &kernel.profiles[line.profile as usize];
            for pair in ts.chunks(2) {
                let a = pair[0] as f64;
                let b = pair.get(1).map_or(f64::INFINITY, |&b| b as f64);
                if b + profile.reach < lo || a - profile.reach > hi {
                    continue;
                }
                add_span(
                    profile,
                    (a, b),
                    (lo, hi),
                    range.start,
                    density,
                    weight,
                    diff,
                );
            }
        }
        if touched {
            add_running_sum(density, diff);
        }
        touched
    }
}

/// Adds to each `density[i]` the running sum `diff[0] + … + diff[i]`, bit for bit the sum
/// taken one step at a time: between two non-zero steps the sum is constant, so each such
/// segment gets one constant (none where it is zero), and the additions of a segment do not
/// wait on one another. Exact because neither the running sum nor a density is ever -0
/// (both start at +0 and only gain non-negative partials and sums of `±full`, and `x - x` is
/// +0), so a step of +0 leaves the sum as it is and adding a zero sum leaves a density.
#[inline]
fn add_running_sum(density: &mut [f64], diff: &[f64]) {
    let mut running = 0.0;
    let mut start = 0;
    for (p, &step) in diff[..density.len()].iter().enumerate() {
        if step != 0.0 {
            if running != 0.0 {
                density[start..p].iter_mut().for_each(|d| *d += running);
            }
            running += step;
            start = p;
        }
    }
    if running != 0.0 {
        density[start..].iter_mut().for_each(|d| *d += running);
    }
}

/// Adds one inside span `[a, b]` (`b` infinite for a line that ends inside) of a line with
/// `profile` to the samples `lo..=hi` of a row whose buffers start at sample `start`: partial
/// integrals near the ends into `density`, the full weight over the middle into `diff`, the
/// crossings' weights into `weight`. [`Rows::run`]'s inner step.
#[inline]
fn add_span(
    profile: &LineProfile,
    (a, b): (f64, f64),
    (lo, hi): (f64, f64),
    start: usize,
    density: &mut [f64],
    weight: &mut [f64],
    diff: &mut [f64],
) {
    let reach = profile.reach;
    let full = profile.total();
    // Samples whose window lies inside the span get the full weight at once.
    let f_lo = (a + reach).ceil().max(lo);
    let f_hi = (b - reach).floor().min(hi);
    let i_lo = (a - reach).ceil().max(lo) as usize;
    let i_hi = (b + reach).floor().min(hi) as usize;
    let partial = |i: usize| {
        let x = i as f64;
        profile.integral_to(b - x) - profile.integral_to(a - x)
    };
    if f_lo <= f_hi {
        diff[f_lo as usize - start] += full;
        diff[f_hi as usize - start + 1] -= full;
        // A long span: near `a` no window reaches `b` (G(b - x) is the full weight), near `b`
        // none reaches back to `a` (G(a - x) is 0), so each end's samples read G and g from
        // one interpolation. The weights' windows (closed) can hold one more sample each,
        // where `a + reach` or `b - reach` is a whole number: that sample gets its weight alone.
        for i in i_lo..f_lo as usize {
            let (big, small) = profile.integral_and_weight(a - i as f64);
            density[i - start] += full - big;
            weight[i - start] += small;
        }
        add_weights(
            profile,
            a,
            (f_lo, (a + reach).floor().min(hi)),
            start,
            weight,
        );
        if b.is_finite() {
            add_weights(
                profile,
                b,
                ((b - reach).ceil().max(lo), f_hi),
                start,
                weight,
            );
            for i in f_hi as usize + 1..=i_hi {
                let (big, small) = profile.integral_and_weight(b - i as f64);
                density[i - start] += big;
                weight[i - start] += small;
            }
        }
        return;
    }
    for i in i_lo..=i_hi {
        density[i - start] += partial(i);
    }
    for c in [a, b].into_iter().filter(|c| c.is_finite()) {
        let window = ((c - reach).ceil().max(lo), (c + reach).floor().min(hi));
        add_weights(profile, c, window, start, weight);
    }
}

/// Adds the weight `g(c - i)` of the crossing at `c` to `weight[i - start]` for the samples
/// `i` from `window.0` to `window.1` (whole numbers; none when the window is empty).
#[inline]
fn add_weights(
    profile: &LineProfile,
    c: f64,
    (from, to): (f64, f64),
    start: usize,
    weight: &mut [f64],
) {
    if to < from {
        return;
    }
    for i in from as usize..=to as usize {
        weight[i - start] += profile.weight_at(c - i as f64);
    }
}

/// Which rows of a family have a non-empty lattice line within reach: a summed-area table of
/// the non-empty lines, so the test is O(1) per row.
struct ActiveLines {
    sums: Vec<u32>,
    width: usize,
    counts: (usize, usize),
    reach: usize,
}

impl ActiveLines {
    fn new(crossings: &LineCrossings, reach: usize) -> ActiveLines {
        let (lu, lv) = crossings.family.line_counts();
        let width = lu + 1;
        let mut sums = vec![0u32; width * (lv + 1)];
        let lines = crossings.lookup();
        for n in 0..lv {
            let mut row = 0u32;
            for m in 0..lu {
                row += !lines.line(m as isize, n as isize).is_empty() as u32;
                sums[(n + 1) * width + m + 1] = sums[n * width + m + 1] + row;
            }
        }
        ActiveLines {
            sums,
            width,
            counts: (lu, lv),
            reach,
        }
    }

    /// Whether any line within `reach` lattice steps of line (m, n) has crossings.
    fn reaches(&self, m: usize, n: usize) -> bool {
        let (m0, m1) = (
            m.saturating_sub(self.reach),
            (m + self.reach + 1).min(self.counts.0),
        );
        let (n0, n1) = (
            n.saturating_sub(self.reach),
            (n + self.reach + 1).min(self.counts.1),
        );
        if m0 >= m1 || n0 >= n1 {
            return false;
        }
        let at = |m: usize, n: usize| self.sums[n * self.width + m];
        at(m1, n1) + at(m0, n0) > at(m0, n1) + at(m1, n0)
    }
}

fn integrate_families(
    families: &[LineCrossings; 3],
    kernel: &LineKernel,
    grid: &Grid,
) -> Result<Volume, SamplingError> {
    let [nx, ny, nz] = grid.dims;
    let q = families[0].family.lines_per_voxel;
    let slice = nx * ny;
    let reach = (kernel.radius * q as f64).ceil() as usize;
    let active: Vec<ActiveLines> = (families.par_iter())
        .map(|f| ActiveLines::new(f, reach))
        .collect();
    memory::check_allocation(
        "the filtered density",
        memory::bytes_of::<f32>(2 * grid.len()),
    )?;
    let mut num: Vec<f32> = memory::zeroed_vec(grid.len());
    let mut den: Vec<f32> = memory::zeroed_vec(grid.len());

    // The row of samples along the family's axis through lattice line (m, n): its density and
    // surface weight in `rows`, or false when no line within reach has a crossing.
    let row = |rows: &mut Rows, f: usize, m: usize, n: usize, range: Range<usize>| {
        active[f].reaches(m * q, n * q)
            && rows.run(
                &families[f],
                kernel,
                (m * q) as isize,
                (n * q) as isize,
                range,
            )
    };

    // x-lines (cross axes y, z) and y-lines (cross axes z, x), slice by slice.
    num.par_chunks_mut(slice)
        .zip(den.par_chunks_mut(slice))
        .enumerate()
        .for_each(|(k, (num, den))| {
            let mut rows = Rows::new(nx.max(ny));
            for j in 0..ny {
                // Samples that see no surface (weight 0) are skipped: their terms are zero
                // (see `blend_z_family`), and the buffers start at +0.
                if row(&mut rows, 0, j, k, 0..nx) {
                    for i in 0..nx {
                        if rows.weight[i] != 0.0 {
                            let (n, d) = rows.weighted(i);
                            num[j * nx + i] = n as f32;
                            den[j * nx + i] = d as f32;
                        }
                    }
                }
            }
            for i in 0..nx {
                if row(&mut rows, 1, k, i, 0..ny) {
                    for j in 0..ny {
                        if rows.weight[j] != 0.0 {
                            let (n, d) = rows.weighted(j);
                            num[j * nx + i] += n as f32;
                            den[j * nx + i] += d as f32;
                        }
                    }
                }
            }
        });

    // z-lines (cross axes x, y); the blend is finished there, for every sample.
    let z_row = |rows: &mut Rows, i: usize, j: usize| {
        active[2].reaches(i * q, j * q)
            && rows.run(
                &families[2],
                kernel,
                (i * q) as isize,
                (j * q) as isize,
                0..nz,
            )
    };
    blend_z_family(&mut num, &den, grid, z_row);
    drop(den);
    Ok(Volume::from_vec(*grid, num)?)
}

/// z-lines of a block of x per task.
const Z_BLOCK: usize = 16;

/// The z family's rows (`z_row(rows, i, j)`: true when it left the row of (i, j) in `rows`)
/// blended into the x and y families' sums `num` (w² f) and `den` (w²): every sample of `num`
/// becomes the blended density. One task per y; each runs the rows of `Z_BLOCK` consecutive
/// x, then writes their samples slice by slice, a cache line at a time instead of one sample
/// per slice and row. The same arithmetic per sample as one row at a time.
///
/// The x and y passes leave a sample's terms at +0 where its row has weight 0 instead of
/// writing `0 · f` (which is -0 for a density a rounding below 0) and adding it: the blend is
/// the same bit for bit, since a term so left out could only change the sign of a zero `num`,
/// and `num` is then either added to a non-zero `w f`, or to `w f = +0` (f is never -0), or not
/// read at all (`total = 0`); `den` gains `w² = +0` either way.
fn blend_z_family<F>(num: &mut [f32], den: &[f32], grid: &Grid, z_row: F)
where
    F: Fn(&mut Rows, usize, usize) -> bool + Sync,
{
    let [nx, ny, nz] = grid.dims;
    let slice = nx * ny;
    let shared_num = DisjointSlice::new(num);
    (0..ny).into_par_iter().for_each_init(
        || (Rows::new(nz), vec![(0.0f64, 0.0f64); nz * Z_BLOCK]),
        |(rows, block), j| {
            for i0 in (0..nx).step_by(Z_BLOCK) {
                let width = Z_BLOCK.min(nx - i0);
                // block[k * Z_BLOCK + b]: (f, w²) of sample (i0 + b, j, k).
                for b in 0..width {
                    let touched = z_row(rows, i0 + b, j);
                    for k in 0..nz {
                        block[k * Z_BLOCK + b] = if touched {
                            (rows.density[k], rows.weight[k] * rows.weight[k])
                        } else {
                            (0.0, 0.0)
                        };
                    }
                }
                for k in 0..nz {
                    let at = k * slice + j * nx + i0;
                    // SAFETY: samples (i0.., j, k) are read and written by task j alone.
                    let out = unsafe { shared_num.run_mut(at, width) };
                    let sums = out.iter_mut().zip(&den[at..at + width]);
                    for ((n, &d), &(f, w)) in sums.zip(&block[k * Z_BLOCK..]) {
                        let total = d as f64 + w;
                        let value = if total > 0.0 {
                            (*n as f64 + w * f) / total
                        } else {
                            f
                        };
                        *n = value as f32;
                    }
                }
            }
        },
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::threshold::ThresholdSolid;
    use crate::{CsgSolid, Shape};
    use voxlod_core::glam::DVec3;

    /// The row integrated sample by sample: `G(b - x) - G(a - x)` for every sample in reach of
    /// a span, the full weight through `diff` where the window lies inside; the reference that
    /// [`Rows::run`] must match bit for bit.
    fn reference_run(
        crossings: &LineCrossings,
        kernel: &LineKernel,
        (m0, n0): (isize, isize),
        range: Range<usize>,
    ) -> (Vec<f64>, Vec<f64>, bool) {
        let n = range.len();
        let (mut density, mut weight, mut diff) = (vec![0.0; n], vec![0.0; n], vec![0.0; n + 1]);
        let (lo, hi) = (range.start as f64, (range.end - 1) as f64);
        let mut touched = false;
        for line in &kernel.lines {
            let ts = crossings
                .lookup()
                .line(m0 + line.du as isize, n0 + line.dv as isize);
            touched |= !ts.is_empty();
            let profile = &kernel.profiles[line.profile as usize];
            let reach = profile.reach;
            for pair in ts.chunks(2) {
                let a = pair[0] as f64;
                let b = pair.get(1).map_or(f64::INFINITY, |&b| b as f64);
                let f_lo = (a + reach).ceil().max(lo);
                let f_hi = (b - reach).floor().min(hi);
                if f_lo <= f_hi {
                    diff[f_lo as usize - range.start] += profile.total();
                    diff[f_hi as usize - range.start + 1] -= profile.total();
                }
                for i in range.clone() {
                    let x = i as f64;
                    let in_reach = x >= a - reach && x <= b + reach;
                    if in_reach && !(f_lo <= x && x <= f_hi) {
                        let partial = profile.integral_to(b - x) - profile.integral_to(a - x);
                        density[i - range.start] += partial;
                    }
                }
                for c in [a, b].into_iter().filter(|c| c.is_finite()) {
                    for i in range.clone() {
                        let x = i as f64;
                        if x >= c - reach && x <= c + reach {
                            weight[i - range.start] += profile.weight_at(c - x);
                        }
                    }
                }
            }
        }
        if touched {
            let mut running = 0.0;
            for (d, step) in density.iter_mut().zip(&diff) {
                running += step;
                *d += running;
            }
        }
        (density, weight, touched)
    }

    /// Every row of every family of `solid` on `grid`, whole and in two windows, against the
    /// reference; returns the rows compared that held crossings.
    fn compare_rows(solid: &dyn Solid, grid: &Grid, filter: Filter, radius: f64) -> usize {
        let options = DensityOptions::new(filter, radius);
        let (crossings, kernel, _) = lattice_crossings(solid, grid, &options, &|_| 0).unwrap();
        compare_family_rows(&crossings, &kernel, grid)
    }

    /// [`compare_rows`] for given crossings (the X, Y, Z families, or fewer) and kernel.
    fn compare_family_rows(crossings: &[LineCrossings], kernel: &LineKernel, grid: &Grid) -> usize {
        let q = crossings[0].family.lines_per_voxel;
        let mut rows = Rows::new(grid.dims.into_iter().max().unwrap());
        let mut touched_rows = 0;
        for (f, family) in crossings.iter().enumerate() {
            let axis = [Axis::X, Axis::Y, Axis::Z][f];
            let (ua, va) = axis.others();
            let len = grid.dims[axis.index()];
            let ranges = [0..len, 0..len / 2 + 1, len / 3..len];
            for m in 0..grid.dims[ua.index()] {
                for n in 0..grid.dims[va.index()] {
                    let line = ((m * q) as isize, (n * q) as isize);
                    for range in ranges.clone() {
                        let touched = rows.run(family, kernel, line.0, line.1, range.clone());
                        let (d, w, t) = reference_run(family, kernel, line, range.clone());
                        assert_eq!(touched, t);
                        touched_rows += t as usize;
                        let k = range.len();
                        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                        assert_eq!(bits(&rows.density[..k]), bits(&d), "{f} {m} {n} {range:?}");
                        assert_eq!(bits(&rows.weight[..k]), bits(&w), "{f} {m} {n} {range:?}");
                    }
                }
            }
        }
        touched_rows
    }

    /// Rows whose running sum steps up and down by unequal amounts (so that it ends a rounding
    /// away from zero), with runs of zero steps and densities already set: the segmented sum
    /// bit for bit the one step at a time.
    #[test]
    fn the_segmented_running_sum_is_the_stepwise_sum() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(1414);
        let mut nonzero_ends = 0;
        for _ in 0..2000 {
            let n = rng.random_range(1..80);
            let mut diff = vec![0.0; n + 1];
            let fulls: Vec<f64> = (0..rng.random_range(0..6))
                .map(|_| rng.random_range(0.001..0.1))
                .collect();
            for &full in &fulls {
                let a = rng.random_range(0..n);
                let b = rng.random_range(a..=n);
                diff[a] += full;
                diff[b] -= full;
            }
            let density: Vec<f64> = (0..n)
                .map(|_| {
                    if rng.random_bool(0.5) {
                        0.0
                    } else {
                        rng.random_range(0.0..0.01)
                    }
                })
                .collect();
            let mut expected = density.clone();
            let mut running = 0.0;
            for (d, step) in expected.iter_mut().zip(&diff) {
                running += step;
                *d += running;
            }
            nonzero_ends += (running != 0.0) as usize;
            let mut got = density;
            add_running_sum(&mut got, &diff);
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&got), bits(&expected));
        }
        assert!(nonzero_ends > 10, "{nonzero_ends}");
    }

    /// Crossings on half and quarter samples, where `a + reach` and `b - reach` are whole
    /// numbers for the lines whose reach is (the sample's own line at radii 1.5 and 2, and
    /// others): the long spans' weight windows hold one more sample than their partials'.
    #[test]
    fn rows_match_the_reference_where_window_ends_are_whole() {
        let grid = Grid::new([16, 5, 4], [1.0; 3], [0.0; 3]).unwrap();
        for (filter, radius) in [
            (Filter::GAUSSIAN, 1.5),
            (Filter::Hypercone, 1.5),
            (Filter::GAUSSIAN, 2.0),
            (Filter::Hypercone, 1.25),
        ] {
            let options = DensityOptions::new(filter, radius);
            let q = options.lines_per_voxel(1.0);
            let family = LineFamily::new(Axis::X, grid, q);
            let (tu, tv) = family.tile_counts();
            let tiles = (0..tu * tv)
                .map(|id| {
                    let (ms, ns) = family.tile_lines(id % tu, id / tu);
                    let mut list = Vec::new();
                    for (row, n) in ns.enumerate() {
                        for (col, m) in ms.clone().enumerate() {
                            let local = (row * crate::lattice::TILE + col) as u16;
                            // Spans of 3.5 to 7.25 samples, starting on a half or a quarter,
                            // and an odd count (open at the end) on every fifth line.
                            let start = ((m + 3 * n) % 7) as f32 * 0.25 - 0.5;
                            let mut t = vec![start, start + 3.5 + (m % 4) as f32, start + 9.5];
                            if (m + n) % 5 != 0 {
                                t.push(start + 12.75);
                            }
                            list.extend(t.into_iter().map(|t| (local, t)));
                        }
                    }
                    list
                })
                .collect();
            let crossings = [LineCrossings::from_tiles(family, tiles)];
            let kernel = LineKernel::new(filter, radius, q);
            assert!(compare_family_rows(&crossings, &kernel, &grid) > 20);
        }
    }

    /// The three families blended one row at a time, every sample written where its rows
    /// are: the reference of [`integrate_families`] and its blocked z pass.
    fn reference_blend(
        families: &[LineCrossings; 3],
        kernel: &LineKernel,
        grid: &Grid,
    ) -> Vec<f32> {
        let [nx, ny, nz] = grid.dims;
        let q = families[0].family.lines_per_voxel as isize;
        let mut rows = Rows::new(nx.max(ny).max(nz));
        let (mut num, mut den) = (vec![0f32; grid.len()], vec![0f32; grid.len()]);
        let at = |i: usize, j: usize, k: usize| k * nx * ny + j * nx + i;
        for k in 0..nz {
            for j in 0..ny {
                if rows.run(&families[0], kernel, j as isize * q, k as isize * q, 0..nx) {
                    for i in 0..nx {
                        let (n, d) = rows.weighted(i);
                        (num[at(i, j, k)], den[at(i, j, k)]) = (n as f32, d as f32);
                    }
                }
            }
            for i in 0..nx {
                if rows.run(&families[1], kernel, k as isize * q, i as isize * q, 0..ny) {
                    for j in 0..ny {
                        let (n, d) = rows.weighted(j);
                        num[at(i, j, k)] += n as f32;
                        den[at(i, j, k)] += d as f32;
                    }
                }
            }
        }
        for j in 0..ny {
            for i in 0..nx {
                let touched = rows.run(&families[2], kernel, i as isize * q, j as isize * q, 0..nz);
                for k in 0..nz {
                    let (f, w) = if touched {
                        (rows.density[k], rows.weight[k] * rows.weight[k])
                    } else {
                        (0.0, 0.0)
                    };
                    let (n, d) = (num[at(i, j, k)], den[at(i, j, k)]);
                    let total = d as f64 + w;
                    num[at(i, j, k)] = if total > 0.0 {
                        ((n as f64 + w * f) / total) as f32
                    } else {
                        f as f32
                    };
                }
            }
        }
        num
    }

    /// A scan of unit spacing whose values jump from sample to sample (-30 to 45): thresholded
    /// at 1, many short spans.
    fn noisy_scan(dims: [usize; 3]) -> Volume {
        let grid = Grid::new(dims, [1.0; 3], [0.0; 3]).unwrap();
        let values = (0..grid.len())
            .map(|n| ((n * 37 % 101) as f32 - 40.0) * 0.75)
            .collect();
        Volume::from_vec(grid, values).unwrap()
    }

    /// Grids whose x is not a whole number of z blocks, a ball and a noisy scan: the blended
    /// density bit for bit the one-row-at-a-time reference's.
    #[test]
    fn the_blocked_blend_is_the_row_by_row_blend() {
        let ball = CsgSolid::new(Shape::sphere(DVec3::new(0.4, 0.3, -0.2), 5.3)).unwrap();
        let grid = Grid::new([37, 15, 13], [1.0; 3], [-18.0, -7.0, -6.0]).unwrap();
        let scan = noisy_scan([21, 9, 10]);
        let scan_grid = scan.grid;
        let noisy = ThresholdSolid::new(&scan, 1.0).unwrap();
        let cases: [(&dyn Solid, Grid, Filter, f64); 3] = [
            (&ball, grid, Filter::Hypercone, 1.0),
            (&ball, grid, Filter::GAUSSIAN, 2.3),
            (&noisy, scan_grid, Filter::Hypercone, 1.5),
        ];
        for (solid, grid, filter, radius) in cases {
            let options = DensityOptions::new(filter, radius);
            let (crossings, kernel, _) = lattice_crossings(solid, &grid, &options, &|_| 0).unwrap();
            let expected = reference_blend(&crossings, &kernel, &grid);
            let got = integrate_families(&crossings, &kernel, &grid).unwrap();
            let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(got.as_slice()), bits(&expected));
            assert!(expected.iter().any(|&v| v > 0.0 && v < 1.0));
        }
    }

    #[test]
    fn rows_match_the_sample_by_sample_reference() {
        // Two balls (long spans: partial ends and full middles), at two filter radii and both
        // filters.
        let balls = CsgSolid::new(Shape::Union(vec![
            Shape::sphere(DVec3::new(0.3, -0.2, 0.1), 3.7),
            Shape::sphere(DVec3::new(4.1, 3.9, -2.6), 1.3),
        ]))
        .unwrap();
        let grid = Grid::new([14, 13, 12], [1.0; 3], [-6.0, -5.5, -6.2]).unwrap();
        for (filter, radius) in [(Filter::Hypercone, 1.0), (Filter::GAUSSIAN, 2.3)] {
            assert!(compare_rows(&balls, &grid, filter, radius) > 100);
        }
        // A noisy thresholded scan: many short spans, windows narrower than the filter.
        let scan = noisy_scan([11, 9, 10]);
        let scan_grid = scan.grid;
        let solid = ThresholdSolid::new(&scan, 1.0).unwrap();
        for radius in [0.7, 1.5] {
            assert!(compare_rows(&solid, &scan_grid, Filter::Hypercone, radius) > 100);
        }
    }
}
