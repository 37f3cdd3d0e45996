//! Properties of the marching cubes output that can fail: exact counts on hand-checked volumes,
//! closed oriented manifolds on random volumes, analytic volume and area of a sphere.

use glam::{DVec3, Vec3};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use voxlod_contouring::{marching_cubes, ContourOptions};
use voxlod_core::{mesh_topology, Grid, TriangleMesh, Volume};

fn volume_from(dims: [usize; 3], f: impl Fn(usize, usize, usize) -> f32) -> Volume {
    let mut data = Vec::with_capacity(dims[0] * dims[1] * dims[2]);
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                data.push(f(i, j, k));
            }
        }
    }
    Volume::from_vec(Grid::unit(dims).unwrap(), data).unwrap()
}

fn assert_closed_oriented(mesh: &TriangleMesh, what: &str) {
    let t = mesh_topology(mesh);
    assert!(
        t.is_closed_manifold(),
        "{what}: not a closed manifold: {t:?}"
    );
    assert!(
        t.is_consistently_oriented(),
        "{what}: inconsistent orientation: {t:?}"
    );
    assert_eq!(t.unreferenced_vertices, 0, "{what}: unreferenced vertices");
    assert!(t.genus.is_some(), "{what}: {t:?}");
    assert!(mesh.signed_volume() > 0.0, "{what}: inside out");
}

#[test]
fn one_inside_sample_gives_an_octahedron() {
    let v = volume_from(
        [3, 3, 3],
        |i, j, k| if (i, j, k) == (1, 1, 1) { 1.0 } else { 0.0 },
    );
    let mesh = marching_cubes(&v, &ContourOptions::at(0.5)).unwrap();
    assert_eq!(mesh.positions.len(), 6);
    assert_eq!(mesh.triangles.len(), 8);
    assert_closed_oriented(&mesh, "octahedron");
    // Vertices halfway along the six edges from the centre.
    for p in &mesh.positions {
        assert!(((*p - Vec3::ONE).length() - 0.5).abs() < 1e-6, "{p}");
    }
    // Normals point away from the centre.
    for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
        assert!(n.dot(*p - Vec3::ONE) > 0.99 * 0.5, "normal {n} at {p}");
    }
    let t = mesh_topology(&mesh);
    assert_eq!((t.edges, t.euler_characteristic, t.genus), (12, 2, Some(0)));
}

#[test]
fn every_cell_case_is_closed_when_embedded() {
    // The 8 samples of the inner cell of a 4x4x4 grid take every pattern; the rest is outside.
    for case in 0..256u32 {
        let v = volume_from([4, 4, 4], |i, j, k| {
            let inner = (1..=2).contains(&i) && (1..=2).contains(&j) && (1..=2).contains(&k);
            if inner && (case >> ((i - 1) | ((j - 1) << 1) | ((k - 1) << 2))) & 1 == 1 {
                1.0
            } else {
                0.0
            }
        });
        let mesh = marching_cubes(&v, &ContourOptions::at(0.5)).unwrap();
        if case == 0 {
            assert!(mesh.triangles.is_empty());
            continue;
        }
        assert_closed_oriented(&mesh, &format!("case {case}"));
        // Each inside sample connected to the others by cube edges forms one component.
        let t = mesh_topology(&mesh);
        let inside: Vec<u32> = (0..8).filter(|c| (case >> c) & 1 == 1).collect();
        let mut parent: Vec<u32> = (0..8).collect();
        fn find(p: &mut [u32], x: u32) -> u32 {
            if p[x as usize] == x {
                x
            } else {
                let r = find(p, p[x as usize]);
                p[x as usize] = r;
                r
            }
        }
        for &a in &inside {
            for &b in &inside {
                if (a ^ b).count_ones() == 1 {
                    let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
                    parent[ra as usize] = rb;
                }
            }
        }
        let mut roots: Vec<u32> = inside.iter().map(|&c| find(&mut parent, c)).collect();
        roots.sort_unstable();
        roots.dedup();
        assert_eq!(t.components, roots.len(), "case {case}");
        assert_eq!(t.genus, Some(0), "case {case}");
    }
}

#[test]
fn random_volumes_give_closed_oriented_manifolds() {
    let mut rng = Pcg64Mcg::seed_from_u64(7);
    for trial in 0..60 {
        let n = [
            rng.random_range(3..24),
            rng.random_range(3..24),
            rng.random_range(3..24),
        ];
        let smooth = trial % 3 == 0;
        let noise: Vec<f32> = (0..n[0] * n[1] * n[2])
            .map(|_| rng.random::<f32>())
            .collect();
        let v = volume_from(n, |i, j, k| {
            if i == 0 || j == 0 || k == 0 || i + 1 == n[0] || j + 1 == n[1] || k + 1 == n[2] {
                0.0
            } else if smooth {
                // A blobby sum of waves plus noise: large connected surfaces with handles.
                let (x, y, z) = (i as f32 * 0.7, j as f32 * 0.9, k as f32 * 1.1);
                0.5 + 0.3 * (x.sin() + y.cos() * z.sin()) + 0.2 * noise[i + n[0] * (j + n[1] * k)]
            } else {
                noise[i + n[0] * (j + n[1] * k)]
            }
        });
        // Iso values that hit samples exactly are included: 0.5 against quantised noise.
        let iso = [0.5f32, 0.3, 0.7][trial % 3];
        let mesh = marching_cubes(&v, &ContourOptions::at(iso)).unwrap();
        if mesh.triangles.is_empty() {
            continue;
        }
        assert_closed_oriented(&mesh, &format!("trial {trial} dims {n:?}"));
        let t = mesh_topology(&mesh);
        assert_eq!(t.degenerate_triangles + t.duplicate_triangles, 0);
    }
}

