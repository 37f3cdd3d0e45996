//! The two-sided distance report against brute force: the same samples as `mesh_distance` draws,
//! measured against every triangle with a point–triangle distance written here independently
//! of the metrics crate (projection onto the plane, else the nearest of the three edges), then
//! pooled by hand. The metrics crate's own tests check single queries against brute force and
//! the sphere and cube analytic cases; these check the whole report (sampling seeds, the BVH's
//! pruning, Z-ordered blocks, chunked sums, pooling, the diagonal) to 1e-6 relative.

use voxlod::core::glam::{DVec3, Vec3};
use voxlod::core::TriangleMesh;
use voxlod::metrics::{
    mesh_distance, DistanceOptions, SampleLayout, SamplingOptions, SurfaceSampler,
};
use voxlod_testkit::shapes::{icosphere, torus, torus_with, unit_cube};

fn point_segment(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let ab = b - a;
    let len2 = ab.length_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + ab * t)).length()
}

/// Distance from `p` to the triangle `abc`: to its plane when the foot of the perpendicular lies
/// inside (same side of all three edges), else to the nearest edge.
fn point_triangle(p: DVec3, [a, b, c]: [DVec3; 3]) -> f64 {
    let n = (b - a).cross(c - a);
    let n2 = n.length_squared();
    if n2 > 0.0 {
        let foot = p - n * ((p - a).dot(n) / n2);
        let inside = [(a, b), (b, c), (c, a)]
            .iter()
            .all(|&(u, v)| (v - u).cross(foot - u).dot(n) >= 0.0);
        if inside {
            return (p - foot).length();
        }
    }
    point_segment(p, a, b)
        .min(point_segment(p, b, c))
        .min(point_segment(p, c, a))
}

fn brute_distance(mesh: &TriangleMesh, p: DVec3) -> f64 {
    (0..mesh.triangles.len())
        .map(|t| point_triangle(p, mesh.corners(t)))
        .fold(f64::INFINITY, f64::min)
}

/// (max, sum, sum of squares, count) of the distances from `from`'s samples to `to`.
fn brute_side(
    from: &TriangleMesh,
    to: &TriangleMesh,
    sampling: &SamplingOptions,
) -> (f64, f64, f64, usize) {
    let sampler = SurfaceSampler::new(from).unwrap();
    let mut acc = (0.0f64, 0.0, 0.0, 0);
    for i in 0..sampling.samples {
        let d = brute_distance(to, sampler.sample(i, sampling).point);
        acc.0 = acc.0.max(d);
        acc.1 += d;
        acc.2 += d * d;
        acc.3 += 1;
    }
    acc
}

fn assert_relative(got: f64, want: f64, what: &str) {
    let tolerance = 1e-6 * want.abs().max(1e-300);
    assert!(
        (got - want).abs() <= tolerance,
        "{what}: report {got:e}, brute force {want:e}"
    );
}

/// Checks `mesh_distance(a, b)` against brute force with the samples it draws.
fn check_pair(a: &TriangleMesh, b: &TriangleMesh, options: &DistanceOptions) {
    let report = mesh_distance(a, b, options).unwrap();
    // The report's sides draw with the options' seed and the next one.
    let side = |k: u64| SamplingOptions {
        samples: options.samples_per_side,
        seed: options.seed.wrapping_add(k),
        layout: options.layout,
    };
    let ab = brute_side(a, b, &side(0));
    let ba = brute_side(b, a, &side(1));
    let n = (ab.3 + ba.3) as f64;
    assert_relative(report.first_to_second.max, ab.0, "first to second max");
    assert_relative(report.second_to_first.max, ba.0, "second to first max");
    assert_relative(
        report.first_to_second.mean,
        ab.1 / ab.3 as f64,
        "first to second mean",
    );
    assert_relative(
        report.second_to_first.rms,
        (ba.2 / ba.3 as f64).sqrt(),
        "second to first rms",
    );
    assert_relative(report.hausdorff, ab.0.max(ba.0), "hausdorff");
    assert_relative(report.mean, (ab.1 + ba.1) / n, "mean");
    assert_relative(report.rms, ((ab.2 + ba.2) / n).sqrt(), "rms");
    // The unit of the fractions: the diagonal of the box of both meshes' vertices.
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for m in [a, b] {
        for t in 0..m.triangles.len() {
            for p in m.corners(t) {
                lo = lo.min(p);
                hi = hi.max(p);
            }
        }
    }
    let diagonal = (hi - lo).length();
    assert_relative(report.diagonal, diagonal, "diagonal");
    assert_relative(
        report.hausdorff_fraction,
        ab.0.max(ba.0) / diagonal,
        "hausdorff fraction",
    );
    assert_relative(
        report.mean_fraction,
        (ab.1 + ba.1) / n / diagonal,
        "mean fraction",
    );
    assert_relative(
        report.rms_fraction,
        ((ab.2 + ba.2) / n).sqrt() / diagonal,
        "rms fraction",
    );
    assert_eq!(report.samples, options.samples_per_side);
}

