//! The quadric stage refuses folds: where two sheets lie close, plain meshoptimizer pulls one
//! through the other, and `simplify_to_budget` does not (no crossing pair by voxlod-testkit's
//! independent predicates), keeping the mesh closed, manifold and of the same genus.

use voxlod_core::glam::Vec3;
use voxlod_core::{crossing_pairs, mesh_topology, TriangleMesh};
use voxlod_quadric::{simplify_to_budget, simplify_unchecked, QuadricOptions, Simplified, Stop};
use voxlod_testkit::intersections::self_intersections;
use voxlod_testkit::shapes::{append, icosphere_at};

/// A hollow ball: a sphere of radius 1 and, inside it, an inward-facing sphere of radius 0.97
/// a little off centre (a wall 0.011 to 0.049 thick), 5120 triangles each.
fn hollow_ball() -> TriangleMesh {
    let mut mesh = icosphere_at(4, 1.0, Vec3::ZERO);
    let mut inner = icosphere_at(4, 0.97, Vec3::new(0.013, -0.007, 0.011));
    inner.flip_orientation();
    append(&mut mesh, &inner);
    mesh
}

/// Closed, manifold, consistently oriented, two components of genus 0, no crossing pair by
/// either test.
fn assert_clean(mesh: &TriangleMesh, what: &str) {
    let topology = mesh_topology(mesh);
    assert!(topology.is_closed_manifold(), "{what}: {topology:?}");
    assert!(topology.is_consistently_oriented(), "{what}: {topology:?}");
    assert_eq!(
        (topology.components, topology.genus),
        (2, Some(0)),
        "{what}"
    );
    assert_eq!(self_intersections(mesh), vec![], "{what}");
    assert_eq!(crossing_pairs(mesh), vec![], "{what}");
}

/// The quadric stage on `mesh` at `budget`, after checking that plain meshoptimizer folds
/// the mesh there (so the stage has a fold to refuse).
fn plain_folds_then_stage(mesh: &TriangleMesh, budget: usize) -> Simplified {
    let (plain, _) = simplify_unchecked(mesh, budget, false).unwrap();
    assert!(
        !self_intersections(&plain).is_empty(),
        "plain does not fold at {budget}"
    );
    simplify_to_budget(mesh, budget, &QuadricOptions::budget(f64::INFINITY)).unwrap()
}

/// At 1000 triangles plain meshoptimizer folds the hollow ball's wall; the quadric stage
/// reaches the budget without a crossing.
#[test]
fn a_thin_wall_reaches_the_budget_without_folding() {
    let mesh = hollow_ball();
    assert_clean(&mesh, "input");
    let out = plain_folds_then_stage(&mesh, 1000);
    assert_clean(&out.mesh, "1000");
    assert_eq!(out.stop, Stop::Budget);
    assert!(out.rejected > 0, "nothing was refused");
    assert!((900..=1000).contains(&out.mesh.triangle_count()));
}

/// Below what the wall can afford (both spheres coarse enough cross), the stage stops above
/// the budget and says why, still without a crossing, and still far below the input.
#[test]
fn below_what_a_thin_wall_affords_the_stop_says_crossings() {
    let mesh = hollow_ball();
    let out = plain_folds_then_stage(&mesh, 200);
    assert_clean(&out.mesh, "200");
    assert_eq!(out.stop, Stop::Crossings);
    let count = out.mesh.triangle_count();
    assert!(count > 200 && count < mesh.triangle_count() / 5, "{count}");
}

/// An input that crosses itself (two overlapping spheres) still reaches its budget: the
/// stage refuses only passes that add crossing pairs, never more than the input had.
#[test]
fn an_input_crossing_itself_reaches_the_budget_with_no_more_crossings() {
    let mut mesh = icosphere_at(4, 1.0, Vec3::ZERO);
    append(&mut mesh, &icosphere_at(4, 0.8, Vec3::new(1.3, 0.1, 0.05)));
    let before = crossing_pairs(&mesh).len();
    assert!(before > 100, "{before}");
    for budget in [2000, 500] {
        let out = simplify_to_budget(&mesh, budget, &QuadricOptions::default()).unwrap();
        assert_eq!(out.stop, Stop::Budget, "{budget}");
        let after = crossing_pairs(&out.mesh).len();
        assert!(
            after > 0 && after <= before,
            "{budget}: {after} of {before}"
        );
        assert_eq!(mesh_topology(&out.mesh).components, 2);
    }
}
