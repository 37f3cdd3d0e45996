//! The inside function of a triangle mesh, along lattice lines, through an obvhs BVH.
//!
//! Paper §2 samples the binary function S of a polygon mesh. We evaluate S along whole lines:
//! for each tile of parallel lattice lines, the BVH (obvhs `Bvh2`, queried with the tile's
//! box) yields the candidate triangles; each is projected onto the plane across the lines and
//! every line inside its projection gets one crossing. The crossings of a line, sorted, give its
//! inside spans by parity ("one ray per row of sample points, sort its crossings, fill the spans").
//!
//! Beyond the paper, the line–triangle test is **watertight**: edge functions are evaluated with
//! each edge's endpoints in one canonical (lexicographic) order, so the two triangles sharing an
//! edge compute the very same number, and a line through an edge or vertex is decided by
//! Simulation of Simplicity as if it were shifted by (δ, δ²). Every decision is then the one for
//! a single line in general position: a line through a closed mesh crosses it an even number of
//! times, however it grazes edges and vertices. (obvhs's own Möller–Trumbore test is not
//! watertight, so a ray test is never trusted for inside/outside here.)
//!
//! Meshes with holes give some lines an odd or wrong count. Beyond the paper, two remedies
//! apply in turn: every boundary loop is first closed by a fan of triangles around its centroid
//! ([`voxlod_core::repair::close_boundary_loops`]), which settles the scanner's holes (the
//! bunny's five, the elephant's hundred) exactly; whatever still leaves an edge used an odd
//! number of times (non-manifold fins, open chains) makes the solid report `is_exact() ==
//! false`, and the sampler then corrects the crossings by a majority vote across the three
//! axis families ([`crate::majority`]). Inside-out shells need nothing: parity ignores
//! orientation. Coincident vertices are welded and degenerate and duplicate triangles dropped
//! first (two copies of a face would cancel each other's crossing).
//!
//! **Union of parts** ([`MeshSolidOptions::union`], beyond the paper): parity makes the space
//! where two closed parts pass through each other outside (it is crossed twice), so their
//! solid has a hollow there. With `union`, each crossing carries the side the triangle faces
//! (the sign of its area projected across the line), and a line is inside where the winding
//! number of the surface around it is not zero: the union of consistently oriented parts,
//! whatever way each faces, as a scene's interpenetrating pieces need. Each line's signed
//! crossings are reduced to the ends of its spans of non-zero winding, so the rest of sampling
//! is unchanged. Cost: one sort per tile's crossings, as the parity path.
//!
//! Cost: building the BVH, O(F log F), once per mesh; per family, one box query per tile of
//! 64×64 lines plus O(1) per (candidate triangle, covered line) pair. Where the lines lie
//! farther apart than twice the mean triangle (a coarse level of a fine mesh), one query per
//! row of a tile's lines instead, so that a triangle between the rows is never visited (the
//! sphereflake's 1.4 M triangles at resolution 25 sample in two fifths less time).

use std::time::Duration;

use glam::{DVec3, Vec3A};
use obvhs::{
    aabb::Aabb, bvh2::builder::build_bvh2_from_tris, bvh2::Bvh2, triangle::Triangle, BvhBuildParams,
};
use rayon::prelude::*;
use voxlod_core::{repair, weld, Bounds, Grid, TriangleMesh};

use crate::lattice::{LineCrossings, LineFamily, TILE};
use crate::solid::{crossings_per_tile, Solid};
use crate::SamplingError;

/// A triangle mesh as a solid. See the module documentation.
pub struct MeshSolid {
    positions: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
    bvh: Bvh2,
    bounds: Bounds,
    closed: bool,
    /// The mean extent of the triangles' boxes along x, y and z (module `ROW_QUERY_SPACING`).
    mean_extent: [f64; 3],
    /// Inside by non-zero winding instead of parity ([`MeshSolidOptions::union`]).
    union: bool,
    /// What preparing the mesh changed, for reports.
    pub preparation: MeshPreparation,
}

