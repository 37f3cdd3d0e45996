//! The Gaussian filter of paper §2 ("to achieve better results, one can employ a higher-order
//! filter, such as a Gaussian"), truncated at the support radius R and renormalised.
//!
//! **σ and R.** We use σ = R/3 by default (`sigma_ratio`): the paper's Table 1 gives only the
//! support radius, and at three standard deviations the truncation removes 1.1 % of the weight
//! along a line through the centre, so the truncated filter behaves like a Gaussian while
//! keeping the finite support that makes each level's cost bounded.
//!
//! **Half-space profile** (paper equation 5). The disc of the ball at height α carries
//! `2πσ² (exp(-α²/2σ²) - exp(-R²/2σ²))`; integrating it from the distance r of the plane to R
//! and dividing by the integral over `[-R, R]` gives, with `s = σ√2` and `E = exp(-R²/2σ²)`,
//!
//! `d(r) = [σ√(π/2) (erf(R/s) - erf(r/s)) - (R - r) E] / [2σ√(π/2) erf(R/s) - 2 R E]`.
//!
//! **Volumes.** [`gaussian_blur`] filters a sampled volume directly (the paper's second route for
//! scanned data, and the peers' `scipy.ndimage.gaussian_filter`) with the separable filter of
//! [`crate::gaussian_filter`], σ given in world units and borders reflected. Cost: O(N³ (2⌈tσ⌉ +
//! 1)) for truncation t, one output volume, about two reads and two writes of its memory.

use voxlod_core::Volume;

use crate::gaussian_filter::{
    gaussian_filter, gaussian_taps_f64, BoundaryMode, GaussianFilterOptions,
};
use crate::SamplingError;

/// σ = R / 3.
pub const DEFAULT_SIGMA_RATIO: f64 = 1.0 / 3.0;

/// The un-normalised truncated Gaussian `exp(-r²/2σ²)` for `r < radius`, zero beyond.
pub fn gaussian_weight(r: f64, radius: f64, sigma: f64) -> f64 {
    if r < radius {
        (-r * r / (2.0 * sigma * sigma)).exp()
    } else {
        0.0
    }
}

/// Density of a half-space filtered by the truncated Gaussian, at signed distance `r`
/// (positive outside). See the module documentation for the formula.
pub fn gaussian_half_space_density(r: f64, radius: f64, sigma: f64) -> f64 {
    let d = r.abs().min(radius);
    let s = sigma * std::f64::consts::SQRT_2;
    let e = (-radius * radius / (2.0 * sigma * sigma)).exp();
    let c = sigma * (std::f64::consts::PI / 2.0).sqrt();
    let upper = c * (libm::erf(radius / s) - libm::erf(d / s)) - (radius - d) * e;
    let total = 2.0 * (c * libm::erf(radius / s) - radius * e);
    let outside = upper / total;
    if r >= 0.0 {
        outside
    } else {
        1.0 - outside
    }
}

/// [`gaussian_taps_f64`] rounded to f32: normalised 1-D Gaussian taps for standard deviation
/// `sigma` (in samples), truncated at `truncate` standard deviations (SciPy's rule).
pub fn gaussian_taps(sigma: f64, truncate: f64) -> Vec<f32> {
    gaussian_taps_f64(sigma, truncate)
        .into_iter()
        .map(|t| t as f32)
        .collect()
}

/// Filters `volume` with a Gaussian of standard deviation `sigma` (world units, per axis)
/// truncated at `truncate` standard deviations, borders reflected (like SciPy's `reflect`):
/// [`crate::gaussian_filter::gaussian_filter`] with σ in samples.
pub fn gaussian_blur(
    volume: &Volume,
    sigma: [f64; 3],
    truncate: f64,
) -> Result<Volume, SamplingError> {
    if sigma.iter().any(|s| !s.is_finite() || *s <= 0.0) || !truncate.is_finite() || truncate <= 0.0
    {
        return Err(SamplingError::InvalidOption(format!(
            "Gaussian sigma {sigma:?} and truncation {truncate} must be positive"
        )));
    }
    let options = GaussianFilterOptions {
        sigma: std::array::from_fn(|a| sigma[a] / volume.grid.spacing[a]),
        truncate,
        mode: BoundaryMode::Reflect,
    };
    let output = gaussian_filter(volume.as_slice(), volume.grid.dims, &options)?;
    Ok(Volume::from_vec(volume.grid, output)?)
}

