//! Marching cubes with the snapping clamp ([`CleanOptions::contour_clamp`]): no edge shorter
//! than a tenth of a cell, no triangle below 1e-3 cell², and exactly plain marching cubes'
//! triangles (the same vertex on the same grid edge, moved along it by at most the clamp).
//! Checked on cells of every case with every vertex at a clamp limit or halfway, on random
//! samples of every case, on fields with samples exactly at the iso value (a ball whose radius puts
//! samples on its surface, a plane through rows of samples, a gyroid rounded to sixteenths),
//! against the sparse extraction, and through cleaning, which then has nothing to do.

use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use voxlod_contouring::clean_mesh::has_defects;
use voxlod_contouring::marching_cubes::snap_clamp;
use voxlod_contouring::{
    clean_mesh, marching_cubes, sparse_marching_cubes, CleanOptions, ContourError, ContourOptions,
    PLAIN_CLAMP,
};
use voxlod_core::{mesh_topology, BrickVolume, Grid, TriangleMesh, Volume};
use voxlod_testkit::fields::gyroid_field;

/// The clamp for cleaning's defaults.
fn clamp() -> f32 {
    CleanOptions::default().contour_clamp()
}

/// The shortest edge (cells) and the smallest triangle (cells²) of `mesh`.
fn shortest_and_smallest(mesh: &TriangleMesh, cell: f64) -> (f64, f64) {
    let (mut edge, mut area) = (f64::INFINITY, f64::INFINITY);
    for t in 0..mesh.triangles.len() {
        let p = mesh.corners(t).map(|c| c / cell);
        for k in 0..3 {
            edge = edge.min(p[k].distance(p[(k + 1) % 3]));
        }
        area = area.min(0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length());
    }
    (edge, area)
}

/// `volume`'s surface at `iso` by plain marching cubes and with the snapping clamp.
fn plain_and_snapped(volume: &Volume, iso: f32) -> (TriangleMesh, TriangleMesh) {
    let plain = marching_cubes(volume, &ContourOptions::at(iso)).unwrap();
    let snapped = marching_cubes(volume, &ContourOptions::at(iso).with_clamp(clamp())).unwrap();
    (plain, snapped)
}

/// `snapped` has `plain`'s triangles and vertex count, and each vertex lies on the same grid
/// edge (both differ along at most one axis), within `clamp` cell of the plain one.
fn assert_same_surface(plain: &TriangleMesh, snapped: &TriangleMesh, cell: f64, what: &str) {
    assert_eq!(plain.triangles, snapped.triangles, "{what}");
    assert_eq!(plain.positions.len(), snapped.positions.len(), "{what}");
    for (p, q) in plain.positions.iter().zip(&snapped.positions) {
        let d = (q.as_dvec3() - p.as_dvec3()) / cell;
        let moved_along = (0..3).filter(|&a| d[a].abs() > 1e-5).count();
        assert!(moved_along <= 1, "{what}: {p} → {q}");
        assert!(d.length() <= clamp() as f64 + 1e-5, "{what}: {p} → {q}");
    }
}

/// A volume of `n³` samples of cell `cell`, away from the origin, with `value(inside)` at each
/// sample, inside with probability one half; and how many cells of each case it has.
fn random_volume(
    n: usize,
    cell: f64,
    rng: &mut Pcg64Mcg,
    mut value: impl FnMut(&mut Pcg64Mcg, bool) -> f32,
) -> (Volume, Vec<usize>) {
    let grid = Grid::new([n; 3], [cell; 3], [3.0, -2.0, 1.5]).unwrap();
    let inside: Vec<bool> = (0..grid.len()).map(|_| rng.random_bool(0.5)).collect();
    let values = inside.iter().map(|&i| value(rng, i)).collect();
    let mut cases = vec![0; 256];
    for (i, j, k) in
        (0..n - 1).flat_map(|k| (0..n - 1).flat_map(move |j| (0..n - 1).map(move |i| (i, j, k))))
    {
        let case = (0..8).fold(0, |case, c| {
            let at = grid.index(i + (c & 1), j + (c >> 1 & 1), k + (c >> 2));
            case | (inside[at] as usize) << c
        });
        cases[case] += 1;
    }
    (Volume::from_vec(grid, values).unwrap(), cases)
}

