//! The hyper-cone filter of paper §2, equation 3: `h(r) = (R - r) w / R` for `r <= R`, zero
//! beyond; its weight peaks at the centre and falls linearly to zero at the support radius R.
//! In three dimensions the normalisation `w` that makes the filter integrate to one is
//! `w = 3 / (π R³)`, since `∫₀^R (1 - r/R) 4π r² dr = π R³ / 3`.
//!
//! Filtering a half-space (paper §3, equation 5) gives a density that depends only on the
//! signed distance `r` of the filter's centre from the plane; with `u = r / R` and the centre
//! outside (`0 <= u <= 1`),
//!
//! `d(u) = 1/2 - u + u³ - u⁴/2`,
//!
//! obtained by integrating the cap of the filter beyond the plane: the disc at height `α` holds
//! `(2π w / R)(R³/6 - R α²/2 + α³/3)`, and integrating that from `r` to `R` gives the above.
//! Inside, `d(-r) = 1 - d(r)`. Cost: O(1) per evaluation.

/// The un-normalised hyper-cone `(R - r) / R` at distance `r` (zero beyond `radius`).
pub fn hypercone_weight(r: f64, radius: f64) -> f64 {
    if r < radius {
        (radius - r) / radius
    } else {
        0.0
    }
}

/// The normalisation `w = 3 / (π R³)` of equation 3.
pub fn hypercone_normalisation(radius: f64) -> f64 {
    3.0 / (std::f64::consts::PI * radius.powi(3))
}

/// Density of a filtered half-space at signed distance `r` from its plane (positive outside).
pub fn hypercone_half_space_density(r: f64, radius: f64) -> f64 {
    let u = (r.abs() / radius).min(1.0);
    let outside = 0.5 - u + u.powi(3) - 0.5 * u.powi(4);
    if r >= 0.0 {
        outside
    } else {
        1.0 - outside
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn profile_matches_numerical_integration() {
        // Integrate w (R - |p|)/R over the part of the ball beyond the plane x = r.
        let radius = 1.5;
        let w = hypercone_normalisation(radius);
        for &r in &[0.0, 0.3, 0.75, 1.2, -0.6] {
            let n = 120;
            let h = 2.0 * radius / n as f64;
            let mut sum = 0.0;
            for i in 0..n {
                for j in 0..n {
                    for k in 0..n {
                        let p = [
                            -radius + (i as f64 + 0.5) * h,
                            -radius + (j as f64 + 0.5) * h,
                            -radius + (k as f64 + 0.5) * h,
                        ];
                        if p[0] > r {
                            let d = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
                            sum += w * hypercone_weight(d, radius) * h * h * h;
                        }
                    }
                }
            }
            let exact = hypercone_half_space_density(r, radius);
            assert!(
                (sum - exact).abs() < 2e-3,
                "r = {r}: numeric {sum} vs {exact}"
            );
        }
        assert_eq!(hypercone_half_space_density(0.0, 2.0), 0.5);
        assert_eq!(hypercone_half_space_density(2.0, 2.0), 0.0);
        assert_eq!(hypercone_half_space_density(-5.0, 2.0), 1.0);
    }
}