#[cfg(test)]
fn reflect_index(i: i64, n: i64) -> usize {
    BoundaryMode::Reflect
        .index(i, n)
        .expect("reflection always lands inside")
}

#[cfg(test)]
mod tests {
    use super::*;
    use voxlod_core::Grid;

    #[test]
    fn half_space_profile_is_symmetric_and_bounded() {
        let (radius, sigma) = (3.0, 1.0);
        assert!((gaussian_half_space_density(0.0, radius, sigma) - 0.5).abs() < 1e-12);
        assert_eq!(gaussian_half_space_density(radius, radius, sigma), 0.0);
        for r in [0.2, 0.9, 1.7, 2.5] {
            let out = gaussian_half_space_density(r, radius, sigma);
            let inside = gaussian_half_space_density(-r, radius, sigma);
            assert!((out + inside - 1.0).abs() < 1e-12);
            // Close to the untruncated profile 0.5 erfc(r / σ√2).
            let untruncated = 0.5 * libm::erfc(r / (sigma * std::f64::consts::SQRT_2));
            assert!(
                (out - untruncated).abs() < 0.01,
                "r {r}: {out} vs {untruncated}"
            );
        }
    }

    #[test]
    fn blur_matches_a_naive_convolution_with_reflected_borders() {
        let dims = [13, 11, 17];
        let grid = Grid::new(dims, [1.0; 3], [0.0; 3]).unwrap();
        let data: Vec<f32> = (0..grid.len())
            .map(|i| ((i * 7919) % 1013) as f32 / 1013.0)
            .collect();
        let v = Volume::from_vec(grid, data).unwrap();
        let sigma = [1.2, 0.9, 1.5];
        let out = gaussian_blur(&v, sigma, 3.0).unwrap();
        let taps: Vec<Vec<f32>> = sigma.iter().map(|&s| gaussian_taps(s, 3.0)).collect();
        let r: Vec<i64> = taps.iter().map(|t| (t.len() / 2) as i64).collect();
        for (i, j, k) in [(0, 0, 0), (12, 10, 16), (6, 5, 8), (1, 9, 2), (11, 0, 15)] {
            let mut want = 0.0f64;
            for (a, wa) in taps[0].iter().enumerate() {
                for (b, wb) in taps[1].iter().enumerate() {
                    for (c, wc) in taps[2].iter().enumerate() {
                        let x = reflect_index(i as i64 - r[0] + a as i64, 13);
                        let y = reflect_index(j as i64 - r[1] + b as i64, 11);
                        let z = reflect_index(k as i64 - r[2] + c as i64, 17);
                        want += (wa * wb * wc) as f64 * v.get(x, y, z) as f64;
                    }
                }
            }
            let got = out.get(i, j, k) as f64;
            assert!((got - want).abs() < 1e-5, "({i},{j},{k}): {got} vs {want}");
        }
    }

    #[test]
    fn blur_preserves_mass_and_matches_direct_convolution() {
        let dims = [9, 7, 8];
        let grid = Grid::new(dims, [1.0, 2.0, 1.0], [0.0; 3]).unwrap();
        let mut data = vec![0.0f32; grid.len()];
        data[grid.index(4, 3, 4)] = 1.0;
        let v = Volume::from_vec(grid, data).unwrap();
        let sigma = [1.0, 2.0, 0.8];
        let out = gaussian_blur(&v, sigma, 3.0).unwrap();
        let total: f32 = out.as_slice().iter().sum();
        assert!((total - 1.0).abs() < 1e-5, "mass {total}");
        // Separable product of the 1-D taps at a few offsets.
        let tx = gaussian_taps(1.0, 3.0);
        let ty = gaussian_taps(1.0, 3.0); // 2 world units / spacing 2
        let tz = gaussian_taps(0.8, 3.0);
        let (rx, ry, rz) = (tx.len() / 2, ty.len() / 2, tz.len() / 2);
        for (di, dj, dk) in [(0i64, 0i64, 0i64), (1, 0, 0), (1, 1, -1), (2, -1, 1)] {
            let expect = tx[(rx as i64 + di) as usize]
                * ty[(ry as i64 + dj) as usize]
                * tz[(rz as i64 + dk) as usize];
            let got = out.get((4 + di) as usize, (3 + dj) as usize, (4 + dk) as usize);
            assert!(
                (got - expect).abs() < 1e-6,
                "{di},{dj},{dk}: {got} vs {expect}"
            );
        }
        assert!(gaussian_blur(&v, [0.0, 1.0, 1.0], 3.0).is_err());
    }
}
