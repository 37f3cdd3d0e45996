//! Inside or outside a closed surface, by the parity of a ray's crossings (the rule by which
//! the voxel paper's samplers decide inside, §2). Cost: O(F) per point, one ray-triangle test
//! (Möller and Trumbore 1997) per triangle.

use glam::DVec3;

use crate::TriangleMesh;

/// The fixed direction of the rays: no axis-aligned or diagonal feature of a typical model
/// contains it (a ray through an edge or a vertex exactly is not handled specially).
const RAY: DVec3 = DVec3::new(0.8017, 0.4479, 0.3959);

/// Whether `point` lies inside the closed surface made of `triangles` of `mesh`: an odd number
/// of them cross the ray from `point`.
///
/// ```
/// use voxlod_core::parity::point_inside;
/// use voxlod_core::{glam::{DVec3, Vec3}, TriangleMesh};
///
/// let tetrahedron = TriangleMesh::new(
///     vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z],
///     vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
/// );
/// assert!(point_inside(&tetrahedron, 0..4, DVec3::splat(0.2)));
/// assert!(!point_inside(&tetrahedron, 0..4, DVec3::splat(0.4)));
/// ```
pub fn point_inside(
    mesh: &TriangleMesh,
    triangles: impl IntoIterator<Item = usize>,
    point: DVec3,
) -> bool {
    let direction = RAY.normalize();
    let crossings = triangles
        .into_iter()
        .filter(|&t| ray_crosses(point, direction, mesh.corners(t)))
        .count();
    crossings % 2 == 1
}

/// Whether the ray from `origin` along `direction` crosses triangle `[a, b, c]` at a positive
/// distance.
fn ray_crosses(origin: DVec3, direction: DVec3, [a, b, c]: [DVec3; 3]) -> bool {
    let (e1, e2) = (b - a, c - a);
    let p = direction.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-300 {
        return false;
    }
    let s = origin - a;
    let u = s.dot(p) / det;
    if !(0.0..=1.0).contains(&u) {
        return false;
    }
    let q = s.cross(e1);
    let v = direction.dot(q) / det;
    if v < 0.0 || u + v > 1.0 {
        return false;
    }
    e2.dot(q) / det > 0.0
}
