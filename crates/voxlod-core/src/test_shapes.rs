//! The unit cube and the octahedron for this crate's unit tests: `voxlod-testkit`, which has it too, depends on
//! this crate and so cannot serve its unit tests.

use glam::Vec3;

use crate::TriangleMesh;

/// The unit cube [0, 1]³: 8 vertices (corner `x + 2y + 4z`), 12 outward triangles.
pub fn unit_cube() -> TriangleMesh {
    let positions = (0..8)
        .map(|c| Vec3::new((c & 1) as f32, ((c >> 1) & 1) as f32, ((c >> 2) & 1) as f32))
        .collect();
    let triangles = vec![
        [0, 2, 1],
        [1, 2, 3],
        [4, 5, 6],
        [5, 7, 6],
        [0, 1, 4],
        [1, 5, 4],
        [2, 6, 3],
        [3, 6, 7],
        [0, 4, 2],
        [2, 4, 6],
        [1, 3, 5],
        [3, 7, 5],
    ];
    TriangleMesh::new(positions, triangles)
}

/// The octahedron with vertices at ±1 on each axis: 6 vertices, 8 outward triangles.
pub fn octahedron() -> TriangleMesh {
    let p = vec![Vec3::X, Vec3::Y, -Vec3::X, -Vec3::Y, Vec3::Z, -Vec3::Z];
    let t = vec![
        [0, 1, 4],
        [1, 2, 4],
        [2, 3, 4],
        [3, 0, 4],
        [1, 0, 5],
        [2, 1, 5],
        [3, 2, 5],
        [0, 3, 5],
    ];
    TriangleMesh::new(p, t)
}
