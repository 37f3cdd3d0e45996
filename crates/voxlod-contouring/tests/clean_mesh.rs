//! Cleaned levels against raw marching cubes, checked with the independent intersection test
//! of `voxlod-testkit`: no crossing pair of triangles, no triangle under a thousandth of a
//! cell², still closed, manifold, oriented and of the same genus, enclosed volume within 0.5 %.
//! The shapes are chosen to put the surface through or next to grid samples: a sphere through
//! many samples exactly, the sphereflake and gyroid fields of the peers' kit, and a filtered
//! chain of two interlocked tori.

use glam::{DVec3, Vec3};
use voxlod_contouring::{clean_mesh, marching_cubes, CleanOptions, ContourOptions};
use voxlod_core::{mesh_topology, Grid, Volume};
use voxlod_sampling::{filtered_density, level_grid, DensityOptions, Filter, MeshSolid, Solid};
use voxlod_testkit::fields::{gyroid_field, sphereflake_field};
use voxlod_testkit::intersections::{self_intersections, triangles_smaller_than};
use voxlod_testkit::shapes::{append, torus};

/// Contours, cleans with the defaults and checks the cleaned level; returns the raw level's
/// (small triangles, crossing pairs) for the caller to check that there was work to do.
fn check(name: &str, volume: &Volume, iso: f32) -> (usize, usize) {
    let cell = volume.grid.spacing[0];
    let raw = marching_cubes(volume, &ContourOptions::at(iso)).unwrap();
    let (clean, report) = clean_mesh(&raw, cell, &CleanOptions::default()).unwrap();
    let limit = CleanOptions::default().min_area * cell * cell;
    let before = (
        triangles_smaller_than(&raw, limit),
        self_intersections(&raw).len(),
    );
    let after = (
        triangles_smaller_than(&clean, limit),
        self_intersections(&clean).len(),
    );
    eprintln!(
        "{name}: {} -> {} triangles; small {} -> {}; crossing pairs {} -> {}; {report:?}",
        raw.triangles.len(),
        clean.triangles.len(),
        before.0,
        after.0,
        before.1,
        after.1
    );
    let smallest = (0..clean.triangles.len())
        .map(|t| {
            let [a, b, c] = clean.corners(t);
            0.5 * (b - a).cross(c - a).length() / (cell * cell)
        })
        .fold(f64::INFINITY, f64::min);
    eprintln!("{name}: smallest area {smallest:e} cells²");
    assert_eq!(after, (0, 0), "{name}");
    assert_eq!(report.small_triangles_left, 0, "{name}");
    let (t_raw, t_clean) = (mesh_topology(&raw), mesh_topology(&clean));
    assert!(t_raw.is_closed_manifold(), "{name}: {t_raw:?}");
    assert!(
        t_clean.is_closed_manifold() && t_clean.is_consistently_oriented(),
        "{name}: {t_clean:?}"
    );
    assert_eq!(t_clean.genus, t_raw.genus, "{name}");
    assert_eq!(t_clean.components, t_raw.components, "{name}");
    assert_eq!(t_clean.unreferenced_vertices, 0);
    assert_eq!(clean.normals.len(), clean.positions.len());
    let (v_raw, v_clean) = (raw.signed_volume(), clean.signed_volume());
    let change = (v_clean - v_raw).abs() / v_raw.abs();
    assert!(change < 0.005, "{name}: volume {v_raw} -> {v_clean}");
    before
}

/// `r - |p - c|` on an n³ unit grid: with `c` on a sample and `r = 5`, the surface passes
/// exactly through every sample at distance 5 (such as (3, 4, 0)).
fn sphere_through_samples(n: usize, r: f64) -> Volume {
    let grid = Grid::unit([n; 3]).unwrap();
    let c = ((n - 1) / 2) as f64;
    let values = (0..grid.len())
        .map(|i| {
            let p = DVec3::new((i % n) as f64, ((i / n) % n) as f64, (i / (n * n)) as f64);
            (r - p.distance(DVec3::splat(c))) as f32
        })
        .collect();
    Volume::from_vec(grid, values).unwrap()
}

