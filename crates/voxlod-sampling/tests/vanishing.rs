//! A sheet thinner than the filter vanishes; the search finds the coarsest resolution at which
//! it does not, against the analytic density of a filtered slab (paper equation 5).

use glam::DVec3;
use voxlod_core::Volume;
use voxlod_sampling::{
    filtered_density, find_surface_resolution, level_is_empty, plan_levels, CsgSolid, Filter,
    PyramidOptions, Shape,
};

/// Density at distance `s` from the middle plane of a slab of thickness `t`, filter radius `r`.
fn slab_density(filter: Filter, t: f64, s: f64, r: f64) -> f64 {
    filter.half_space_density(s - t / 2.0, r) - filter.half_space_density(s + t / 2.0, r)
}

#[test]
fn a_thin_sheet_vanishes_until_the_filter_is_narrow_enough() {
    let t = 0.02;
    let sheet = Shape::cuboid(
        DVec3::new(-1.0, -1.0, -t / 2.0),
        DVec3::new(1.0, 1.0, t / 2.0),
    );
    let solid = CsgSolid::new(sheet).unwrap();
    let pyramid = PyramidOptions::for_resolutions(vec![16], Filter::Hypercone);
    let found = find_surface_resolution(&solid, &pyramid, 16, 0.5, 256).unwrap();
    eprintln!("{found:?}");
    assert!(found.empty);
    assert!(found.peak_density < 0.5);
    let n = found.surface_resolution.expect("a surface below 256");
    // The analytic coarsest resolution: radius one voxel, and the samples nearest to the
    // sheet's middle plane where each level's grid puts them (the grid is centred on the
    // sheet, so with an even number of samples across they sit half a voxel off).
    let bounds = voxlod_sampling::Solid::bounds(&solid);
    let analytic = (16..256)
        .find(|&n| {
            let options = PyramidOptions::for_resolutions(vec![n], Filter::Hypercone);
            let plan = plan_levels(&bounds, &options).unwrap()[0];
            let nearest = (0..plan.grid.dims[2])
                .map(|k| plan.grid.position(0.0, 0.0, k as f64).z.abs())
                .fold(f64::INFINITY, f64::min);
            slab_density(Filter::Hypercone, t, nearest, plan.radius) >= 0.5
        })
        .unwrap();
    eprintln!("found {n}, analytic {analytic}");
    // The sampled density is within 0.01 of the analytic one: a few resolutions either way.
    assert!(
        n.abs_diff(analytic) <= analytic / 20 + 1,
        "{n} vs {analytic}"
    );
    // Checked directly: a surface at n, none at n - 1.
    let level = |n: usize| -> Volume {
        let options = PyramidOptions::for_resolutions(vec![n], Filter::Hypercone);
        let plan = plan_levels(&voxlod_sampling::Solid::bounds(&solid), &options).unwrap()[0];
        filtered_density(&solid, &plan.grid, &plan.density_options(&options))
            .unwrap()
            .0
    };
    assert!(!level_is_empty(&level(n), 0.5));
    assert!(level_is_empty(&level(n - 1), 0.5));
}

#[test]
fn a_level_with_a_surface_is_its_own_answer_and_a_limit_is_respected() {
    let ball = CsgSolid::new(Shape::sphere(DVec3::ZERO, 1.0)).unwrap();
    let pyramid = PyramidOptions::for_resolutions(vec![8], Filter::GAUSSIAN);
    let found = find_surface_resolution(&ball, &pyramid, 8, 0.5, 64).unwrap();
    assert!(!found.empty);
    assert_eq!(found.surface_resolution, Some(8));
    let sheet = Shape::cuboid(DVec3::new(-1.0, -1.0, -0.001), DVec3::new(1.0, 1.0, 0.001));
    let solid = CsgSolid::new(sheet).unwrap();
    let found = find_surface_resolution(&solid, &pyramid, 8, 0.5, 40).unwrap();
    assert!(found.empty);
    assert_eq!(found.surface_resolution, None);
    assert!(find_surface_resolution(&solid, &pyramid, 8, f32::NAN, 40).is_err());
}
