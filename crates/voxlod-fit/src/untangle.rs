//! Crossings that a fit made, undone: the corners of every pair of triangles that cross are
//! put back where they were before the fit, and the test is repeated, since a corner put back
//! can make its neighbours cross in turn. The step check of the fit ([`crate::fit_with`]) sees
//! folds of a triangle against its own first normal, not two sheets of the level moving
//! through each other where they lie close (two spheres of the sphereflake that meet at a
//! crease); this does.
//!
//! Cost: one crossing test ([`voxlod_core::crossing_pairs`], a grid of the triangles) per
//! round, at most [`ROUNDS`] rounds; each pair found is then tested in the level alone.

use voxlod_core::crossing_pairs;
use voxlod_core::crossings::triangles_cross;
use voxlod_core::TriangleMesh;

/// Rounds of putting corners back before giving up.
const ROUNDS: usize = 6;

/// What [`untangled`] made of a fitted level.
pub(crate) struct Untangled {
    /// The fitted level with the corners of its new crossings put back.
    pub mesh: TriangleMesh,
    /// Vertices put back.
    pub restored: usize,
    /// Pairs of `mesh`'s triangles that cross (all of which crossed in the level too), where
    /// the last round counted them; `None` where it gave up after [`ROUNDS`] rounds.
    pub crossings: Option<usize>,
}

/// `fitted` with the corners of its crossing triangles moved back to their positions in
/// `level` (the same triangles), until no pair crosses that did not cross in `level`, or
/// [`ROUNDS`] rounds.
pub(crate) fn untangled(level: &TriangleMesh, mut fitted: TriangleMesh) -> Untangled {
    let mut restored = vec![false; fitted.positions.len()];
    let mut crossings = None;
    for _ in 0..ROUNDS {
        let pairs = crossing_pairs(&fitted);
        let count = pairs.len();
        let new: Vec<(u32, u32)> = (pairs.into_iter())
            .filter(|&pair| !crossed_in(level, pair))
            .collect();
        if new.is_empty() {
            crossings = Some(count);
            break;
        }
        for (a, b) in new {
            for t in [a, b] {
                for v in fitted.triangles[t as usize] {
                    fitted.positions[v as usize] = level.positions[v as usize];
                    restored[v as usize] = true;
                }
            }
        }
    }
    if restored.iter().any(|&r| r) && !fitted.normals.is_empty() {
        fitted.compute_vertex_normals();
    }
    Untangled {
        mesh: fitted,
        restored: restored.iter().filter(|&&r| r).count(),
        crossings,
    }
}

/// Whether triangles `a` and `b` of `level` cross (the test [`crossing_pairs`] makes).
fn crossed_in(level: &TriangleMesh, (a, b): (u32, u32)) -> bool {
    let (a, b) = (a as usize, b as usize);
    let (ia, ib) = (level.triangles[a], level.triangles[b]);
    triangles_cross(level.corners(a), ia, level.corners(b), ib, 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use voxlod_core::glam::Vec3;

    #[test]
    fn a_corner_pushed_through_another_sheet_goes_back() {
        // Two parallel triangles 0.1 apart; the fit lifts a corner of the lower one through
        // the upper one.
        let level = TriangleMesh::new(
            vec![
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(2.0, 0.0, 0.0),
                Vec3::new(0.0, 2.0, 0.0),
                Vec3::new(0.0, 0.0, 0.1),
                Vec3::new(2.0, 0.0, 0.1),
                Vec3::new(0.0, 2.0, 0.1),
            ],
            vec![[0, 1, 2], [3, 4, 5]],
        );
        assert!(crossing_pairs(&level).is_empty());
        let mut fitted = level.clone();
        fitted.positions[2] = Vec3::new(0.0, 2.0, 0.5);
        fitted.positions[3] = Vec3::new(0.01, 0.0, 0.1);
        assert_eq!(crossing_pairs(&fitted), vec![(0, 1)]);
        let done = untangled(&level, fitted);
        assert!(crossing_pairs(&done.mesh).is_empty());
        assert_eq!(done.restored, 6);
        assert_eq!(done.crossings, Some(0));
        assert_eq!(done.mesh.positions, level.positions);

        // A crossing the level had already stays, counted, and nothing is put back.
        let kept = untangled(&done.mesh, done.mesh.clone());
        assert_eq!((kept.crossings, kept.restored), (Some(0), 0));
        let mut crossing = level.clone();
        crossing.positions[2] = Vec3::new(0.0, 2.0, 0.5);
        crossing.positions[3] = Vec3::new(0.01, 0.0, 0.1);
        let kept = untangled(&crossing, crossing.clone());
        assert_eq!((kept.crossings, kept.restored), (Some(1), 0));
    }
}
