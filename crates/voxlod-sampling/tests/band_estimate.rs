//! The plan's bound on a mesh's narrow band ([`Solid::band_bricks_bound`]) against the band the
//! sampler finds: never fewer bricks, and not many more, so that the memory the plan states
//! for a level through the band is honest.

use voxlod_core::Grid;
use voxlod_sampling::{
    level_grid, narrow_band_density, DensityOptions, Filter, MeshSolid, NarrowBandOptions, Solid,
};
use voxlod_testkit::shapes::{holed_block, icosphere, torus};

/// The sampler's band bricks and the bound, for `solid` at `resolution` with a support of
/// `radius_voxels`.
fn band_and_bound(solid: &dyn Solid, resolution: usize, radius_voxels: f64) -> (usize, usize) {
    let bounds = solid.bounds();
    let h = bounds.longest_extent() / resolution as f64;
    let grid: Grid = level_grid(&bounds, resolution, radius_voxels * h).unwrap();
    let options = DensityOptions::new(Filter::Hypercone, radius_voxels * h);
    let band = NarrowBandOptions::default();
    let (_, _, report) = narrow_band_density(solid, &grid, &options, &band).unwrap();
    // The narrow band's margin: the support radius and two samples for the gradients.
    let bound = solid
        .band_bricks_bound(&grid, band.brick_size, radius_voxels + 2.0)
        .unwrap();
    (report.band_bricks, bound)
}

#[test]
fn the_bound_holds_the_band_and_stays_close_to_it() {
    let solids = [
        ("torus", MeshSolid::new(&torus(96, 48, 1.0, 0.3)).unwrap()),
        ("holed block", MeshSolid::new(&holed_block()).unwrap()),
        ("ball", MeshSolid::new(&icosphere(5)).unwrap()),
    ];
    for (name, solid) in &solids {
        for (resolution, radius) in [(64, 1.0), (160, 1.0), (96, 2.5)] {
            let (band, bound) = band_and_bound(solid, resolution, radius);
            assert!(band > 0, "{name} at {resolution}");
            assert!(
                bound >= band,
                "{name} at {resolution}: bound {bound} < band {band}"
            );
            assert!(
                bound as f64 <= 1.6 * band as f64,
                "{name} at {resolution}: bound {bound} far above band {band}"
            );
        }
    }
}

#[test]
fn solids_that_cannot_tell_give_no_bound() {
    let ball =
        voxlod_sampling::CsgSolid::new(voxlod_sampling::Shape::sphere(glam::DVec3::ZERO, 1.0))
            .unwrap();
    let grid = level_grid(&ball.bounds(), 32, 0.1).unwrap();
    assert_eq!(ball.band_bricks_bound(&grid, 8, 3.0), None);
}