#[test]
fn samples_equal_to_iso_are_inside_and_nothing_collapses() {
    // Integer-valued data with an integer iso: skimage's hole-producing case.
    let v = volume_from([9, 9, 9], |i, j, k| {
        let d = (i as i32 - 4)
            .abs()
            .max((j as i32 - 4).abs())
            .max((k as i32 - 4).abs());
        (4 - d).max(0) as f32
    });
    for iso in [1.0f32, 2.0, 3.0] {
        let mesh = marching_cubes(&v, &ContourOptions::at(iso)).unwrap();
        assert_closed_oriented(&mesh, &format!("iso {iso}"));
        for t in 0..mesh.triangles.len() {
            let [a, b, c] = mesh.corners(t);
            assert!(
                (b - a).cross(c - a).length() > 1e-12,
                "zero-area triangle at iso {iso}"
            );
        }
        // The inside samples form a cube of side 2(4 - iso) + 1 samples; the surface encloses it.
        let side = 2.0 * (4.0 - iso as f64);
        assert!(
            mesh.signed_volume() >= side.powi(3),
            "iso {iso}: {}",
            mesh.signed_volume()
        );
    }
}

#[test]
fn sphere_volume_area_and_normals_match_analytic_values() {
    let n = 64;
    let r = 20.0f64;
    let c = DVec3::splat(31.5);
    let spacing = [0.5, 0.5, 0.5];
    let origin = [-3.0, 2.0, 10.0];
    let mut data = Vec::new();
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let p = DVec3::new(i as f64, j as f64, k as f64);
                data.push((r - (p - c).length()) as f32);
            }
        }
    }
    let grid = Grid::new([n, n, n], spacing, origin).unwrap();
    let v = Volume::from_vec(grid, data).unwrap();
    let mesh = marching_cubes(&v, &ContourOptions::at(0.0)).unwrap();
    assert_closed_oriented(&mesh, "sphere");
    // World radius 10 (20 samples of 0.5).
    let world_r = 10.0f64;
    let world_c = DVec3::from(origin) + c * 0.5;
    let volume = mesh.signed_volume();
    let exact_volume = 4.0 / 3.0 * std::f64::consts::PI * world_r.powi(3);
    assert!(
        (volume / exact_volume - 1.0).abs() < 0.005,
        "volume {volume} vs {exact_volume}"
    );
    let area = mesh.area();
    let exact_area = 4.0 * std::f64::consts::PI * world_r * world_r;
    assert!(
        (area / exact_area - 1.0).abs() < 0.01,
        "area {area} vs {exact_area}"
    );
    for (p, nrm) in mesh.positions.iter().zip(&mesh.normals) {
        let radial = (p.as_dvec3() - world_c).normalize();
        assert!((p.as_dvec3() - world_c).length() - world_r < 0.05);
        assert!(nrm.as_dvec3().dot(radial) > 0.999, "normal {nrm} at {p}");
    }
    assert_eq!(mesh_topology(&mesh).genus, Some(0));
}

#[test]
fn output_does_not_depend_on_the_thread_count() {
    let mut rng = Pcg64Mcg::seed_from_u64(3);
    let noise: Vec<f32> = (0..40 * 30 * 20).map(|_| rng.random::<f32>()).collect();
    let v = Volume::from_vec(Grid::unit([40, 30, 20]).unwrap(), noise).unwrap();
    let run = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| marching_cubes(&v, &ContourOptions::at(0.5)).unwrap())
    };
    assert_eq!(run(1), run(2));
}

#[test]
fn geometry_only_skips_normals_and_bad_iso_is_refused() {
    let v = volume_from(
        [3, 3, 3],
        |i, j, k| if (i, j, k) == (1, 1, 1) { 1.0 } else { 0.0 },
    );
    let mesh = marching_cubes(&v, &ContourOptions::geometry_only(0.5)).unwrap();
    assert!(mesh.normals.is_empty());
    assert_eq!(mesh.triangles.len(), 8);
    assert!(marching_cubes(&v, &ContourOptions::at(f32::NAN)).is_err());
    // A grid without cells gives an empty mesh, not an error.
    let flat = volume_from([5, 5, 1], |_, _, _| 1.0);
    assert!(marching_cubes(&flat, &ContourOptions::default())
        .unwrap()
        .is_empty());
}

#[test]
fn nan_samples_are_outside_and_never_reach_a_vertex() {
    // A 3x3x3 block of ones in a 70-sample-wide grid (wider than one 64-sample word), with a
    // NaN at its centre: the NaN is outside, so the block becomes a shell around a cavity.
    let v = volume_from([70, 7, 7], |i, j, k| {
        if (i, j, k) == (33, 3, 3) {
            f32::NAN
        } else if (32..=34).contains(&i) && (2..=4).contains(&j) && (2..=4).contains(&k) {
            1.0
        } else {
            0.0
        }
    });
    let mesh = marching_cubes(&v, &ContourOptions::at(0.5)).unwrap();
    assert!(mesh.positions.iter().all(|p| p.is_finite()));
    let t = mesh_topology(&mesh);
    assert!(t.is_closed_manifold(), "{t:?}");
    assert_eq!(
        t.components, 2,
        "outer surface and the cavity around the NaN"
    );
}