/// What [`MeshSolid::new`] did to the input.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct MeshPreparation {
    /// Vertices merged into another with the same coordinates.
    pub welded_vertices: usize,
    /// Triangles dropped for a repeated vertex or zero area.
    pub degenerate_triangles: usize,
    /// Triangles dropped as copies of another.
    pub duplicate_triangles: usize,
    /// Triangles turned to agree with the orientation of their piece (the budget levels'
    /// preparation; sampling a solid needs no orientation, and turns none).
    pub flipped_triangles: usize,
    /// Boundary loops closed by a fan before sampling ([`repair::close_boundary_loops`]).
    pub holes_closed: usize,
    /// Whether every edge is shared by an even number of triangles (parity is then exact).
    pub closed: bool,
}

impl MeshPreparation {
    /// What preparing the mesh repaired, in words ("158 coincident vertices welded, 6240
    /// duplicate triangles dropped"); `None` where it repaired nothing.
    pub fn repairs(&self) -> Option<String> {
        let repairs: Vec<String> = [
            (self.welded_vertices, "coincident vertices welded"),
            (self.degenerate_triangles, "degenerate triangles dropped"),
            (self.duplicate_triangles, "duplicate triangles dropped"),
            (
                self.flipped_triangles,
                "triangles turned to agree with their neighbours",
            ),
            (self.holes_closed, "holes closed"),
        ]
        .iter()
        .filter(|(n, _)| *n > 0)
        .map(|(n, what)| format!("{n} {what}"))
        .collect();
        (!repairs.is_empty()).then(|| repairs.join(", "))
    }
}

/// How to prepare a mesh for sampling.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MeshSolidOptions {
    /// Close boundary loops with fans before sampling (otherwise only the majority vote
    /// guards against holes).
    pub close_holes: bool,
    /// Parts that pass through each other are sampled as their union (non-zero winding, module
    /// docs); off, parity decides, which needs no orientation.
    pub union: bool,
}

impl Default for MeshSolidOptions {
    /// Holes closed, parity.
    fn default() -> Self {
        MeshSolidOptions {
            close_holes: true,
            union: false,
        }
    }
}

impl MeshSolidOptions {
    /// No hole closing: the majority vote alone decides around holes.
    pub fn majority_only() -> Self {
        MeshSolidOptions {
            close_holes: false,
            ..Default::default()
        }
    }

    /// Holes closed, interpenetrating parts sampled as their union.
    pub fn union() -> Self {
        MeshSolidOptions {
            union: true,
            ..Default::default()
        }
    }
}

impl MeshSolid {
    /// Prepares `mesh` for sampling with the default options: checks coordinates, welds, drops
    /// degenerate and duplicate triangles, closes holes, builds the BVH.
    pub fn new(mesh: &TriangleMesh) -> Result<MeshSolid, SamplingError> {
        MeshSolid::new_with(mesh, MeshSolidOptions::default())
    }

    /// Prepares `mesh` for sampling.
    pub fn new_with(
        mesh: &TriangleMesh,
        options: MeshSolidOptions,
    ) -> Result<MeshSolid, SamplingError> {
        voxlod_core::validate::validate_mesh(mesh, &Default::default())?;
        let mut clean = TriangleMesh::new(mesh.positions.clone(), mesh.triangles.clone());
        let welded = weld::weld_vertices(&mut clean);
        let removed = repair::remove_degenerate_and_duplicate_triangles(&mut clean);
        if clean.triangles.is_empty() {
            return Err(SamplingError::EmptyMesh);
        }
        let holes_closed = if options.close_holes {
            repair::close_boundary_loops(&mut clean)
        } else {
            0
        };
        let closed = every_edge_even(&clean.triangles);
        let positions: Vec<DVec3> = clean.positions.iter().map(|p| p.as_dvec3()).collect();
        let tris: Vec<Triangle> = clean
            .triangles
            .iter()
            .map(|&[a, b, c]| Triangle {
                v0: Vec3A::from(clean.positions[a as usize]),
                v1: Vec3A::from(clean.positions[b as usize]),
                v2: Vec3A::from(clean.positions[c as usize]),
            })
            .collect();
        let bvh = build_bvh2_from_tris(
            &tris,
            BvhBuildParams::fast_build(),
            &mut Duration::default(),
        );
        let bounds = clean.bounds();
        let mean_extent = mean_extent(&positions, &clean.triangles);
        Ok(MeshSolid {
            mean_extent,
            union: options.union,
            positions,
            triangles: clean.triangles,
            bvh,
            bounds,
            closed,
            preparation: MeshPreparation {
                welded_vertices: welded.vertices_before - welded.vertices_after,
                degenerate_triangles: removed.degenerate_triangles,
                duplicate_triangles: removed.duplicate_triangles,
                flipped_triangles: 0,
                holes_closed,
                closed,
            },
        })
    }

