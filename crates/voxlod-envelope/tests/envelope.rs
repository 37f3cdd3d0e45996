//! Simplification envelopes on meshes built in code, where the right answer is known: what must
//! stay stays (border, sharp ridges, a vertex too curved to remove within ε), what may go goes
//! (a flat patch empties), the guarantees hold (vertex subset, topology, two-sided distance
//! within ε, no self-intersection), and bad input fails with a message naming the problem.

use std::collections::HashSet;

use voxlod_core::glam::{DVec3, Vec3};
use voxlod_core::{mesh_topology, TriangleMesh};
use voxlod_envelope::{
    envelope_series, repair_for_envelope, self_intersections, simplify_envelope, EnvelopeError,
    EnvelopeLevel, EnvelopeOptions, Epsilon, RegionEpsilon, RemovalOrder,
};
use voxlod_metrics::{mesh_distance, DistanceOptions, MeshDistance};
use voxlod_testkit::shapes::{icosphere, torus};

// -------------------------------------------------------------------------------------------
// Meshes.

/// An open `n` × `n` grid on [0, 1]² with height `z(x, y)` (one border loop).
fn grid(n: u32, z: impl Fn(f32, f32) -> f32) -> TriangleMesh {
    let mut positions = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (i as f32 / n as f32, j as f32 / n as f32);
            positions.push(Vec3::new(x, y, z(x, y)));
        }
    }
    let id = |i: u32, j: u32| j * (n + 1) + i;
    let mut triangles = Vec::new();
    for j in 0..n {
        for i in 0..n {
            triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    TriangleMesh::new(positions, triangles)
}

// -------------------------------------------------------------------------------------------
// Checks.

/// Every guarantee of a level against its input: vertices are input vertices (same position
/// and normal), same genus, components and border loops, a consistently oriented manifold, no
/// new self-intersection, and the two-sided distance within ε: exactly for every input vertex,
/// and by sampling 200 000 points per surface. Sampling only finds a lower bound of the
/// Hausdorff distance, so it is compared with ε itself (plus 10⁻⁹ relative for rounding); a
/// violation narrower than the sample spacing (printed) could go unseen, which the exact
/// per-vertex check narrows down.
fn assert_guarantees(input: &TriangleMesh, level: &EnvelopeLevel, what: &str) {
    let out = &level.mesh;
    let eps = level.report.epsilon;
    assert_eq!(out.positions.len(), level.vertex_map.len(), "{what}");
    assert!(level.vertex_map.windows(2).all(|w| w[0] < w[1]), "{what}");
    for (i, &v) in level.vertex_map.iter().enumerate() {
        assert_eq!(
            out.positions[i], input.positions[v as usize],
            "{what}: vertex {i}"
        );
    }
    let (a, b) = (mesh_topology(input), mesh_topology(out));
    assert_eq!(a.genus, b.genus, "{what}: genus");
    assert_eq!(a.components, b.components, "{what}: components");
    assert_eq!(a.boundary_loops, b.boundary_loops, "{what}: border loops");
    assert_eq!(
        a.boundary_edges, b.boundary_edges,
        "{what}: border edges (kept exactly)"
    );
    assert!(
        b.is_manifold() && b.is_consistently_oriented(),
        "{what}: {b:?}"
    );
    assert_eq!(b.duplicate_triangles, 0, "{what}");
    let before = self_intersections(input).unwrap().len();
    let after = self_intersections(out).unwrap().len();
    assert!(
        after <= before,
        "{what}: {after} self-intersecting pairs (input {before})"
    );

    let slack = eps * (1.0 + 1e-9);
    let md = MeshDistance::new(out).unwrap();
    let used: Vec<DVec3> = {
        let mut seen = vec![false; input.positions.len()];
        input
            .triangles
            .iter()
            .flatten()
            .for_each(|&v| seen[v as usize] = true);
        (0..input.positions.len())
            .filter(|&v| seen[v])
            .map(|v| input.positions[v].as_dvec3())
            .collect()
    };
    let worst = md.distances(&used).into_iter().fold(0.0, f64::max);
    assert!(
        worst <= slack,
        "{what}: an input vertex is {worst} from the output (ε {eps})"
    );
    let samples = 200_000;
    let d = mesh_distance(input, out, &DistanceOptions::for_samples(samples)).unwrap();
    let spacing = (input.area() / samples as f64).sqrt();
    eprintln!(
        "{what}: {} -> {} triangles, sampled two-sided distance {:.3e} = {:.3} ε (sample spacing {:.2e})",
        input.triangles.len(),
        out.triangles.len(),
        d.hausdorff,
        d.hausdorff / eps,
        spacing
    );
    assert!(
        d.hausdorff <= slack,
        "{what}: sampled {} > ε {eps}",
        d.hausdorff
    );
}

fn options() -> EnvelopeOptions {
    EnvelopeOptions::unmeasured()
}

// -------------------------------------------------------------------------------------------
// What must stay, what may go.

#[test]
fn a_sphere_keeps_its_guarantees_and_simplifies() {
    let sphere = icosphere(4); // 5120 triangles
    for (what, options) in [
        ("coverage", options().with_order(RemovalOrder::Coverage)),
        ("deviation", options().with_order(RemovalOrder::Deviation)),
        ("tight", EnvelopeOptions::tight().with_measure_samples(0)),
    ] {
        let level = simplify_envelope(&sphere, Epsilon::percent(1.0), &options).unwrap();
        assert_guarantees(&sphere, &level, &format!("sphere {what}"));
        assert!(
            level.report.triangles < sphere.triangles.len() / 3,
            "{what}: {}",
            level.report.triangles
        );
        assert!(level.report.removal.removed > 0);
    }
}

#[test]
fn below_the_smallest_deviation_nothing_moves() {
    // Removing any vertex of a subdivided icosphere moves the surface by about h²/8 ≈ 1e-3:
    // with ε a thousand times smaller every removal must be refused.
    let sphere = icosphere(3);
    let level = simplify_envelope(&sphere, Epsilon::Absolute(1e-6), &options()).unwrap();
    assert_eq!(level.mesh.triangles.len(), sphere.triangles.len());
    assert_eq!(level.report.removal.removed, 0);
    assert_eq!(
        level.vertex_map,
        (0..sphere.positions.len() as u32).collect::<Vec<_>>()
    );
}

#[test]
fn a_flat_patch_empties_and_its_border_stays() {
    let flat = grid(16, |_, _| 0.0);
    let level = simplify_envelope(&flat, Epsilon::percent(0.5), &options()).unwrap();
    assert_guarantees(&flat, &level, "flat grid");
    let kept: HashSet<u32> = level.vertex_map.iter().copied().collect();
    let border = |v: u32| {
        let (i, j) = (v % 17, v / 17);
        i == 0 || j == 0 || i == 16 || j == 16
    };
    let border_count = (0..17 * 17).filter(|&v| border(v)).count();
    assert!((0..17 * 17)
        .filter(|&v| border(v))
        .all(|v| kept.contains(&v)));
    let inner_left = kept.iter().filter(|&&v| !border(v)).count();
    // Only the valence cap and the aspect-ratio floor can keep an inner vertex of a plane.
    assert!(inner_left <= 12, "{inner_left} inner vertices left of 225");
    assert!(kept.len() >= border_count);
}

#[test]
fn a_torus_stays_a_torus_at_any_epsilon() {
    let ring = torus(48, 16, 1.0, 0.3);
    for percent in [1.0, 5.0, 20.0] {
        for options in [
            options(),
            EnvelopeOptions::less_cautious().with_measure_samples(0),
        ] {
            let level = simplify_envelope(&ring, Epsilon::percent(percent), &options).unwrap();
            assert_guarantees(
                &ring,
                &level,
                &format!("torus {percent}% {:?}", options.offsets),
            );
            assert_eq!(level.report.topology.genus, Some(1));
        }
    }
}

#[test]
fn sharp_ridges_are_kept_when_asked() {
    // A roof: two planes meeting along y = 0.5 at a dihedral angle of about 11°.
    let roof = grid(16, |_, y| 0.1 * (0.5 - (y - 0.5).abs()));
    let ridge: Vec<u32> = (0..=16).map(|i| 8 * 17 + i).collect();
    let loose = simplify_envelope(&roof, Epsilon::percent(2.0), &options()).unwrap();
    assert_guarantees(&roof, &loose, "roof");
    let kept: HashSet<u32> = loose.vertex_map.iter().copied().collect();
    assert!(
        ridge.iter().filter(|v| kept.contains(v)).count() < ridge.len(),
        "without --keep-sharp some inner ridge vertex can go (the ridge is a straight line)"
    );
    let sharp = simplify_envelope(
        &roof,
        Epsilon::percent(2.0),
        &options().with_keep_sharp(5.0),
    )
    .unwrap();
    assert_guarantees(&roof, &sharp, "roof, sharp kept");
    let kept: HashSet<u32> = sharp.vertex_map.iter().copied().collect();
    assert!(ridge.iter().all(|v| kept.contains(v)));
    // Every ridge edge survives.
    let edges: HashSet<(u32, u32)> = sharp
        .mesh
        .triangles
        .iter()
        .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
        .map(|(a, b)| {
            let (a, b) = (sharp.vertex_map[a as usize], sharp.vertex_map[b as usize]);
            (a.min(b), a.max(b))
        })
        .collect();
    assert!(ridge.windows(2).all(|w| edges.contains(&(w[0], w[1]))));
    // Above the ridge's angle nothing is sharp.
    let blunt = simplify_envelope(
        &roof,
        Epsilon::percent(2.0),
        &options().with_keep_sharp(30.0),
    )
    .unwrap();
    assert_eq!(blunt.mesh.triangles, loose.mesh.triangles);
}

#[test]
fn a_region_with_a_smaller_epsilon_keeps_more() {
    let sphere = icosphere(4);
    let half = RegionEpsilon {
        min: DVec3::new(0.0, -2.0, -2.0),
        max: DVec3::new(2.0, 2.0, 2.0),
        scale: 0.1,
    };
    let level = simplify_envelope(
        &sphere,
        Epsilon::percent(2.0),
        &options().with_regions(vec![half]),
    )
    .unwrap();
    let fine = level.mesh.positions.iter().filter(|p| p.x > 0.05).count();
    let coarse = level.mesh.positions.iter().filter(|p| p.x < -0.05).count();
    assert!(
        fine > 3 * coarse,
        "x > 0 keeps {fine} vertices, x < 0 {coarse}"
    );
    // Each part within its own ε: the coarse half within 2 %, the fine half within 0.2 %.
    let eps = level.report.epsilon;
    let md = MeshDistance::new(&level.mesh).unwrap();
    for p in &sphere.positions {
        let d = md.distance(p.as_dvec3());
        let limit = if p.x >= 0.0 { 0.1 * eps } else { eps };
        assert!(d <= limit * (1.0 + 1e-9), "vertex {p}: {d} > {limit}");
    }
}

#[test]
fn a_series_nests_and_each_level_keeps_its_own_epsilon() {
    let sphere = icosphere(4);
    let eps: Vec<Epsilon> = [0.5, 1.0, 2.0, 4.0].map(Epsilon::percent).to_vec();
    let levels = envelope_series(&sphere, &eps, &options()).unwrap();
    assert_eq!(levels.len(), 4);
    for (i, level) in levels.iter().enumerate() {
        assert_eq!(level.report.level, i);
        assert_guarantees(&sphere, level, &format!("sphere series level {i}"));
        if i > 0 {
            let before: HashSet<u32> = levels[i - 1].vertex_map.iter().copied().collect();
            assert!(
                level.vertex_map.iter().all(|v| before.contains(v)),
                "level {i} not nested"
            );
            assert!(level.report.triangles <= levels[i - 1].report.triangles);
        }
    }
    assert!(levels[3].report.triangles < levels[0].report.triangles);
    // Deterministic.
    let again = envelope_series(&sphere, &eps, &options()).unwrap();
    for (a, b) in levels.iter().zip(&again) {
        assert_eq!(a.mesh.triangles, b.mesh.triangles);
    }
}

#[test]
fn the_report_measures_the_distance_when_asked() {
    let sphere = icosphere(3);
    let level = simplify_envelope(
        &sphere,
        Epsilon::percent(2.0),
        &EnvelopeOptions::paper().with_measure_samples(20_000),
    )
    .unwrap();
    let d = level.report.distance.expect("measured");
    assert!(d.hausdorff > 0.0 && d.hausdorff_over_epsilon <= 1.0 + 1e-9);
    assert!((level.report.epsilon_fraction - 0.02).abs() < 1e-12);
    assert!(level.report.quality_factor >= 1.0);
    let json = serde_json::to_value(&level.report).unwrap();
    assert!(json["reduction_percent"].as_f64().unwrap() > 0.0);
}

// -------------------------------------------------------------------------------------------
// Bad input.

#[test]
fn bad_input_is_refused_with_a_reason() {
    let sphere = icosphere(1);
    let run = |mesh: &TriangleMesh, eps: Epsilon| simplify_envelope(mesh, eps, &options());
    let empty = TriangleMesh::new(vec![Vec3::ZERO], vec![]);
    assert!(matches!(
        run(&empty, Epsilon::percent(1.0)),
        Err(EnvelopeError::Core(voxlod_core::CoreError::Mesh(
            voxlod_core::validate::MeshDefect::NoTriangles
        )))
    ));
    for eps in [
        Epsilon::Absolute(0.0),
        Epsilon::Absolute(-1.0),
        Epsilon::Absolute(f64::NAN),
        Epsilon::DiagonalFraction(0.0),
        Epsilon::Absolute(f64::INFINITY),
    ] {
        let e = run(&sphere, eps).unwrap_err();
        assert!(
            matches!(e, EnvelopeError::InvalidEpsilon(_)),
            "{eps:?}: {e}"
        );
    }
    let e = envelope_series(
        &sphere,
        &[Epsilon::percent(2.0), Epsilon::percent(1.0)],
        &options(),
    )
    .unwrap_err();
    assert!(e.to_string().contains("growing"), "{e}");
    let e = envelope_series(&sphere, &[], &options()).unwrap_err();
    assert!(e.to_string().contains("levels"), "{e}");

    let mut bad = sphere.clone();
    bad.triangles[3][1] = 999;
    let e = run(&bad, Epsilon::percent(1.0)).unwrap_err().to_string();
    assert!(e.contains("triangle 3 refers to vertex 999"), "{e}");
    let mut bad = sphere.clone();
    bad.positions[5].y = f32::NAN;
    let e = run(&bad, Epsilon::percent(1.0)).unwrap_err().to_string();
    assert!(e.contains("vertex 5 has a non-finite coordinate"), "{e}");

    let mut o = options();
    o.min_aspect = 1.5;
    assert!(simplify_envelope(&sphere, Epsilon::percent(1.0), &o).is_err());
    let o = options().with_keep_sharp(200.0);
    assert!(simplify_envelope(&sphere, Epsilon::percent(1.0), &o).is_err());
}

#[test]
fn a_non_manifold_mesh_names_its_edges_and_repairs() {
    let mut fin = icosphere(2);
    // A fin on the edge of the first triangle (already used by two triangles).
    let [a, b, _] = fin.triangles[0];
    fin.positions.push(Vec3::new(3.0, 3.0, 3.0));
    let tip = (fin.positions.len() - 1) as u32;
    fin.triangles.push([a, b, tip]);
    let e = simplify_envelope(&fin, Epsilon::percent(1.0), &options()).unwrap_err();
    let text = e.to_string();
    assert!(matches!(e, EnvelopeError::NotManifold(_)));
    let (lo, hi) = (a.min(b), a.max(b));
    assert!(
        text.contains(&format!("edge {lo}–{hi} (3 triangles)")),
        "{text}"
    );
    assert!(text.contains("--repair"), "{text}");

    let mut flipped = icosphere(2);
    flipped.triangles[7].swap(1, 2);
    let text = simplify_envelope(&flipped, Epsilon::percent(1.0), &options())
        .unwrap_err()
        .to_string();
    assert!(text.contains("used twice in the same direction"), "{text}");

    let (repaired, report) = repair_for_envelope(&fin);
    assert!(report.changed_anything());
    let level = simplify_envelope(&repaired, Epsilon::percent(1.0), &options()).unwrap();
    assert_guarantees(&repaired, &level, "repaired fin");
}
