//! The exact point–triangle distance and the BVH closest-point search, against constructions
//! whose answer is known and against brute force over every triangle.

mod common;

use glam::{DVec3, Vec3};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use rayon::prelude::*;
use voxlod_core::validate::MeshDefect;
use voxlod_core::{CoreError, TriangleMesh};
use voxlod_metrics::{closest_point_on_triangle, MeshDistance, MetricsError, QueryHint};
use voxlod_testkit::data::shared_data_or_skip;

fn random_unit(rng: &mut Pcg64Mcg) -> DVec3 {
    loop {
        let v = DVec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        if v.length_squared() > 1e-4 && v.length_squared() <= 1.0 {
            return v.normalize();
        }
    }
}

/// An independent reference: the foot of the perpendicular on the plane when it lies inside
/// the triangle (barycentric coordinates from a 2×2 solve), else the nearest of the three
/// clamped edge projections.
fn reference_distance(p: DVec3, [a, b, c]: [DVec3; 3]) -> f64 {
    let (e0, e1) = (b - a, c - a);
    let n = e0.cross(e1);
    if n.length_squared() > 0.0 {
        let foot = p - n * ((p - a).dot(n) / n.length_squared());
        let (d00, d01, d11) = (e0.dot(e0), e0.dot(e1), e1.dot(e1));
        let (d20, d21) = ((foot - a).dot(e0), (foot - a).dot(e1));
        let det = d00 * d11 - d01 * d01;
        let v = (d11 * d20 - d01 * d21) / det;
        let w = (d00 * d21 - d01 * d20) / det;
        if v >= 0.0 && w >= 0.0 && v + w <= 1.0 {
            return (p - foot).length();
        }
    }
    [(a, b), (b, c), (c, a)]
        .iter()
        .map(|&(s, e)| {
            let d = e - s;
            let t = if d.length_squared() > 0.0 {
                ((p - s).dot(d) / d.length_squared()).clamp(0.0, 1.0)
            } else {
                0.0
            };
            (p - (s + d * t)).length()
        })
        .fold(f64::INFINITY, f64::min)
}

fn assert_relative(got: f64, want: f64, tolerance: f64, what: &str) {
    assert!(
        (got - want).abs() <= tolerance * want.abs().max(1e-300),
        "{what}: got {got:e}, want {want:e} (relative error {:e})",
        (got - want).abs() / want.abs()
    );
}

#[test]
fn point_triangle_distance_in_every_voronoi_region_on_both_sides() {
    let mut rng = Pcg64Mcg::seed_from_u64(1);
    let mut cases = [0usize; 3];
    for _ in 0..2000 {
        // Triangles of every shape (acute, obtuse, thin), at scales from 1e-3 to 1e3, away from
        // the origin.
        let scale = 10f64.powf(rng.random_range(-3.0..3.0));
        let offset = random_unit(&mut rng) * scale * rng.random_range(0.0..10.0);
        let corners = [(); 3].map(|_| offset + random_unit(&mut rng) * scale);
        let [a, b, c] = corners;
        let normal = (b - a).cross(c - a);
        if normal.length() < 1e-3 * scale * scale {
            continue;
        }
        let n = normal.normalize();
        // Outward in-plane normal of edge (s, e), pointing away from the opposite corner o.
        let outward = |s: DVec3, e: DVec3, o: DVec3| {
            let m = (e - s).cross(n).normalize();
            if m.dot(o - s) > 0.0 {
                -m
            } else {
                m
            }
        };
        let m_ab = outward(a, b, c);
        let m_bc = outward(b, c, a);
        let m_ca = outward(c, a, b);
        let magnitude = |rng: &mut Pcg64Mcg| scale * rng.random_range(0.01..2.0);
        let mut points: Vec<(DVec3, DVec3, usize)> = Vec::new(); // (query, expected nearest, region kind)
        for side in [-1.0, 1.0] {
            let height = side * magnitude(&mut rng);
            // Vertex regions: the cone of the two adjacent edges' outward normals, plus height.
            for (v, m1, m2) in [(a, m_ab, m_ca), (b, m_ab, m_bc), (c, m_bc, m_ca)] {
                let (s, t) = (rng.random_range(0.0..1.0), rng.random_range(0.0..1.0));
                let dir = (m1 * s + m2 * t).normalize();
                points.push((v + dir * magnitude(&mut rng) + n * height, v, 0));
            }
            // Edge regions: a point of the edge, pushed outward and off the plane.
            for (s, e, m) in [(a, b, m_ab), (b, c, m_bc), (c, a, m_ca)] {
                let q = s + (e - s) * rng.random_range(0.01..0.99);
                points.push((q + m * magnitude(&mut rng) + n * height, q, 1));
            }
            // Face region: an interior point, off the plane.
            let (u, v) = (rng.random_range(0.0..1.0), rng.random_range(0.0..1.0));
            let (u, v) = if u + v > 1.0 {
                (1.0 - u, 1.0 - v)
            } else {
                (u, v)
            };
            let q = a + (b - a) * u + (c - a) * v;
            points.push((q + n * height, q, 2));
        }
        for (p, expected, kind) in points {
            cases[kind] += 1;
            let want = (p - expected).length();
            let got = closest_point_on_triangle(p, corners);
            assert_relative((p - got).length(), want, 1e-6, "distance");
            assert!(
                (got - expected).length() <= 1e-6 * scale,
                "nearest point {got} instead of {expected} (region kind {kind})"
            );
            assert_relative(reference_distance(p, corners), want, 1e-6, "reference");
        }
    }
    assert!(cases.iter().all(|&c| c >= 3000), "{cases:?}");
}

