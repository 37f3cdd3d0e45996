//! Point seams: the vertices of one position whose attributes differ only at that point, such
//! as a latitude-longitude sphere's pole or a cone's apex, where one position is held by a
//! vertex per segment, each with its own texture coordinate.
//!
//! Two vertices `a` and `a'` of one position are joined by a point seam when an edge leaves
//! that position towards one vertex `b` on both sides: the triangles on the two sides of the
//! edge name `(a, b)` and `(b, a')`. The texture is then discontinuous at the position only,
//! not along the edge (on a curve seam, a UV seam of non-zero length, both ends of the edge
//! differ between the sides). The vertices of a position joined by point seams into a group of
//! at least [`SeamOptions::min_fan`] are a fan whose texture coordinates degenerate to a
//! point of the surface; meshoptimizer sees each as a seam of its own and keeps the fan whole.
//! Welded into one vertex for a collapse (their triangles unchanged), they collapse as one;
//! each triangle of the level then takes back the member whose attributes suit it
//! ([`resolve`]).
//!
//! Cost: linear in the triangles (hash maps of positions and edges).

use std::collections::HashMap;

use voxlod_core::glam::{IVec3, Vec3};
use voxlod_core::memory::{bytes_of, check_allocation};

use crate::{AssetError, AssetMesh};

/// Options of [`point_seams`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SeamOptions {
    /// Fewest vertices of one position joined by point seams that are welded. Two vertices
    /// joined by one point seam are also how a curve seam ends inside a surface (a slit),
    /// where welding would lose the seam's last vertex; a fan of three or more is a pole.
    pub min_fan: usize,
    /// Vertices closer than this, relative to the diagonal of the mesh's box, hold one
    /// position: a pole generated with `sin(π)` is a ring of vertices about 1e-7 of the
    /// radius apart. Zero compares coordinates bit for bit, as meshoptimizer does.
    pub tolerance: f32,
}

impl Default for SeamOptions {
    fn default() -> Self {
        SeamOptions {
            min_fan: 3,
            tolerance: 1e-6,
        }
    }
}

/// The vertices welded at point seams: for each vertex, the vertex that stands for its group
/// (itself when it is in no group), and each group's members.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PointSeams {
    /// The representative of each vertex.
    pub representative: Vec<u32>,
    /// The members of each group with more than one vertex, by representative.
    pub members: HashMap<u32, Vec<u32>>,
}

impl PointSeams {
    /// No vertex welded, for `n` vertices.
    pub fn none(n: usize) -> Self {
        PointSeams {
            representative: (0..n as u32).collect(),
            members: HashMap::new(),
        }
    }

    /// How many groups were welded.
    pub fn groups(&self) -> usize {
        self.members.len()
    }
}

/// The point-seam groups of `mesh` (module docs). Vertices of one position are those within
/// [`SeamOptions::tolerance`]. Asks the memory limit for its tables.
pub fn point_seams(mesh: &AssetMesh, options: &SeamOptions) -> Result<PointSeams, AssetError> {
    let n = mesh.positions.len();
    check_allocation("the point seams' tables", bytes_of::<[u32; 4]>(n))?;
    let position = position_ids(mesh, options.tolerance);
    // Directed edges by their positions: the vertices that name them.
    let mut edges: HashMap<(u32, u32), Vec<(u32, u32)>> = HashMap::new();
    for t in &mesh.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let key = (position[a as usize], position[b as usize]);
            if key.0 != key.1 {
                edges.entry(key).or_default().push((a, b));
            }
        }
    }
    let mut parent: Vec<u32> = (0..n as u32).collect();
    for (&(pa, pb), named) in &edges {
        let Some(opposite) = edges.get(&(pb, pa)) else {
            continue;
        };
        for &(a, b) in named {
            for &(b2, a2) in opposite {
                if b == b2 && a != a2 {
                    union(&mut parent, a, a2);
                }
            }
        }
    }
    let mut members: HashMap<u32, Vec<u32>> = HashMap::new();
    for v in 0..n as u32 {
        let root = find(&mut parent, v);
        members.entry(root).or_default().push(v);
    }
    // A group's root is its smallest vertex (union keeps the smaller root).
    members.retain(|_, group| group.len() >= options.min_fan.max(2));
    let mut representative: Vec<u32> = (0..n as u32).collect();
    for (&root, group) in &members {
        for &v in group {
            representative[v as usize] = root;
        }
    }
    Ok(PointSeams {
        representative,
        members,
    })
}

