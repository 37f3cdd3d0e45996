//! Levels that vanish: a part thinner than the filter has a filtered density below the
//! isodensity everywhere (paper §2: a sheet of thickness `t` peaks near `t/R` under the
//! hyper-cone of radius `R`), and the level's surface is empty. A pipeline must say so rather
//! than write an empty mesh silently, and a triangle budget must still give a mesh, from a
//! finer resolution if it must.
//!
//! [`level_is_empty`] checks one sampled level; [`find_surface_resolution`] says whether the
//! level at a resolution is empty and, if so, the coarsest finer resolution at which it is not
//! (doubling, then bisecting). Beyond the paper, which has no empty levels in its tables.
//!
//! The search assumes that a level that has a surface keeps it at every finer resolution (the
//! radius shrinks with the voxel, so the peak density grows); near the threshold the sampling
//! position can make that fail by a resolution or two, which the bisection then lands beside.
//!
//! Cost: one filtered sampling per probe, about `2 log2(max/resolution)` probes, each no bigger
//! than the finest probed level (checked against the memory limit first).

use serde::Serialize;
use voxlod_core::Volume;

use crate::{filtered_density, plan_levels, PyramidOptions, SamplingError, Solid};

/// Whether no sample reaches `iso` (NaN never does): marching cubes then makes no triangle.
pub fn level_is_empty(volume: &Volume, iso: f32) -> bool {
    !volume.as_slice().iter().any(|&v| v >= iso)
}

/// What [`find_surface_resolution`] found.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Vanishing {
    /// The resolution asked about.
    pub resolution: usize,
    /// Whether its level has no surface.
    pub empty: bool,
    /// The largest filtered density of its level.
    pub peak_density: f32,
    /// The coarsest resolution, from `resolution` up to the search's limit, whose level has a
    /// surface (`resolution` itself when it is not empty); `None` when even the limit is empty.
    pub surface_resolution: Option<usize>,
}

/// The largest finite density of `solid`'s level at `resolution`, with `pyramid`'s filter,
/// radius (in voxels of the level) and quadrature.
fn peak_density(
    solid: &dyn Solid,
    pyramid: &PyramidOptions,
    resolution: usize,
) -> Result<f32, SamplingError> {
    let options = PyramidOptions {
        resolutions: vec![resolution],
        ..pyramid.clone()
    };
    let plan = plan_levels(&solid.bounds(), &options)?[0];
    let (volume, _) = filtered_density(solid, &plan.grid, &plan.density_options(&options))?;
    Ok(volume.range().map_or(f32::NEG_INFINITY, |(_, hi)| hi))
}

/// Whether `solid`'s level at `resolution` is empty at `iso`, and the coarsest resolution up to
/// `max_resolution` whose level is not. See the module documentation.
pub fn find_surface_resolution(
    solid: &dyn Solid,
    pyramid: &PyramidOptions,
    resolution: usize,
    iso: f32,
    max_resolution: usize,
) -> Result<Vanishing, SamplingError> {
    if !iso.is_finite() {
        return Err(SamplingError::InvalidOption(format!(
            "the isodensity {iso} is not a finite number"
        )));
    }
    let peak = peak_density(solid, pyramid, resolution)?;
    let mut found = Vanishing {
        resolution,
        empty: peak < iso,
        peak_density: peak,
        surface_resolution: None,
    };
    if !found.empty {
        found.surface_resolution = Some(resolution);
        return Ok(found);
    }
    let has_surface =
        |n: usize| -> Result<bool, SamplingError> { Ok(peak_density(solid, pyramid, n)? >= iso) };
    // Double until a level has a surface (or the limit is reached), then bisect.
    let (mut empty, mut full) = (resolution, None);
    while empty < max_resolution {
        let next = empty.saturating_mul(2).min(max_resolution);
        if has_surface(next)? {
            full = Some(next);
            break;
        }
        empty = next;
    }
    let Some(mut full) = full else {
        return Ok(found);
    };
    while full - empty > 1 {
        let middle = empty + (full - empty) / 2;
        if has_surface(middle)? {
            full = middle;
        } else {
            empty = middle;
        }
    }
    found.surface_resolution = Some(full);
    Ok(found)
}
