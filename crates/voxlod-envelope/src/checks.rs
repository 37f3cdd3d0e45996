//! Checks of a result that the guarantees rest on, for tests and reports: pairs of triangles
//! that touch although they share no vertex (a mesh crossing itself, or folding onto itself).
//!
//! Cost: one BVH over the triangles (`TriangleSet`) and one query per triangle, in parallel.
//! Pairs that share a vertex are not tested (two triangles of one fan can still overlap if the
//! fan folds; the simplifier's projection test rules that out for the fans it makes).

use glam::DVec3;
use rayon::prelude::*;
use voxlod_core::TriangleMesh;

use super::obstacles::TriangleSet;
use super::EnvelopeError;

/// The pairs `(s, t)`, `s < t`, of triangles of `mesh` that share no vertex and touch (within
/// 10⁻⁹ of the bounding-box diagonal).
pub fn self_intersections(mesh: &TriangleMesh) -> Result<Vec<(u32, u32)>, EnvelopeError> {
    if mesh.triangles.is_empty() {
        return Ok(Vec::new());
    }
    let corners: Vec<[DVec3; 3]> = (0..mesh.triangles.len()).map(|t| mesh.corners(t)).collect();
    let tol = 1e-9 * mesh.bounds().diagonal();
    let set = TriangleSet::new(&corners, &mesh.triangles, tol)?;
    let mut pairs: Vec<(u32, u32)> = (0..mesh.triangles.len())
        .into_par_iter()
        .flat_map_iter(|s| {
            let mine = mesh.triangles[s];
            let mut found = Vec::new();
            set.each_touching(
                &corners[s],
                |ids, t| t as usize <= s || ids.iter().any(|v| mine.contains(v)),
                |t| found.push((s as u32, t)),
            );
            found
        })
        .collect();
    pairs.sort_unstable();
    Ok(pairs)
}