#[test]
fn every_case_at_the_clamp_limits_keeps_edges_and_areas() {
    // Inside samples at the iso value or 1 above it, outside ones 1e-3 or 1 below it: every
    // crossed edge's parameter at either clamp limit or halfway, 250 000 cells with all 256
    // cases and (with all likelihood) nearly all of their 4⁸ combinations of samples.
    let (cell, iso) = (0.5, 0.25f32);
    let mut rng = Pcg64Mcg::seed_from_u64(14);
    let (volume, cases) = random_volume(64, cell, &mut rng, |rng, inside| {
        match (inside, rng.random_bool(0.5)) {
            (true, false) => iso,
            (true, true) => iso + 1.0,
            (false, false) => iso - 1e-3,
            (false, true) => iso - 1.0,
        }
    });
    assert!(cases.iter().all(|&c| c > 200), "{cases:?}");
    let (plain, snapped) = plain_and_snapped(&volume, iso);
    assert_same_surface(&plain, &snapped, cell, "limits");
    let (edge, area) = shortest_and_smallest(&snapped, cell);
    assert!(edge >= 0.1 && area >= 1e-3, "{edge} {area}");
    // The bounds are those of the reasoning, and reached: √2·c and (√3/2)·c².
    let bound = 3f64.sqrt() / 2.0 * (clamp() as f64).powi(2);
    assert!((edge - 2f64.sqrt() * clamp() as f64).abs() < 1e-5, "{edge}");
    assert!((area - bound).abs() < 1e-5, "{area} against {bound}");
}

#[test]
fn random_samples_of_every_case_keep_edges_and_areas() {
    // Distances from the iso value spread over six decades, some samples exactly at it.
    let (cell, iso) = (1.0, 0.5f32);
    let mut rng = Pcg64Mcg::seed_from_u64(15);
    let (volume, cases) = random_volume(64, cell, &mut rng, |rng, inside| {
        let d = 10f32.powf(rng.random_range(-6.0..0.0));
        match (inside, d < 1e-5) {
            (true, true) => iso,
            (true, false) => iso + d,
            (false, _) => iso - d,
        }
    });
    assert!(cases.iter().all(|&c| c > 200), "{cases:?}");
    let (plain, snapped) = plain_and_snapped(&volume, iso);
    assert_same_surface(&plain, &snapped, cell, "random");
    let (edge, area) = shortest_and_smallest(&snapped, cell);
    assert!(edge >= 0.1 && area >= 1e-3, "{edge} {area}");
    // Plain marching cubes has the slivers the clamp removes.
    let (edge, area) = shortest_and_smallest(&plain, cell);
    assert!(edge < 1e-3 && area < 1e-6, "{edge} {area}");
}

/// A volume of `dims` unit cells with `f` at each sample.
fn field(dims: [usize; 3], f: impl Fn(DVec3) -> f32) -> Volume {
    let grid = Grid::new(dims, [1.0; 3], [0.0; 3]).unwrap();
    let mut values = Vec::with_capacity(grid.len());
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                values.push(f(DVec3::new(i as f64, j as f64, k as f64)));
            }
        }
    }
    Volume::from_vec(grid, values).unwrap()
}

/// Plain and snapped marching cubes of `volume` at `iso`: plain has an edge under a tenth of
/// a cell (the field puts samples at or next to the iso value), snapped none and no triangle
/// under 1e-3 cell², with plain's triangles; the sparse extraction gives the snapped mesh bit
/// for bit; cleaning it does nothing. Returns the snapped mesh.
fn assert_snapped(volume: &Volume, iso: f32, what: &str) -> TriangleMesh {
    let (plain, snapped) = plain_and_snapped(volume, iso);
    assert!(!plain.triangles.is_empty(), "{what}: no surface");
    assert_same_surface(&plain, &snapped, 1.0, what);
    let (edge, area) = shortest_and_smallest(&plain, 1.0);
    assert!(edge < 0.1 && area < 1e-3, "{what}: plain {edge} {area}");
    let (edge, area) = shortest_and_smallest(&snapped, 1.0);
    assert!(edge >= 0.1 && area >= 1e-3, "{what}: snapped {edge} {area}");
    for brick in BrickVolume::BRICK_SIZES {
        let bricks = BrickVolume::from_volume(volume, brick).unwrap();
        let options = ContourOptions::at(iso).with_clamp(clamp());
        let sparse = sparse_marching_cubes(&bricks, &options).unwrap();
        let mut a: Vec<[u32; 3]> = (sparse.positions.iter())
            .map(|p| p.to_array().map(f32::to_bits))
            .collect();
        let mut b: Vec<[u32; 3]> = (snapped.positions.iter())
            .map(|p| p.to_array().map(f32::to_bits))
            .collect();
        a.sort_unstable();
        b.sort_unstable();
        assert_eq!(a, b, "{what}, bricks of {brick}: vertex positions");
        assert_eq!(sparse.triangles.len(), snapped.triangles.len(), "{what}");
    }
    let defaults = CleanOptions::default();
    assert!(has_defects(&plain, 1.0, &defaults), "{what}");
    assert!(!has_defects(&snapped, 1.0, &defaults), "{what}");
    let (clean, report) = clean_mesh(&snapped, 1.0, &defaults).unwrap();
    assert_eq!(report.collapsed_edges + report.flipped_edges, 0, "{what}");
    assert_eq!(
        (report.relaxed_vertices, report.small_triangles_left),
        (0, 0)
    );
    assert_eq!(clean.triangles.len(), snapped.triangles.len(), "{what}");
    snapped
}

