//! Closed triangle meshes made in code: for examples, tests and benchmarks that must not depend
//! on files. All are counter-clockwise seen from outside (positive enclosed volume).
//!
//! Two unit cubes with different vertex numberings: [`unit_cube`] (corner `x + 2y + 4z`) and
//! [`unit_cube_ringwise`] (around the bottom face, then the top), which hand-checked tests rely
//! on index by index.

use std::collections::HashMap;

use glam::{DVec3, Vec3};

use voxlod_core::TriangleMesh;

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
    let points: Vec<DVec3> = [
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
    let triangles: Vec<[u32; 3]> = vec![
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
    subdivided(points, triangles, levels, DVec3::normalize)
}

/// The mesh of `points` and `triangles` with every triangle split into four at its edges'
/// midpoints, `levels` times, each midpoint moved by `project` (the identity keeps it on its
/// triangle's plane; `normalize` puts it on the unit sphere), an edge's midpoint shared by its
/// two triangles: 4^levels times the triangles.
pub fn subdivided(
    mut points: Vec<DVec3>,
    mut triangles: Vec<[u32; 3]>,
    levels: u32,
    project: impl Fn(DVec3) -> DVec3,
) -> TriangleMesh {
    for _ in 0..levels {
        let mut midpoints: HashMap<(u32, u32), u32> = HashMap::new();
        let mut midpoint = |a: u32, b: u32, points: &mut Vec<DVec3>| -> u32 {
            *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
                points.push(project((points[a as usize] + points[b as usize]) * 0.5));
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

/// The unit cube [0, 1]³ with its vertices numbered counter-clockwise around the bottom face
/// (z = 0), then around the top: 8 vertices, 12 outward triangles.
pub fn unit_cube_ringwise() -> TriangleMesh {
    let p = Vec3::new;
    TriangleMesh::new(
        vec![
            p(0., 0., 0.),
            p(1., 0., 0.),
            p(1., 1., 0.),
            p(0., 1., 0.),
            p(0., 0., 1.),
            p(1., 0., 1.),
            p(1., 1., 1.),
            p(0., 1., 1.),
        ],
        vec![
            [0, 2, 1],
            [0, 3, 2],
            [4, 5, 6],
            [4, 6, 7],
            [0, 1, 5],
            [0, 5, 4],
            [1, 2, 6],
            [1, 6, 5],
            [2, 3, 7],
            [2, 7, 6],
            [3, 0, 4],
            [3, 4, 7],
        ],
    )
}

/// An [`icosphere`] of radius `radius` centred at `centre`.
pub fn icosphere_at(levels: u32, radius: f32, centre: Vec3) -> TriangleMesh {
    let mut mesh = icosphere(levels);
    mesh.positions
        .iter_mut()
        .for_each(|p| *p = *p * radius + centre);
    mesh
}

/// Appends `other` to `mesh` (its own vertices, indices shifted).
pub fn append(mesh: &mut TriangleMesh, other: &TriangleMesh) {
    let base = mesh.positions.len() as u32;
    mesh.positions.extend_from_slice(&other.positions);
    mesh.triangles
        .extend(other.triangles.iter().map(|t| t.map(|v| v + base)));
}

/// A box with a through-hole along z (genus 1), as a closed triangle mesh: the outer box
/// [-1, 1]² × [-0.5, 0.5] minus the square hole [-0.4, 0.4]².
pub fn holed_block() -> TriangleMesh {
    let (o, i, h) = (1.0f32, 0.4f32, 0.5f32);
    let mut positions = Vec::new();
    // Rings: outer and inner squares at bottom (z = -h) and top (z = +h).
    for &z in &[-h, h] {
        for &s in &[o, i] {
            positions.extend([
                Vec3::new(-s, -s, z),
                Vec3::new(s, -s, z),
                Vec3::new(s, s, z),
                Vec3::new(-s, s, z),
            ]);
        }
    }
    // Indices: bottom outer 0..4, bottom inner 4..8, top outer 8..12, top inner 12..16.
    let mut triangles = Vec::new();
    for k in 0..4u32 {
        let n = (k + 1) % 4;
        // Top face ring (normal +z) and bottom face ring (normal -z).
        triangles.push([8 + k, 8 + n, 12 + n]);
        triangles.push([8 + k, 12 + n, 12 + k]);
        triangles.push([k, 4 + n, n]);
        triangles.push([k, 4 + k, 4 + n]);
        // Outer walls (normal outwards) and inner walls (normal into the hole).
        triangles.push([k, n, 8 + n]);
        triangles.push([k, 8 + n, 8 + k]);
        triangles.push([4 + k, 12 + n, 4 + n]);
        triangles.push([4 + k, 12 + k, 12 + n]);
    }
    TriangleMesh::new(positions, triangles)
}

/// A closed prism along x from 0 to `length`: rings of the cross-section `section` (y, z
/// points, counter-clockwise) every `spacing` starting at `spacing / 2`, closed by a fan to a
/// centre point at each end (x = 0 and x = `length`).
pub fn prism(section: &[(f32, f32)], length: f32, spacing: f32) -> TriangleMesh {
    let n = section.len() as u32;
    let rings = (length / spacing).round() as u32;
    let mut positions = Vec::new();
    for r in 0..rings {
        let x = spacing * (r as f32 + 0.5);
        for &(y, z) in section {
            positions.push(Vec3::new(x, y, z));
        }
    }
    let start = positions.len() as u32;
    positions.push(Vec3::ZERO);
    positions.push(Vec3::new(length, 0.0, 0.0));
    let mut triangles = Vec::new();
    for r in 0..rings - 1 {
        for i in 0..n {
            let a = r * n + i;
            let b = r * n + (i + 1) % n;
            let (c, d) = (a + n, b + n);
            triangles.push([a, b, d]);
            triangles.push([a, d, c]);
        }
    }
    let last = (rings - 1) * n;
    for i in 0..n {
        triangles.push([start, (i + 1) % n, i]);
        triangles.push([start + 1, last + i, last + (i + 1) % n]);
    }
    TriangleMesh::new(positions, triangles)
}

/// A regular `n`-gon of diameter `d` centred on the x axis, as (y, z) points
/// counter-clockwise: a [`prism`]'s cross-section.
pub fn round_section(n: usize, d: f32) -> Vec<(f32, f32)> {
    (0..n)
        .map(|i| {
            let a = i as f32 * std::f32::consts::TAU / n as f32;
            (0.5 * d * a.cos(), 0.5 * d * a.sin())
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use voxlod_core::mesh_topology;

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
