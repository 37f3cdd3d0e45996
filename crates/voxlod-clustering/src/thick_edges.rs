//! Thick edges, Low–Tan step 5: a width and a normal for every dangling edge, so that the
//! renderer can draw the strip of triangles that collapsed onto it as a thick line, shaded.
//!
//! The patent asks, "for each group of triangles which are going to degenerate into the same
//! edge", for "an estimate for the thickness of the group", to be drawn as a multi-pixel line
//! with a "dynamic normal" computed for it. It gives no formula; ours:
//!
//! - **Width**: `A / (π ℓ)`, with `A` the total area of the group's original triangles and `ℓ`
//!   their extent along the edge. The triangles that collapse onto an edge are the wall of a thin
//!   part (a rod, a fin, a rim) over a length `ℓ`; its cross-section has perimeter `P ≈ A / ℓ`,
//!   and by Cauchy's formula a convex cross-section seen from a random direction across the edge
//!   is `P / π` wide on average: a round rod of diameter `D` gets `D`, a square bar of side `t`
//!   gets `4t/π`, a closed slab of width `w` and thickness `d` gets `2(w + d)/π`. The estimate
//!   does not depend on where the representatives sit (on the axis or on the surface). An open
//!   ribbon, one-sided, gets half of its mean width. If `ℓ` is 0, or the estimate exceeds the
//!   diagonal of the group's extent across the edge, that diagonal is the width.
//! - **Normal**: the area-weighted mean of the group's triangle normals with its component along
//!   the edge removed, normalised. For a closed rod these cancel; any unit vector across the edge
//!   is then stored. A line has no normal of its own: the renderer turns the stored one about the
//!   edge until it faces the viewer, see [`dynamic_normal`]; the stored one is what is left when
//!   the viewer looks along the edge.
//!
//! Both are stored as line attributes of the output: `width`, `normal_x`, `normal_y`, `normal_z`.
//!
//! Cost: one parallel pass over the original triangles, a binary search among the dangling edges
//! for each triangle that collapses to an edge, and a radix sort of those, O(T + G log E).

use glam::{DVec3, Vec3};
use rayon::prelude::*;
use voxlod_core::{Attribute, PolyMesh, TriangleMesh};

use crate::sort::{bits_for, radix_sort_by_key};

/// Width and static normal of one dangling edge.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThickEdge {
    /// Estimated thickness of the collapsed part, in the mesh's units.
    pub width: f32,
    /// Unit vector across the edge (see the module documentation).
    pub normal: Vec3,
}

/// Name of the line attribute that [`attach`] writes the widths to.
pub const WIDTH: &str = "width";
/// Names of the line attributes that [`attach`] writes the normals' x, y and z to.
pub const NORMAL: [&str; 3] = ["normal_x", "normal_y", "normal_z"];

/// For each of `edges` (cluster ids `[a, b]`, `a < b`, sorted), the width and normal of the group
/// of `original`'s triangles that collapse onto it when vertex `v` goes to cluster
/// `cluster_of[v]`, whose representative is `positions[cluster]`.
pub fn thick_edges(
    original: &TriangleMesh,
    cluster_of: &[u32],
    positions: &[Vec3],
    edges: &[[u32; 2]],
) -> Vec<ThickEdge> {
    debug_assert!(edges.windows(2).all(|w| w[0] < w[1]));
    debug_assert!(edges.iter().all(|e| e[0] < e[1]));
    if edges.is_empty() {
        return Vec::new();
    }
    // (edge, triangle) for every triangle that collapses onto a dangling edge.
    let mut members: Vec<(u32, u32)> = original
        .triangles
        .par_iter()
        .enumerate()
        .with_min_len(1 << 14)
        .filter_map(|(t, tri)| {
            let [a, b, c] = tri.map(|v| cluster_of[v as usize]);
            let (p, q) = if a == b && b != c {
                (a, c)
            } else if (b == c || a == c) && a != b {
                (a, b)
            } else {
                return None;
            };
            let key = [p.min(q), p.max(q)];
            edges.binary_search(&key).ok().map(|e| (e as u32, t as u32))
        })
        .collect();
    radix_sort_by_key(&mut members, bits_for(edges.len()), |m| m.0 as u64);

    let mut starts = vec![0usize; edges.len() + 1];
    for m in &members {
        starts[m.0 as usize + 1] += 1;
    }
    for i in 0..edges.len() {
        starts[i + 1] += starts[i];
    }
    (0..edges.len())
        .into_par_iter()
        .map(|e| {
            let group = members[starts[e]..starts[e + 1]]
                .iter()
                .map(|m| m.1 as usize);
            let [a, b] = edges[e];
            estimate(
                original,
                group,
                positions[a as usize],
                positions[b as usize],
            )
        })
        .collect()
}