#[test]
fn a_ball_with_samples_on_its_surface_is_snapped_closed() {
    // Density 25 − |p − c|²: samples such as c + (3, 4, 0) and c + (5, 0, 0) lie exactly at
    // the iso value 0 (inside), others within rounding of it.
    let c = DVec3::splat(7.0);
    let ball = field([15; 3], |p| (25.0 - p.distance_squared(c)) as f32);
    let mesh = assert_snapped(&ball, 0.0, "ball");
    let topology = mesh_topology(&mesh);
    assert!(topology.is_closed_manifold() && topology.is_consistently_oriented());
    assert_eq!((topology.genus, topology.components), (Some(0), 1));
    // Within a cell of the sphere of radius 5: 4/3 π 125 = 523.6.
    assert!(
        (mesh.signed_volume() - 523.6).abs() < 60.0,
        "{}",
        mesh.signed_volume()
    );
}

#[test]
fn a_plane_through_rows_of_samples_is_snapped() {
    // x + y + 2z = 17 passes through whole rows of samples; it leaves the grid at its sides.
    let plane = field([12, 12, 12], |p| (17.0 - p.x - p.y - 2.0 * p.z) as f32);
    assert_snapped(&plane, 0.0, "plane");
}

#[test]
fn a_gyroid_rounded_to_sixteenths_is_snapped_with_its_topology() {
    let mut gyroid = gyroid_field(48).unwrap();
    gyroid.values.mapv_inplace(|v| (v * 16.0).round() / 16.0);
    let grid = Grid::new(gyroid.grid.dims, [1.0; 3], [0.0; 3]).unwrap();
    let gyroid = Volume::from_vec(grid, gyroid.as_slice().to_vec()).unwrap();
    let mesh = assert_snapped(&gyroid, 0.0, "gyroid");
    let plain = marching_cubes(&gyroid, &ContourOptions::at(0.0)).unwrap();
    assert_eq!(mesh_topology(&mesh), mesh_topology(&plain));
}

#[test]
fn clamps_outside_zero_to_a_half_are_refused() {
    let volume = field([3; 3], |p| p.x as f32);
    for bad in [-1e-3, 0.51, f32::NAN] {
        let options = ContourOptions::at(0.5).with_clamp(bad);
        let err = marching_cubes(&volume, &options).unwrap_err();
        assert!(matches!(err, ContourError::BadClamp(_)), "{bad}: {err}");
        let bricks = BrickVolume::from_volume(&volume, 8).unwrap();
        let err = sparse_marching_cubes(&bricks, &options).unwrap_err();
        assert!(matches!(err, ContourError::BadClamp(_)), "{bad}: {err}");
    }
    // A half puts every vertex at its edge's midpoint.
    let half = marching_cubes(&volume, &ContourOptions::at(0.2).with_clamp(0.5)).unwrap();
    assert!(half.positions.iter().all(|p| p.x == 0.5));
    assert_eq!(ContourOptions::default().clamp, PLAIN_CLAMP);
    // The clamp grows with what cleaning would fix, within [PLAIN_CLAMP, 0.5].
    assert!((snap_clamp(0.1, 1e-3) - 0.0721).abs() < 1e-4);
    assert!((snap_clamp(1e-3, 1e-6) - 1.0961e-3).abs() < 1e-6);
    assert_eq!(
        (snap_clamp(0.0, 0.0), snap_clamp(5.0, 0.0)),
        (PLAIN_CLAMP, 0.5)
    );
}
