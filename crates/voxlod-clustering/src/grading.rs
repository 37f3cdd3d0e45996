//! Grading: one weight per vertex, its perceptual importance (Rossignac–Borrel §3.1; Low–Tan
//! step 1).
//!
//! Both papers grade a vertex from the same two measurements of its incident edges, the edges
//! to its distinct neighbours `e_1 … e_k`:
//!
//! - `θ`, the largest angle between any pair of incident edges. A vertex whose edges all lie in a
//!   narrow cone (a spike, a corner) has a small `θ` and is likely to lie on the silhouette from
//!   many viewing directions; a vertex inside a flat or gently curved region has `θ` close to π.
//! - `L`, the length of the longest incident edge: a vertex that bounds large faces should not be
//!   moved to remove small details.
//!
//! Neither text gives a formula combining them, so we chose:
//!
//! - **Rossignac–Borrel**: `w = L · π / max(θ, θ₀)` with `θ₀ = 10⁻³` rad. The paper names "the
//!   inverse of the maximum angle" and "the length of the longest edge" as the two factors; their
//!   product is the plainest combination and keeps the weight a length: a flat interior vertex
//!   (θ = π) weighs exactly its longest edge, a right-angled corner twice that, a cone tip of
//!   opening 18° ten times. The floor `θ₀` keeps a needle (all edges along one direction) finite.
//! - **Low–Tan**: `w = L · cos(θ / 2)`. The patent says only that the weight is a function of the
//!   angles between all pairs of incident edges and of their lengths. `cos(θ/2)` decreases from 1
//!   for a needle to 0 for a flat vertex, like the inverse angle, but is bounded, needs no floor,
//!   and comes straight from the smallest dot product without an arc cosine:
//!   `cos(θ/2) = √((1 + cos θ) / 2)`. Flat regions weigh nothing, so the floating cells are
//!   centred on features first, which is the point of the patent's weight-controlled clustering.
//!
//! A vertex that no triangle uses, or whose incident edges all have zero length, weighs 0. With
//! one incident direction only (every neighbour on the same ray) `θ = 0`. The Rossignac–Borrel
//! weight takes `θ` from `cos θ` with a polynomial arc cosine ([`fast_acos`], within
//! 7·10⁻⁵ rad), which changes weights by less than 10⁻⁴ of themselves.
//!
//! Cost: O(Σ k²) over the vertices, k the number of distinct neighbours (6 on average for a
//! triangulated surface), parallel over vertices. Interior vertices with at most 8 corners,
//! nearly all of a scanned or contoured surface, take a branch-free path on 8 float lanes (about
//! 30 ns a vertex on one core of the reference machine). Above [`EXACT_VALENCE`] distinct neighbours
//! (fan centres, poles of a UV sphere) the pair search would be quadratic, so `θ` is found by a
//! few rounds of "the direction farthest from the current one", exact for the symmetric fans
//! those vertices usually are and a lower bound otherwise. We go beyond the papers here only in
//! bounding the cost.

use glam::Vec3;
use rayon::prelude::*;
use serde::Serialize;
use voxlod_core::TriangleMesh;

use crate::input::{self, Prepared};
use crate::ClusteringError;

/// Which paper's weight formula to use. See the module documentation for the formulas.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Grading {
    /// `L · π / max(θ, θ₀)` (§3.1).
    RossignacBorrel,
    /// `L · cos(θ/2)` (step 1).
    LowTan,
}

/// Above this many distinct neighbours the largest angle is found approximately.
pub const EXACT_VALENCE: usize = 48;

/// Smallest angle used by the Rossignac–Borrel weight, in radians.
pub const MIN_ANGLE: f32 = 1e-3;

/// The two measurements of a vertex that both weights are made of.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VertexShape {
    /// Length of the longest incident edge (0 if none has a length).
    pub longest_edge: f32,
    /// Cosine of the largest angle between two incident edges: 1 with fewer than two
    /// directions, −1 when two edges point in opposite directions.
    pub max_angle_cos: f32,
}

/// `L · π / max(θ, θ₀)`, θ in radians.
#[inline]
pub fn rossignac_borrel_weight(longest_edge: f32, max_angle: f32) -> f32 {
    longest_edge * std::f32::consts::PI / max_angle.max(MIN_ANGLE)
}

/// `L · cos(θ/2)`, from `cos θ`.
#[inline]
pub fn low_tan_weight(longest_edge: f32, max_angle_cos: f32) -> f32 {
    longest_edge * (0.5 * (1.0 + max_angle_cos.clamp(-1.0, 1.0))).sqrt()
}

impl Grading {
    /// The weight of a vertex of this shape under this grading.
    #[inline]
    pub fn weight(self, shape: VertexShape) -> f32 {
        match self {
            Grading::RossignacBorrel => {
                rossignac_borrel_weight(shape.longest_edge, fast_acos(shape.max_angle_cos))
            }
            Grading::LowTan => low_tan_weight(shape.longest_edge, shape.max_angle_cos),
        }
    }
}

