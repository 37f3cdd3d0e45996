//! Edges the simplification must keep (paper §6.5, "preserving user-specified edges"): edges
//! whose dihedral angle exceeds a threshold, i.e. sharp features.
//!
//! The paper keeps an edge by making its bilinear patch "opaque" to candidate triangles. In the
//! vertex-removal variant an edge disappears only when one of its ends is removed (new triangles
//! only add diagonals), so keeping an edge is keeping both its ends: every vertex of a sharp edge
//! is fixed. Cost: O(F) with each vertex's star.

use glam::DVec3;

use super::base::Base;

/// Vertices on an edge whose two triangles' normals differ by more than `degrees`, and the
/// number of such edges.
pub(crate) fn sharp_vertices(base: &Base, degrees: f64) -> (Vec<bool>, usize) {
    let cos_limit = degrees.to_radians().cos();
    let normal = |t: usize| {
        let [a, b, c] = base.corners(t);
        (b - a).cross(c - a).normalize_or_zero()
    };
    let mut sharp = vec![false; base.vertex_count()];
    let mut edges = 0;
    for (t, tri) in base.tris.iter().enumerate() {
        for e in 0..3 {
            let (a, b) = (tri[e], tri[(e + 1) % 3]);
            // The other triangle on a–b runs b → a; count each edge once, from its a < b side.
            let Some(&u) = base.star(a as usize).iter().find(|&&u| {
                let o = base.tris[u as usize];
                u as usize != t && (0..3).any(|i| o[i] == b && o[(i + 1) % 3] == a)
            }) else {
                continue;
            };
            if a > b {
                continue;
            }
            let (n1, n2) = (normal(t), normal(u as usize));
            if n1 == DVec3::ZERO || n2 == DVec3::ZERO {
                continue;
            }
            if n1.dot(n2) < cos_limit {
                edges += 1;
                sharp[a as usize] = true;
                sharp[b as usize] = true;
            }
        }
    }
    (sharp, edges)
}
