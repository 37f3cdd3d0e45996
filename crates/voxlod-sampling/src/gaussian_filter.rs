//! A separable Gaussian filter of a sampled volume with SciPy's boundary modes: what
//! `scipy.ndimage.gaussian_filter` computes on a 3-D array, for the paper's second route for
//! scanned data (§4, filtering the data directly) and for the Python package's drop-in.
//!
//! Not in the paper, which filters with the hyper-cone or a truncated Gaussian of finite
//! support (see [`crate::gaussian`]); this is the plain sampled Gaussian of image processing.
//!
//! **Taps.** Per axis, `exp(-x²/2σ²)` at the integers `|x| ≤ ⌊truncate·σ + 1/2⌋`, normalised to
//! sum 1 (SciPy's rule, [`gaussian_taps_f64`]); an axis with σ = 0 is left alone.
//!
//! **Borders.** [`BoundaryMode`] extends the samples past each end as SciPy's modes do:
//! `reflect` (d c b a | a b c d | d c b a), `mirror` (d c b | a b c d | c b a), `nearest`
//! (a a a | a b c d | d d d), `wrap` (b c d | a b c d | a b c) and `constant` (k k k | a b c d |
//! k k k).
//!
//! **Passes.** The x and y passes run slice by slice in cache into the output; the z pass then
//! sweeps strips of the slices along z in place, keeping the last `r + 1` original slices of its
//! strip in a ring. Every pass is one kernel, [`combine_rows`]: the output, 32 samples at a time
//! held in registers, is the centre tap times its row plus, per `k = 1 ..= r`, the shared tap of
//! offsets ±k times the sum of the two rows `k` away (the taps are symmetric, as SciPy also
//! exploits): r + 1 multiply-adds and r additions per sample and axis instead of 2r + 1 of each,
//! and one store. On x86-64 CPUs with AVX2 and FMA (checked at run time) the passes are compiled
//! for them: eight `f32` per instruction and fused multiply-adds, whose single rounding moves
//! results by an ulp or so (beyond the paper: a speed matter only). Cost: O(N³ Σₐ(rₐ + 1))
//! multiply-adds, one output volume, about two reads and two writes of it.

use std::ops::{Add, AddAssign, Mul};

use rayon::prelude::*;
use voxlod_core::disjoint::DisjointSlice;
use voxlod_core::memory;

use crate::SamplingError;

/// How samples past the ends of an axis are made up (SciPy's `mode`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BoundaryMode {
    /// Half-sample symmetric: the edge sample is repeated (`d c b a | a b c d`).
    Reflect,
    /// Whole-sample symmetric: the edge sample is not repeated (`d c b | a b c d`).
    Mirror,
    /// The edge sample extends (`a a a | a b c d`).
    Nearest,
    /// Periodic (`b c d | a b c d | a b c`).
    Wrap,
    /// A constant outside (`k k k | a b c d`).
    Constant(f64),
}

impl BoundaryMode {
    /// The mode of a SciPy mode name (`cval` used by `constant` only), or `None`.
    pub fn from_name(name: &str, cval: f64) -> Option<BoundaryMode> {
        Some(match name {
            "reflect" | "grid-mirror" => BoundaryMode::Reflect,
            "mirror" => BoundaryMode::Mirror,
            "nearest" => BoundaryMode::Nearest,
            "wrap" | "grid-wrap" => BoundaryMode::Wrap,
            "constant" | "grid-constant" => BoundaryMode::Constant(cval),
            _ => return None,
        })
    }

    /// The sample standing for index `i` of an axis of `n` samples; `None` for the constant.
    #[inline]
    pub fn index(self, i: i64, n: i64) -> Option<usize> {
        if (0..n).contains(&i) {
            return Some(i as usize);
        }
        let folded = match self {
            BoundaryMode::Constant(_) => return None,
            BoundaryMode::Nearest => i.clamp(0, n - 1),
            BoundaryMode::Wrap => i.rem_euclid(n),
            BoundaryMode::Reflect => {
                let period = 2 * n;
                let m = i.rem_euclid(period);
                if m < n {
                    m
                } else {
                    period - 1 - m
                }
            }
            BoundaryMode::Mirror if n == 1 => 0,
            BoundaryMode::Mirror => {
                let period = 2 * n - 2;
                let m = i.rem_euclid(period);
                if m < n {
                    m
                } else {
                    period - m
                }
            }
        };
        Some(folded as usize)
    }