/// A position id per vertex: vertices within `tolerance` of the box's diagonal of each other
/// (through cells of that size and their neighbours) share one.
fn position_ids(mesh: &AssetMesh, tolerance: f32) -> Vec<u32> {
    let (lo, hi) = mesh.positions.iter().fold(
        (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    let eps = tolerance * (hi - lo).length();
    if eps.is_nan() || eps <= 0.0 {
        let mut ids: HashMap<[u32; 3], u32> = HashMap::new();
        return (mesh.positions.iter())
            .map(|p| {
                let next = ids.len() as u32;
                *ids.entry(p.to_array().map(f32::to_bits)).or_insert(next)
            })
            .collect();
    }
    let cell = |p: Vec3| ((p - lo) / eps).floor().as_ivec3();
    // The first vertex of each occupied cell.
    let mut first: HashMap<IVec3, u32> = HashMap::new();
    for (v, &p) in mesh.positions.iter().enumerate() {
        first.entry(cell(p)).or_insert(v as u32);
    }
    let mut parent: Vec<u32> = (0..mesh.positions.len() as u32).collect();
    for (v, &p) in mesh.positions.iter().enumerate() {
        let c = cell(p);
        for offset in neighbours() {
            if let Some(&w) = first.get(&(c + offset)) {
                if mesh.positions[w as usize].distance(p) <= eps {
                    union(&mut parent, v as u32, w);
                }
            }
        }
    }
    (0..mesh.positions.len() as u32)
        .map(|v| find(&mut parent, v))
        .collect()
}

/// The 27 cell offsets of a cell's neighbourhood, itself included.
fn neighbours() -> impl Iterator<Item = IVec3> {
    (-1..=1).flat_map(|x| (-1..=1).flat_map(move |y| (-1..=1).map(move |z| IVec3::new(x, y, z))))
}

fn find(parent: &mut [u32], v: u32) -> u32 {
    let mut r = v;
    while parent[r as usize] != r {
        r = parent[r as usize];
    }
    let mut x = v;
    while parent[x as usize] != r {
        let next = parent[x as usize];
        parent[x as usize] = r;
        x = next;
    }
    r
}

fn union(parent: &mut [u32], a: u32, b: u32) {
    let (ra, rb) = (find(parent, a), find(parent, b));
    if ra != rb {
        parent[ra.max(rb) as usize] = ra.min(rb);
    }
}

/// `indices` (three per triangle) with each vertex replaced by its representative, and the
/// triangles that two corners of one group would make degenerate left out.
pub fn weld(indices: &[u32], seams: &PointSeams) -> Vec<u32> {
    let mut out = Vec::with_capacity(indices.len());
    for t in indices.chunks_exact(3) {
        let w = [0, 1, 2].map(|k| seams.representative[t[k] as usize]);
        if w[0] != w[1] && w[1] != w[2] && w[0] != w[2] {
            out.extend_from_slice(&w);
        }
    }
    out
}

/// Each welded corner of `indices` (a level made from welded indices) replaced by the member of
/// its group whose attribute row (`stride` values per vertex in `attributes`) is nearest the
/// mean of the triangle's other two corners' rows: the member on the side of the point seam the
/// triangle lies on. Cost: linear in the corners times the group sizes.
pub fn resolve(indices: &mut [u32], seams: &PointSeams, attributes: &[f32], stride: usize) {
    if seams.members.is_empty() {
        return;
    }
    let row = |v: u32| &attributes[v as usize * stride..(v as usize + 1) * stride];
    for t in indices.chunks_exact_mut(3) {
        let welded = [0, 1, 2].map(|k| seams.members.get(&t[k]));
        for k in 0..3 {
            let Some(group) = welded[k] else {
                continue;
            };
            let (o1, o2) = (row(t[(k + 1) % 3]), row(t[(k + 2) % 3]));
            let distance = |m: u32| -> f32 {
                (row(m).iter().zip(o1.iter().zip(o2)))
                    .map(|(x, (a, b))| (x - 0.5 * (a + b)).powi(2))
                    .sum()
            };
            let best = group
                .iter()
                .copied()
                .min_by(|&a, &b| distance(a).total_cmp(&distance(b)))
                .unwrap_or(t[k]);
            t[k] = best;
        }
    }
}