#[test]
fn degenerate_triangles_are_measured_as_segments_and_points() {
    let a = DVec3::new(0.0, 0.0, 0.0);
    let b = DVec3::new(2.0, 0.0, 0.0);
    let p = DVec3::new(1.0, 3.0, 4.0);
    // Collinear corners, a repeated corner, and a single point.
    for tri in [
        [a, b, DVec3::new(1.0, 0.0, 0.0)],
        [a, b, b],
        [a, a, b],
        [b, a, a],
    ] {
        let q = closest_point_on_triangle(p, tri);
        assert!(
            (q - DVec3::new(1.0, 0.0, 0.0)).length() < 1e-12,
            "{tri:?} gave {q}"
        );
    }
    let q = closest_point_on_triangle(p, [b, b, b]);
    assert_eq!(q, b);
}

/// A random soup of `count` triangles in the unit cube, some of them degenerate.
fn random_mesh(rng: &mut Pcg64Mcg, count: usize) -> TriangleMesh {
    let mut mesh = TriangleMesh::default();
    for t in 0..count {
        let base = mesh.positions.len() as u32;
        let centre = Vec3::new(rng.random(), rng.random(), rng.random());
        let size = 0.3 * rng.random::<f32>();
        for _ in 0..3 {
            let offset = Vec3::new(rng.random(), rng.random(), rng.random()) - 0.5;
            mesh.positions.push(centre + offset * size);
        }
        match t % 17 {
            0 => mesh.triangles.push([base, base, base + 1]),
            1 => {
                mesh.positions[base as usize + 2] =
                    (mesh.positions[base as usize] + mesh.positions[base as usize + 1]) * 0.5;
                mesh.triangles.push([base, base + 1, base + 2]);
            }
            _ => mesh.triangles.push([base, base + 1, base + 2]),
        }
    }
    mesh
}

fn brute_force(mesh: &TriangleMesh, p: DVec3) -> f64 {
    (0..mesh.triangles.len())
        .map(|t| (p - closest_point_on_triangle(p, mesh.corners(t))).length())
        .fold(f64::INFINITY, f64::min)
}

/// Checks every query of `queries` against brute force: the distance, the reported point
/// being on the reported triangle, and the bounded and hinted variants.
fn check_against_brute_force(mesh: &TriangleMesh, queries: &[DVec3]) {
    let index = MeshDistance::new(mesh).unwrap();
    assert_eq!(index.triangle_count(), mesh.triangles.len());
    let wanted: Vec<f64> = queries.par_iter().map(|&p| brute_force(mesh, p)).collect();
    let batch = index.distances(queries);
    let mut hint = QueryHint::default();
    for ((&p, &want), &from_batch) in queries.iter().zip(&wanted).zip(&batch) {
        let got = index.closest(p);
        let scale = mesh.bounds().diagonal();
        let tolerance = |w: f64| 1e-6 * w + 1e-12 * scale;
        assert!(
            (got.distance - want).abs() <= tolerance(want),
            "query {p}: BVH {} vs brute force {want}",
            got.distance
        );
        let on_triangle =
            (got.point - closest_point_on_triangle(got.point, mesh.corners(got.triangle))).length();
        assert!(
            on_triangle <= 1e-9 * scale,
            "point off its triangle by {on_triangle}"
        );
        assert!(((p - got.point).length() - got.distance).abs() <= 1e-12 * scale);
        assert!((from_batch - want).abs() <= tolerance(want));
        let hinted = index.closest_with_hint(p, &mut hint);
        assert!((hinted.distance - want).abs() <= tolerance(want));
        // Bounded queries: found when the bound reaches the distance, refused below it.
        let within = index.distance_within(p, want * 1.001 + 1e-9 * scale);
        assert!(within.is_some_and(|d| (d - want).abs() <= tolerance(want)));
        if want > 1e-6 * scale {
            assert_eq!(index.distance_within(p, want * 0.999), None);
        }
        // A vertex is at distance exactly 0, which a bound of 0 accepts.
        let vertex = mesh.corners(got.triangle)[0];
        assert_eq!(index.distance_within(vertex, 0.0), Some(0.0));
    }
}

