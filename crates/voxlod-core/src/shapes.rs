//! Closed triangle meshes made in code: for examples, tests and benchmarks that must not depend
//! on files. All are counter-clockwise seen from outside (positive enclosed volume).

use std::collections::HashMap;

use glam::{DVec3, Vec3};

use crate::TriangleMesh;

/// The unit cube [0, 1]³: 8 vertices, 12 triangles.
pub fn unit_cube() -> TriangleMesh {
    let positions = (0..8)
        .map(|c| Vec3::new((c & 1) as f32, ((c >> 1) & 1) as f32, ((c >> 2) & 1) as f32))
        .collect();
    // Corner c = x + 2y + 4z; two triangles per face.
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

/// The icosahedron subdivided `levels` times, vertices on the unit sphere (computed in f64):
/// 20·4^levels triangles.
pub fn icosphere(levels: u32) -> TriangleMesh {
    let phi = (1.0 + 5f64.sqrt()) / 2.0;
    let mut points: Vec<DVec3> = [
        (-1.0, phi, 0.0),
        (1.0, phi, 0.0),
        (-1.0, -phi, 0.0),
        (1.0, -phi, 0.0),
        (0.0, -1.0, phi),
        (0.0, 1.0, phi),
        (0.0, -1.0, -phi),
        (0.0, 1.0, -phi),
        (phi, 0.0, -1.0),
        (phi, 0.0, 1.0),
        (-phi, 0.0, -1.0),
        (-phi, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| DVec3::new(x, y, z).normalize())
    .collect();
    let mut triangles: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..levels {
        let mut midpoints: HashMap<(u32, u32), u32> = HashMap::new();
        let mut midpoint = |a: u32, b: u32, points: &mut Vec<DVec3>| -> u32 {
            *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
                points.push(((points[a as usize] + points[b as usize]) * 0.5).normalize());
                points.len() as u32 - 1
            })
        };
        let mut finer = Vec::with_capacity(triangles.len() * 4);
        for &[a, b, c] in &triangles {
            let ab = midpoint(a, b, &mut points);
            let bc = midpoint(b, c, &mut points);
            let ca = midpoint(c, a, &mut points);
            finer.extend_from_slice(&[[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        triangles = finer;
    }
    TriangleMesh::new(points.iter().map(|p| p.as_vec3()).collect(), triangles)
}

/// A torus around the z axis: major radius `major`, tube radius `tube(u, v)` at the angles `u`
/// around the axis and `v` around the tube, as an `n × m` grid of quads (2nm triangles).
pub fn torus_with(n: u32, m: u32, major: f64, tube: impl Fn(f64, f64) -> f64) -> TriangleMesh {
    let tau = std::f64::consts::TAU;
    let mut positions = Vec::with_capacity((n * m) as usize);
    for i in 0..n {
        let u = tau * i as f64 / n as f64;
        for j in 0..m {
            let v = tau * j as f64 / m as f64;
            let r = tube(u, v);
            positions.push(
                DVec3::new(
                    (major + r * v.cos()) * u.cos(),
                    (major + r * v.cos()) * u.sin(),
                    r * v.sin(),
                )
                .as_vec3(),
            );
        }
    }
    let id = |i: u32, j: u32| (i % n) * m + (j % m);
    let mut triangles = Vec::with_capacity((2 * n * m) as usize);
    for i in 0..n {
        for j in 0..m {
            triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    TriangleMesh::new(positions, triangles)
}

/// A round torus: major radius `major`, tube radius `minor`.
pub fn torus(n: u32, m: u32, major: f64, minor: f64) -> TriangleMesh {
    torus_with(n, m, major, |_, _| minor)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh_topology;

    #[test]
    fn shapes_are_closed_outward_and_of_the_right_genus() {
        for (mesh, genus, volume) in [
            (unit_cube(), 0, 1.0),
            (icosphere(3), 0, 4.0 / 3.0 * std::f64::consts::PI),
            (
                torus(64, 32, 2.0, 0.5),
                1,
                2.0 * std::f64::consts::PI.powi(2) * 2.0 * 0.25,
            ),
        ] {
            let t = mesh_topology(&mesh);
            assert!(
                t.is_closed_manifold() && t.is_consistently_oriented(),
                "{t:?}"
            );
            assert_eq!(t.genus, Some(genus));
            let v = mesh.signed_volume();
            assert!(
                v > 0.0 && (v / volume - 1.0).abs() < 0.03,
                "{v} vs {volume}"
            );
        }
    }
}