fn moved(mut mesh: TriangleMesh, by: Vec3, scale: f32) -> TriangleMesh {
    for p in &mut mesh.positions {
        *p = *p * scale + by;
    }
    mesh
}

#[test]
fn report_matches_brute_force_on_small_pairs() {
    // Near and overlapping, nested, disjoint, and of very different triangle counts.
    let bumpy = torus_with(24, 12, 2.0, |u, v| {
        0.7 + 0.1 * (3.0 * u).sin() * (2.0 * v).cos()
    });
    let pairs = [
        (torus(20, 10, 2.0, 0.7), bumpy),
        (
            icosphere(2),
            moved(icosphere(1), Vec3::new(0.1, -0.05, 0.02), 0.9),
        ),
        (
            unit_cube(),
            moved(unit_cube(), Vec3::new(3.0, 0.5, -1.0), 0.5),
        ),
        (icosphere(3), unit_cube()),
    ];
    for (a, b) in &pairs {
        for layout in [SampleLayout::Stratified, SampleLayout::Independent] {
            let options = DistanceOptions {
                layout,
                ..DistanceOptions::for_samples(3_000)
            };
            check_pair(a, b, &options);
        }
    }
}

#[test]
fn report_matches_brute_force_across_sample_blocks() {
    // More samples than one block of the metrics crate holds (2^20) would take minutes by brute
    // force; a seed change and an odd count check the bookkeeping instead.
    let a = icosphere(1);
    let b = moved(torus(12, 6, 0.6, 0.25), Vec3::new(0.0, 0.0, 0.3), 1.0);
    let options = DistanceOptions {
        seed: 12345,
        ..DistanceOptions::for_samples(20_001)
    };
    check_pair(&a, &b, &options);
}

#[test]
fn independent_point_triangle_distance_agrees_with_hand_cases() {
    // The brute force's own check: a triangle in z = 0 and points over each region.
    let tri = [DVec3::ZERO, DVec3::X, DVec3::Y];
    let cases = [
        (DVec3::new(0.25, 0.25, 2.0), 2.0),         // above the face
        (DVec3::new(0.25, 0.25, -3.0), 3.0),        // below it
        (DVec3::new(-1.0, -1.0, 0.0), 2f64.sqrt()), // beyond vertex a
        (DVec3::new(0.5, -2.0, 0.0), 2.0),          // beyond edge ab
        (DVec3::new(1.0, 1.0, 0.0), 0.5f64.sqrt()), // beyond edge bc
        (DVec3::new(3.0, 0.0, 4.0), 20f64.sqrt()),  // beyond vertex b, off the plane
    ];
    for (p, want) in cases {
        assert!((point_triangle(p, tri) - want).abs() < 1e-12, "{p}");
    }
    // A degenerate triangle is its longest segment.
    let flat = [DVec3::ZERO, DVec3::X, DVec3::X * 2.0];
    assert!((point_triangle(DVec3::new(1.0, 1.0, 0.0), flat) - 1.0).abs() < 1e-12);
}
