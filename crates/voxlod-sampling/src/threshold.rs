//! A scanned volume thresholded into a solid, for the first of paper §4's two routes for CT and
//! MRI data: "for a given point it is still possible to test whether this point is inside or
//! outside the surface by tri-linearly interpolating the point value from the neighboring eight
//! vertices and comparing it to the isodensity".
//!
//! A point is inside when the trilinear interpolation of the data there is `>= threshold`.
//! Along an axis-parallel line the trilinear interpolant is the bilinear blend of four data
//! rows, linear between samples, so the crossings are found exactly, cell by cell. Outside the
//! data's box everything is outside, so the solid is bounded and a surface touching the edge of
//! the scan is closed there. Each column of cells between four data rows is classified once,
//! run-length encoded as all-outside, all-inside or mixed (the eight corners disagree,
//! [`crate::cell_columns`]); a line through the column only evaluates its mixed cells. Cost: one
//! pass over the data for the three axes' runs, then O(runs + mixed cells) per lattice line.

use std::sync::OnceLock;

use voxlod_core::{Axis, Bounds, Grid, Volume, WorldTransform};

use crate::cell_columns::{classify, CellRun, CellState, ColumnRuns};
use crate::lattice::{LineCrossings, LineFamily, TILE};
use crate::solid::{crossings_per_line, crossings_per_tile, Solid};
use crate::SamplingError;

/// The solid `{ p : trilinear(volume, p) >= threshold }`.
pub struct ThresholdSolid<'a> {
    /// The samples held: the whole scan, or a window of it ([`ThresholdSolid::window`]).
    volume: &'a Volume,
    /// The whole scan's grid; all arithmetic is in its indices and coordinates.
    grid: Grid,
    /// Index in the whole scan of the held samples' first one.
    start: [usize; 3],
    threshold: f32,
    bounds: Bounds,
    /// Per axis, the run-length encoded cell columns, built on first use and kept for all levels.
    columns: OnceLock<[ColumnRuns; 3]>,
    /// Whether the three axes' columns are classified side by side (a whole scan, classified
    /// once on all threads) or one axis after another (a window of the blockwise route, whose
    /// windows are already classified side by side, and whose memory stays that of one axis).
    axes_side_by_side: bool,
}

impl<'a> ThresholdSolid<'a> {
    /// Fails when the threshold is not finite or nothing of the volume reaches it.
    pub fn new(volume: &'a Volume, threshold: f32) -> Result<ThresholdSolid<'a>, SamplingError> {
        if !threshold.is_finite() {
            return Err(SamplingError::InvalidOption(format!(
                "the threshold {threshold} is not a finite number"
            )));
        }
        // The first sample that reaches the threshold settles it; the range only for the error.
        let reached = |v: &f32| v.is_finite() && *v >= threshold;
        if !volume.as_slice().iter().any(reached) {
            let (lo, hi) = volume.range().ok_or(SamplingError::EmptyBounds)?;
            return Err(SamplingError::InvalidOption(format!(
                "the threshold {threshold} is above every value of the volume (range {lo} to {hi})"
            )));
        }
        let mut solid = Self::window(volume, volume.grid, [0; 3], threshold);
        solid.axes_side_by_side = true;
        Ok(solid)
    }

    /// The solid of a scan with grid `grid`, of which only `window` is held: the samples from
    /// index `start` on. Along a lattice line it gives the crossings the whole scan gives inside
    /// the window (computed with the whole scan's coordinates, so bit for bit the same), plus
    /// one where the line leaves the window inside the solid, at each end (for the blockwise
    /// route, [`crate::blockwise_threshold`], whose windows reach beyond what a block reads).
    pub fn window(
        window: &'a Volume,
        grid: Grid,
        start: [usize; 3],
        threshold: f32,
    ) -> ThresholdSolid<'a> {
        ThresholdSolid {
            volume: window,
            grid,
            start,
            threshold,
            bounds: grid.bounds(),
            columns: Default::default(),
            axes_side_by_side: false,
        }
    }

    /// Sample `i` along `axis` and `(a, b)` across it, in the whole scan's indices (the
    /// reference that [`HeldRows`] reads the same samples as, faster).
    #[cfg(test)]
    fn value(&self, axis: Axis, i: usize, a: usize, b: usize) -> f32 {
        let (ua, va) = axis.others();
        let mut p = [0usize; 3];
        p[axis.index()] = i;
        p[ua.index()] = a;
        p[va.index()] = b;
        let s = self.start;
        self.volume.get(p[0] - s[0], p[1] - s[1], p[2] - s[2])
    }