#[test]
fn spheres_through_and_next_to_samples() {
    let (small, _) = check("sphere r=5", &sphere_through_samples(15, 5.0), 0.0);
    assert!(small > 0, "the raw level should have slivers");
    check(
        "sphere r=7+1e-6",
        &sphere_through_samples(19, 7.000001),
        0.0,
    );
    check("sphere r=13", &sphere_through_samples(31, 13.0), 0.0);
}

#[test]
fn two_spheres_a_thousandth_of_a_cell_apart() {
    // Two spheres of radius 5 whose gap, 1e-3 cells wide, straddles the sample (11, 11, 11):
    // a near-pinch, where cleaning must neither join the sheets nor push one through the other.
    let n = 23;
    let grid = Grid::unit([n; 3]).unwrap();
    let values = (0..grid.len())
        .map(|i| {
            let p = DVec3::new((i % n) as f64, ((i / n) % n) as f64, (i / (n * n)) as f64);
            let d = |x: f64| 5.0 - p.distance(DVec3::new(x, 11.0, 11.0));
            d(11.0 - 5.0005).max(d(11.0 + 5.0005)) as f32
        })
        .collect();
    let volume = Volume::from_vec(grid, values).unwrap();
    check("two spheres", &volume, 0.0);
}

#[test]
fn the_kits_fields() {
    let (small, _) = check("sphereflake 96", &sphereflake_field(96).unwrap(), 0.0);
    assert!(small > 0);
    check("gyroid 64", &gyroid_field(64).unwrap(), 0.0);
}

#[test]
fn a_filtered_chain_of_two_tori() {
    let mut chain = torus(96, 48, 1.0, 0.3);
    let mut second = torus(96, 48, 1.0, 0.3);
    for p in &mut second.positions {
        *p = Vec3::new(p.x + 1.0, p.z, p.y);
    }
    append(&mut chain, &second);
    let solid = MeshSolid::new(&chain).unwrap();
    for resolution in [48, 24] {
        let h = solid.bounds().longest_extent() / resolution as f64;
        let grid = level_grid(&solid.bounds(), resolution, h).unwrap();
        let options = DensityOptions::new(Filter::Hypercone, h);
        let (density, _) = filtered_density(&solid, &grid, &options).unwrap();
        check(&format!("chain at {resolution}"), &density, 0.5);
    }
}

/// One sample barely above the isodensity among neighbours below it, as at the coarse level of
/// thingi10k-138207 where the filter's peak just reaches 0.5: marching cubes makes an
/// octahedron whose six vertices lie within a tenth of a cell of the sample, so all its edges
/// are short, and the neighbourhood of any edge is the whole closed octahedron, whose area
/// vectors sum to zero. Whether a collapse "turns a triangle over" against that sum is then
/// rounding noise, and collapsing the octahedron down to a tetrahedron turned some of them
/// inside out. Cleaning must leave every one outward-facing, closed and oriented.
#[test]
fn a_lone_sample_is_never_turned_inside_out() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_pcg::Pcg64::seed_from_u64(138207);
    let grid = Grid::unit([5, 5, 5]).unwrap();
    let mut inverted = 0;
    for _ in 0..300 {
        let mut values = vec![0.0f32; grid.len()];
        for k in 1..4 {
            for j in 1..4 {
                for i in 1..4 {
                    values[grid.index(i, j, k)] = rng.random_range(0.0..0.45);
                }
            }
        }
        values[grid.index(2, 2, 2)] = 0.5 + rng.random_range(0.002..0.04);
        let volume = Volume::from_vec(grid, values).unwrap();
        let raw = marching_cubes(&volume, &ContourOptions::at(0.5)).unwrap();
        assert_eq!(raw.triangles.len(), 8);
        assert!(raw.signed_volume() > 0.0);
        let (clean, _) = clean_mesh(&raw, 1.0, &CleanOptions::default()).unwrap();
        let t = mesh_topology(&clean);
        assert!(
            t.is_closed_manifold() && t.is_consistently_oriented(),
            "{t:?}"
        );
        if clean.signed_volume() <= 0.0 {
            inverted += 1;
        }
    }
    assert_eq!(inverted, 0, "cleaning turned lone samples inside out");
}
