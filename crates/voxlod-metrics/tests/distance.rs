//! Two-sided surface distances against cases whose answer is known exactly.

mod common;

use glam::{DVec3, Vec3};
use voxlod_core::TriangleMesh;
use voxlod_metrics::{
    closest_point_on_triangle, mesh_distance, DistanceOptions, DistanceReport, MeshDistance,
    MetricsError, SampleLayout,
};

/// Smallest distance from the centre to a face of `mesh` (each face's nearest point to the
/// origin, exactly).
fn nearest_face_distance(mesh: &TriangleMesh) -> f64 {
    (0..mesh.triangles.len())
        .map(|t| closest_point_on_triangle(DVec3::ZERO, mesh.corners(t)).length())
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn sphere_against_inscribed_icosphere_gives_the_analytic_hausdorff_distance() {
    // The unit sphere, as a level-6 icosphere: 81 920 triangles, within `fine_gap` of it.
    let sphere = common::icosphere(6);
    let fine_gap = 1.0 - nearest_face_distance(&sphere);
    assert!(fine_gap < 1e-4, "fine sphere gap {fine_gap}");
    for level in 0..=2 {
        let coarse = common::icosphere(level);
        // The coarse icosphere is convex and inscribed: every point of the sphere is nearest to
        // the face it projects through, at most 1 - (that face's distance from the centre),
        // and every point of the icosphere is at 1 - |x| from the sphere. Both maxima are
        // reached at the foot of the perpendicular from the centre on the flattest face, so
        // H = 1 - min over faces of the distance from the centre.
        let (flattest, foot) = (0..coarse.triangles.len())
            .map(|t| (t, closest_point_on_triangle(DVec3::ZERO, coarse.corners(t))))
            .min_by(|x, y| x.1.length().total_cmp(&y.1.length()))
            .unwrap();
        let analytic = 1.0 - foot.length();
        // The foot is inside the face (not on an edge), as the argument needs.
        let [a, b, c] = coarse.corners(flattest);
        let n = (b - a).cross(c - a).normalize();
        assert!((foot - n * n.dot(a)).length() < 1e-12);

        // The exact query from the sphere point above the foot finds the same number.
        let index = MeshDistance::new(&coarse).unwrap();
        let above = foot.normalize();
        let exact = index.closest(above);
        assert!((exact.distance - analytic).abs() < 1e-9 * analytic);

        let report =
            mesh_distance(&sphere, &coarse, &DistanceOptions::for_samples(200_000)).unwrap();
        let error = report.hausdorff - analytic;
        eprintln!(
            "level {level}: analytic {analytic:.6e}, sampled {:.6e} ({:+.2e} relative)",
            report.hausdorff,
            error / analytic
        );
        // Sampling can only miss the worst point (from below); the fine sphere's own distance
        // from the true sphere and f32 vertices move it by at most `fine_gap` + 1e-6.
        assert!(report.hausdorff <= analytic + fine_gap + 1e-6);
        assert!(error >= -(fine_gap + 1e-6) - 2e-3 * analytic, "{report}");
        assert_eq!(report.samples, 200_000);
        assert!((report.hausdorff_fraction - report.hausdorff / report.diagonal).abs() < 1e-15);
        // Both meshes lie in [-1, 1]³: the diagonal of their common box is 2√3.
        assert!((report.diagonal - 2.0 * 3f64.sqrt()).abs() < 1e-5);
    }
}

#[test]
fn a_mesh_is_at_distance_zero_from_itself() {
    for mesh in [common::icosphere(3), common::torus(40, 20)] {
        let report = mesh_distance(&mesh, &mesh, &DistanceOptions::quick()).unwrap();
        assert!(report.hausdorff < 1e-12 * report.diagonal, "{report}");
        assert!(report.rms <= report.hausdorff);
    }
}

/// A cube and its copy shifted by `d` along x: Hausdorff `d`; on each cube the distance is `d`
/// on one face, `d - x` on a strip of width `d` of four faces and `min(d, distance to the
/// face's border)` on the face inside the other cube. So the mean is `d/3 + 2d³/9` and the
/// mean square `(2d² - 4d³/3 + 2d⁴)/6`.
#[test]
fn shifted_cubes_give_the_analytic_mean_and_rms() {
    let d: f64 = 0.125; // exact in binary
    let cube = common::unit_cube();
    let mut shifted = cube.clone();
    for p in &mut shifted.positions {
        p.x += d as f32;
    }
    let mean = d / 3.0 + 2.0 * d.powi(3) / 9.0;
    let rms = ((2.0 * d * d - 4.0 * d.powi(3) / 3.0 + 2.0 * d.powi(4)) / 6.0).sqrt();
    for (layout, tolerance) in [
        (SampleLayout::Stratified, 0.002),
        (SampleLayout::Independent, 0.01),
    ] {
        let options = DistanceOptions {
            layout,
            ..DistanceOptions::for_samples(200_000)
        };
        let report = mesh_distance(&cube, &shifted, &options).unwrap();
        eprintln!(
            "{layout:?}: mean {} (analytic {mean}), rms {} (analytic {rms})",
            report.mean, report.rms
        );
        assert!((report.hausdorff - d).abs() < 1e-12, "{report}");
        assert!((report.mean - mean).abs() < tolerance * mean, "{report}");
        assert!((report.rms - rms).abs() < tolerance * rms, "{report}");
        for side in [report.first_to_second, report.second_to_first] {
            assert!((side.max - d).abs() < 1e-12);
            assert!((side.mean - mean).abs() < 2.0 * tolerance * mean);
            assert_eq!(side.samples, 200_000);
        }
        let diagonal = (((1.0 + d) * (1.0 + d)) + 2.0f64).sqrt();
        assert!((report.diagonal - diagonal).abs() < 1e-12);
        assert!((report.mean_fraction - report.mean / diagonal).abs() < 1e-15);
        assert!((report.rms_fraction - report.rms / diagonal).abs() < 1e-15);
    }
}

fn without_time(mut r: DistanceReport) -> DistanceReport {
    r.seconds = 0.0;
    r
}

#[test]
fn reports_are_deterministic_and_seeded() {
    let a = common::torus(60, 30);
    let b = common::torus_with(50, 25, 2.0, |u, v| 1.0 + 0.05 * (3.0 * u).sin() * v.cos());
    let options = DistanceOptions::for_samples(30_000);
    let report = without_time(mesh_distance(&a, &b, &options).unwrap());
    assert_eq!(
        report,
        without_time(mesh_distance(&a, &b, &options).unwrap())
    );
    let one_thread = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(|| mesh_distance(&a, &b, &options).unwrap());
    assert_eq!(report, without_time(one_thread));
    let reseeded = mesh_distance(
        &a,
        &b,
        &DistanceOptions {
            seed: 99,
            ..options
        },
    )
    .unwrap();
    assert_ne!(report.mean, reseeded.mean);
    assert!((report.mean - reseeded.mean).abs() < 0.02 * report.mean);
    // Swapping the meshes swaps the one-sided figures' roles; the diagonal is that of both.
    let swapped = mesh_distance(&b, &a, &options).unwrap();
    assert_eq!(swapped.diagonal, report.diagonal);
    assert!((swapped.hausdorff - report.hausdorff).abs() < 0.05 * report.hausdorff);
}

#[test]
fn report_serialises_with_the_documented_keys() {
    let report = mesh_distance(
        &common::unit_cube(),
        &common::icosphere(1),
        &DistanceOptions::quick(),
    )
    .unwrap();
    let json = serde_json::to_value(report).unwrap();
    for key in [
        "hausdorff",
        "mean",
        "rms",
        "hausdorff_fraction",
        "mean_fraction",
        "rms_fraction",
        "samples",
        "diagonal",
        "seconds",
    ] {
        assert!(json.get(key).is_some(), "missing key {key} in {json}");
    }
    assert_eq!(json["samples"], 10_000);
    assert!(json["first_to_second"]["max"].is_number());
}

#[test]
fn refuses_empty_flat_and_broken_meshes_naming_which() {
    let cube = common::unit_cube();
    let flat = TriangleMesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 1]]);
    let message = |a: &TriangleMesh, b: &TriangleMesh| {
        mesh_distance(a, b, &DistanceOptions::quick())
            .unwrap_err()
            .to_string()
    };
    assert_eq!(
        message(&cube, &flat),
        "second mesh: the mesh has no area (1 triangles, all degenerate)"
    );
    assert_eq!(
        message(&TriangleMesh::default(), &cube),
        "first mesh: the mesh has no triangles"
    );
    let mut broken = cube.clone();
    broken.positions[0].x = f32::NAN;
    assert!(
        message(&cube, &broken).starts_with("second mesh: vertex 0 has a non-finite coordinate")
    );
    assert!(matches!(
        mesh_distance(&cube, &cube, &DistanceOptions::for_samples(0)),
        Err(MetricsError::NoSamples)
    ));
}