    /// The held data rows along `axis` through `corners` (whole-scan indices across the axis).
    #[inline]
    fn rows<const N: usize>(&self, axis: Axis, corners: [(usize, usize); N]) -> HeldRows<'_, N> {
        let (ua, va) = axis.others();
        let dims = self.volume.grid.dims;
        let strides = [1, dims[0], dims[0] * dims[1]];
        let s = self.start;
        debug_assert!(corners.iter().all(|&(a, b)| {
            (s[ua.index()]..s[ua.index()] + dims[ua.index()]).contains(&a)
                && (s[va.index()]..s[va.index()] + dims[va.index()]).contains(&b)
        }));
        HeldRows {
            samples: self.volume.as_slice(),
            base: corners.map(|(a, b)| {
                (a - s[ua.index()]) * strides[ua.index()]
                    + (b - s[va.index()]) * strides[va.index()]
            }),
            first: s[axis.index()],
            stride: strides[axis.index()],
        }
    }

    /// The held cells along `axis` (whole-scan indices of their lower samples) and the number
    /// of cell columns across it.
    fn held_cells(&self, axis: Axis) -> (std::ops::Range<usize>, usize, usize) {
        let (ua, va) = axis.others();
        let w = self.volume.grid.dims;
        let first = self.start[axis.index()];
        let cells = first..first + w[axis.index()].saturating_sub(1);
        let (cu, cv) = (
            w[ua.index()].saturating_sub(1).max(1),
            w[va.index()].saturating_sub(1).max(1),
        );
        (cells, cu, cv)
    }

    /// The cells of one column along `axis` (the cells between data rows `a0..=a0+1` and
    /// `b0..=b0+1` of the cross axes, whole-scan indices), run-length encoded as all-outside,
    /// all-inside or mixed, sample by sample: the reference that [`classify`] must match.
    #[cfg(test)]
    fn column_runs(&self, axis: Axis, a0: usize, b0: usize) -> Vec<CellRun> {
        let g = &self.grid;
        let (ua, va) = axis.others();
        let (nu, nv) = (g.dims[ua.index()], g.dims[va.index()]);
        let (a1, b1) = ((a0 + 1).min(nu - 1), (b0 + 1).min(nv - 1));
        // Inside count of the four samples of each cross-section.
        let rows = self.rows(axis, [(a0, b0), (a1, b0), (a0, b1), (a1, b1)]);
        let section = |i: usize| rows.at(i).iter().filter(|&&v| v >= self.threshold).count();
        let (cells, _, _) = self.held_cells(axis);
        let mut runs: Vec<CellRun> = Vec::new();
        let mut prev = section(cells.start);
        for i in cells {
            let next = section(i + 1);
            let state = match (prev, next) {
                (0, 0) => CellState::Outside,
                (4, 4) => CellState::Inside,
                _ => CellState::Mixed,
            };
            match runs.last_mut() {
                Some(run) if run.state == state => run.end = i as u32 + 1,
                _ => runs.push(CellRun {
                    start: i as u32,
                    end: i as u32 + 1,
                    state,
                }),
            }
            prev = next;
        }
        runs
    }
}

/// `N` data rows along one axis of the held window, read by flat index: sample `i` (whole-scan
/// index along the axis) of row `r` is `samples[base[r] + (i - first) * stride]`: the sample
/// that the volume's three-index lookup gives (a test checks it), without its index arithmetic
/// per sample. Used by the column classification and by every lattice line's walk.
struct HeldRows<'s, const N: usize> {
    samples: &'s [f32],
    base: [usize; N],
    first: usize,
    stride: usize,
}

impl<const N: usize> HeldRows<'_, N> {
    /// Sample `i` of every row.
    #[inline]
    fn at(&self, i: usize) -> [f32; N] {
        let along = (i - self.first) * self.stride;
        self.base.map(|b| self.samples[b + along])
    }

    /// The rows blended with `weights` at sample `i`, a weight of zero skipping its row (so a
    /// non-finite sample there does not spoil the sum), summed in row order.
    #[inline]
    fn bilinear(&self, i: usize, weights: &[f32; N]) -> f32 {
        let values = self.at(i);
        weights
            .iter()
            .zip(values)
            .map(|(&w, v)| if w > 0.0 { w * v } else { 0.0 })
            .sum()
    }
}