/// The estimate for one group of triangles collapsing onto the edge from `a` to `b`.
pub fn estimate(
    original: &TriangleMesh,
    group: impl Iterator<Item = usize>,
    a: Vec3,
    b: Vec3,
) -> ThickEdge {
    let u = (b - a).as_dvec3().try_normalize().unwrap_or(DVec3::X);
    let (e1, e2) = u.any_orthonormal_pair();
    let mut area = 0.0f64;
    let mut normal = DVec3::ZERO;
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for t in group {
        let [p, q, r] = original.corners(t);
        let n = 0.5 * (q - p).cross(r - p);
        area += n.length();
        normal += n;
        for x in [p, q, r] {
            for (axis, d) in [u, e1, e2].into_iter().enumerate() {
                let s = x.dot(d);
                lo[axis] = lo[axis].min(s);
                hi[axis] = hi[axis].max(s);
            }
        }
    }
    if area == 0.0 || !lo[0].is_finite() {
        return ThickEdge {
            width: 0.0,
            normal: e1.as_vec3(),
        };
    }
    let length = hi[0] - lo[0];
    let across = (hi[1] - lo[1]).hypot(hi[2] - lo[2]);
    let width = if length > 0.0 {
        (area / (std::f64::consts::PI * length)).min(across)
    } else {
        across
    };
    let n = normal - normal.dot(u) * u;
    let normal = if n.length() > 1e-6 * area {
        n.normalize()
    } else {
        e1
    };
    ThickEdge {
        width: width as f32,
        normal: normal.as_vec3(),
    }
}

/// The patent's dynamic normal: the unit vector across the edge from `a` to `b` that faces the
/// viewer, `towards_viewer` being the direction from the edge to the eye. When the viewer looks
/// along the edge, `stored` (the normal kept with the edge).
pub fn dynamic_normal(a: Vec3, b: Vec3, stored: Vec3, towards_viewer: Vec3) -> Vec3 {
    let Some(u) = (b - a).try_normalize() else {
        return stored;
    };
    let across = towards_viewer - towards_viewer.dot(u) * u;
    across.try_normalize().unwrap_or(stored)
}

/// Stores `edges` (one per line of `poly`) as the line attributes `width` and `normal_x/y/z`.
pub fn attach(poly: &mut PolyMesh, edges: &[ThickEdge]) {
    assert_eq!(edges.len(), poly.lines.len(), "one thick edge per line");
    poly.line_attributes
        .retain(|a| a.name != WIDTH && !NORMAL.contains(&a.name.as_str()));
    poly.line_attributes.push(Attribute {
        name: WIDTH.to_string(),
        values: edges.iter().map(|e| e.width).collect(),
    });
    for (axis, name) in NORMAL.iter().enumerate() {
        poly.line_attributes.push(Attribute {
            name: name.to_string(),
            values: edges.iter().map(|e| e.normal[axis]).collect(),
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dynamic_normal_faces_the_viewer() {
        let n = dynamic_normal(Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(3.0, 0.0, 2.0));
        assert!((n - Vec3::Z).length() < 1e-6);
        let n = dynamic_normal(Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(-5.0, 0.0, 0.0));
        assert_eq!(n, Vec3::Y);
    }

    #[test]
    fn a_flat_strip_keeps_its_face_normal() {
        // Two triangles of a 1 × 0.1 strip in the z = 0 plane, collapsing onto the x axis.
        let mesh = TriangleMesh::new(
            vec![
                Vec3::ZERO,
                Vec3::X,
                Vec3::new(1.0, 0.1, 0.0),
                Vec3::new(0.0, 0.1, 0.0),
            ],
            vec![[0, 1, 2], [0, 2, 3]],
        );
        let e = estimate(&mesh, 0..2, Vec3::ZERO, Vec3::X);
        assert!((e.normal - Vec3::Z).length() < 1e-6, "{e:?}");
        // One-sided: area 0.1 over length 1, half the strip's mean width 2·0.1/π.
        assert!((e.width - 0.1 / std::f32::consts::PI).abs() < 1e-6, "{e:?}");
    }
}
