//! The whole-mesh count of crossing triangles (`crossing_pairs`, re-exported from voxlod-core)
//! agrees with voxlod-testkit's independent test, on spheres apart and overlapping and on
//! coplanar pairs.

use voxlod_contouring::crossing_pairs;
use voxlod_core::glam::Vec3;
use voxlod_core::TriangleMesh;
use voxlod_testkit::intersections::self_intersections;
use voxlod_testkit::shapes::{append, icosphere_at};

/// Spheres placed so that some overlap: the pairs are exactly those an independent test
/// (orientation predicates, voxlod-testkit) finds, and none where the spheres lie apart.
#[test]
fn crossing_pairs_are_the_independent_tests_pairs() {
    for (offset, crossing) in [(0.7f32, true), (1.3, true), (2.5, false)] {
        let mut mesh = icosphere_at(3, 1.0, Vec3::ZERO);
        append(
            &mut mesh,
            &icosphere_at(3, 0.8, Vec3::new(offset, 0.1, 0.05)),
        );
        let ours: Vec<(usize, usize)> = crossing_pairs(&mesh)
            .into_iter()
            .map(|(s, t)| (s as usize, t as usize))
            .collect();
        let mut theirs = self_intersections(&mesh);
        theirs.sort_unstable();
        assert_eq!(ours, theirs, "offset {offset}");
        assert_eq!(!ours.is_empty(), crossing, "offset {offset}");
    }
}

/// A closed sphere alone has no crossing pair.
#[test]
fn a_closed_sphere_has_no_crossing_pair() {
    assert!(crossing_pairs(&icosphere_at(4, 1.0, Vec3::ZERO)).is_empty());
}

/// Coplanar pairs in the plane z = 0: apart, overlapping, folded over a shared edge, side
/// by side along it, overlapping and touching wedges at a shared corner; each decided as the
/// independent test decides it, and both answers occur.
#[test]
fn coplanar_pairs_are_decided_as_the_independent_test_decides() {
    let p = |x: f32, y: f32| Vec3::new(x, y, 0.0);
    let cases: [(Vec<Vec3>, [[u32; 3]; 2], bool); 6] = [
        (
            vec![
                p(0., 0.),
                p(1., 0.),
                p(0., 1.),
                p(2., 2.),
                p(3., 2.),
                p(2., 3.),
            ],
            [[0, 1, 2], [3, 4, 5]],
            false,
        ),
        (
            vec![
                p(0., 0.),
                p(2., 0.),
                p(0., 2.),
                p(0.5, 0.5),
                p(3., 0.5),
                p(0.5, 3.),
            ],
            [[0, 1, 2], [3, 4, 5]],
            true,
        ),
        (
            vec![p(0., 0.), p(2., 0.), p(0., 2.), p(1.5, 1.5)],
            [[0, 1, 2], [1, 3, 2]],
            false,
        ),
        (
            vec![p(0., 0.), p(2., 0.), p(0., 2.), p(0.5, 0.5)],
            [[0, 1, 2], [2, 1, 3]],
            true,
        ),
        (
            vec![p(0., 0.), p(2., 0.), p(0., 2.), p(2., 1.), p(1., 2.)],
            [[0, 1, 2], [0, 3, 4]],
            true,
        ),
        (
            vec![p(0., 0.), p(2., 0.), p(0., 2.), p(-2., 0.)],
            [[0, 1, 2], [0, 2, 3]],
            false,
        ),
    ];
    for (k, (positions, triangles, overlap)) in cases.into_iter().enumerate() {
        let mesh = TriangleMesh::new(positions, triangles.to_vec());
        let ours = !crossing_pairs(&mesh).is_empty();
        let theirs = voxlod_testkit::intersections::triangles_intersect(&mesh, 0, 1);
        assert_eq!((ours, theirs), (overlap, overlap), "case {k}");
    }
}

/// Two strips of a flat face from a marching-cubes level of Thingi10K 42722 (`f32` corners,
/// one shared): coplanar up to rounding and apart but for the shared corner. The guard's
/// predicate, where a zero sign counts as meeting, said they meet; they do not cross, and
/// neither test counts them.
#[test]
fn near_coplanar_neighbours_do_not_cross() {
    let p = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
    let mesh = TriangleMesh::new(
        vec![
            p(-4.82514, -13.9212, -2.22045e-16),
            p(-4.82514, -13.5548, -2.22045e-16),
            p(-4.57933, -13.9212, -0.214946),
            p(-4.82514, -13.1885, -2.22045e-16),
            p(-4.57933, -13.5548, -0.214946),
        ],
        vec![[0, 1, 2], [1, 3, 4]],
    );
    let (a, b) = (mesh.corners(0), mesh.corners(1));
    let (ia, ib) = (mesh.triangles[0], mesh.triangles[1]);
    assert!(voxlod_core::crossings::triangles_meet(a, ia, b, ib, 1e-9));
    assert!(crossing_pairs(&mesh).is_empty());
    assert!(self_intersections(&mesh).is_empty());
}
