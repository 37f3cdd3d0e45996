//! A scan-like closed surface with holes and cracks: a bumpy sphere (a longitude–latitude grid,
//! radius modulated by low-frequency sines plus a little noise), open where six caps were not
//! captured, and with three seams along meridians where the scanner's patches meet: the seam's
//! vertices are stored twice (same position, different index), the triangles on one side using
//! one copy, the other side the other.
//!
//! Before welding, each seam is a slit: one more boundary loop. Welding closes the slits and
//! leaves exactly the six holes.

use glam::DVec3;

use voxlod_core::TriangleMesh;

use super::build::{hash_noise, polar_surface, sphere_direction};

/// Longitudes and latitude bands of the grid.
const NU: u32 = 160;
const NV: u32 = 120;

/// The holes: (longitude, latitude, angular radius), in degrees; apart from each other, from the
/// poles and from the seams.
pub(super) const HOLES: [(f64, f64, f64); 6] = [
    (40.0, 20.0, 14.0),
    (80.0, -35.0, 6.0),
    (165.0, 10.0, 20.0),
    (200.0, 45.0, 3.5),
    (290.0, -15.0, 10.0),
    (320.0, 50.0, 8.0),
];

/// The seams: (longitude column, first and last latitude ring stored twice).
pub(super) const SEAMS: [(u32, u32, u32); 3] = [(0, 12, 108), (53, 25, 105), (107, 15, 95)];

/// The scan at scale `scale` (module docs): 36 188 triangles; the seams' 259 duplicated
/// vertices are all used, and no vertex is unused.
pub(super) fn scan(scale: f64) -> TriangleMesh {
    let radius = |d: DVec3| {
        1.0 + 0.07 * (3.0 * d.x + 0.5).sin() * (2.0 * d.y).cos()
            + 0.05 * (2.0 * d.z + 1.3 * d.x).sin()
            + 0.03 * (5.0 * d.y - d.z).cos()
    };
    let mut mesh = polar_surface(NU, NV, true, |i, j| {
        let d = sphere_direction(i, j, NU, NV);
        d * scale * (radius(d) + 0.003 * hash_noise(i % NU, j))
    });
    cut_holes(&mut mesh);
    for (column, first, last) in SEAMS {
        split_seam(&mut mesh, column, first, last);
    }
    mesh.remove_unreferenced_vertices();
    mesh
}

/// Removes every triangle with a corner inside one of [`HOLES`] (by the grid's directions).
fn cut_holes(mesh: &mut TriangleMesh) {
    let centres: Vec<(DVec3, f64)> = HOLES
        .iter()
        .map(|&(lon, lat, r)| {
            let (lon, lat) = (lon.to_radians(), lat.to_radians());
            let centre = DVec3::new(lat.cos() * lon.cos(), lat.cos() * lon.sin(), lat.sin());
            (centre, r.to_radians().cos())
        })
        .collect();
    let inside: Vec<bool> = (0..mesh.positions.len() as u32)
        .map(|v| {
            let d = vertex_direction(v);
            centres.iter().any(|&(c, cos)| d.dot(c) > cos)
        })
        .collect();
    mesh.triangles
        .retain(|t| t.iter().all(|&v| !inside[v as usize]));
}

/// The grid direction of vertex `v` of the [`polar_surface`] layout.
fn vertex_direction(v: u32) -> DVec3 {
    let last = 1 + (NV - 1) * NU;
    match v {
        0 => sphere_direction(0, 0, NU, NV),
        _ if v == last => sphere_direction(0, NV, NU, NV),
        _ => sphere_direction((v - 1) % NU, 1 + (v - 1) / NU, NU, NV),
    }
}

/// Stores the vertices of longitude `column`, rings `first..=last`, twice: the triangles east
/// of the meridian (those with a corner in the next column) use the new copies.
fn split_seam(mesh: &mut TriangleMesh, column: u32, first: u32, last: u32) {
    let ring = |i: u32, j: u32| 1 + (j - 1) * NU + i % NU;
    let east = |v: u32| v != 0 && v <= (NV - 1) * NU && (v - 1) % NU == (column + 1) % NU;
    for j in first..=last {
        let original = ring(column, j);
        let copy = mesh.positions.len() as u32;
        mesh.positions.push(mesh.positions[original as usize]);
        for t in mesh.triangles.iter_mut() {
            if t.contains(&original) && t.iter().any(|&v| east(v)) {
                t.iter_mut()
                    .filter(|v| **v == original)
                    .for_each(|v| *v = copy);
            }
        }
    }
}