    fn constant(self) -> f64 {
        match self {
            BoundaryMode::Constant(value) => value,
            _ => 0.0,
        }
    }
}

/// Options of [`gaussian_filter`]: SciPy's defaults.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GaussianFilterOptions {
    /// Standard deviation per axis (x, y, z) in samples; 0 leaves an axis unfiltered.
    pub sigma: [f64; 3],
    /// Truncation in standard deviations.
    pub truncate: f64,
    /// How samples past the borders are made up.
    pub mode: BoundaryMode,
}

impl Default for GaussianFilterOptions {
    /// σ = 1 sample on every axis, truncated at 4σ, borders reflected (SciPy's defaults).
    fn default() -> Self {
        GaussianFilterOptions::isotropic(1.0)
    }
}

impl GaussianFilterOptions {
    /// The same σ (in samples) on every axis, SciPy's truncation and border.
    pub fn isotropic(sigma: f64) -> Self {
        GaussianFilterOptions {
            sigma: [sigma; 3],
            truncate: 4.0,
            mode: BoundaryMode::Reflect,
        }
    }
}

/// A sample type the filter runs in: `f32` or `f64`.
pub trait FilterSample:
    Copy + Send + Sync + Default + Add<Output = Self> + Mul<Output = Self> + AddAssign + 'static
{
    /// The nearest value of this type.
    fn from_f64(value: f64) -> Self;
    /// `self · a + b` rounded once (a fused multiply-add).
    fn mul_add(self, a: Self, b: Self) -> Self;
}

impl FilterSample for f32 {
    #[inline]
    fn from_f64(value: f64) -> Self {
        value as f32
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        f32::mul_add(self, a, b)
    }
}

impl FilterSample for f64 {
    #[inline]
    fn from_f64(value: f64) -> Self {
        value
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        f64::mul_add(self, a, b)
    }
}

/// One axis's taps and border.
struct AxisKernel<T> {
    /// The taps at offsets `-r ..= r`.
    taps: Vec<T>,
    /// The centre tap, then the tap shared by offsets `±k` for `k = 1 ..= r` (the taps are
    /// symmetric).
    half: Vec<T>,
    mode: BoundaryMode,
    constant: T,
}

impl<T: FilterSample> AxisKernel<T> {
    fn new(sigma: f64, truncate: f64, mode: BoundaryMode) -> Self {
        let taps = if sigma > 0.0 {
            gaussian_taps_f64(sigma, truncate)
        } else {
            vec![1.0]
        };
        let r = taps.len() / 2;
        debug_assert!((1..=r).all(|k| taps[r - k] == taps[r + k]));
        AxisKernel {
            half: taps[r..].iter().map(|&t| T::from_f64(t)).collect(),
            taps: taps.into_iter().map(T::from_f64).collect(),
            mode,
            constant: T::from_f64(mode.constant()),
        }
    }

    fn radius(&self) -> usize {
        self.half.len() - 1
    }

    /// The `2r + 1` rows whose weighted sum is output row `j` of an axis of `n` rows:
    /// `row(i)` for the rows inside, `outside` (filled with the constant) for the others.
    #[inline]
    fn source_rows<'s>(
        &self,
        j: usize,
        n: usize,
        outside: &'s [T],
        row: impl Fn(usize) -> &'s [T],
        rows: &mut Vec<&'s [T]>,
    ) {
        rows.clear();
        let r = self.radius() as i64;
        for offset in -r..=r {
            rows.push(match self.mode.index(j as i64 + offset, n as i64) {
                Some(i) => row(i),
                None => outside,
            });
        }
    }
}

