//! The triangle estimate against marching cubes' actual count, on analytic fields whose zero
//! set is the same shape as a fine mesh: a sphere, a torus and a rotated box, at two
//! resolutions each, within 15 %.

use glam::{DMat3, DVec3};
use voxlod_contouring::triangle_estimate::{estimated_triangles_at, resolution_for_triangles};
use voxlod_contouring::{marching_cubes, ContourOptions};
use voxlod_core::{Grid, TriangleMesh, Volume};
use voxlod_testkit::shapes::{icosphere, torus, unit_cube};

/// Marching cubes' triangles of `inside(p) > 0` at `resolution` samples across `extent`, the
/// grid padded by two samples and centred on the origin.
fn actual(inside: impl Fn(DVec3) -> f64, extent: f64, resolution: usize) -> usize {
    let h = extent / resolution as f64;
    let n = resolution + 5;
    let origin = -((n - 1) as f64) * h / 2.0;
    let grid = Grid::new([n; 3], [h; 3], [origin; 3]).unwrap();
    let values = (0..grid.len())
        .map(|i| {
            let (x, y, z) = (i % n, (i / n) % n, i / (n * n));
            inside(grid.position(x as f64, y as f64, z as f64)) as f32
        })
        .collect();
    let volume = Volume::from_vec(grid, values).unwrap();
    marching_cubes(&volume, &ContourOptions::geometry_only(0.0))
        .unwrap()
        .triangle_count()
}

fn check(name: &str, mesh: &TriangleMesh, inside: impl Fn(DVec3) -> f64, resolution: usize) {
    let extent = mesh.bounds().longest_extent();
    let got = actual(inside, extent, resolution) as f64;
    let estimate = estimated_triangles_at(mesh, resolution);
    let error = (estimate - got).abs() / got;
    eprintln!("{name} at {resolution}: estimate {estimate:.0}, marching cubes {got}");
    assert!(
        error < 0.15,
        "{name} at {resolution}: {estimate:.0} for {got}"
    );
}

fn rotation() -> DMat3 {
    DMat3::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.7)
}

#[test]
fn the_estimate_is_within_15_percent_of_marching_cubes() {
    let sphere = icosphere(5);
    for n in [24, 64] {
        check("sphere", &sphere, |p| 1.0 - p.length(), n);
    }
    let ring = torus(192, 96, 1.0, 0.35);
    let tube = |p: DVec3| 0.35 - DVec3::new(p.truncate().length() - 1.0, p.z, 0.0).length();
    for n in [24, 64] {
        check("torus", &ring, tube, n);
    }
    // The unit cube, centred and rotated: faces oblique to every axis.
    let r = rotation();
    let mut cube = unit_cube();
    for p in &mut cube.positions {
        *p = (r * (p.as_dvec3() - DVec3::splat(0.5))).as_vec3();
    }
    let inverse = r.transpose();
    let inside = |p: DVec3| 0.5 - (inverse * p).abs().max_element();
    for n in [24, 64] {
        check("rotated cube", &cube, inside, n);
    }
}

#[test]
fn the_resolution_for_a_budget_lands_under_it() {
    let sphere = icosphere(5);
    for budget in [500usize, 5_000, 50_000] {
        let n = resolution_for_triangles(&sphere, budget).unwrap();
        let got = actual(|p| 1.0 - p.length(), 2.0, n);
        eprintln!("sphere budget {budget}: resolution {n}, {got} triangles");
        assert!(got as f64 <= budget as f64 * 1.15, "{got} for {budget}");
        assert!(got as f64 >= budget as f64 * 0.7, "{got} for {budget}");
    }
}
