//! Area-uniform sampling: shares proportional to area, uniform inside a triangle, seeded.

mod common;

use std::collections::HashMap;

use glam::{DVec3, Vec3};
use voxlod_core::validate::MeshDefect;
use voxlod_core::{CoreError, TriangleMesh};
use voxlod_metrics::{
    closest_point_on_triangle, sample_surface, MetricsError, SampleLayout, SamplingOptions,
    SurfaceSampler,
};

/// Triangle 0 of area 1, a zero-area triangle, triangle 2 of area 3.
fn uneven_pair() -> TriangleMesh {
    let v = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
    TriangleMesh::new(
        vec![
            v(0., 0., 0.),
            v(2., 0., 0.),
            v(0., 1., 0.),
            v(5., 0., 1.),
            v(6., 0., 1.),
            v(7., 0., 1.),
            v(0., 0., 5.),
            v(3., 0., 5.),
            v(0., 2., 5.),
        ],
        vec![[0, 1, 2], [3, 4, 5], [6, 7, 8]],
    )
}

const LAYOUTS: [SampleLayout; 2] = [SampleLayout::Stratified, SampleLayout::Independent];

#[test]
fn triangles_get_samples_in_proportion_to_their_area() {
    let mesh = uneven_pair();
    let sampler = SurfaceSampler::new(&mesh).unwrap();
    assert!((sampler.total_area() - 4.0).abs() < 1e-12);
    let n = 200_000;
    for layout in LAYOUTS {
        let options = SamplingOptions {
            samples: n,
            seed: 7,
            layout,
        };
        let samples = sampler.samples(&options).unwrap();
        assert_eq!(samples.len(), n);
        let mut counts = [0usize; 3];
        for s in &samples {
            counts[s.triangle as usize] += 1;
        }
        assert_eq!(
            counts[1], 0,
            "{layout:?}: the zero-area triangle was sampled"
        );
        let share = counts[0] as f64 / n as f64;
        // Independent draws: binomial standard deviation sqrt(0.25·0.75/n) ≈ 0.001.
        assert!((share - 0.25).abs() < 0.005, "{layout:?}: share {share}");
        if layout == SampleLayout::Stratified {
            assert!(counts[0].abs_diff(n / 4) <= 1, "{layout:?}: {counts:?}");
        }
    }
}

#[test]
fn skewed_areas_keep_their_shares() {
    // One large triangle among 3000 tiny ones and 999 zero-area ones, the large one in the
    // middle: the guide table's buckets hold very different numbers of triangles.
    let mut mesh = TriangleMesh::default();
    let push = |mesh: &mut TriangleMesh, a: Vec3, b: Vec3, c: Vec3| {
        let base = mesh.positions.len() as u32;
        mesh.positions.extend([a, b, c]);
        mesh.triangles.push([base, base + 1, base + 2]);
    };
    for i in 0..4000 {
        let o = Vec3::new(i as f32, 0.0, 0.0);
        if i == 2000 {
            push(&mut mesh, o, o + Vec3::X * 40.0, o + Vec3::Y * 50.0); // area 1000
        } else if i % 4 == 0 {
            push(&mut mesh, o, o + Vec3::X, o + Vec3::X * 2.0); // area 0
        } else {
            push(&mut mesh, o, o + Vec3::X * 0.04, o + Vec3::Y * 0.05); // area 0.001
        }
    }
    let sampler = SurfaceSampler::new(&mesh).unwrap();
    let total = sampler.total_area();
    // (The tiny ones' f32 corners, thousands of units from the origin, round their areas.)
    assert!((total - (1000.0 + 3000.0 * 0.001)).abs() < 0.1, "{total}");
    let n = 300_000;
    for layout in LAYOUTS {
        let samples = sampler
            .samples(&SamplingOptions {
                samples: n,
                seed: 5,
                layout,
            })
            .unwrap();
        let on_large = samples.iter().filter(|s| s.triangle == 2000).count();
        assert!(samples
            .iter()
            .all(|s| s.triangle == 2000 || s.triangle % 4 != 0));
        let expected = n as f64 * 1000.0 / total;
        let sd = (n as f64 * (1000.0 / total) * (1.0 - 1000.0 / total)).sqrt();
        assert!(
            (on_large as f64 - expected).abs() < 5.0 * sd + 1.0,
            "{layout:?}: {on_large} on the large triangle, expected {expected:.1}"
        );
    }
}