/// Normalised 1-D Gaussian taps for standard deviation `sigma` (in samples), truncated at
/// `truncate` standard deviations: SciPy's rule, radius `⌊truncate σ + 1/2⌋`, taps summing to 1.
pub fn gaussian_taps_f64(sigma: f64, truncate: f64) -> Vec<f64> {
    let radius = (truncate * sigma + 0.5).floor().max(0.0) as i64;
    let taps: Vec<f64> = (-radius..=radius)
        .map(|i| (-(i * i) as f64 / (2.0 * sigma * sigma)).exp())
        .collect();
    let sum: f64 = taps.iter().sum();
    taps.into_iter().map(|t| t / sum).collect()
}

/// Samples combined per register block: 32 `f32` are four AVX registers.
const LANES: usize = 32;

/// `w·x + acc`: a fused multiply-add when `FUSED` (only instantiated where the CPU has one).
#[inline(always)]
fn multiply_add<T: FilterSample, const FUSED: bool>(x: T, w: T, acc: T) -> T {
    if FUSED {
        x.mul_add(w, acc)
    } else {
        x * w + acc
    }
}

/// `out[i] = h₀·rows[r][i] + Σₖ hₖ·(rows[r−k][i] + rows[r+k][i])` for the symmetric taps
/// `half` across `2r + 1` rows: [`LANES`] samples at a time, summed in registers over the taps
/// and stored once.
#[inline(always)]
fn combine_rows<T: FilterSample, const FUSED: bool>(half: &[T], rows: &[&[T]], out: &mut [T]) {
    let r = half.len() - 1;
    debug_assert_eq!(rows.len(), 2 * r + 1);
    let n = out.len();
    let mut start = 0;
    while start + LANES <= n {
        let block = |row: &[T]| -> [T; LANES] {
            row[start..start + LANES]
                .try_into()
                .expect("a block of LANES samples")
        };
        let centre = block(rows[r]);
        let mut acc = [T::default(); LANES];
        for i in 0..LANES {
            acc[i] = half[0] * centre[i];
        }
        for k in 1..=r {
            let (below, above) = (block(rows[r - k]), block(rows[r + k]));
            for i in 0..LANES {
                acc[i] = multiply_add::<T, FUSED>(below[i] + above[i], half[k], acc[i]);
            }
        }
        out[start..start + LANES].copy_from_slice(&acc);
        start += LANES;
    }
    for (i, o) in out.iter_mut().enumerate().skip(start) {
        let mut sum = half[0] * rows[r][i];
        for k in 1..=r {
            sum = multiply_add::<T, FUSED>(rows[r - k][i] + rows[r + k][i], half[k], sum);
        }
        *o = sum;
    }
}

/// Convolves one line along x: the interior through [`combine_rows`] on shifted views of the
/// line, the `r` samples at each end tap by tap through the border rule.
#[inline(always)]
fn convolve_line<'s, T: FilterSample, const FUSED: bool>(
    input: &'s [T],
    kernel: &AxisKernel<T>,
    shifted: &mut Vec<&'s [T]>,
    output: &mut [T],
) {
    let n = input.len();
    let r = kernel.radius();
    if n > 2 * r {
        shifted.clear();
        shifted.extend((0..=2 * r).map(|d| &input[d..d + n - 2 * r]));
        combine_rows::<T, FUSED>(&kernel.half, shifted, &mut output[r..n - r]);
    }
    let border = (0..r.min(n)).chain(n.saturating_sub(r).max(r.min(n))..n);
    for i in border {
        let mut sum = T::default();
        for (t, &w) in kernel.taps.iter().enumerate() {
            let value = match kernel.mode.index(i as i64 - r as i64 + t as i64, n as i64) {
                Some(s) => input[s],
                None => kernel.constant,
            };
            sum += w * value;
        }
        output[i] = sum;
    }
}

