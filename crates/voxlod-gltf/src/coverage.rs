//! `MSFT_screencoverage` from the pixel-size rule of `voxlod select` (Low–Tan's display step,
//! Rossignac–Borrel §5.4; the voxel pyramid of He et al. 1995 §2 has a voxel as its cell).
//!
//! `voxlod select` draws the coarsest level whose cell size is at most `tolerance × pixel size`,
//! where a pixel covers `2·d·tan(fov/2) / H` of object space at distance `d` for a viewport `H`
//! pixels high. An engine that reads `MSFT_lod` does not know cell sizes; it measures the
//! **screen coverage** of the object. We define the coverage as the fraction of the viewport
//! height spanned by the bounding-sphere diameter `D` of the chain (the diagonal of its box),
//! `c = D / (2·d·tan(fov/2))` — the "screen size" of common engines. Then the pixel size is
//! `D / (c·H)` and level `k` (cell `s_k`) fits exactly while `c ≤ tolerance·D / (H·s_k)`.
//!
//! `MSFT_screencoverage[k]` is the coverage below which level `k` gives way to level `k + 1`
//! (the MSFT_lod README: LOD k is drawn from entry `k − 1` down to entry `k`): the largest
//! coverage at which level `k + 1` fits, and 0 for the coarsest level, which is drawn however
//! small the object gets. Where no level fits (closer than entry 0), the finest is drawn, as
//! `select` falls back to the original. The rule depends on `H`: the file records the viewport
//! height it assumed, and a viewer with another height scales the coverages by `H_file / H`.
//!
//! Beyond the paper: the paper picks levels by hand; the rule is `voxlod select`'s.
//! Cost: O(levels).

use crate::GltfError;

/// The viewing assumptions behind the coverages.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CoverageOptions {
    /// Viewport height in pixels the coverages are computed for.
    pub viewport_height: u32,
    /// A level fits when its cell size is at most `tolerance` pixel sizes (as `select`).
    pub tolerance: f64,
}

impl Default for CoverageOptions {
    /// A 1080-pixel-high viewport; a cell fits when its side is at most a pixel.
    fn default() -> Self {
        CoverageOptions {
            viewport_height: 1080,
            tolerance: 1.0,
        }
    }
}

impl CoverageOptions {
    /// A cell fits when its diagonal is at most a pixel (`select --tolerance 0.577`).
    pub fn diagonal() -> Self {
        CoverageOptions {
            tolerance: 1.0 / 3f64.sqrt(),
            ..Default::default()
        }
    }
}

/// The largest coverage at which a level with cell `cell_size` still fits.
pub fn fitting_coverage(
    cell_size: f64,
    diameter: f64,
    options: &CoverageOptions,
) -> Result<f64, GltfError> {
    positive("a level's cell size", cell_size)?;
    positive("the bounding diameter", diameter)?;
    positive("the coverage tolerance", options.tolerance)?;
    positive("the viewport height", options.viewport_height as f64)?;
    Ok(options.tolerance * diameter / (options.viewport_height as f64 * cell_size))
}

/// `MSFT_screencoverage` for levels with these cell sizes, finest first (strictly increasing).
pub fn screen_coverages(
    cell_sizes: &[f64],
    diameter: f64,
    options: &CoverageOptions,
) -> Result<Vec<f64>, GltfError> {
    if cell_sizes.windows(2).any(|w| w[1].total_cmp(&w[0]).is_le()) {
        return Err(GltfError::InvalidChain(format!(
            "cell sizes must grow strictly from the finest level to the coarsest, got {cell_sizes:?}"
        )));
    }
    for &s in cell_sizes {
        positive("a level's cell size", s)?;
    }
    let mut out = Vec::with_capacity(cell_sizes.len());
    for &next in cell_sizes.iter().skip(1) {
        out.push(fitting_coverage(next, diameter, options)?);
    }
    if !cell_sizes.is_empty() {
        out.push(0.0);
    }
    Ok(out)
}

/// The pixel size (object space) that a coverage means for a viewport `options.viewport_height`
/// high: `D / (c·H)`. The inverse of the coverage definition, for tests and viewers.
pub fn pixel_size_at(coverage: f64, diameter: f64, options: &CoverageOptions) -> f64 {
    diameter / (coverage * options.viewport_height as f64)
}

fn positive(what: &'static str, value: f64) -> Result<(), GltfError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(GltfError::InvalidParameter { what, value })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coverages_of_a_halving_chain_halve_and_end_at_zero() {
        // D = 2, H = 1000, tolerance 1: level k+1 (cell 0.01·2^(k+1)) fits while c ≤ 0.2/2^(k+1).
        let options = CoverageOptions {
            viewport_height: 1000,
            tolerance: 1.0,
        };
        let c = screen_coverages(&[0.01, 0.02, 0.04], 2.0, &options).unwrap();
        assert_eq!(c.len(), 3);
        assert!((c[0] - 0.1).abs() < 1e-12, "{c:?}");
        assert!((c[1] - 0.05).abs() < 1e-12, "{c:?}");
        assert_eq!(c[2], 0.0);
    }

    #[test]
    fn unordered_or_bad_cell_sizes_are_refused() {
        let o = CoverageOptions::default();
        assert!(screen_coverages(&[0.02, 0.01], 1.0, &o).is_err());
        assert!(screen_coverages(&[0.01, 0.01], 1.0, &o).is_err());
        assert!(screen_coverages(&[0.0, 0.01], 1.0, &o).is_err());
        assert!(screen_coverages(&[0.01, f64::NAN], 1.0, &o).is_err());
        assert!(screen_coverages(&[0.01], 0.0, &o).is_ok()); // one level: nothing to switch
        assert!(screen_coverages(&[0.01, 0.02], 0.0, &o).is_err());
    }
}
