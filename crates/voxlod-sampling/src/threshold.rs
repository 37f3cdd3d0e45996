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
//! run-length encoded as all-outside, all-inside or mixed (the eight corners disagree); a line
//! through the column only evaluates its mixed cells. Cost: one pass over the data per axis,
//! then O(runs + mixed cells) per lattice line.

use std::sync::OnceLock;

use rayon::prelude::*;
use voxlod_core::{Axis, Bounds, Volume, WorldTransform};

use crate::lattice::{LineCrossings, LineFamily};
use crate::solid::{crossings_per_line, Solid};
use crate::SamplingError;

/// The solid `{ p : trilinear(volume, p) >= threshold }`.
pub struct ThresholdSolid<'a> {
    volume: &'a Volume,
    threshold: f32,
    bounds: Bounds,
    /// Per axis, the run-length encoded cell columns, built on first use and kept for all levels.
    columns: [OnceLock<Vec<Vec<CellRun>>>; 3],
}

impl<'a> ThresholdSolid<'a> {
    /// Fails when the threshold is not finite or nothing of the volume reaches it.
    pub fn new(volume: &'a Volume, threshold: f32) -> Result<ThresholdSolid<'a>, SamplingError> {
        if !threshold.is_finite() {
            return Err(SamplingError::InvalidOption(format!(
                "the threshold {threshold} is not a finite number"
            )));
        }
        let (lo, hi) = volume.range().ok_or(SamplingError::EmptyBounds)?;
        if hi < threshold {
            return Err(SamplingError::InvalidOption(format!(
                "the threshold {threshold} is above every value of the volume (range {lo} to {hi})"
            )));
        }
        Ok(ThresholdSolid {
            volume,
            threshold,
            bounds: volume.grid.bounds(),
            columns: Default::default(),
        })
    }

    /// The cells of one column along `axis` (the cells between data rows `a0..=a0+1` and
    /// `b0..=b0+1` of the cross axes), run-length encoded as all-outside, all-inside or mixed.
    fn column_runs(&self, axis: Axis, a0: usize, b0: usize) -> Vec<CellRun> {
        let g = &self.volume.grid;
        let (ua, va) = axis.others();
        let na = g.dims[axis.index()];
        let (nu, nv) = (g.dims[ua.index()], g.dims[va.index()]);
        let (a1, b1) = ((a0 + 1).min(nu - 1), (b0 + 1).min(nv - 1));
        let at = |i: usize, a: usize, b: usize| {
            let mut p = [0usize; 3];
            p[axis.index()] = i;
            p[ua.index()] = a;
            p[va.index()] = b;
            self.volume.get(p[0], p[1], p[2])
        };
        // Inside count of the four samples of each cross-section.
        let section = |i: usize| {
            [(a0, b0), (a1, b0), (a0, b1), (a1, b1)]
                .iter()
                .filter(|&&(a, b)| at(i, a, b) >= self.threshold)
                .count()
        };
        let mut runs: Vec<CellRun> = Vec::new();
        let mut prev = section(0);
        for i in 0..na.saturating_sub(1) {
            let next = section(i + 1);
            let state = match (prev, next) {
                (0, 0) => CellState::Outside,
                (4, 4) => CellState::Inside,
                _ => CellState::Mixed,
            };
            match runs.last_mut() {
                Some(run) if run.state == state => run.end = i + 1,
                _ => runs.push(CellRun {
                    start: i,
                    end: i + 1,
                    state,
                }),
            }
            prev = next;
        }
        runs
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum CellState {
    Outside,
    Inside,
    Mixed,
}

/// Cells `start..end` of a column share a state.
#[derive(Clone, Copy, Debug)]
struct CellRun {
    start: usize,
    end: usize,
    state: CellState,
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

    fn crossings(&self, family: &LineFamily) -> Result<LineCrossings, SamplingError> {
        let g = self.volume.grid;
        let axis = family.axis;
        let (ua, va) = axis.others();
        let (na, nu, nv) = (g.dims[axis.index()], g.dims[ua.index()], g.dims[va.index()]);
        // Columns of cells between neighbouring data rows, indexed [b0 * cu + a0].
        let (cu, cv) = (nu.saturating_sub(1).max(1), nv.saturating_sub(1).max(1));
        let columns = self.columns[axis.index()].get_or_init(|| {
            (0..cu * cv)
                .into_par_iter()
                .map(|c| self.column_runs(axis, c % cu, c / cu))
                .collect()
        });
        let t = self.threshold;
        let value = |i: usize, a: usize, b: usize| {
            let mut p = [0usize; 3];
            p[axis.index()] = i;
            p[ua.index()] = a;
            p[va.index()] = b;
            self.volume.get(p[0], p[1], p[2])
        };
        let to_world = |i: f64| g.origin[axis.index()] + i * g.spacing[axis.index()];
        Ok(crossings_per_line(family, |u, v, out| {
            let fu = (u - g.origin[ua.index()]) / g.spacing[ua.index()];
            let fv = (v - g.origin[va.index()]) / g.spacing[va.index()];
            if !(0.0..=(nu - 1) as f64).contains(&fu) || !(0.0..=(nv - 1) as f64).contains(&fv) {
                return;
            }
            let a0 = (fu.floor() as usize).min(cu - 1);
            let b0 = (fv.floor() as usize).min(cv - 1);
            let (a1, b1) = ((a0 + 1).min(nu - 1), (b0 + 1).min(nv - 1));
            let (wu, wv) = ((fu - a0 as f64) as f32, (fv - b0 as f64) as f32);
            let weights = [
                (a0, b0, (1.0 - wu) * (1.0 - wv)),
                (a1, b0, wu * (1.0 - wv)),
                (a0, b1, (1.0 - wu) * wv),
                (a1, b1, wu * wv),
            ];
            let sample = |i: usize| -> f32 {
                weights
                    .iter()
                    .map(|&(a, b, w)| if w > 0.0 { w * value(i, a, b) } else { 0.0 })
                    .sum()
            };
            let runs = &columns[b0 * cu + a0];
            if na == 1 || runs.iter().all(|r| r.state == CellState::Outside) {
                if na == 1 && sample(0) >= t {
                    out.push(to_world(0.0));
                    out.push(to_world(0.0));
                }
                return;
            }
            // Walk the runs; inside state at the start of the column decided by its first sample.
            let mut inside = sample(0) >= t;
            if inside {
                out.push(to_world(0.0));
            }
            for run in runs {
                match run.state {
                    CellState::Outside | CellState::Inside => {
                        let now = run.state == CellState::Inside;
                        debug_assert_eq!(now, inside, "uniform run entered in the wrong state");
                        inside = now;
                    }
                    CellState::Mixed => {
                        let mut prev = sample(run.start);
                        for i in run.start + 1..=run.end {
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
                out.push(to_world((na - 1) as f64));
            }
        }))
    }
}