    /// Triangles sampled: the prepared mesh's, hole fans included.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }
}

fn every_edge_even(triangles: &[[u32; 3]]) -> bool {
    let mut keys: Vec<u64> = triangles
        .par_iter()
        .flat_map_iter(|&[a, b, c]| [(a, b), (b, c), (c, a)])
        .map(|(a, b)| ((a.min(b) as u64) << 32) | a.max(b) as u64)
        .collect();
    keys.par_sort_unstable();
    keys.chunk_by(|a, b| a == b).all(|run| run.len() % 2 == 0)
}

/// Edge function of the edge (a, b) at q with the endpoints in canonical order, and whether the
/// order was swapped. Zero is replaced by the sign of the (δ, δ²) perturbation of q.
#[cfg(test)]
fn canonical_edge(a: [f64; 2], b: [f64; 2], q: [f64; 2]) -> (f64, f64) {
    let edge = CanonicalEdge::new(a, b);
    edge.at(edge.row(q[1]), q[0])
}

/// One edge of a projected triangle with its endpoints in canonical (lexicographic) order, set
/// up once per triangle so that a line's test costs a multiply and a subtraction per edge: the
/// term of the edge function that depends on the row alone ([`CanonicalEdge::row`]) is shared
/// by the row's lines. The values are those of evaluating `du (q_v - a_v) - dv (q_u - a_u)` in
/// full for each line, bit for bit.
#[derive(Clone, Copy, Debug)]
struct CanonicalEdge {
    a: [f64; 2],
    du: f64,
    dv: f64,
    /// The decided sign's value where the edge function is zero (the (δ, δ²) perturbation).
    tie: f64,
    swapped: bool,
}

impl CanonicalEdge {
    #[inline]
    fn new(a: [f64; 2], b: [f64; 2]) -> CanonicalEdge {
        let swapped = (b[0], b[1]) < (a[0], a[1]);
        let (a, b) = if swapped { (b, a) } else { (a, b) };
        let (du, dv) = (b[0] - a[0], b[1] - a[1]);
        let tie = if dv != 0.0 { -dv } else { du };
        CanonicalEdge {
            a,
            du,
            dv,
            tie,
            swapped,
        }
    }

    /// The part of the edge function shared by the lines of row `qv`.
    #[inline]
    fn row(&self, qv: f64) -> f64 {
        self.du * (qv - self.a[1])
    }

    /// The edge function at `(qu, qv)` given `row = self.row(qv)`: its raw value (for
    /// barycentrics) and its decided sign (never zero for a non-degenerate edge), both as for
    /// the edge in the caller's order.
    #[inline]
    fn at(&self, row: f64, qu: f64) -> (f64, f64) {
        let e = row - self.dv * (qu - self.a[0]);
        let decided = if e != 0.0 { e } else { self.tie };
        if self.swapped {
            (-e, -decided)
        } else {
            (e, decided)
        }
    }
}

/// Resident bytes per input triangle while a mesh is sampled: the solid's f64 vertices, its
/// triangles and BVH, the loaded mesh the command keeps, and the allocator's slack. Measured:
/// about 600 MB resident for the peers' 1.4 M-triangle sphereflake before its lattice is cast,
/// rounded up.
const RESIDENT_BYTES_PER_TRIANGLE: u64 = 450;

impl Solid for MeshSolid {
    fn resident_bytes(&self) -> u64 {
        RESIDENT_BYTES_PER_TRIANGLE * self.triangles.len() as u64
    }

    fn bounds(&self) -> Bounds {
        self.bounds
    }

    fn band_bricks_bound(&self, grid: &Grid, brick_size: usize, margin: f64) -> Option<usize> {
        crate::band_cover::triangle_band_bricks(
            &self.positions,
            &self.triangles,
            grid,
            brick_size,
            margin,
        )
    }