/// `acos(x)` within 7·10⁻⁵ rad (Abramowitz and Stegun 4.4.45), several times faster than the
/// library's; weights need no more.
#[inline]
pub fn fast_acos(x: f32) -> f32 {
    let a = x.abs().min(1.0);
    let r =
        (1.0 - a).sqrt() * (1.570_728_8 + a * (-0.212_114_4 + a * (0.074_261 + a * -0.018_729_3)));
    if x < 0.0 {
        std::f32::consts::PI - r
    } else {
        r
    }
}

/// Weights of every vertex of `mesh` (0 for vertices no triangle uses).
pub fn grade(mesh: &TriangleMesh, grading: Grading) -> Result<Vec<f32>, ClusteringError> {
    let prepared = input::prepare(mesh)?;
    Ok(grade_prepared(&prepared, mesh, grading))
}

/// The measurements of every vertex of `mesh`.
pub fn vertex_shapes(mesh: &TriangleMesh) -> Result<Vec<VertexShape>, ClusteringError> {
    let prepared = input::prepare(mesh)?;
    Ok((0..mesh.positions.len())
        .into_par_iter()
        .map_init(Scratch::default, |s, v| vertex_shape(&prepared, mesh, v, s))
        .collect())
}

pub(crate) fn grade_prepared(
    prepared: &Prepared,
    mesh: &TriangleMesh,
    grading: Grading,
) -> Vec<f32> {
    // Two passes: the measurements, then the weights in a loop of plain arithmetic that
    // vectorises (a square root and a division per vertex cost more as a dependent chain).
    const BLOCK: usize = 1 << 12;
    let mut weights = vec![0.0f32; mesh.positions.len()];
    weights
        .par_chunks_mut(BLOCK)
        .enumerate()
        .for_each_init(Scratch::default, |s, (b, out)| {
            let mut longest = [0.0f32; BLOCK];
            let mut cos = [0.0f32; BLOCK];
            for (i, _) in out.iter().enumerate() {
                let shape = vertex_shape(prepared, mesh, b * BLOCK + i, s);
                longest[i] = shape.longest_edge;
                cos[i] = shape.max_angle_cos;
            }
            for (i, w) in out.iter_mut().enumerate() {
                *w = grading.weight(VertexShape {
                    longest_edge: longest[i],
                    max_angle_cos: cos[i],
                });
            }
        });
    weights
}

#[derive(Default)]
struct Scratch {
    neighbours: Vec<u32>,
    directions: Vec<Vec3>,
}

fn vertex_shape(
    prepared: &Prepared,
    mesh: &TriangleMesh,
    v: usize,
    s: &mut Scratch,
) -> VertexShape {
    let corners = prepared.neighbours_of(v);
    if let Some(shape) = ring_shape(corners, &mesh.positions, mesh.positions[v]) {
        return shape;
    }
    general_shape(corners, &mesh.positions, mesh.positions[v], s)
}

/// The common case, without branches that depend on the data: at most 8 corners, every
/// previous vertex also a next one (an interior vertex of a consistently oriented surface),
/// no neighbour at the vertex's own position. Works on 8 lanes, padded with copies of the first
/// neighbour (a pair of equal directions is at angle 0 and changes nothing), and takes every
/// ordered pair: more products than needed, but in whole blocks, which vectorise. `None` when
/// the case does not apply.
#[inline]
fn ring_shape(corners: &[[u32; 2]], positions: &[Vec3], p: Vec3) -> Option<VertexShape> {
    const W: usize = 8;
    if corners.is_empty() || corners.len() > W {
        return None;
    }
    let mut nexts = [corners[0][0]; W];
    let mut prevs = [corners[0][1]; W];
    for (i, c) in corners.iter().enumerate() {
        nexts[i] = c[0];
        prevs[i] = c[1];
    }
    if !prevs.iter().all(|q| nexts.contains(q)) {
        return None;
    }
    let (mut x, mut y, mut z, mut len2) = ([0f32; W], [0f32; W], [0f32; W], [0f32; W]);
    for i in 0..W {
        let d = positions[nexts[i] as usize] - p;
        x[i] = d.x;
        y[i] = d.y;
        z[i] = d.z;
        len2[i] = d.length_squared();
    }
    if !len2.iter().all(|&l| l > 0.0) {
        return None;
    }
    let mut longest = 0.0f32;
    for i in 0..W {
        longest = if len2[i] > longest { len2[i] } else { longest };
        let inv = 1.0 / len2[i].sqrt();
        x[i] *= inv;
        y[i] *= inv;
        z[i] *= inv;
    }
    let mut lanes = [1.0f32; W];
    // Each direction against all 8 lanes; the padding lanes repeat direction 0, so rows past the
    // real directions would only repeat row 0.
    for i in 0..corners.len() {
        let (xi, yi, zi) = (x[i], y[i], z[i]);
        for l in 0..W {
            let dot = xi * x[l] + yi * y[l] + zi * z[l];
            lanes[l] = if dot < lanes[l] { dot } else { lanes[l] };
        }
    }
    let best = lanes
        .into_iter()
        .fold(1.0f32, |a, b| if b < a { b } else { a });
    Some(VertexShape {
        longest_edge: longest.sqrt(),
        max_angle_cos: best.clamp(-1.0, 1.0),
    })
}