/// Filters the samples `input` (x fastest, `dims` = [nx, ny, nz]) with a Gaussian. See the
/// module documentation. Fails on a negative or non-finite σ or truncation, a sample count that
/// does not match `dims`, or an output that does not fit in memory.
pub fn gaussian_filter<T: FilterSample>(
    input: &[T],
    dims: [usize; 3],
    options: &GaussianFilterOptions,
) -> Result<Vec<T>, SamplingError> {
    let GaussianFilterOptions {
        sigma,
        truncate,
        mode,
    } = *options;
    if sigma.iter().any(|s| !s.is_finite() || *s < 0.0) || !truncate.is_finite() || truncate < 0.0 {
        return Err(SamplingError::InvalidOption(format!(
            "Gaussian sigma {sigma:?} and truncation {truncate} must be finite and not negative"
        )));
    }
    let len = dims.iter().try_fold(1usize, |a, &d| a.checked_mul(d));
    if len != Some(input.len()) {
        return Err(SamplingError::InvalidOption(format!(
            "{} samples given for a {}x{}x{} grid",
            input.len(),
            dims[0],
            dims[1],
            dims[2]
        )));
    }
    memory::check_allocation(
        "a filtered copy of the volume",
        memory::bytes_of::<T>(input.len()),
    )?;
    // The taps: 2r + 1 per axis with r = ⌊truncate σ + ½⌋ (a σ of 10⁹ asks for gigabytes).
    let taps: f64 = (sigma.iter())
        .map(|s| 2.0 * (truncate * s + 0.5).floor() + 1.0)
        .sum();
    memory::check_allocation(
        &format!("the Gaussian taps of sigma {sigma:?} truncated at {truncate}"),
        (taps * (8 + 2 * std::mem::size_of::<T>()) as f64).min(u64::MAX as f64) as u64,
    )?;
    if input.is_empty() {
        return Ok(Vec::new());
    }
    let kernels: Vec<AxisKernel<T>> = (0..3)
        .map(|a| AxisKernel::new(sigma[a], truncate, mode))
        .collect();
    // Huge pages when the kernel has them: far fewer page faults on first touch.
    let mut output: Vec<T> = memory::zeroed_vec(input.len());
    let fused = fused_multiply_add_available();
    filter_xy(input, dims, &kernels, &mut output, fused);
    filter_z_in_place(&mut output, dims, &kernels[2], fused);
    Ok(output)
}

/// Whether this CPU runs the AVX2 and FMA build of the inner loops (checked once per call).
fn fused_multiply_add_available() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Pass 1: x then y, slice by slice, from `input` into `output`.
fn filter_xy<T: FilterSample>(
    input: &[T],
    dims: [usize; 3],
    kernels: &[AxisKernel<T>],
    output: &mut [T],
    fused: bool,
) {
    let [nx, ny, _] = dims;
    let slice_len = nx * ny;
    let outside = vec![kernels[1].constant; nx];
    output
        .par_chunks_mut(slice_len)
        .zip(input.par_chunks(slice_len))
        .for_each_init(
            || vec![T::default(); slice_len],
            |tmp, (out, slice)| {
                let slice = XySlice {
                    input: slice,
                    tmp,
                    output: out,
                    outside: &outside,
                    nx,
                };
                #[cfg(target_arch = "x86_64")]
                if fused {
                    // SAFETY: `fused` says this CPU has AVX2 and FMA.
                    unsafe { slice.filter_fused(kernels) };
                    return;
                }
                let _ = fused;
                slice.filter::<false>(kernels);
            },
        );
}

/// One z-slice of pass 1: its samples, a slice of scratch, its output, a row of the constant.
struct XySlice<'a, T> {
    input: &'a [T],
    tmp: &'a mut [T],
    output: &'a mut [T],
    outside: &'a [T],
    nx: usize,
}

impl<T: FilterSample> XySlice<'_, T> {
    /// The x pass row by row into the scratch, then the y pass into the output.
    #[inline(always)]
    fn filter<const FUSED: bool>(self, kernels: &[AxisKernel<T>]) {
        let nx = self.nx;
        let ny = self.input.len() / nx;
        let mut shifted = Vec::with_capacity(kernels[0].taps.len());
        for (row_out, row_in) in self.tmp.chunks_mut(nx).zip(self.input.chunks(nx)) {
            convolve_line::<T, FUSED>(row_in, &kernels[0], &mut shifted, row_out);
        }
        let tmp: &[T] = self.tmp;
        let mut rows = Vec::with_capacity(kernels[1].taps.len());
        for (j, row) in self.output.chunks_mut(nx).enumerate() {
            kernels[1].source_rows(
                j,
                ny,
                self.outside,
                |i| &tmp[i * nx..(i + 1) * nx],
                &mut rows,
            );
            combine_rows::<T, FUSED>(&kernels[1].half, &rows, row);
        }
    }

    /// [`Self::filter`] compiled for AVX2 and FMA.
    ///
    /// # Safety
    /// The CPU must have AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn filter_fused(self, kernels: &[AxisKernel<T>]) {
        self.filter::<true>(kernels)
    }
}