    fn is_exact(&self) -> bool {
        self.closed
    }

    fn crossings(&self, family: &LineFamily) -> Result<LineCrossings, SamplingError> {
        let ua = family.cross_axes().0.index();
        let spacing = family.grid.spacing[ua] / family.lines_per_voxel as f64;
        let by_row = spacing > ROW_QUERY_SPACING * self.mean_extent[ua];
        Ok(self.crossings_by(family, by_row))
    }
}

impl MeshSolid {
    /// The crossings of `family`'s lines, tile by tile, each tile's triangles found with one
    /// box query or (`by_row`) one per row of its lines; with `union`, reduced to the ends of
    /// each line's spans of non-zero winding.
    fn crossings_by(&self, family: &LineFamily, by_row: bool) -> LineCrossings {
        crossings_per_tile(family, |ms, ns, out| {
            if self.union {
                let mut signed = Vec::new();
                self.tile_crossings(family, ms, ns, by_row, &mut |line, t, up| {
                    signed.push((line, t, up))
                });
                non_zero_spans(signed, out);
            } else {
                self.tile_crossings(family, ms, ns, by_row, &mut |line, t, _| {
                    out.push((line, t))
                });
            }
        })
    }

    /// Every crossing of one tile's lines, given to `emit` as (line in the tile, position
    /// along the line in index units, whether the triangle faces up the line's axis).
    fn tile_crossings<E: FnMut(u16, f32, bool)>(
        &self,
        family: &LineFamily,
        ms: std::ops::Range<usize>,
        ns: std::ops::Range<usize>,
        by_row: bool,
        emit: &mut E,
    ) {
        let axis = family.axis.index();
        let (ua, va) = family.cross_axes();
        let (ua, va) = (ua.index(), va.index());
        let q = family.lines_per_voxel as f64;
        let g = family.grid;
        let (step_u, step_v) = (g.spacing[ua] / q, g.spacing[va] / q);
        let (origin_u, origin_v) = (g.origin[ua], g.origin[va]);
        let (u0, v0) = family.line_position(ms.start, ns.start);
        let (u1, v1) = family.line_position(ms.end - 1, ns.end - 1);
        let lines = TileLines {
            ms: ms.clone(),
            ns: ns.clone(),
            first: (ms.start, ns.start),
        };
        let mut cross = |lines: &TileLines, lo_u: f64, hi_u: f64| {
            let query = tile_box(ua, va, (lo_u, hi_u), (v0, v1));
            self.bvh.aabb_traverse(query, |bvh, node_index| {
                let node = &bvh.nodes[node_index as usize];
                for i in node.first_index..node.first_index + node.prim_count {
                    let t = bvh.primitive_indices[i as usize] as usize;
                    let (origin, step) = ([origin_u, origin_v], [step_u, step_v]);
                    self.cross_triangle(t, axis, ua, va, lines, origin, step, family, emit);
                }
                true
            });
        };
        if by_row {
            for m in ms.clone() {
                let u = family.line_position(m, ns.start).0;
                let row = TileLines {
                    ms: m..m + 1,
                    ..lines.clone()
                };
                cross(&row, u, u);
            }
        } else {
            cross(&lines, u0, u1);
        }
    }
}

/// The ends of the spans of non-zero winding of each line of a tile, from its signed
/// crossings (in any order), sorted by line and along it: a span starts where the winding
/// leaves zero and ends where it returns. Closed, consistently oriented parts give each line
/// an even number of ends.
fn non_zero_spans(mut signed: Vec<(u16, f32, bool)>, out: &mut Vec<(u16, f32)>) {
    signed.sort_unstable_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)).then(a.2.cmp(&b.2)));
    let mut line = None;
    let mut winding = 0i32;
    for (l, t, up) in signed {
        if line != Some(l) {
            line = Some(l);
            winding = 0;
        }
        let before = winding;
        winding += if up { 1 } else { -1 };
        if (before == 0) != (winding == 0) {
            out.push((l, t));
        }
    }
}