/// Every other vertex: the next vertex of every corner, then the previous ones not already
/// there (at a boundary one previous vertex is new). Repeats that remain (non-manifold input)
/// only add pairs at angle 0, which cannot change the largest angle.
fn general_shape(
    corners: &[[u32; 2]],
    positions: &[Vec3],
    p: Vec3,
    s: &mut Scratch,
) -> VertexShape {
    s.neighbours.clear();
    s.neighbours.extend(corners.iter().map(|c| c[0]));
    let k = s.neighbours.len();
    for c in corners {
        if corners.len() > EXACT_VALENCE || !s.neighbours[..k].contains(&c[1]) {
            s.neighbours.push(c[1]);
        }
    }
    if corners.len() > EXACT_VALENCE {
        s.neighbours.sort_unstable();
        s.neighbours.dedup();
    }
    let mut longest = 0.0f32;
    s.directions.clear();
    for &n in &s.neighbours {
        let d = positions[n as usize] - p;
        let len = d.length();
        if len > 0.0 {
            longest = longest.max(len);
            s.directions.push(d / len);
        }
    }
    VertexShape {
        longest_edge: longest,
        max_angle_cos: min_pair_dot(&s.directions),
    }
}

/// The smallest dot product between two of `dirs` (unit vectors): the cosine of the largest
/// angle between them. 1 with fewer than two directions.
fn min_pair_dot(dirs: &[Vec3]) -> f32 {
    let mut best = 1.0f32;
    if dirs.len() <= EXACT_VALENCE {
        for i in 0..dirs.len() {
            for j in i + 1..dirs.len() {
                best = best.min(dirs[i].dot(dirs[j]));
            }
        }
    } else {
        // Walk to the direction farthest from the current one a few times.
        let mut current = 0;
        for _ in 0..4 {
            let (far, dot) = dirs
                .iter()
                .enumerate()
                .map(|(j, d)| (j, dirs[current].dot(*d)))
                .fold((current, 1.0f32), |a, b| if b.1 < a.1 { b } else { a });
            best = best.min(dot);
            if far == current {
                break;
            }
            current = far;
        }
    }
    best.clamp(-1.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f32::consts::PI;

    fn shape_of(mesh: &TriangleMesh, v: usize) -> VertexShape {
        vertex_shapes(mesh).unwrap()[v]
    }

    #[test]
    fn flat_fan_centre_has_a_straight_angle() {
        // A regular hexagon fan around the origin: opposite spokes make 180°.
        let mut positions = vec![Vec3::ZERO];
        for i in 0..6 {
            let a = i as f32 * PI / 3.0;
            positions.push(Vec3::new(a.cos(), a.sin(), 0.0));
        }
        let triangles = (0..6u32).map(|i| [0, 1 + i, 1 + (i + 1) % 6]).collect();
        let mesh = TriangleMesh::new(positions, triangles);
        let s = shape_of(&mesh, 0);
        assert!((s.max_angle_cos + 1.0).abs() < 1e-6, "{s:?}");
        assert!((s.longest_edge - 1.0).abs() < 1e-6);
        // Flat: R–B weight = L, L–T weight = 0.
        let w = grade(&mesh, Grading::RossignacBorrel).unwrap();
        assert!((w[0] - 1.0).abs() < 1e-3, "{}", w[0]);
        let w = grade(&mesh, Grading::LowTan).unwrap();
        assert!(w[0].abs() < 1e-3, "{}", w[0]);
    }

    #[test]
    fn cube_corner_has_a_right_angle_and_weighs_twice_its_edge() {
        // The corner of a cube: edges along x, y and z, pairwise at 90°.
        let mesh = TriangleMesh::new(
            vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z],
            vec![[0, 2, 1], [0, 1, 3], [0, 3, 2]],
        );
        let s = shape_of(&mesh, 0);
        assert!(s.max_angle_cos.abs() < 1e-6, "{s:?}");
        let w = grade(&mesh, Grading::RossignacBorrel).unwrap();
        assert!((w[0] - 2.0).abs() < 1e-4, "{}", w[0]);
        let w = grade(&mesh, Grading::LowTan).unwrap();
        assert!((w[0] - (0.5f32).sqrt()).abs() < 1e-6, "{}", w[0]);
    }

    #[test]
    fn spike_outweighs_flat_neighbours() {
        // A thin cone: the tip's edges span a small angle.
        let mut positions = vec![Vec3::new(0.0, 0.0, 10.0)];
        for i in 0..8 {
            let a = i as f32 * PI / 4.0;
            positions.push(Vec3::new(a.cos(), a.sin(), 0.0));
        }
        let triangles = (0..8u32).map(|i| [0, 1 + i, 1 + (i + 1) % 8]).collect();
        let mesh = TriangleMesh::new(positions, triangles);
        for g in [Grading::RossignacBorrel, Grading::LowTan] {
            let w = grade(&mesh, g).unwrap();
            assert!(w[0] > w[1] && w[0] > 1.0, "{g:?} {w:?}");
        }
        // Tip opening: 2·atan(1/10).
        let s = shape_of(&mesh, 0);
        let expected = (2.0 * (0.1f32).atan()).cos();
        assert!((s.max_angle_cos - expected).abs() < 1e-5);
    }

    #[test]
    fn the_ring_fast_path_agrees_with_the_general_one() {
        // A torus (every vertex interior, valence 6) and an open grid (boundary vertices, which
        // take the general path), jittered so that no two rings look alike.
        let (nu, nv) = (40u32, 24u32);
        let mut positions = Vec::new();
        for i in 0..nu {
            for j in 0..nv {
                let (u, w) = (i as f32 * 0.157, j as f32 * 0.262);
                let r = 1.0 + (0.3 + 0.05 * (7.0 * u).sin()) * w.cos();
                positions.push(Vec3::new(
                    r * u.cos(),
                    r * u.sin(),
                    0.3 * w.sin() + 0.01 * (i % 3) as f32,
                ));
            }
        }
        let at = |i: u32, j: u32| (i % nu) * nv + j % nv;
        let mut triangles = Vec::new();
        for i in 0..nu {
            for j in 0..nv {
                triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                triangles.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
        let torus = TriangleMesh::new(positions.clone(), triangles.clone());
        let open = TriangleMesh::new(positions, triangles[..triangles.len() / 2].to_vec());
        for mesh in [torus, open] {
            let prepared = input::prepare(&mesh).unwrap();
            let mut s = Scratch::default();
            let mut fast = 0;
            for v in 0..mesh.positions.len() {
                let corners = prepared.neighbours_of(v);
                let general = general_shape(corners, &mesh.positions, mesh.positions[v], &mut s);
                if let Some(ring) = ring_shape(corners, &mesh.positions, mesh.positions[v]) {
                    fast += 1;
                    assert!((ring.longest_edge - general.longest_edge).abs() < 1e-6);
                    assert!(
                        (ring.max_angle_cos - general.max_angle_cos).abs() < 1e-5,
                        "{v}"
                    );
                }
            }
            assert!(fast > 0);
        }
    }

    #[test]
    fn fast_acos_is_close() {
        for i in -1000..=1000 {
            let x = i as f32 / 1000.0;
            assert!((fast_acos(x) - x.acos()).abs() < 1e-4, "{x}");
        }
    }

    #[test]
    fn high_valence_fans_are_graded_approximately_but_closely() {
        let n = 200;
        let mut positions = vec![Vec3::ZERO];
        for i in 0..n {
            let a = i as f32 * 2.0 * PI / n as f32;
            positions.push(Vec3::new(a.cos(), a.sin(), 0.1 * (3.0 * a).sin()));
        }
        let triangles = (0..n as u32)
            .map(|i| [0, 1 + i, 1 + (i + 1) % n as u32])
            .collect();
        let mesh = TriangleMesh::new(positions, triangles);
        let approx = shape_of(&mesh, 0).max_angle_cos;
        let dirs: Vec<Vec3> = mesh.positions[1..].iter().map(|p| p.normalize()).collect();
        let mut exact = 1.0f32;
        for i in 0..dirs.len() {
            for j in i + 1..dirs.len() {
                exact = exact.min(dirs[i].dot(dirs[j]));
            }
        }
        assert!(
            approx >= exact - 1e-6 && approx - exact < 1e-3,
            "{approx} vs {exact}"
        );
    }

    #[test]
    fn unreferenced_and_collapsed_vertices_weigh_nothing() {
        let mesh = TriangleMesh::new(
            vec![Vec3::ZERO, Vec3::ZERO, Vec3::ZERO, Vec3::ONE],
            vec![[0, 1, 2]],
        );
        for g in [Grading::RossignacBorrel, Grading::LowTan] {
            assert_eq!(grade(&mesh, g).unwrap(), vec![0.0; 4]);
        }
    }
}