impl Solid for ThresholdSolid<'_> {
    fn bounds(&self) -> Bounds {
        self.bounds
    }

    fn is_exact(&self) -> bool {
        true
    }

    fn world(&self) -> Option<WorldTransform> {
        Some(self.volume.world())
    }

    /// The cell columns of the three axes, classified on all threads.
    fn prepare(&self) {
        self.columns_along(Axis::X);
    }

    fn crossings(&self, family: &LineFamily) -> Result<LineCrossings, SamplingError> {
        let columns = self.columns_along(family.axis);
        Ok(crossings_per_line(family, |u, v, out| {
            self.line_crossings(family.axis, columns, u, v, out)
        }))
    }
}

impl ThresholdSolid<'_> {
    /// The cell columns along `axis`, indexed `[b * cu + a]` from the held window's first
    /// (those of the three axes are made together, on first use).
    fn columns_along(&self, axis: Axis) -> &ColumnRuns {
        let columns = self.columns.get_or_init(|| {
            let held = &self.volume;
            let side_by_side = self.axes_side_by_side;
            classify(
                held.as_slice(),
                held.grid.dims,
                self.start,
                self.threshold,
                side_by_side,
            )
        });
        &columns[axis.index()]
    }

    /// The crossings of `family`'s lines `lines` (ranges of m and n), as a [`LineCrossings`] of
    /// `window_family` (a family with as many lines, whose line (m, n) is the whole family's
    /// line (m + lines.0.start, n + lines.1.start)). Positions are those of the whole family.
    pub(crate) fn window_crossings(
        &self,
        family: &LineFamily,
        window_family: &LineFamily,
        first_line: (usize, usize),
    ) -> LineCrossings {
        let columns = self.columns_along(family.axis);
        crossings_per_tile(window_family, |tile_m, tile_n, out| {
            let mut world = Vec::new();
            for (row, n) in tile_n.clone().enumerate() {
                for (col, m) in tile_m.clone().enumerate() {
                    world.clear();
                    let (u, v) = family.line_position(m + first_line.0, n + first_line.1);
                    self.line_crossings(family.axis, columns, u, v, &mut world);
                    let local = (row * TILE + col) as u16;
                    out.extend(world.iter().map(|&w| (local, family.index_t(w) as f32)));
                }
            }
        })
    }

    /// The world coordinates of the crossings of the line along `axis` at `(u, v)` (see the
    /// module documentation); for a window, within the window (see [`ThresholdSolid::window`]).
    fn line_crossings(&self, axis: Axis, columns: &ColumnRuns, u: f64, v: f64, out: &mut Vec<f64>) {
        let g = self.grid;
        let (ua, va) = axis.others();
        let (na, nu, nv) = (g.dims[axis.index()], g.dims[ua.index()], g.dims[va.index()]);
        let (cu, cv) = (nu.saturating_sub(1).max(1), nv.saturating_sub(1).max(1));
        let t = self.threshold;
        let to_world = |i: f64| g.origin[axis.index()] + i * g.spacing[axis.index()];
        let fu = (u - g.origin[ua.index()]) / g.spacing[ua.index()];
        let fv = (v - g.origin[va.index()]) / g.spacing[va.index()];
        if !(0.0..=(nu - 1) as f64).contains(&fu) || !(0.0..=(nv - 1) as f64).contains(&fv) {
            return;
        }
        let a0 = (fu.floor() as usize).min(cu - 1);
        let b0 = (fv.floor() as usize).min(cv - 1);
        let (a1, b1) = ((a0 + 1).min(nu - 1), (b0 + 1).min(nv - 1));
        // The column of the held window, if the line runs through it.
        let (cells, wcu, wcv) = self.held_cells(axis);
        let (su, sv) = (self.start[ua.index()], self.start[va.index()]);
        let held = self.volume.grid.dims;
        if a0 < su || b0 < sv || a1 >= su + held[ua.index()] || b1 >= sv + held[va.index()] {
            return;
        }
        let (ca, cb) = (a0 - su, b0 - sv);
        if ca >= wcu || cb >= wcv {
            return;
        }
        let (wu, wv) = ((fu - a0 as f64) as f32, (fv - b0 as f64) as f32);
        let weights = [
            (1.0 - wu) * (1.0 - wv),
            wu * (1.0 - wv),
            (1.0 - wu) * wv,
            wu * wv,
        ];
        let rows = self.rows(axis, [(a0, b0), (a1, b0), (a0, b1), (a1, b1)]);
        let sample = |i: usize| -> f32 { rows.bilinear(i, &weights) };
        let runs = columns.column(cb * wcu + ca);
        if na == 1 || runs.iter().all(|r| r.state == CellState::Outside) {
            if na == 1 && sample(0) >= t {
                out.push(to_world(0.0));
                out.push(to_world(0.0));
            }
            return;
        }
        walk_column(runs, cells, t, sample, to_world, out);
    }
}