/// Lines at least this many mean triangle extents apart (across the lines, along the tile's
/// rows) are queried row by row: each row's thin box meets only the triangles that straddle it,
/// a small share of a fine mesh at a coarse level's lattice, where the tile's box would meet
/// every triangle between the rows too. The crossings are the same (a triangle crosses a line
/// only if its box straddles the line's row), and sorting by line makes their order the same.
const ROW_QUERY_SPACING: f64 = 2.0;

/// A tile's lines to cross: the ranges of line indices to test, and the tile's first line (its
/// crossings are numbered from there).
#[derive(Clone)]
struct TileLines {
    ms: std::ops::Range<usize>,
    ns: std::ops::Range<usize>,
    first: (usize, usize),
}

/// The box of the lines between `u` and `v` (inclusive) across axis families `ua`, `va`,
/// unbounded along the lines, widened by a float ulp-scale margin so that triangles touching
/// it are not missed.
fn tile_box(ua: usize, va: usize, u: (f64, f64), v: (f64, f64)) -> Aabb {
    let pad = |x: f64| x.abs() * 1e-6 + 1e-9;
    let mut lo = Vec3A::splat(f32::NEG_INFINITY);
    let mut hi = Vec3A::splat(f32::INFINITY);
    lo[ua] = (u.0 - pad(u.0)) as f32;
    hi[ua] = (u.1 + pad(u.1)) as f32;
    lo[va] = (v.0 - pad(v.0)) as f32;
    hi[va] = (v.1 + pad(v.1)) as f32;
    Aabb::new(lo, hi)
}

/// The mean extent of the triangles' boxes along each axis.
fn mean_extent(positions: &[DVec3], triangles: &[[u32; 3]]) -> [f64; 3] {
    let sum = triangles
        .par_iter()
        .map(|t| {
            let p = t.map(|i| positions[i as usize]);
            (p[0].max(p[1]).max(p[2]) - p[0].min(p[1]).min(p[2])).to_array()
        })
        .reduce(|| [0.0; 3], |a, b| [a[0] + b[0], a[1] + b[1], a[2] + b[2]]);
    sum.map(|s| s / triangles.len().max(1) as f64)
}

