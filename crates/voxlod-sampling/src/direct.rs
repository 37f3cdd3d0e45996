//! Direct filtering of a scanned volume, the second route of paper §4: "directly apply the
//! reconstruction filters with different radius supports on the original volumes" (after
//! Westover). The level's samples take the filter-weighted mean of the data samples within the
//! support radius, so the values stay in the data's own units and `--iso` is, say, Hounsfield
//! units rather than an isodensity between 0 and 1.
//!
//! Outside the scan, the data is taken to be its minimum (air, for a CT), so surfaces that touch
//! the edge of the scan close there. A level sample with no data sample within its support (a
//! radius below the data spacing) falls back to trilinear interpolation.
//!
//! Cost: O(samples × (2R/h)³) with h the data spacing; since R doubles when the level's
//! resolution halves, every level costs about the same, a few multiply-adds per data sample.

use rayon::prelude::*;
use voxlod_core::{memory, Grid, Volume};

use crate::{Filter, SamplingError};

/// Filters `volume` onto `grid` with `filter` of support `radius` (world units).
pub fn direct_density(
    volume: &Volume,
    grid: &Grid,
    filter: Filter,
    radius: f64,
) -> Result<Volume, SamplingError> {
    if !(radius.is_finite() && radius > 0.0) {
        return Err(SamplingError::InvalidOption(format!(
            "the support radius must be positive, got {radius}"
        )));
    }
    let (background, _) = volume.range().ok_or(SamplingError::EmptyBounds)?;
    memory::check_allocation("the filtered volume", memory::bytes_of::<f32>(grid.len()))?;
    let data = &volume.grid;
    let [dx, dy, dz] = data.dims;
    let reach: [i64; 3] = [0, 1, 2].map(|a| (radius / data.spacing[a]).ceil() as i64);
    let [nx, ny, _] = grid.dims;
    let mut out: Vec<f32> = memory::zeroed_vec(grid.len());
    out.par_chunks_mut(nx * ny)
        .enumerate()
        .for_each(|(k, slice)| {
            for j in 0..ny {
                for i in 0..nx {
                    let p = grid.position(i as f64, j as f64, k as f64);
                    // Position in data index units.
                    let f = [
                        (p.x - data.origin[0]) / data.spacing[0],
                        (p.y - data.origin[1]) / data.spacing[1],
                        (p.z - data.origin[2]) / data.spacing[2],
                    ];
                    let lo = [0, 1, 2].map(|a| (f[a] - reach[a] as f64).ceil() as i64);
                    let hi = [0, 1, 2].map(|a| (f[a] + reach[a] as f64).floor() as i64);
                    let (mut sum, mut weight) = (0.0f64, 0.0f64);
                    for c in lo[2]..=hi[2] {
                        let ez = (c as f64 - f[2]) * data.spacing[2];
                        for b in lo[1]..=hi[1] {
                            let ey = (b as f64 - f[1]) * data.spacing[1];
                            for a in lo[0]..=hi[0] {
                                let ex = (a as f64 - f[0]) * data.spacing[0];
                                let r = (ex * ex + ey * ey + ez * ez).sqrt();
                                let w = filter.weight(r, radius);
                                if w <= 0.0 {
                                    continue;
                                }
                                let inside = a >= 0
                                    && b >= 0
                                    && c >= 0
                                    && (a as usize) < dx
                                    && (b as usize) < dy
                                    && (c as usize) < dz;
                                let v = if inside {
                                    volume.get(a as usize, b as usize, c as usize)
                                } else {
                                    background
                                };
                                sum += w * v as f64;
                                weight += w;
                            }
                        }
                    }
                    slice[j * nx + i] = if weight > 0.0 {
                        (sum / weight) as f32
                    } else {
                        let outside = f
                            .iter()
                            .zip(data.dims)
                            .any(|(&x, n)| x < 0.0 || x > (n - 1) as f64);
                        if outside {
                            background
                        } else {
                            volume.sample_trilinear(f[0], f[1], f[2])
                        }
                    };
                }
            }
        });
    Ok(Volume::from_vec(*grid, out)?)
}
