//! A scanned volume thresholded into a solid, for the first of paper §4's two routes for CT and
//! MRI data: "for a given point it is still possible to test whether this point is inside or
//! outside the surface by tri-linearly interpolating the point value from the neighboring eight
//! vertices and comparing it to the isodensity".
//!
//! A point is inside when the trilinear interpolation of the data there is `>= threshold`.
//! Along an axis-parallel line the trilinear interpolant is the bilinear blend of four data
//! rows, linear between samples, so the crossings are found exactly, cell by cell. Outside the
//! data's box everything is outside, so the solid is bounded and a surface touching the edge of
//! the scan is closed there. Rows of data with no sample at or above the threshold are skipped
//! as a whole. Cost per lattice line: O(samples along it) when it passes near the object.

use voxlod_core::{Axis, Bounds, Volume};

use crate::lattice::{LineCrossings, LineFamily};
use crate::solid::{crossings_per_line, Solid};
use crate::SamplingError;

/// The solid `{ p : trilinear(volume, p) >= threshold }`.
pub struct ThresholdSolid<'a> {
    volume: &'a Volume,
    threshold: f32,
    bounds: Bounds,
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
        })
    }

    /// Whether the data row along `axis` at data indices `(a, b)` of the cross axes holds a
    /// sample at or above the threshold.
    fn row_reaches(&self, axis: Axis, a: usize, b: usize) -> bool {
        let g = &self.volume.grid;
        let (ua, va) = axis.others();
        (0..g.dims[axis.index()]).any(|i| {
            let mut p = [0usize; 3];
            p[axis.index()] = i;
            p[ua.index()] = a;
            p[va.index()] = b;
            self.volume.get(p[0], p[1], p[2]) >= self.threshold
        })
    }
}

impl Solid for ThresholdSolid<'_> {
    fn bounds(&self) -> Bounds {
        self.bounds
    }

    fn is_exact(&self) -> bool {
        true
    }

    fn crossings(&self, family: &LineFamily) -> Result<LineCrossings, SamplingError> {
        let g = self.volume.grid;
        let axis = family.axis;
        let (ua, va) = axis.others();
        let (na, nu, nv) = (g.dims[axis.index()], g.dims[ua.index()], g.dims[va.index()]);
        // Rows that reach the threshold, indexed [b * nu + a].
        let reaches: Vec<bool> = (0..nu * nv)
            .map(|r| self.row_reaches(axis, r % nu, r / nu))
            .collect();
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
            let a0 = (fu.floor() as usize).min(nu.saturating_sub(2));
            let b0 = (fv.floor() as usize).min(nv.saturating_sub(2));
            let (a1, b1) = ((a0 + 1).min(nu - 1), (b0 + 1).min(nv - 1));
            let (wu, wv) = ((fu - a0 as f64) as f32, (fv - b0 as f64) as f32);
            let weights = [
                (a0, b0, (1.0 - wu) * (1.0 - wv)),
                (a1, b0, wu * (1.0 - wv)),
                (a0, b1, (1.0 - wu) * wv),
                (a1, b1, wu * wv),
            ];
            if !weights
                .iter()
                .any(|&(a, b, w)| w > 0.0 && reaches[b * nu + a])
            {
                return;
            }
            let sample = |i: usize| -> f32 {
                weights
                    .iter()
                    .filter(|w| w.2 > 0.0)
                    .map(|&(a, b, w)| w * value(i, a, b))
                    .sum()
            };
            let mut prev = sample(0);
            let mut inside = prev >= t;
            if inside {
                out.push(to_world(0.0));
            }
            for i in 1..na {
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
            if inside {
                out.push(to_world((na - 1) as f64));
            }
        }))
    }
}
