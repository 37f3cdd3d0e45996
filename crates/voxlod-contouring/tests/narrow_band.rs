//! The narrow band against the dense sampler: the same filtered density at every sample (to
//! rounding), exactly 0 or 1 outside the band, and through marching cubes
//! (dense on the dense volume, sparse on the bricks) the same closed surface: the same vertex
//! and triangle counts and the same vertex positions.
//!
//! End to end (sampling, then marching cubes), so it lives here rather than in voxlod-sampling,
//! which does not depend on voxlod-contouring.

use glam::{DVec3, Vec3};
use voxlod_contouring::{marching_cubes, sparse_marching_cubes, ContourOptions};
use voxlod_core::{mesh_topology, Axis, BrickVolume, TriangleMesh, Volume};
use voxlod_sampling::{
    filtered_density, level_grid, narrow_band_density, CsgSolid, DensityOptions, Filter, MeshSolid,
    NarrowBandOptions, Shape, Solid, ThresholdSolid,
};
use voxlod_testkit::data::shared_data_or_skip;
use voxlod_testkit::readers::read_obj;
use voxlod_testkit::shapes::{holed_block, torus};
use voxlod_testkit::volumes::shared_ct_head;

/// Compares the two samplings of `solid` at `resolution` with a support of `radius_voxels`;
/// returns the number of bricks and of band bricks.
fn compare(
    solid: &dyn Solid,
    resolution: usize,
    radius_voxels: f64,
    filter: Filter,
    what: &str,
) -> (usize, usize) {
    let bounds = solid.bounds();
    let h = bounds.longest_extent() / resolution as f64;
    let grid = level_grid(&bounds, resolution, radius_voxels * h).unwrap();
    let options = DensityOptions::new(filter, radius_voxels * h);
    let (dense, dense_report) = filtered_density(solid, &grid, &options).unwrap();
    let mut counts = (0, 0);
    for band in [
        NarrowBandOptions::default(),
        NarrowBandOptions::large_bricks(),
    ] {
        let (bricks, report, band_report) =
            narrow_band_density(solid, &grid, &options, &band).unwrap();
        assert_eq!(report, dense_report, "{what}: same lattice");
        assert_eq!(bricks.leaf_count(), band_report.band_bricks);
        assert_same_values(&dense, &bricks, what);
        assert_same_surface(&dense, &bricks, what);
        if band == NarrowBandOptions::default() {
            counts = (band_report.bricks, band_report.band_bricks);
        }
    }
    counts
}

fn assert_same_values(dense: &Volume, bricks: &BrickVolume, what: &str) {
    // The band cuts each row at its brick: the f64 partial sums cancel in another order, which
    // leaves residues of 1e-16 where the density is 0 or 1, and a few units in the last place
    // of f32 elsewhere. Anything more is a wrong sample.
    let sparse = bricks.to_volume().unwrap();
    for (n, (&d, &s)) in dense.as_slice().iter().zip(sparse.as_slice()).enumerate() {
        let close = (d - s).abs() <= 1e-12 || (d - s).abs() <= 4.0 * f32::EPSILON * d.abs();
        assert!(close, "{what}: sample {n}: dense {d:e}, band {s:e}");
    }
}

fn assert_same_surface(dense: &Volume, bricks: &BrickVolume, what: &str) {
    let options = ContourOptions::default();
    let a = marching_cubes(dense, &options).unwrap();
    let b = sparse_marching_cubes(bricks, &options).unwrap();
    assert!(!a.triangles.is_empty(), "{what}: no surface");
    assert_eq!(
        (a.positions.len(), a.triangles.len()),
        (b.positions.len(), b.triangles.len()),
        "{what}: vertex and triangle counts"
    );
    let sorted = |m: &TriangleMesh| {
        let mut p: Vec<[f32; 3]> = m.positions.iter().map(|v| v.to_array()).collect();
        p.sort_by(|x, y| x.partial_cmp(y).unwrap());
        p
    };
    for (p, q) in sorted(&a).iter().zip(&sorted(&b)) {
        let d = (Vec3::from(*p) - Vec3::from(*q)).length();
        assert!(
            d <= 1e-5 * (1.0 + Vec3::from(*p).length()),
            "{what}: {p:?} vs {q:?}"
        );
    }
    let t = mesh_topology(&b);
    assert!(
        t.is_closed_manifold() && t.is_consistently_oriented(),
        "{what}: {t:?}"
    );
    assert_eq!(t.genus, mesh_topology(&a).genus, "{what}: genus");
}

#[test]
fn csg_solids_match_the_dense_sampler() {
    let ball = CsgSolid::new(Shape::sphere(DVec3::new(0.1, -0.2, 0.3), 1.0)).unwrap();
    let (bricks, band) = compare(&ball, 128, 1.0, Filter::Hypercone, "ball");
    assert!(
        band * 2 < bricks,
        "the band is a thin shell: {band} of {bricks}"
    );
    let drilled = Shape::cuboid(DVec3::splat(-1.0), DVec3::new(1.0, 0.7, 0.9))
        .minus(Shape::cylinder(DVec3::ZERO, Axis::Z, 0.45, 2.0));
    let block = CsgSolid::new(drilled).unwrap();
    compare(&block, 45, 1.0, Filter::Hypercone, "drilled block");
    compare(
        &block,
        30,
        2.5,
        Filter::GAUSSIAN,
        "drilled block, wide Gaussian",
    );
}

#[test]
fn meshes_match_the_dense_sampler() {
    let ring = MeshSolid::new(&torus(48, 24, 1.0, 0.35)).unwrap();
    compare(&ring, 50, 1.0, Filter::Hypercone, "torus");
    let block = MeshSolid::new(&holed_block()).unwrap();
    compare(&block, 40, 1.5, Filter::Hypercone, "holed block");
}

#[test]
fn scanned_bunny_matches_the_dense_sampler() {
    let Some(path) = shared_data_or_skip("meshes/stanford-bunny.obj", "narrow band bunny") else {
        return;
    };
    let solid = MeshSolid::new(&read_obj(&path)).unwrap();
    let (bricks, band) = compare(&solid, 96, 1.0, Filter::Hypercone, "bunny");
    assert!(band * 2 < bricks, "{band} of {bricks}");
    // The default chain's finest level of a scan.
    let (bricks, band) = compare(&solid, 256, 1.0, Filter::Hypercone, "bunny at 256");
    assert!(band * 4 < bricks, "{band} of {bricks}");
}

#[test]
fn thresholded_ct_head_matches_the_dense_sampler() {
    let Some(ct) = shared_ct_head("narrow band CT head") else {
        return;
    };
    // Bone (many handles, thin skull) and skin: the threshold route's solids at the scan's
    // full resolution.
    for threshold in [1500.0, 500.0] {
        let solid = ThresholdSolid::new(&ct, threshold).unwrap();
        let what = format!("CT head at {threshold}");
        let (bricks, band) = compare(&solid, 256, 1.0, Filter::Hypercone, &what);
        assert!(band < bricks, "{what}: {band} of {bricks}");
    }
}

#[test]
fn bad_brick_sizes_are_refused() {
    let ball = CsgSolid::new(Shape::sphere(DVec3::ZERO, 1.0)).unwrap();
    let grid = level_grid(&ball.bounds(), 16, 0.125).unwrap();
    let options = DensityOptions::new(Filter::Hypercone, 0.125);
    let err = narrow_band_density(&ball, &grid, &options, &NarrowBandOptions { brick_size: 5 })
        .unwrap_err()
        .to_string();
    assert!(err.contains("brick side 5"), "{err}");
}
