//! Sparse marching cubes against the dense extraction on the same samples: the same number of
//! vertices and triangles, the same vertex positions bit for bit, the same normals (bit for bit
//! where the gradient does not vanish; a vanished one is repaired from the triangles, summed in
//! another order), the same triangles with the same orientation, and a closed, consistently
//! oriented mesh.

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use voxlod_contouring::{marching_cubes, sparse_marching_cubes, ContourOptions};
use voxlod_core::{mesh_topology, BrickVolume, Grid, TriangleMesh, Volume};
use voxlod_testkit::fields::{gyroid_field, sphereflake_field};

type Key = [u32; 3];

fn key(p: glam::Vec3) -> Key {
    p.to_array().map(f32::to_bits)
}

/// Vertices (position, normal) sorted by position, and triangles as position triples rotated to start at
/// their smallest corner (keeping the winding), sorted.
fn canonical(mesh: &TriangleMesh) -> (Vec<(Key, glam::Vec3)>, Vec<[Key; 3]>) {
    let mut vertices: Vec<(Key, glam::Vec3)> = mesh
        .positions
        .iter()
        .enumerate()
        .map(|(n, &p)| (key(p), mesh.normals.get(n).copied().unwrap_or_default()))
        .collect();
    vertices.sort_unstable_by_key(|v| v.0);
    let mut triangles: Vec<[Key; 3]> = mesh
        .triangles
        .iter()
        .map(|t| {
            let c = t.map(|v| key(mesh.positions[v as usize]));
            let first = (0..3).min_by_key(|&r| c[r]).unwrap();
            [c[first], c[(first + 1) % 3], c[(first + 2) % 3]]
        })
        .collect();
    triangles.sort_unstable();
    (vertices, triangles)
}

fn assert_same_as_dense(volume: &Volume, iso: f32, what: &str) -> TriangleMesh {
    let dense = marching_cubes(volume, &ContourOptions::at(iso)).unwrap();
    assert!(!dense.triangles.is_empty(), "{what}: empty test surface");
    for brick in BrickVolume::BRICK_SIZES {
        let bricks = BrickVolume::from_volume(volume, brick).unwrap();
        let sparse = sparse_marching_cubes(&bricks, &ContourOptions::at(iso)).unwrap();
        assert_eq!(
            (sparse.positions.len(), sparse.triangles.len()),
            (dense.positions.len(), dense.triangles.len()),
            "{what}, bricks of {brick}: vertex and triangle counts"
        );
        let (dv, dt) = canonical(&dense);
        let (sv, st) = canonical(&sparse);
        for ((dp, dn), (sp, sn)) in dv.iter().zip(&sv) {
            assert_eq!(dp, sp, "{what}, bricks of {brick}: vertex positions differ");
            assert!(
                (*dn - *sn).length() < 1e-5,
                "{what}, bricks of {brick}: normals {dn} and {sn}"
            );
        }
        assert!(dt == st, "{what}, bricks of {brick}: triangles differ");
        let geometry = sparse_marching_cubes(&bricks, &ContourOptions::geometry_only(iso)).unwrap();
        assert!(geometry.normals.is_empty());
        assert_eq!(geometry.triangles.len(), dense.triangles.len());
    }
    let bricks = BrickVolume::from_volume(volume, 8).unwrap();
    sparse_marching_cubes(&bricks, &ContourOptions::at(iso)).unwrap()
}

fn assert_closed_oriented(mesh: &TriangleMesh, what: &str) {
    let t = mesh_topology(mesh);
    assert!(t.is_closed_manifold(), "{what}: {t:?}");
    assert!(t.is_consistently_oriented(), "{what}: {t:?}");
    assert_eq!(t.unreferenced_vertices, 0, "{what}");
    assert!(mesh.signed_volume() > 0.0, "{what}: inside out");
}

fn field(dims: [usize; 3], mut f: impl FnMut(f64, f64, f64) -> f32) -> Volume {
    let grid = Grid::new(dims, [1.0; 3], [0.0; 3]).unwrap();
    let mut values = Vec::with_capacity(grid.len());
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                values.push(f(i as f64, j as f64, k as f64));
            }
        }
    }
    Volume::from_vec(grid, values).unwrap()
}