/// Pass 2: z, in place, strip by strip of the slices. Before slice k of a strip is overwritten
/// its original is kept in a ring of the last r + 1 slices; the slices above k are still
/// original in place; with `wrap` the first r slices are also kept, for the last ones. Each
/// sample is read from memory about once.
fn filter_z_in_place<T: FilterSample>(
    output: &mut [T],
    dims: [usize; 3],
    kernel: &AxisKernel<T>,
    fused: bool,
) {
    let [nx, ny, nz] = dims;
    if kernel.taps.len() == 1 {
        return;
    }
    let slice_len = nx * ny;
    let r = kernel.radius();
    let head_len = if kernel.mode == BoundaryMode::Wrap {
        r.min(nz)
    } else {
        0
    };
    let outside = vec![kernel.constant; Z_STRIP];
    let shared = DisjointSlice::new(output);
    (0..slice_len.div_ceil(Z_STRIP))
        .into_par_iter()
        .for_each_init(
            || {
                let buffer = |slices: usize| vec![T::default(); slices * Z_STRIP];
                (buffer(r + 1), buffer(head_len))
            },
            |(ring, head), strip| {
                let start = strip * Z_STRIP;
                let strip = ZStrip {
                    shared: &shared,
                    start,
                    width: Z_STRIP.min(slice_len - start),
                    slice_len,
                    nz,
                    ring,
                    head,
                    outside: &outside,
                };
                #[cfg(target_arch = "x86_64")]
                if fused {
                    // SAFETY: `fused` says this CPU has AVX2 and FMA.
                    unsafe { strip.filter_fused(kernel) };
                    return;
                }
                let _ = fused;
                strip.filter::<false>(kernel);
            },
        );
}

/// Samples of each slice that one task of the z pass filters together.
const Z_STRIP: usize = 2048;

/// One strip of the z pass: the run `start..start + width` of every slice, which belongs to
/// this task alone, and its ring, head and constant buffers.
struct ZStrip<'a, 'b, T> {
    shared: &'a DisjointSlice<'b, T>,
    start: usize,
    width: usize,
    slice_len: usize,
    nz: usize,
    ring: &'a mut [T],
    head: &'a mut [T],
    outside: &'a [T],
}

impl<T: FilterSample> ZStrip<'_, '_, T> {
    #[inline(always)]
    fn filter<const FUSED: bool>(self, kernel: &AxisKernel<T>) {
        let ZStrip {
            shared,
            start,
            width,
            slice_len,
            nz,
            ring,
            head,
            outside,
        } = self;
        let ring_len = kernel.radius() + 1;
        let head_len = head.len() / Z_STRIP;
        // Slice k of the strip, in place. SAFETY (of each use): the strip belongs to this task
        // (`DisjointSlice::run_mut`'s rule), and no other reference to slice k of it is alive.
        let slice = |k: usize| unsafe { shared.run_mut(k * slice_len + start, width) };
        for k in 0..nz {
            let here = slice(k);
            ring[(k % ring_len) * Z_STRIP..][..width].copy_from_slice(here);
            if k < head_len {
                head[k * Z_STRIP..][..width].copy_from_slice(here);
            }
            let (ring, head): (&[T], &[T]) = (ring, head);
            let source = |j: usize| -> &[T] {
                if j > k {
                    // Slice j > k of the strip: not yet written, only read here.
                    slice(j)
                } else if k - j < ring_len {
                    &ring[(j % ring_len) * Z_STRIP..][..width]
                } else {
                    // Only `wrap` reaches back further than r slices: to j < r.
                    &head[j * Z_STRIP..][..width]
                }
            };
            let mut rows = Vec::with_capacity(kernel.taps.len());
            kernel.source_rows(k, nz, &outside[..width], source, &mut rows);
            // The rows read are slices j > k, the ring and the head, never slice k.
            combine_rows::<T, FUSED>(&kernel.half, &rows, slice(k));
        }
    }

