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
/// the memory budget. Shared by [`filtered_density`] and [`crate::narrow_band`].
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
    let mut families = [Axis::X, Axis::Y, Axis::Z].map(|a| LineFamily::new(a, *grid, q));
    let crossings: Result<Vec<LineCrossings>, SamplingError> =
        families.iter_mut().map(|f| solid.crossings(f)).collect();
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
    /// Whether a line of the pattern held a crossing (else the row is empty).
    touched: bool,
}

impl Rows {
    pub(crate) fn new(n: usize) -> Rows {
        Rows {
            density: vec![0.0; n],
            weight: vec![0.0; n],
            diff: vec![0.0; n + 1],
            touched: false,
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
        let block = std::slice::from_mut(self);
        Rows::run_block(block, &[(m0, n0)], crossings, kernel, range);
        self.touched
    }

    /// [`Rows::run`] for the rows `block`, row `r` along line `starts[r]`, all over `range`.
    /// The pattern's lines are the outer loop, so one line's profile table serves every row of
    /// the block while it is in cache; each sample still gets its terms in the pattern's order,
    /// so the sums are bit for bit those of one row at a time.
    pub(crate) fn run_block(
        block: &mut [Rows],
        starts: &[(isize, isize)],
        crossings: &LineCrossings,
        kernel: &LineKernel,
        range: Range<usize>,
    ) {
        let n = range.len();
        for rows in block.iter_mut() {
            rows.density[..n].fill(0.0);
            rows.weight[..n].fill(0.0);
            rows.diff[..n + 1].fill(0.0);
            rows.touched = false;
        }
        let lines = crossings.lookup();
        for line in &kernel.lines {
            let profile = &kernel.profiles[line.profile as usize];
            for (rows, &(m0, n0)) in block.iter_mut().zip(starts) {
                let ts = lines.line(m0 + line.du as isize, n0 + line.dv as isize);
                if ts.is_empty() {
                    continue;
                }
                rows.touched = true;
                for pair in ts.chunks(2) {
                    let b = pair.get(1).map_or(f64::INFINITY, |&b| b as f64);
                    rows.span(profile, pair[0] as f64, b, &range);
                }
            }
        }
        for rows in block.iter_mut().filter(|rows| rows.touched) {
            let mut running = 0.0;
            for (d, step) in rows.density[..n].iter_mut().zip(&rows.diff[..n + 1]) {
                running += step;
                *d += running;
            }
        }
    }

    /// Adds the inside span `[a, b]` of one pattern line (`b` infinite: inside to the end) to
    /// the samples `range` of the row: the partial integrals at its ends, the full weight of
    /// the line through `diff` between them, and the crossings' surface weights.
    ///
    /// The sums are those of the reference `G(b - x) - G(a - x)` at every sample in reach, in
    /// the same order, with the lookups that are known constants left out: before the samples
    /// that get the full weight `b - x` exceeds the reach by at least a sample (so `G(b - x)`
    /// is the full integral, bit for bit), after them `a - x` lies a sample below `-L` (so
    /// `G(a - x)` is 0, and subtracting 0 changes nothing).
    #[inline]
    fn span(&mut self, profile: &LineProfile, a: f64, b: f64, range: &Range<usize>) {
        let (lo, hi) = (range.start as f64, (range.end - 1) as f64);
        let base = range.start;
        let reach = profile.reach;
        if b + reach < lo || a - reach > hi {
            return;
        }
        let density = &mut self.density[..range.len()];
        // Samples whose window lies inside the span get the full weight at once.
        let f_lo = (a + reach).ceil().max(lo);
        let f_hi = (b - reach).floor().min(hi);
        let i_lo = (a - reach).ceil().max(lo) as usize;
        let i_hi = (b + reach).floor().min(hi) as usize;
        if f_lo <= f_hi {
            let full = profile.total();
            let (f_lo, f_hi) = (f_lo as usize, f_hi as usize);
            self.diff[f_lo - base] += full;
            self.diff[f_hi - base + 1] -= full;
            for (d, i) in density[i_lo - base..f_lo - base].iter_mut().zip(i_lo..) {
                *d += full - profile.integral_to(a - i as f64);
            }
            let after = f_hi + 1;
            for (d, i) in density[after - base..=i_hi - base].iter_mut().zip(after..) {
                *d += profile.integral_to(b - i as f64);
            }
        } else {
            for (d, i) in density[i_lo - base..i_hi + 1 - base].iter_mut().zip(i_lo..) {
                let x = i as f64;
                *d += profile.integral_to(b - x) - profile.integral_to(a - x);
            }
        }
        for c in [a, b].into_iter().filter(|c| c.is_finite()) {
            let w_lo = (c - reach).ceil().max(lo);
            let w_hi = (c + reach).floor().min(hi);
            if w_hi < w_lo {
                continue;
            }
            let (w_lo, w_hi) = (w_lo as usize, w_hi as usize);
            let weight = &mut self.weight[w_lo - base..=w_hi - base];
            for (w, i) in weight.iter_mut().zip(w_lo..) {
                *w += profile.weight_at(c - i as f64);
            }
        }
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

/// Rows integrated together by [`Rows::run_block`], up to `BLOCK` neighbours at a time.
const BLOCK: usize = 16;

/// A block of rows of one family: scratch for `BLOCK` rows, and for each row of the block
/// whether it held crossings and in which slot.
struct RowBlock {
    rows: Vec<Rows>,
    starts: [(isize, isize); BLOCK],
    slots: [Option<usize>; BLOCK],
}

impl RowBlock {
    fn new(n: usize) -> RowBlock {
        RowBlock {
            rows: (0..BLOCK).map(|_| Rows::new(n)).collect(),
            starts: [(0, 0); BLOCK],
            slots: [None; BLOCK],
        }
    }

    /// Integrates the rows `first..first + width` (at most `BLOCK`) over `range`, row `r`
    /// along lattice line `line(r)`; rows with no non-empty line in reach are not integrated.
    fn run(
        &mut self,
        family: (&LineCrossings, &ActiveLines),
        kernel: &LineKernel,
        line: impl Fn(usize) -> (usize, usize),
        first: usize,
        width: usize,
        range: Range<usize>,
    ) {
        let (crossings, active) = family;
        let mut count = 0;
        for r in 0..width {
            let (m, n) = line(first + r);
            self.slots[r] = active.reaches(m, n).then(|| {
                self.starts[count] = (m as isize, n as isize);
                count += 1;
                count - 1
            });
        }
        let block = &mut self.rows[..count];
        Rows::run_block(block, &self.starts[..count], crossings, kernel, range);
        for slot in &mut self.slots[..width] {
            *slot = slot.filter(|&s| self.rows[s].touched);
        }
    }

    /// Row `r` of the last block (0 for its first), when it held crossings.
    #[inline]
    fn row(&self, r: usize) -> Option<&Rows> {
        self.slots[r].map(|s| &self.rows[s])
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
    let active = [0, 1, 2].map(|f| ActiveLines::new(&families[f], reach));
    memory::check_allocation(
        "the filtered density",
        memory::bytes_of::<f32>(2 * grid.len()),
    )?;
    let mut num: Vec<f32> = memory::zeroed_vec(grid.len());
    let mut den: Vec<f32> = memory::zeroed_vec(grid.len());

    let family = |f: usize| (&families[f], &active[f]);

    // x-lines (cross axes y, z) and y-lines (cross axes z, x), slice by slice.
    num.par_chunks_mut(slice)
        .zip(den.par_chunks_mut(slice))
        .enumerate()
        .for_each_init(
            || RowBlock::new(nx.max(ny)),
            |block, (k, (num, den))| {
                for j0 in (0..ny).step_by(BLOCK) {
                    let width = BLOCK.min(ny - j0);
                    block.run(family(0), kernel, |j| (j * q, k * q), j0, width, 0..nx);
                    for (j, rows) in (j0..j0 + width)
                        .zip(0..)
                        .filter_map(|(j, r)| Some((j, block.row(r)?)))
                    {
                        for i in 0..nx {
                            let (n, d) = rows.weighted(i);
                            num[j * nx + i] = n as f32;
                            den[j * nx + i] = d as f32;
                        }
                    }
                }
                for i0 in (0..nx).step_by(BLOCK) {
                    let width = BLOCK.min(nx - i0);
                    block.run(family(1), kernel, |i| (k * q, i * q), i0, width, 0..ny);
                    for j in 0..ny {
                        for r in 0..width {
                            if let Some(rows) = block.row(r) {
                                let (n, d) = rows.weighted(j);
                                num[j * nx + i0 + r] += n as f32;
                                den[j * nx + i0 + r] += d as f32;
                            }
                        }
                    }
                }
            },
        );

    // z-lines (cross axes x, y): the blend is finished there, for every sample.
    finish_z_lines(
        &mut num,
        &den,
        grid,
        &|block: &mut RowBlock, i0, width, j| {
            block.run(family(2), kernel, |i| (i * q, j * q), i0, width, 0..nz);
        },
    );
    drop(den);
    Ok(Volume::from_vec(*grid, num)?)
}

/// Adds the z-lines to the x and y families' sums `num` and `den` and finishes the blend in
/// `num`: one task per y, integrating `BLOCK` rows along x at a time with
/// `run(block, i0, width, j)` and writing them slice by slice (a run of samples along x per
/// slice, not one). Each task reads and writes only its own (i, j, k) samples.
fn finish_z_lines(
    num: &mut [f32],
    den: &[f32],
    grid: &Grid,
    run: &(dyn Fn(&mut RowBlock, usize, usize, usize) + Sync),
) {
    let [nx, ny, nz] = grid.dims;
    let slice = nx * ny;
    let shared_num = DisjointSlice::new(num);
    (0..ny).into_par_iter().for_each_init(
        || RowBlock::new(nz),
        |block, j| {
            for i0 in (0..nx).step_by(BLOCK) {
                let width = BLOCK.min(nx - i0);
                run(block, i0, width, j);
                for k in 0..nz {
                    let first = k * slice + j * nx + i0;
                    for r in 0..width {
                        let (f, w) = match block.row(r) {
                            Some(rows) => (rows.density[k], rows.weight[k] * rows.weight[k]),
                            None => (0.0, 0.0),
                        };
                        let at = first + r;
                        // SAFETY: sample (i, j, k) is read and written by task j alone.
                        let n = unsafe { shared_num.get(at) };
                        let total = den[at] as f64 + w;
                        let value = if total > 0.0 {
                            (n as f64 + w * f) / total
                        } else {
                            f
                        };
                        // SAFETY: as above.
                        unsafe { shared_num.set(at, value as f32) };
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
                        let touched = rows.run(family, &kernel, line.0, line.1, range.clone());
                        let (d, w, t) = reference_run(family, &kernel, line, range.clone());
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

    /// Blocks of rows of every family against the reference: the block's lines outermost must
    /// give each row the sums of one row at a time.
    fn compare_blocks(solid: &dyn Solid, grid: &Grid, filter: Filter, radius: f64) {
        let options = DensityOptions::new(filter, radius);
        let (crossings, kernel, _) = lattice_crossings(solid, grid, &options, &|_| 0).unwrap();
        let q = crossings[0].family.lines_per_voxel as isize;
        let longest = grid.dims.into_iter().max().unwrap();
        let mut block: Vec<Rows> = (0..5).map(|_| Rows::new(longest)).collect();
        for (f, family) in crossings.iter().enumerate() {
            let axis = [Axis::X, Axis::Y, Axis::Z][f];
            let (ua, va) = axis.others();
            let range = 0..grid.dims[axis.index()];
            let count = grid.dims[ua.index()] as isize;
            for n in 0..grid.dims[va.index()] as isize {
                let lines: Vec<(isize, isize)> = (0..count).map(|m| (m * q, n * q)).collect();
                for starts in lines.chunks(5) {
                    let block = &mut block[..starts.len()];
                    Rows::run_block(block, starts, family, &kernel, range.clone());
                    for (rows, &line) in block.iter().zip(starts) {
                        let (d, w, t) = reference_run(family, &kernel, line, range.clone());
                        assert_eq!(rows.touched, t);
                        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                        assert_eq!(bits(&rows.density[..range.len()]), bits(&d), "{f} {line:?}");
                        assert_eq!(bits(&rows.weight[..range.len()]), bits(&w), "{f} {line:?}");
                    }
                }
            }
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
            compare_blocks(&balls, &grid, filter, radius);
        }
        // A noisy thresholded scan: many short spans, windows narrower than the filter.
        let scan_grid = Grid::new([11, 9, 10], [1.0; 3], [0.0; 3]).unwrap();
        let values = (0..scan_grid.len())
            .map(|n| ((n * 37 % 101) as f32 - 40.0) * 0.75)
            .collect();
        let scan = Volume::from_vec(scan_grid, values).unwrap();
        let solid = ThresholdSolid::new(&scan, 1.0).unwrap();
        for radius in [0.7, 1.5] {
            assert!(compare_rows(&solid, &scan_grid, Filter::Hypercone, radius) > 100);
            compare_blocks(&solid, &scan_grid, Filter::Hypercone, radius);
        }
    }
}
