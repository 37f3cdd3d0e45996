//! The low-pass filters of paper §2: which one, and what it does to a half-space (§3,
//! equation 5). Cost: O(1) per weight or profile value.

use serde::Serialize;

use crate::{gaussian, hypercone};

/// A radially symmetric low-pass filter with finite support radius R.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum Filter {
    /// `h(r) = (R - r) w / R` (paper equation 3): cheap, the paper's choice for the CT head.
    Hypercone,
    /// `exp(-r² / 2σ²)` truncated at R and renormalised, with `σ = sigma_ratio · R`: the
    /// paper's "higher-order filter", used for the sphereflake and the mechanical part.
    Gaussian {
        /// σ as a fraction of the support radius R ([`Filter::GAUSSIAN`]: 1/3).
        sigma_ratio: f64,
    },
}

impl Filter {
    /// The Gaussian with σ = R/3, so that the truncation at R = 3σ drops 1.1 % of a line's
    /// weight and the filter is smooth to a good approximation.
    pub const GAUSSIAN: Filter = Filter::Gaussian {
        sigma_ratio: gaussian::DEFAULT_SIGMA_RATIO,
    };

    /// Un-normalised weight at distance `r` from the centre, for support `radius`.
    pub fn weight(&self, r: f64, radius: f64) -> f64 {
        match *self {
            Filter::Hypercone => hypercone::hypercone_weight(r, radius),
            Filter::Gaussian { sigma_ratio } => {
                gaussian::gaussian_weight(r, radius, sigma_ratio * radius)
            }
        }
    }

    /// The density of a filtered half-space at signed distance `r` from its plane (positive
    /// outside): the profile d(r) of paper equation 5, analytically.
    pub fn half_space_density(&self, r: f64, radius: f64) -> f64 {
        match *self {
            Filter::Hypercone => hypercone::hypercone_half_space_density(r, radius),
            Filter::Gaussian { sigma_ratio } => {
                gaussian::gaussian_half_space_density(r, radius, sigma_ratio * radius)
            }
        }
    }

    /// `"hypercone"` or `"gaussian"`.
    pub fn name(&self) -> &'static str {
        match self {
            Filter::Hypercone => "hypercone",
            Filter::Gaussian { .. } => "gaussian",
        }
    }
}

impl std::str::FromStr for Filter {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.to_ascii_lowercase().as_str() {
            "hypercone" | "hyper-cone" | "cone" => Ok(Filter::Hypercone),
            "gaussian" | "gauss" => Ok(Filter::GAUSSIAN),
            other => Err(format!(
                "unknown filter '{other}': choose hypercone or gaussian"
            )),
        }
    }
}