/// The cell of barycentric coordinates (u, v, w) in the subdivision of the triangle into
/// `k²` congruent triangles.
fn cell(u: f64, v: f64, w: f64, k: f64) -> (i64, i64, i64) {
    let f = |x: f64| ((x * k).floor() as i64).clamp(0, k as i64 - 1);
    (f(u), f(v), f(w))
}

#[test]
fn points_are_uniform_inside_a_triangle_and_lie_on_it() {
    // An obtuse triangle, away from the origin.
    let (a, b, c) = (
        Vec3::new(1.0, 2.0, 3.0),
        Vec3::new(4.0, 2.5, 3.0),
        Vec3::new(0.5, 3.0, 4.0),
    );
    let mesh = TriangleMesh::new(vec![a, b, c], vec![[0, 1, 2]]);
    let corners = mesh.corners(0);
    let n = 160_000;
    let k = 4.0;
    for layout in LAYOUTS {
        let samples = sample_surface(
            &mesh,
            &SamplingOptions {
                samples: n,
                seed: 11,
                layout,
            },
        )
        .unwrap();
        let mut counts: HashMap<(i64, i64, i64), usize> = HashMap::new();
        let (e0, e1) = (corners[1] - corners[0], corners[2] - corners[0]);
        for s in &samples {
            let on = closest_point_on_triangle(s.point, corners);
            assert!((on - s.point).length() < 1e-12, "sample off the triangle");
            // Barycentric coordinates of the sample.
            let d = s.point - corners[0];
            let (d00, d01, d11) = (e0.dot(e0), e0.dot(e1), e1.dot(e1));
            let det = d00 * d11 - d01 * d01;
            let v = (d11 * d.dot(e0) - d01 * d.dot(e1)) / det;
            let w = (d00 * d.dot(e1) - d01 * d.dot(e0)) / det;
            *counts.entry(cell(1.0 - v - w, v, w, k)).or_default() += 1;
        }
        assert_eq!(counts.len(), 16, "{layout:?}: cells {:?}", counts.keys());
        let expected = n as f64 / 16.0;
        let chi_square: f64 = counts
            .values()
            .map(|&c| (c as f64 - expected).powi(2) / expected)
            .sum();
        // 15 degrees of freedom: P(χ² > 37.7) = 0.001.
        assert!(chi_square < 37.7, "{layout:?}: χ² = {chi_square}");
    }
}

#[test]
fn samples_depend_only_on_the_seed_and_the_index() {
    let sphere = common::icosphere(3);
    let sampler = SurfaceSampler::new(&sphere).unwrap();
    let options = SamplingOptions {
        samples: 5000,
        seed: 3,
        layout: SampleLayout::Stratified,
    };
    let all = sampler.samples(&options).unwrap();
    assert_eq!(all, sampler.samples(&options).unwrap());
    for i in [0, 1, 2500, 4999] {
        assert_eq!(all[i], sampler.sample(i, &options));
    }
    let single_thread = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(|| sampler.samples(&options).unwrap());
    assert_eq!(all, single_thread);
    let other = sampler
        .samples(&SamplingOptions { seed: 4, ..options })
        .unwrap();
    let same = all.iter().zip(&other).filter(|(x, y)| x == y).count();
    assert_eq!(same, 0);
    // Stratified samples come in triangle order.
    assert!(all.windows(2).all(|w| w[0].triangle <= w[1].triangle));
    // All on the unit sphere's inscribed surface.
    assert!(all
        .iter()
        .all(|s| s.point.length() <= 1.0 + 1e-6 && s.point.length() > 0.9));
    let mean = all.iter().map(|s| s.point).sum::<DVec3>() / all.len() as f64;
    assert!(mean.length() < 0.01, "centroid of sphere samples {mean}");
}

#[test]
fn refuses_a_mesh_without_area() {
    let flat = TriangleMesh::new(
        vec![Vec3::ZERO, Vec3::X, Vec3::X * 2.0],
        vec![[0, 1, 2], [0, 0, 1]],
    );
    let error = SurfaceSampler::new(&flat).err().unwrap();
    assert!(matches!(error, MetricsError::NoArea { triangles: 2 }));
    assert_eq!(
        error.to_string(),
        "the mesh has no area (2 triangles, all degenerate)"
    );
    assert!(matches!(
        sample_surface(&TriangleMesh::default(), &SamplingOptions::default()),
        Err(MetricsError::Core(CoreError::Mesh(MeshDefect::NoTriangles)))
    ));
}
