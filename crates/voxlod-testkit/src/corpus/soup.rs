//! A broken export: a closed box (every face a 16×16 grid) with two fins glued on its top, a
//! few faults added, then written as a triangle soup (every triangle its own three vertices, as
//! STL stores them).
//!
//! The faults, each on triangles that share no vertex with one another, with a fin or with the
//! top face, so that every count below is exact after welding:
//! - [`DUPLICATES`] triangles stored twice (each of their 3 edges then used 3 times);
//! - [`FLIPPED`] triangles wound the wrong way (3 inconsistent edges each);
//! - [`ZERO_AREA`] extra triangles with a repeated corner;
//! - a fin standing on [`FIN_EDGES`] edges of the top face's grid (each used 3 times);
//! - a fin of two triangles whose base spans 4 grid edges in one (T-junctions at the 3 grid
//!   vertices inside it, which it only touches).

use std::collections::HashSet;

use glam::{DQuat, DVec3, Vec3};

use voxlod_core::TriangleMesh;

use super::build::{placed, subdivide};

/// Triangles stored twice.
pub(super) const DUPLICATES: usize = 154;
/// Triangles wound the wrong way.
pub(super) const FLIPPED: usize = 12;
/// Triangles with a repeated corner.
pub(super) const ZERO_AREA: usize = 8;
/// Grid edges under the glued fin.
pub(super) const FIN_EDGES: usize = 6;

/// The welded box [0, 2] × [0, 1]² with the fins and faults of the module docs (before the
/// soup is made of it). The grid's coordinates are multiples of 1/8 along x and 1/16 along y
/// and z, exact in f32, and so are the fins' base points.
pub(super) fn faulty_box() -> TriangleMesh {
    let cube = subdivide(&crate::shapes::unit_cube(), 4);
    let mut mesh = placed(
        &cube,
        DVec3::new(2.0, 1.0, 1.0),
        DQuat::IDENTITY,
        DVec3::ZERO,
    );
    let picked = disjoint_triangles(&mesh, DUPLICATES + FLIPPED + ZERO_AREA);
    let (duplicated, rest) = picked.split_at(DUPLICATES);
    let (flipped, zero_area) = rest.split_at(FLIPPED);
    for &t in duplicated {
        mesh.triangles.push(mesh.triangles[t]);
    }
    for &t in flipped {
        mesh.triangles[t].swap(1, 2);
    }
    for &t in zero_area {
        let [a, b, _] = mesh.triangles[t];
        mesh.triangles.push([a, a, b]);
    }
    add_fin(&mut mesh, (0.25, 0.5), (1.0, 0.5), FIN_EDGES, 0.2);
    add_fin(&mut mesh, (1.5, 0.25), (1.5, 0.5), 1, 0.15);
    mesh
}

/// `count` triangles of `mesh` off its top face (z = 1), no two sharing a vertex, picked in a
/// fixed scattered order.
fn disjoint_triangles(mesh: &TriangleMesh, count: usize) -> Vec<usize> {
    let n = mesh.triangles.len();
    let mut used: HashSet<u32> = HashSet::new();
    let mut picked = Vec::with_capacity(count);
    for t in (0..n).map(|i| (i * 7919) % n) {
        let corners = mesh.triangles[t];
        let on_top = corners.iter().any(|&v| mesh.positions[v as usize].z >= 1.0);
        if on_top || corners.iter().any(|v| used.contains(v)) {
            continue;
        }
        used.extend(corners);
        picked.push(t);
        if picked.len() == count {
            return picked;
        }
    }
    panic!("only {} disjoint triangles", picked.len());
}

/// A vertical strip of `segments` quads standing on the top face (z = 1) from `from` to `to`
/// (x, y), `height` tall, its base points at the same coordinates as the grid's vertices there.
fn add_fin(
    mesh: &mut TriangleMesh,
    from: (f32, f32),
    to: (f32, f32),
    segments: usize,
    height: f32,
) {
    let base = mesh.positions.len() as u32;
    // Steps of multiples of 1/16 from such a point: every base point exact.
    let step = (
        (to.0 - from.0) / segments as f32,
        (to.1 - from.1) / segments as f32,
    );
    for s in 0..=segments {
        let (x, y) = (from.0 + step.0 * s as f32, from.1 + step.1 * s as f32);
        mesh.positions.push(Vec3::new(x, y, 1.0));
        mesh.positions.push(Vec3::new(x, y, 1.0 + height));
    }
    for s in 0..segments as u32 {
        let (b0, t0, b1, t1) = (
            base + 2 * s,
            base + 2 * s + 1,
            base + 2 * s + 2,
            base + 2 * s + 3,
        );
        mesh.triangles.push([b0, b1, t1]);
        mesh.triangles.push([b0, t1, t0]);
    }
}

/// Every triangle of `mesh` with its own three vertices, in the same order: nothing welded.
pub(super) fn exploded(mesh: &TriangleMesh) -> TriangleMesh {
    let positions = mesh
        .triangles
        .iter()
        .flat_map(|t| t.map(|v| mesh.positions[v as usize]))
        .collect();
    let triangles = (0..mesh.triangles.len() as u32)
        .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
        .collect();
    TriangleMesh::new(positions, triangles)
}