#[test]
fn bvh_matches_brute_force_on_random_meshes() {
    let mut rng = Pcg64Mcg::seed_from_u64(2);
    for count in [1, 2, 7, 60, 500, 3000] {
        let mesh = random_mesh(&mut rng, count);
        let mut queries: Vec<DVec3> = (0..1000)
            .map(|_| DVec3::new(rng.random(), rng.random(), rng.random()) * 3.0 - 1.0)
            .collect();
        // Queries on and just off the triangles too, where many boxes overlap the answer.
        for _ in 0..500 {
            let t = rng.random_range(0..count);
            let [a, b, c] = mesh.corners(t);
            let (u, v) = (rng.random::<f64>(), rng.random::<f64>());
            let (u, v) = if u + v > 1.0 {
                (1.0 - u, 1.0 - v)
            } else {
                (u, v)
            };
            let off = random_unit(&mut rng) * 1e-3 * rng.random::<f64>();
            queries.push(a + (b - a) * u + (c - a) * v + off);
        }
        check_against_brute_force(&mesh, &queries);
    }
}

/// Far from the origin the `f32` boxes and queries round by a sizeable part of the mesh: the
/// search widens its bound by the query's rounding and still finds the nearest triangle, on
/// a soup a unit across at 10³ and 10⁶ (where `f32` has 1/16 of a unit).
#[test]
fn bvh_matches_brute_force_far_from_the_origin() {
    let mut rng = Pcg64Mcg::seed_from_u64(3);
    for offset in [1e3f32, -1e6, 1e6] {
        let mut mesh = random_mesh(&mut rng, 400);
        mesh.positions.iter_mut().for_each(|p| *p += offset);
        let base = DVec3::splat(offset as f64);
        let mut queries: Vec<DVec3> = (0..600)
            .map(|_| base + DVec3::new(rng.random(), rng.random(), rng.random()) * 2.0 - 0.5)
            .collect();
        for _ in 0..300 {
            let [a, b, c] = mesh.corners(rng.random_range(0..400));
            queries.push((a + b + c) / 3.0 + random_unit(&mut rng) * 0.01);
        }
        check_against_brute_force(&mesh, &queries);
    }
}

#[test]
fn bvh_matches_brute_force_on_the_fandisk() {
    let Some(path) = shared_data_or_skip(
        "meshes/fandisk.obj",
        "bvh_matches_brute_force_on_the_fandisk",
    ) else {
        return;
    };
    let mesh = common::read_obj(&path);
    assert_eq!(mesh.triangles.len(), 12_946);
    let bounds = mesh.bounds();
    let mut rng = Pcg64Mcg::seed_from_u64(3);
    let mut queries: Vec<DVec3> = (0..2000)
        .map(|_| {
            let u = DVec3::new(rng.random(), rng.random(), rng.random());
            bounds.min - bounds.size() * 0.25 + bounds.size() * 1.5 * u
        })
        .collect();
    let diagonal = bounds.diagonal();
    for _ in 0..2000 {
        let [a, b, c] = mesh.corners(rng.random_range(0..mesh.triangles.len()));
        let w = DVec3::new(rng.random(), rng.random(), rng.random());
        let p = (a * w.x + b * w.y + c * w.z) / w.element_sum();
        queries.push(p + random_unit(&mut rng) * diagonal * 0.01 * rng.random::<f64>());
    }
    check_against_brute_force(&mesh, &queries);
}

#[test]
fn refuses_meshes_it_cannot_measure() {
    let message = |mesh: &TriangleMesh| MeshDistance::new(mesh).err().unwrap().to_string();
    assert_eq!(
        message(&TriangleMesh::default()),
        "the mesh has no triangles"
    );
    let mut cube = common::unit_cube();
    cube.positions[5].z = f32::INFINITY;
    assert!(message(&cube).starts_with("vertex 5 has a non-finite coordinate"));
    let mut cube = common::unit_cube();
    cube.triangles[3][2] = 42;
    assert_eq!(
        message(&cube),
        "triangle 3 refers to vertex 42 but there are only 8 vertices"
    );
    assert!(matches!(
        MeshDistance::new(&TriangleMesh::default()),
        Err(MetricsError::Core(CoreError::Mesh(MeshDefect::NoTriangles)))
    ));
}

#[test]
fn the_centre_of_a_sphere_is_equidistant_from_everything() {
    // The worst case for pruning: every triangle is nearly as close as the best.
    let sphere = common::icosphere(4);
    let index = MeshDistance::new(&sphere).unwrap();
    let want = brute_force(&sphere, DVec3::ZERO);
    assert_relative(index.distance(DVec3::ZERO), want, 1e-12, "centre");
}
