//! A level's corners grouped into smooth fans, for an atlas whose charts cut along creases:
//! the corners of a vertex are one group where its triangles meet across edges that bend by
//! at most the crease angle, and each group becomes a vertex of its own with one normal. An
//! edge between two groups (a crease, or a non-manifold or boundary edge) is where xatlas
//! sees a normal seam and so a chart border.
//!
//! A group's normal is the level's own vertex normal where the vertex is one group (no crease
//! there) and the level has normals (a voxel level's gradient normals), else the
//! angle-weighted mean of its triangles' normals (Thürmer and Wüthrich 1998).
//!
//! Cost: O(T log T) for T triangles (the edges sorted), then linear.

use voxlod_core::glam::Vec3;
use voxlod_core::TriangleMesh;

/// The level with its vertices split at creases.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Creased {
    /// One per group.
    pub positions: Vec<Vec3>,
    /// Unit normal of each group.
    pub normals: Vec<Vec3>,
    /// The level's triangles, naming groups.
    pub triangles: Vec<[u32; 3]>,
    /// The level vertex each group belongs to.
    pub level_vertex: Vec<u32>,
}

/// Groups `level`'s corners into smooth fans; edges bending by more than `crease_degrees`
/// separate them. The level's indices must be in range.
pub fn crease(level: &TriangleMesh, crease_degrees: f32) -> Creased {
    let faces: Vec<Vec3> = level
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| level.positions[v as usize]);
            (b - a).cross(c - a).normalize_or_zero()
        })
        .collect();
    let cos_crease = crease_degrees.to_radians().cos();
    // Each corner is linked to the corner of the same vertex across each of its two edges
    // where that edge is smooth; a group is a chain of links.
    let mut links = vec![[NONE; 2]; level.triangles.len() * 3];
    for pair in manifold_edges(&level.triangles) {
        let (s, t) = (pair.first_triangle, pair.second_triangle);
        if faces[s].dot(faces[t]) >= cos_crease {
            for end in 0..2 {
                let (a, b) = (
                    3 * s + pair.first_corners[end],
                    3 * t + pair.second_corners[end],
                );
                link(&mut links, a, b);
                link(&mut links, b, a);
            }
        }
    }
    let mut group_of = vec![NONE; links.len()];
    let mut creased = Creased::default();
    let mut sums: Vec<Vec3> = Vec::new();
    let mut groups_at_vertex = vec![0u32; level.positions.len()];
    let mut pending = Vec::new();
    for first in 0..links.len() {
        if group_of[first] != NONE {
            continue;
        }
        let group = creased.positions.len() as u32;
        let v = level.triangles[first / 3][first % 3];
        creased.positions.push(level.positions[v as usize]);
        creased.level_vertex.push(v);
        groups_at_vertex[v as usize] += 1;
        let mut sum = Vec3::ZERO;
        group_of[first] = group;
        pending.push(first);
        while let Some(corner) = pending.pop() {
            let (t, k) = (corner / 3, corner % 3);
            sum += faces[t] * corner_angle(level, &level.triangles[t], k);
            for &next in &links[corner] {
                if next != NONE && group_of[next as usize] == NONE {
                    group_of[next as usize] = group;
                    pending.push(next as usize);
                }
            }
        }
        sums.push(sum);
    }
    creased.triangles = group_of
        .chunks_exact(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect();
    let own = level.normals.len() == level.positions.len();
    creased.normals = sums
        .iter()
        .zip(&creased.level_vertex)
        .map(|(&sum, &v)| {
            let stored = level.normals.get(v as usize).copied().unwrap_or(Vec3::ZERO);
            if own && groups_at_vertex[v as usize] == 1 && stored.length_squared() > 0.0 {
                stored.normalize()
            } else {
                sum.try_normalize().unwrap_or(Vec3::Z)
            }
        })
        .collect();
    creased
}

/// No corner.
const NONE: u32 = u32::MAX;

/// Records `to` as a smooth neighbour of corner `from` (a corner has at most two).
fn link(links: &mut [[u32; 2]], from: usize, to: usize) {
    let slot = if links[from][0] == NONE { 0 } else { 1 };
    links[from][slot] = to as u32;
}

/// The angle of triangle `tri` at its corner `k`.
fn corner_angle(level: &TriangleMesh, tri: &[u32; 3], k: usize) -> f32 {
    let p = |i: usize| level.positions[tri[i % 3] as usize];
    let (e0, e1) = (p(k + 1) - p(k), p(k + 2) - p(k));
    e0.angle_between(e1).max(0.0)
}

/// An interior edge shared by exactly two triangles that wind it in opposite directions,
/// with the corners (0..3) each triangle has at the edge's two ends, in the same order.
struct EdgePair {
    first_triangle: usize,
    first_corners: [usize; 2],
    second_triangle: usize,
    second_corners: [usize; 2],
}

/// The manifold, consistently oriented interior edges of `triangles`.
fn manifold_edges(triangles: &[[u32; 3]]) -> Vec<EdgePair> {
    // (low vertex, high vertex, triangle, corner at low, corner at high, forward)
    let mut half: Vec<(u32, u32, usize, usize, usize, bool)> = triangles
        .iter()
        .enumerate()
        .flat_map(|(t, tri)| {
            (0..3).map(move |k| {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                if a < b {
                    (a, b, t, k, (k + 1) % 3, true)
                } else {
                    (b, a, t, (k + 1) % 3, k, false)
                }
            })
        })
        .filter(|h| h.0 != h.1)
        .collect();
    half.sort_unstable_by_key(|h| (h.0, h.1));
    let mut pairs = Vec::new();
    let mut i = 0;
    while i < half.len() {
        let mut j = i + 1;
        while j < half.len() && (half[j].0, half[j].1) == (half[i].0, half[i].1) {
            j += 1;
        }
        if j - i == 2 && half[i].5 != half[i + 1].5 {
            let (s, t) = (half[i], half[i + 1]);
            pairs.push(EdgePair {
                first_triangle: s.2,
                first_corners: [s.3, s.4],
                second_triangle: t.2,
                second_corners: [t.3, t.4],
            });
        }
        i = j;
    }
    pairs
}
