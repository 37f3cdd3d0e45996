//! The finest level of a mesh's default chain, from the input's triangle count: the pyramid is
//! scaled down (never up) so that marching cubes' estimated triangle count at its finest level
//! is at most the input's, and a chain of levels of detail starts at or below its input instead
//! of above it (at a fixed 256, the Stanford bunny's 69 451 triangles would give 455 000).
//!
//! Beyond the paper (He et al. 1995 choose the resolutions by hand, §2 and Tables 1–3). The
//! estimate is `voxlod_contouring::triangle_estimate` (the surface's projected area over the
//! cell area, from the input alone, before any sampling), which tends high on detail finer than
//! the filter, so the finest level lands at or a little below the input's count. A level that
//! vanishes at the chosen resolution (a sheet thinner than the filter: the turbine blade) would
//! give an empty chain; [`surface_resolution`] then finds the coarsest resolution, up to the
//! pyramid's own, at which it has a surface, and the chain starts there, with a warning.
//!
//! Cost: O(F) over the input's triangles for the estimate; a vanishing first level costs the
//! probes of `voxlod_sampling::vanishing` (a few samplings no finer than the pyramid's own).

use serde::Serialize;
use voxlod_contouring::triangle_estimate::{estimated_triangles_at, resolution_for_triangles};
use voxlod_core::TriangleMesh;
use voxlod_sampling::{find_surface_resolution, PyramidOptions, SamplingError, Solid};

/// How the finest level's resolution is chosen ([`crate::LodOptions::finest`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Finest {
    /// The pyramid's resolutions as they are.
    Given,
    /// For a mesh, the pyramid scaled down so that its finest level has no more triangles than
    /// the input (by the estimate; at least [`MIN_RESOLUTION`] samples); other sources as given.
    #[default]
    InputTriangles,
}

/// The coarsest finest level chosen from the input's count: below it a chain of halving levels
/// has nothing left to show (a 78-triangle print model would start at 4 samples).
pub const MIN_RESOLUTION: usize = 16;

/// What [`Finest::InputTriangles`] chose, for the report.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FinestChoice {
    /// The input's triangles.
    pub input_triangles: usize,
    /// The pyramid's own finest resolution (the most the choice may take).
    pub given_resolution: usize,
    /// The finest resolution chosen.
    pub resolution: usize,
    /// Marching cubes' estimated triangles at that resolution.
    pub estimated_triangles: f64,
}

/// `pyramid` with its finest level chosen from `mesh`'s triangle count (see the module
/// documentation), and the choice; `pyramid` unchanged and `None` for a mesh without area.
pub fn choose_finest(
    mesh: &TriangleMesh,
    pyramid: &PyramidOptions,
) -> (PyramidOptions, Option<FinestChoice>) {
    let Some(&given) = pyramid.resolutions.first() else {
        return (pyramid.clone(), None);
    };
    let Some(fit) = resolution_for_triangles(mesh, mesh.triangle_count()) else {
        return (pyramid.clone(), None);
    };
    let resolution = fit.max(MIN_RESOLUTION).min(given);
    let choice = FinestChoice {
        input_triangles: mesh.triangle_count(),
        given_resolution: given,
        resolution,
        estimated_triangles: estimated_triangles_at(mesh, resolution),
    };
    (scaled(pyramid, resolution), Some(choice))
}

/// `pyramid` with every resolution scaled by `finest / resolutions[0]` (rounded; at least 2, as
/// halving gives, unless the given one was smaller).
pub fn scaled(pyramid: &PyramidOptions, finest: usize) -> PyramidOptions {
    let given = pyramid
        .resolutions
        .first()
        .copied()
        .unwrap_or(finest)
        .max(1);
    let resolutions = pyramid
        .resolutions
        .iter()
        .map(|&r| ((r * finest + given / 2) / given).max(r.min(2)))
        .collect();
    PyramidOptions {
        resolutions,
        ..pyramid.clone()
    }
}

/// The coarsest resolution from `from` up to `up_to` whose level of `solid` has a surface at
/// `iso`, when the level at `from` has none; `None` when even `up_to` has none.
pub fn surface_resolution(
    solid: &dyn Solid,
    pyramid: &PyramidOptions,
    from: usize,
    up_to: usize,
    iso: f32,
) -> Result<Option<usize>, SamplingError> {
    let found = find_surface_resolution(solid, pyramid, from, iso, up_to)?;
    Ok(found.surface_resolution)
}

#[cfg(test)]
mod tests {
    use super::*;
    use voxlod_sampling::Filter;

    #[test]
    fn scaling_keeps_the_ratios() {
        let pyramid = PyramidOptions::halving(256, 6, Filter::Hypercone);
        assert_eq!(scaled(&pyramid, 100).resolutions, [100, 50, 25, 13, 6, 3]);
        assert_eq!(scaled(&pyramid, 256).resolutions, pyramid.resolutions);
    }

    #[test]
    fn a_sphere_starts_where_its_count_fits_within_the_floor_and_the_cap() {
        // The unit icosphere of 20 480 triangles: a sphere gets 3 · area / h² = 3π N²
        // triangles at N samples across its diameter 2, so N = √(20480 / 3π) = 46.6 → 46.
        let sphere = voxlod_testkit::shapes::icosphere(5);
        let pyramid = PyramidOptions::halving(256, 3, Filter::Hypercone);
        let (chosen, choice) = choose_finest(&sphere, &pyramid);
        let choice = choice.unwrap();
        assert_eq!(chosen.resolutions, [46, 23, 12]);
        assert_eq!(
            (choice.input_triangles, choice.given_resolution),
            (20480, 256)
        );
        assert!(choice.estimated_triangles <= 20480.0);
        assert!(estimated_triangles_at(&sphere, 47) > 20480.0);
        // Never finer than the pyramid's own finest level, never coarser than the floor.
        let (capped, _) =
            choose_finest(&sphere, &PyramidOptions::halving(32, 2, Filter::Hypercone));
        assert_eq!(capped.resolutions, [32, 16]);
        let (floored, _) = choose_finest(&voxlod_testkit::shapes::icosphere(1), &pyramid);
        assert_eq!(floored.resolutions[0], MIN_RESOLUTION);
        assert!(choose_finest(&TriangleMesh::default(), &pyramid)
            .1
            .is_none());
    }
}