#[test]
fn sphere_matches_dense_across_partial_bricks() {
    // 37 x 29 x 45 samples: no axis a multiple of 8 or 16; a sphere crossing many brick faces,
    // with uniform 0 and 1 bricks far from it as a narrow-band sampler makes them.
    let c = [18.3, 14.1, 22.7];
    let sphere = field([37, 29, 45], |x, y, z| {
        let d = ((x - c[0]).powi(2) + (y - c[1]).powi(2) + (z - c[2]).powi(2)).sqrt();
        (0.5 + (11.0 - d) / 4.0).clamp(0.0, 1.0) as f32
    });
    let mesh = assert_same_as_dense(&sphere, 0.5, "sphere");
    assert_closed_oriented(&mesh, "sphere");
    let bricks = BrickVolume::from_volume(&sphere, 8).unwrap();
    assert!(
        bricks.leaf_count() < bricks.brick_count() / 2,
        "most bricks are uniform"
    );
}

#[test]
fn gyroid_and_sphereflake_fields_match_dense() {
    let gyroid = gyroid_field(70).unwrap();
    assert_closed_oriented(&assert_same_as_dense(&gyroid, 0.0, "gyroid"), "gyroid");
    let flake = sphereflake_field(90).unwrap();
    assert_closed_oriented(&assert_same_as_dense(&flake, 0.0, "flake"), "sphereflake");
}

/// The peers' 512³ sphereflake field (about 2.4 M triangles), in bricks of 8 only: the same
/// vertices, normals and triangles as the dense path.
#[test]
fn sphereflake_field_at_512_matches_dense() {
    let flake = sphereflake_field(512).unwrap();
    let dense = marching_cubes(&flake, &ContourOptions::at(0.0)).unwrap();
    let bricks = BrickVolume::from_volume(&flake, 8).unwrap();
    drop(flake);
    let sparse = sparse_marching_cubes(&bricks, &ContourOptions::at(0.0)).unwrap();
    drop(bricks);
    assert!(
        dense.triangles.len() > 2_000_000,
        "{}",
        dense.triangles.len()
    );
    let (dv, dt) = canonical(&dense);
    let (sv, st) = canonical(&sparse);
    assert_eq!(dv.len(), sv.len(), "vertex counts");
    for ((dp, dn), (sp, sn)) in dv.iter().zip(&sv) {
        assert_eq!(dp, sp, "vertex positions differ");
        assert!((*dn - *sn).length() < 1e-5, "normals {dn} and {sn}");
    }
    assert!(dt == st, "triangles differ");
    assert_closed_oriented(&sparse, "sphereflake at 512");
}

#[test]
fn random_noise_with_every_case_matches_dense() {
    let mut rng = Pcg64Mcg::seed_from_u64(14);
    let noise = field([21, 18, 19], |_, _, _| rng_value(&mut rng));
    assert_same_as_dense(&noise, 0.5, "noise");
    // Samples exactly at the iso value, and NaN (outside in both paths).
    let mut rng = Pcg64Mcg::seed_from_u64(15);
    let ties = field([17, 17, 17], |_, _, _| match rng.random_range(0..4) {
        0 => 0.5,
        1 => f32::NAN,
        2 => 1.0,
        _ => 0.0,
    });
    assert_same_as_dense(&ties, 0.5, "ties and NaN");
}

fn rng_value(rng: &mut Pcg64Mcg) -> f32 {
    rng.random::<f32>()
}

#[test]
fn surface_touching_the_grid_border_matches_dense() {
    // Inside everywhere below a tilted plane: open at the grid's faces, as the dense one is.
    let slab = field([19, 23, 17], |x, y, z| {
        (10.0 - 0.3 * x - 0.2 * y - 0.4 * z) as f32
    });
    assert_same_as_dense(&slab, 0.0, "tilted plane");
}

#[test]
fn uniform_and_degenerate_volumes_give_no_surface_or_errors() {
    let grid = Grid::unit([40, 40, 40]).unwrap();
    let inside = BrickVolume::uniform(grid, 8, 1.0).unwrap();
    assert!(sparse_marching_cubes(&inside, &ContourOptions::at(0.5))
        .unwrap()
        .triangles
        .is_empty());
    assert!(sparse_marching_cubes(&inside, &ContourOptions::at(f32::NAN)).is_err());
    let flat = BrickVolume::uniform(Grid::unit([40, 1, 40]).unwrap(), 8, 1.0).unwrap();
    assert!(sparse_marching_cubes(&flat, &ContourOptions::at(0.5))
        .unwrap()
        .positions
        .is_empty());
}