    /// [`Self::filter`] compiled for AVX2 and FMA.
    ///
    /// # Safety
    /// The CPU must have AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn filter_fused(self, kernel: &AxisKernel<T>) {
        self.filter::<true>(kernel)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The 3-D convolution with the product of the taps, sample by sample, in f64.
    fn naive(
        input: &[f64],
        dims: [usize; 3],
        options: &GaussianFilterOptions,
        at: [usize; 3],
    ) -> f64 {
        let taps: Vec<Vec<f64>> = (0..3)
            .map(|a| {
                if options.sigma[a] > 0.0 {
                    gaussian_taps_f64(options.sigma[a], options.truncate)
                } else {
                    vec![1.0]
                }
            })
            .collect();
        let mut sum = 0.0;
        for (c, wc) in taps[2].iter().enumerate() {
            for (b, wb) in taps[1].iter().enumerate() {
                for (a, wa) in taps[0].iter().enumerate() {
                    let offset = [a, b, c];
                    let mut index = [0usize; 3];
                    let mut outside = false;
                    for axis in 0..3 {
                        let r = (taps[axis].len() / 2) as i64;
                        let i = at[axis] as i64 - r + offset[axis] as i64;
                        match options.mode.index(i, dims[axis] as i64) {
                            Some(s) => index[axis] = s,
                            None => outside = true,
                        }
                    }
                    let value = if outside {
                        options.mode.constant()
                    } else {
                        input[index[0] + dims[0] * (index[1] + dims[1] * index[2])]
                    };
                    sum += wa * wb * wc * value;
                }
            }
        }
        sum
    }

    /// Samples in [0, 1) scrambled over the grid, in f64 and rounded to f32.
    fn scrambled_samples(dims: [usize; 3]) -> (Vec<f64>, Vec<f32>) {
        let input: Vec<f64> = (0..dims.iter().product::<usize>())
            .map(|i| ((i * 7919) % 1013) as f64 / 1013.0)
            .collect();
        let input32 = input.iter().map(|&v| v as f32).collect();
        (input, input32)
    }

    #[test]
    fn every_mode_matches_a_naive_convolution() {
        let dims = [13, 6, 17];
        let (input, input32) = scrambled_samples(dims);
        for mode in [
            BoundaryMode::Reflect,
            BoundaryMode::Mirror,
            BoundaryMode::Nearest,
            BoundaryMode::Wrap,
            BoundaryMode::Constant(0.25),
        ] {
            // The y radius (5) is nearly the axis length: the border rules fold twice.
            let options = GaussianFilterOptions {
                sigma: [1.2, 1.3, 0.0],
                truncate: 4.0,
                mode,
            };
            let got = gaussian_filter(&input, dims, &options).unwrap();
            let got32 = gaussian_filter(&input32, dims, &options).unwrap();
            let with_z = GaussianFilterOptions {
                sigma: [0.7, 0.0, 2.1],
                ..options
            };
            let got_z = gaussian_filter(&input, dims, &with_z).unwrap();
            for at in [[0, 0, 0], [12, 5, 16], [6, 3, 8], [1, 4, 2], [11, 0, 15]] {
                let i = at[0] + 13 * (at[1] + 6 * at[2]);
                let want = naive(&input, dims, &options, at);
                assert!((got[i] - want).abs() < 1e-12, "{mode:?} {at:?}");
                assert!((got32[i] as f64 - want).abs() < 1e-5, "{mode:?} {at:?}");
                let want_z = naive(&input, dims, &with_z, at);
                assert!((got_z[i] - want_z).abs() < 1e-12, "{mode:?} z {at:?}");
            }
        }
    }