/// The crossings of one column's runs, walked from the first held cell: the line's value by
/// `sample` at sample `i`, world coordinates by `to_world` (the second half of
/// [`ThresholdSolid::line_crossings`]).
fn walk_column(
    runs: &[CellRun],
    cells: std::ops::Range<usize>,
    t: f32,
    sample: impl Fn(usize) -> f32,
    to_world: impl Fn(f64) -> f64,
    out: &mut Vec<f64>,
) {
    // Where the walk starts, and the inside state there: the scan's first sample, or for a
    // window the end of its first cell, in the state the whole scan's walk has there.
    let (first, mut inside) = match runs.first() {
        Some(run) if cells.start > 0 => {
            let from = cells.start + 1;
            let state = match run.state {
                CellState::Mixed => sample(from) >= t,
                uniform => uniform == CellState::Inside,
            };
            (from, state)
        }
        _ => (cells.start, sample(cells.start) >= t),
    };
    if inside {
        out.push(to_world(first as f64));
    }
    for run in runs {
        let (start, end) = (run.start as usize, run.end as usize);
        let start = start.max(first);
        if start >= end {
            continue;
        }
        match run.state {
            CellState::Outside | CellState::Inside => {
                let now = run.state == CellState::Inside;
                debug_assert_eq!(now, inside, "uniform run entered in the wrong state");
                inside = now;
            }
            CellState::Mixed => {
                let mut prev = sample(start);
                for i in start + 1..=end {
                    let cur = sample(i);
                    let now = cur >= t;
                    if now != inside {
                        let f = ((t - prev) / (cur - prev)) as f64;
                        let f = if f.is_finite() {
                            f.clamp(0.0, 1.0)
                        } else {
                            0.5
                        };
                        out.push(to_world(i as f64 - 1.0 + f));
                        inside = now;
                    }
                    prev = cur;
                }
            }
        }
    }
    if inside {
        out.push(to_world(cells.end as f64));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A window of a small scan with values that are not a simple function of position, and a
    /// NaN where a zero weight must keep it out of the sum.
    fn scan() -> Volume {
        let grid = Grid::new([7, 6, 5], [1.0, 0.5, 2.0], [-1.0, 0.25, 3.0]).unwrap();
        let values = (0..grid.len())
            .map(|n| ((n * 37 % 101) as f32 - 40.0) * 0.75)
            .collect();
        Volume::from_vec(grid, values).unwrap()
    }

    #[test]
    fn held_rows_read_the_samples_of_the_three_index_lookup() {
        let whole = scan();
        let start = [1, 2, 1];
        let dims = [5, 3, 4];
        let held: Vec<f32> = (0..dims[2])
            .flat_map(|k| (0..dims[1]).flat_map(move |j| (0..dims[0]).map(move |i| (i, j, k))))
            .map(|(i, j, k)| whole.get(i + start[0], j + start[1], k + start[2]))
            .collect();
        let window_grid = Grid::new(dims, whole.grid.spacing, [0.0; 3]).unwrap();
        let window = Volume::from_vec(window_grid, held).unwrap();
        for (volume, start) in [(&whole, [0; 3]), (&window, start)] {
            let solid = ThresholdSolid::window(volume, whole.grid, start, 1.0);
            let held = volume.grid.dims;
            for axis in [Axis::X, Axis::Y, Axis::Z] {
                let (ua, va) = axis.others();
                let (s, n) = (start[axis.index()], held[axis.index()]);
                for a in start[ua.index()]..start[ua.index()] + held[ua.index()] - 1 {
                    for b in start[va.index()]..start[va.index()] + held[va.index()] - 1 {
                        let corners = [(a, b), (a + 1, b), (a, b + 1), (a + 1, b + 1)];
                        let rows = solid.rows(axis, corners);
                        let weights = [0.3f32, 0.0, 0.2, 0.5];
                        for i in s..s + n {
                            let expected = corners.map(|(a, b)| solid.value(axis, i, a, b));
                            assert_eq!(rows.at(i), expected, "{axis:?} {a} {b} {i}");
                            let sum: f32 = weights
                                .iter()
                                .zip(expected)
                                .map(|(&w, v)| if w > 0.0 { w * v } else { 0.0 })
                                .sum();
                            assert_eq!(rows.bilinear(i, &weights).to_bits(), sum.to_bits());
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn cell_runs_are_those_of_the_sample_by_sample_reference() {
        // The scan, a window of it, a scan with a degenerate axis, and a NaN sample.
        let whole = scan();
        let mut with_nan = whole.clone();
        with_nan.as_slice_mut()[3 + 7 * (2 + 6)] = f32::NAN;
        let flat = Volume::from_vec(
            Grid::new([6, 1, 4], [1.0; 3], [0.0; 3]).unwrap(),
            (0..24).map(|n| (n * 7 % 11) as f32).collect(),
        )
        .unwrap();
        let (start, dims) = ([1, 2, 1], [5, 3, 4]);
        let held: Vec<f32> = (0..dims[2])
            .flat_map(|k| (0..dims[1]).flat_map(move |j| (0..dims[0]).map(move |i| (i, j, k))))
            .map(|(i, j, k)| whole.get(i + start[0], j + start[1], k + start[2]))
            .collect();
        let window = Volume::from_vec(Grid::new(dims, [1.0; 3], [0.0; 3]).unwrap(), held).unwrap();
        let cases = [
            (&whole, whole.grid, [0; 3]),
            (&with_nan, whole.grid, [0; 3]),
            (&window, whole.grid, start),
            (&flat, flat.grid, [0; 3]),
        ];
        for (volume, grid, start) in cases {
            for (threshold, side_by_side) in
                [(-10.0, false), (1.0, false), (1.0, true), (20.5, true)]
            {
                let mut solid = ThresholdSolid::window(volume, grid, start, threshold);
                solid.axes_side_by_side = side_by_side;
                for axis in [Axis::X, Axis::Y, Axis::Z] {
                    let (ua, va) = axis.others();
                    let (_, cu, cv) = solid.held_cells(axis);
                    let runs = solid.columns_along(axis);
                    for c in 0..cu * cv {
                        let (a, b) = (start[ua.index()] + c % cu, start[va.index()] + c / cu);
                        let reference = solid.column_runs(axis, a, b);
                        assert_eq!(runs.column(c), reference, "{axis:?} column {c}");
                    }
                }
            }
        }
    }

    /// `prepare` classifies the cells once, for all three families, and the crossings it
    /// leads to are those of a solid that classifies on first use.
    #[test]
    fn prepared_crossings_are_those_made_on_first_use() {
        let volume = scan();
        let lazy = ThresholdSolid::new(&volume, 1.0).unwrap();
        let prepared = ThresholdSolid::new(&volume, 1.0).unwrap();
        assert!(prepared.columns.get().is_none());
        prepared.prepare();
        assert!(prepared.columns.get().is_some());
        for axis in [Axis::X, Axis::Y, Axis::Z] {
            let family = LineFamily::new(axis, volume.grid, 3);
            let (a, b) = (
                lazy.crossings(&family).unwrap(),
                prepared.crossings(&family).unwrap(),
            );
            assert!(!a.is_empty(), "{axis:?}");
            assert_eq!(a.offsets, b.offsets, "{axis:?}");
            let bits = |c: &LineCrossings| c.t.iter().map(|t| t.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&a), bits(&b), "{axis:?}");
        }
    }

    #[test]
    fn a_zero_weight_keeps_a_non_finite_sample_out() {
        let grid = Grid::new([2, 2, 2], [1.0; 3], [0.0; 3]).unwrap();
        let mut values = vec![1.0f32; 8];
        values[1] = f32::NAN; // (1, 0, 0)
        let volume = Volume::from_vec(grid, values).unwrap();
        let solid = ThresholdSolid::new(&volume, 0.5).unwrap();
        let rows = solid.rows(Axis::Z, [(0, 0), (1, 0), (0, 1), (1, 1)]);
        assert!(rows.at(0)[1].is_nan());
        assert_eq!(rows.bilinear(0, &[0.5, 0.0, 0.5, 0.0]), 1.0);
        assert!(rows.bilinear(0, &[0.5, 0.5, 0.0, 0.0]).is_nan());
    }
}
