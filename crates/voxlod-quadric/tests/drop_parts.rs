//! Dropping the smallest parts where the budget cannot afford every component: on a large
//! sphere with a swarm of small ones (generated here), the plain quadric stage stalls far above
//! a small budget, while the dropping stage reaches it, keeps a closed genus-0 manifold per kept
//! part, keeps the large sphere, and drops only parts no larger than any it keeps.

use voxlod_core::glam::Vec3;
use voxlod_core::{mesh_topology, TriangleMesh};
use voxlod_quadric::{simplify_dropping_parts, PartsOptions};
use voxlod_testkit::shapes::{append, icosphere_at};

/// A unit sphere (1 280 triangles) and `small` spheres of radius 0.04 to 0.12 (80 triangles
/// each) on a shell of radius 1.5 around it, none touching.
fn sphere_swarm(small: usize) -> TriangleMesh {
    let mut mesh = icosphere_at(3, 1.0, Vec3::ZERO);
    for (centre, radius) in small_spheres(small) {
        append(&mut mesh, &icosphere_at(1, radius, centre));
    }
    mesh
}

/// Centres (a Fibonacci lattice on the shell) and radii of the swarm's small spheres.
fn small_spheres(small: usize) -> Vec<(Vec3, f32)> {
    let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    (0..small)
        .map(|i| {
            let y = 1.0 - 2.0 * (i as f32 + 0.5) / small as f32;
            let ring = (1.0 - y * y).sqrt();
            let angle = golden * i as f32;
            let centre = Vec3::new(ring * angle.cos(), y, ring * angle.sin()) * 1.5;
            (centre, 0.04 + 0.08 * (i % 5) as f32 / 4.0)
        })
        .collect()
}

#[test]
fn the_swarm_stalls_without_dropping_and_reaches_the_budget_with_it() {
    let mesh = sphere_swarm(100);
    assert_eq!(mesh.triangle_count(), 1280 + 100 * 80);
    assert_eq!(mesh_topology(&mesh).components, 101);
    let budget = 200;
    let plain = PartsOptions {
        max_rounds: 0,
        ..PartsOptions::default()
    };
    let stalled = simplify_dropping_parts(&mesh, budget, &plain).unwrap();
    // 101 closed parts need at least 4 triangles each: the plain stage cannot reach 200.
    assert!(stalled.simplified.mesh.triangle_count() >= 404);
    assert_eq!(stalled.dropped_parts, 0);

    let done = simplify_dropping_parts(&mesh, budget, &PartsOptions::default()).unwrap();
    let out = &done.simplified.mesh;
    let t = mesh_topology(out);
    assert!(t.is_closed_manifold(), "{t:?}");
    assert!(t.is_consistently_oriented(), "{t:?}");
    assert_eq!(t.genus, Some(0), "every kept part is a sphere");
    assert!(
        (out.triangle_count() as f64 / budget as f64 - 1.0).abs() <= 0.10,
        "{} triangles for {budget}",
        out.triangle_count()
    );
    assert_eq!(t.components + done.dropped_parts, 101);
    assert!(done.dropped_parts > 0);
    // The large sphere is kept: a vertex on it lies about 1 from the centre.
    assert!(out
        .positions
        .iter()
        .any(|p| (p.length() - 1.0).abs() < 0.02));
    // Only parts no larger than every kept small sphere went: a small sphere is kept when an
    // output vertex lies on it.
    let (mut largest_dropped, mut smallest_kept) = (0.0f32, f32::INFINITY);
    for (centre, radius) in small_spheres(100) {
        let kept = out
            .positions
            .iter()
            .any(|p| ((*p - centre).length() - radius).abs() < 1e-4);
        if kept {
            smallest_kept = smallest_kept.min(radius);
        } else {
            largest_dropped = largest_dropped.max(radius);
        }
    }
    assert!(
        largest_dropped <= smallest_kept,
        "{largest_dropped} > {smallest_kept}"
    );
    assert!(done.largest_dropped <= 2.0 * 3f64.sqrt() * f64::from(largest_dropped) + 1e-4);
    assert_eq!(
        done.dropped_triangles,
        80 * done.dropped_parts,
        "dropped parts are whole small spheres"
    );
}

#[test]
fn nothing_is_dropped_when_the_budget_affords_every_part() {
    let mesh = sphere_swarm(10);
    let done = simplify_dropping_parts(&mesh, 600, &PartsOptions::default()).unwrap();
    assert_eq!(done.dropped_parts, 0);
    assert_eq!(mesh_topology(&done.simplified.mesh).components, 11);
}