    #[test]
    fn rows_wider_than_a_register_block_match_a_naive_convolution() {
        // x and y long enough for the 32-sample blocks of every pass, with tails; z short.
        let dims = [75, 41, 9];
        let (input, input32) = scrambled_samples(dims);
        for mode in [
            BoundaryMode::Reflect,
            BoundaryMode::Wrap,
            BoundaryMode::Constant(-0.5),
        ] {
            let options = GaussianFilterOptions {
                sigma: [2.0, 1.5, 1.0],
                truncate: 4.0,
                mode,
            };
            let got = gaussian_filter(&input, dims, &options).unwrap();
            let got32 = gaussian_filter(&input32, dims, &options).unwrap();
            for k in 0..9 {
                for j in (0..41).step_by(4) {
                    for i in 0..75 {
                        let at = i + 75 * (j + 41 * k);
                        let want = naive(&input, dims, &options, [i, j, k]);
                        assert!((got[at] - want).abs() < 1e-12, "{mode:?} {i} {j} {k}");
                        assert!(
                            (got32[at] as f64 - want).abs() < 1e-5,
                            "{mode:?} {i} {j} {k}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn border_indices_follow_scipy() {
        // Indices -5 ..= 8 of an axis of 4 samples, as SciPy's documentation draws them.
        let table: [(BoundaryMode, [usize; 14]); 4] = [
            (
                BoundaryMode::Reflect,
                [3, 3, 2, 1, 0, 0, 1, 2, 3, 3, 2, 1, 0, 0],
            ),
            (
                BoundaryMode::Mirror,
                [1, 2, 3, 2, 1, 0, 1, 2, 3, 2, 1, 0, 1, 2],
            ),
            (
                BoundaryMode::Nearest,
                [0, 0, 0, 0, 0, 0, 1, 2, 3, 3, 3, 3, 3, 3],
            ),
            (
                BoundaryMode::Wrap,
                [3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0],
            ),
        ];
        for (mode, want) in table {
            let got: Vec<Option<usize>> = (-5..9).map(|i| mode.index(i, 4)).collect();
            let want: Vec<Option<usize>> = want.iter().map(|&i| Some(i)).collect();
            assert_eq!(got, want, "{mode:?}");
        }
        assert_eq!(BoundaryMode::Constant(1.0).index(-1, 4), None);
        assert_eq!(BoundaryMode::Mirror.index(-3, 1), Some(0));
    }

    #[test]
    fn constant_mode_keeps_mass_only_inside() {
        let dims = [9, 9, 9];
        let mut input = vec![0.0f64; 729];
        input[4 + 9 * (4 + 9 * 4)] = 1.0;
        let options = GaussianFilterOptions {
            mode: BoundaryMode::Constant(0.0),
            ..GaussianFilterOptions::isotropic(1.0)
        };
        let out = gaussian_filter(&input, dims, &options).unwrap();
        let total: f64 = out.iter().sum();
        // The taps reach 4 samples: everything stays inside the 9³ grid.
        assert!((total - 1.0).abs() < 1e-12, "mass {total}");
        let nearest = GaussianFilterOptions {
            mode: BoundaryMode::Nearest,
            ..options
        };
        let ones = gaussian_filter(&vec![1.0f64; 729], dims, &nearest).unwrap();
        assert!(ones.iter().all(|v| (v - 1.0).abs() < 1e-12));
    }

    #[test]
    fn bad_options_and_sizes_are_refused() {
        let input = vec![0.0f32; 8];
        let bad = GaussianFilterOptions::isotropic(-1.0);
        assert!(gaussian_filter(&input, [2, 2, 2], &bad).is_err());
        let nan = GaussianFilterOptions::isotropic(f64::NAN);
        assert!(gaussian_filter(&input, [2, 2, 2], &nan).is_err());
        let ok = GaussianFilterOptions::isotropic(1.0);
        assert!(gaussian_filter(&input, [2, 2, 3], &ok).is_err());
        assert!(gaussian_filter(&input, [2, 2, 2], &ok).is_ok());
        // A σ whose taps would not fit is refused before they are made (it aborted).
        let huge = GaussianFilterOptions::isotropic(1e15);
        let error = gaussian_filter(&input, [2, 2, 2], &huge).unwrap_err();
        assert!(error.to_string().contains("Gaussian taps"), "{error}");
    }
}