impl MeshSolid {
    /// Appends the crossings of triangle `t` with the lines of one tile.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn cross_triangle(
        &self,
        t: usize,
        axis: usize,
        ua: usize,
        va: usize,
        lines: &TileLines,
        origin: [f64; 2],
        step: [f64; 2],
        family: &LineFamily,
        emit: &mut impl FnMut(u16, f32, bool),
    ) {
        let [a, b, c] = self.triangles[t];
        let p = [
            self.positions[a as usize],
            self.positions[b as usize],
            self.positions[c as usize],
        ];
        let uv = p.map(|v| [v[ua], v[va]]);
        let area2 = (uv[1][0] - uv[0][0]) * (uv[2][1] - uv[0][1])
            - (uv[1][1] - uv[0][1]) * (uv[2][0] - uv[0][0]);
        if area2 == 0.0 {
            return; // seen edge-on: a line in general position misses it
        }
        let (umin, umax) = (
            uv[0][0].min(uv[1][0]).min(uv[2][0]),
            uv[0][0].max(uv[1][0]).max(uv[2][0]),
        );
        let (vmin, vmax) = (
            uv[0][1].min(uv[1][1]).min(uv[2][1]),
            uv[0][1].max(uv[1][1]).max(uv[2][1]),
        );
        let (ms, ns) = (&lines.ms, &lines.ns);
        let m_lo = (((umin - origin[0]) / step[0]).ceil().max(ms.start as f64)) as usize;
        let m_hi = (((umax - origin[0]) / step[0]).floor()).min((ms.end - 1) as f64);
        let n_lo = (((vmin - origin[1]) / step[1]).ceil().max(ns.start as f64)) as usize;
        let n_hi = (((vmax - origin[1]) / step[1]).floor()).min((ns.end - 1) as f64);
        if m_hi < m_lo as f64 || n_hi < n_lo as f64 {
            return;
        }
        let orientation = area2.signum();
        let edges = [
            CanonicalEdge::new(uv[1], uv[2]), // opposite vertex 0
            CanonicalEdge::new(uv[2], uv[0]), // opposite vertex 1
            CanonicalEdge::new(uv[0], uv[1]), // opposite vertex 2
        ];
        for n in n_lo..=n_hi as usize {
            let qv = origin[1] + n as f64 * step[1];
            let rows = edges.map(|e| e.row(qv));
            for m in m_lo..=m_hi as usize {
                let qu = origin[0] + m as f64 * step[0];
                let (e0, s0) = edges[0].at(rows[0], qu);
                let (e1, s1) = edges[1].at(rows[1], qu);
                let (e2, s2) = edges[2].at(rows[2], qu);
                if s0 * orientation > 0.0 && s1 * orientation > 0.0 && s2 * orientation > 0.0 {
                    let sum = e0 + e1 + e2;
                    let w = if sum != 0.0 {
                        [e0 / sum, e1 / sum, e2 / sum]
                    } else {
                        [1.0 / 3.0; 3]
                    };
                    let t_world = w[0] * p[0][axis] + w[1] * p[1][axis] + w[2] * p[2][axis];
                    let local = ((n - lines.first.1) * TILE + (m - lines.first.0)) as u16;
                    emit(local, family.index_t(t_world) as f32, orientation > 0.0);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lattice::LineFamily;
    use voxlod_core::Axis;

    #[test]
    fn shared_edges_are_decided_once() {
        // Two triangles sharing the edge (0,0)-(1,1), a point exactly on it.
        let (a, b) = ([0.0, 0.0], [1.0, 1.0]);
        let q = [0.5, 0.5];
        let (e_ab, s_ab) = canonical_edge(a, b, q);
        let (e_ba, s_ba) = canonical_edge(b, a, q);
        assert_eq!(e_ab, 0.0);
        assert_eq!(e_ba, 0.0);
        assert_eq!(s_ab, -s_ba);
        assert!(s_ab != 0.0);
    }

    /// A closed latitude–longitude sphere of radius 1: `rings` bands of `sectors` quads, fans at
    /// the poles.
    fn uv_sphere(rings: u32, sectors: u32) -> TriangleMesh {
        use std::f32::consts::PI;
        let mut positions = vec![[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]];
        for r in 1..rings {
            let (z, rho) = (
                (PI * r as f32 / rings as f32).cos(),
                (PI * r as f32 / rings as f32).sin(),
            );
            for s in 0..sectors {
                let phi = 2.0 * PI * s as f32 / sectors as f32;
                positions.push([rho * phi.cos(), rho * phi.sin(), z]);
            }
        }
        let at = |r: u32, s: u32| 2 + (r - 1) * sectors + s % sectors;
        let mut triangles = Vec::new();
        for s in 0..sectors {
            triangles.push([0, at(1, s), at(1, s + 1)]);
            triangles.push([1, at(rings - 1, s + 1), at(rings - 1, s)]);
            for r in 1..rings - 1 {
                triangles.push([at(r, s), at(r + 1, s), at(r + 1, s + 1)]);
                triangles.push([at(r, s), at(r + 1, s + 1), at(r, s + 1)]);
            }
        }
        TriangleMesh::new(
            positions.into_iter().map(glam::Vec3::from).collect(),
            triangles,
        )
    }

    /// A fine sphere (19 900 triangles) on lattices from coarse (lines far apart, queried row
    /// by row) to fine: both queries give the same crossings, bit for bit, on every family.
    #[test]
    fn row_queries_give_the_tile_queries_crossings() {
        let sphere = uv_sphere(100, 100);
        let solid = MeshSolid::new(&sphere).unwrap();
        assert!(solid.closed);
        for cells in [3, 8, 40] {
            let spacing = 2.4 / cells as f64;
            let grid = Grid::new([cells + 1; 3], [spacing; 3], [-1.2; 3]).unwrap();
            for axis in [Axis::X, Axis::Y, Axis::Z] {
                let family = LineFamily::new(axis, grid, 4);
                let (tiles, rows) = (
                    solid.crossings_by(&family, false),
                    solid.crossings_by(&family, true),
                );
                assert!(!tiles.is_empty());
                assert_eq!(tiles.offsets, rows.offsets);
                let bits = |c: &LineCrossings| c.t.iter().map(|t| t.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&tiles), bits(&rows));
            }
        }
    }

    /// Two unit spheres of `rings`×`sectors` around (±0.5, 0, 0), the second turned inside out
    /// when `flip_second`.
    fn two_spheres(flip_second: bool) -> TriangleMesh {
        let mut mesh = uv_sphere(40, 40);
        let mut other = uv_sphere(40, 40);
        for p in &mut mesh.positions {
            p.x -= 0.5;
        }
        for p in &mut other.positions {
            p.x += 0.5;
        }
        if flip_second {
            for t in &mut other.triangles {
                t.swap(1, 2);
            }
        }
        let offset = mesh.positions.len() as u32;
        mesh.positions.extend(other.positions);
        mesh.triangles
            .extend(other.triangles.iter().map(|t| t.map(|v| v + offset)));
        mesh
    }

    #[test]
    fn union_fills_where_parts_pass_through_each_other() {
        // The x-line through the centres crosses both spheres: parity sees four crossings and
        // a hollow lens between -0.5 + 1 and 0.5 - 1; the union, two ends at ±1.5.
        let grid = Grid::new([5, 5, 5], [0.8; 3], [-1.6; 3]).unwrap();
        let family = LineFamily::new(Axis::X, grid, 1);
        for flip in [false, true] {
            let mesh = two_spheres(flip);
            let parity = MeshSolid::new(&mesh).unwrap().crossings_by(&family, false);
            let union = MeshSolid::new_with(&mesh, MeshSolidOptions::union()).unwrap();
            let union = union.crossings_by(&family, false);
            let mid = family.line_counts().0 / 2;
            let (p, u) = (
                parity.line(mid as isize, mid as isize),
                union.line(mid as isize, mid as isize),
            );
            assert_eq!(p.len(), 4, "{p:?}");
            // An inside-out part is a union too only when the winding is non-zero there: the
            // lens of an outward and an inward part winds to zero, a hollow again.
            let expected = if flip { 4 } else { 2 };
            assert_eq!(u.len(), expected, "flip {flip}: {u:?}");
            let world = |t: f32| family.world_t(t as f64);
            assert!(
                (world(u[0]) + 1.5).abs() < 0.01 && (world(*u.last().unwrap()) - 1.5).abs() < 0.01
            );
        }
    }

    #[test]
    fn even_edge_check() {
        assert!(every_edge_even(&[[0, 1, 2], [0, 2, 1]]));
        assert!(!every_edge_even(&[[0, 1, 2]]));
    }
    /// The reference for [`CanonicalEdge`]: the edge function evaluated in full for every line.
    fn reference_edge(a: [f64; 2], b: [f64; 2], q: [f64; 2]) -> (f64, f64) {
        let swapped = (b[0], b[1]) < (a[0], a[1]);
        let (a, b) = if swapped { (b, a) } else { (a, b) };
        let (du, dv) = (b[0] - a[0], b[1] - a[1]);
        let e = du * (q[1] - a[1]) - dv * (q[0] - a[0]);
        let decided = if e != 0.0 {
            e
        } else if dv != 0.0 {
            -dv
        } else {
            du
        };
        if swapped {
            (-e, -decided)
        } else {
            (e, decided)
        }
    }

    #[test]
    fn canonical_edges_give_the_full_evaluation_bit_for_bit() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(14);
        let mut ties = 0;
        for _ in 0..20_000 {
            // Coordinates on a coarse lattice make exact zeros (lines through edges) common.
            let mut point = || -> [f64; 2] {
                if rng.random_bool(0.5) {
                    [
                        rng.random_range(-4..=4) as f64 * 0.25,
                        rng.random_range(-4..=4) as f64 * 0.25,
                    ]
                } else {
                    [rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)]
                }
            };
            let (a, b, q) = (point(), point(), point());
            let edge = CanonicalEdge::new(a, b);
            let (e, s) = edge.at(edge.row(q[1]), q[0]);
            let (re, rs) = reference_edge(a, b, q);
            assert_eq!((e.to_bits(), s.to_bits()), (re.to_bits(), rs.to_bits()));
            ties += (re == 0.0) as usize;
        }
        assert!(ties > 100, "only {ties} lines through an edge");
    }
}
