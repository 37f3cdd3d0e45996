//! The two offset surfaces P(+ε) and P(−ε) of paper §4: every vertex moved along its normal by
//! its own ε⁺ outwards and ε⁻ inwards, each at most the vertex's target ε and shrunk where a full
//! offset would make a surface cross itself (§4.3). The offsets keep the input's connectivity.
//!
//! Two steps:
//!
//! 1. **Voronoi limit** (§4.3's condition). An offset vertex must stay in the Voronoi regions of
//!    its own triangles: the point of the input nearest to `v ± s·n(v)` must lie on a triangle
//!    around `v`. The paper replaces the Voronoi diagram by a conservative prism test on an
//!    octree; we test the condition itself with the closest-point BVH of voxlod-metrics: first at
//!    the full target (most vertices pass), otherwise by bisection on `s` (12 steps), keeping the
//!    largest `s` found to pass. A nearest point on another triangle at the same distance as the
//!    star (a shared edge) passes.
//! 2. **Crossing check** (our addition, the guarantee itself). The two offsets are built, each
//!    put in its own BVH (`TriangleSet`; two thin sheets apart make far tighter boxes than one
//!    tree over both) and every offset triangle is tested against all triangles sharing
//!    no vertex with it, on both surfaces; an offset triangle whose normal turned against its
//!    input triangle's counts as crossing too (a fold between neighbours). The ε of every
//!    vertex of a crossing triangle, on that side, is multiplied by 0.6 and the check repeats on
//!    the triangles that moved, up to 24 rounds (the trees are refitted between rounds, not
//!    rebuilt); ε of a vertex still involved after that is set to zero, and what crosses even
//!    then is counted as unresolved. An input that crosses itself leaves such crossings; so do,
//!    rarely, offsets far out along noisy normals (the bunny at 8 % of its diagonal: a few
//!    dozen of 139 000 offset triangles), where a zero offset meets a kink of the other one.
//!    The removal's own checks (no crossing with the current mesh, the covered-vertex guard)
//!    still hold for the output there; only the shell's argument for the topology is local.
//!
//! With `OffsetRule::CrossingsOnly` step 1 is skipped: each ε shrinks only where the offsets
//! really cross, which is less cautious than the paper (its §7 notes that its offsets were
//! "overcautious").
//!
//! Cost: step 1 is one closest-point query per vertex and side, 13 for the few that bisect;
//! step 2 is one BVH build over 2F triangles and one triangle query per offset triangle per
//! round (later rounds only for the triangles that moved).

use std::time::Instant;

use glam::DVec3;
use rayon::prelude::*;
use serde::Serialize;

use super::base::Base;
use super::geometry::point_triangle_distance;
use super::obstacles::TriangleSet;
use super::EnvelopeError;

/// How the per-vertex ε of the offsets is limited (see the module documentation).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum OffsetRule {
    /// §4.3: offset vertices stay in their own triangles' Voronoi regions, then the crossing check.
    #[default]
    Voronoi,
    /// Only the crossing check.
    CrossingsOnly,
}

/// Factor applied to the ε of the vertices of a crossing offset triangle, per round.
const SHRINK: f64 = 0.6;
/// Rounds of the crossing check before the remaining ε are set to zero.
const ROUNDS: usize = 24;
/// Bisection steps of the Voronoi limit.
const BISECTIONS: usize = 12;

/// What the offsets came out as.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct OffsetReport {
    /// Vertices with an offset (used by some triangle).
    pub vertices: usize,
    /// Vertex sides (two per vertex) whose ε the Voronoi limit lowered.
    pub limited_by_voronoi: usize,
    /// Vertex sides whose ε the crossing check lowered.
    pub limited_by_crossings: usize,
    /// Rounds of the crossing check that found something to fix.
    pub crossing_rounds: usize,
    /// Vertex sides whose ε ended at zero although the target was positive.
    pub zero_sides: usize,
    /// Offset triangles still crossing after the last round, whose vertices' ε on that side
    /// were then set to zero.
    pub zeroed_after_rounds: usize,
    /// Offset triangles crossing even then (see the module documentation).
    pub unresolved_crossings: usize,
    /// Mean of ε⁺/target and ε⁻/target over the used vertices: 1 when nothing was shrunk.
    pub mean_fraction: f64,
    /// Wall time of both steps.
    pub seconds: f64,
}

/// The per-vertex offsets of one level, and the envelope (both offset surfaces) they make.
pub(crate) struct Offsets {
    /// ε⁺ of each vertex (outwards, along the normal).
    pub outer: Vec<f64>,
    /// ε⁻ of each vertex (inwards).
    pub inner: Vec<f64>,
    /// What the limits did.
    pub report: OffsetReport,
}

impl Offsets {
    /// Computes the offsets for per-vertex targets `target` (zero for unused vertices).
    pub fn new(base: &Base, target: &[f64], rule: OffsetRule) -> Result<Offsets, EnvelopeError> {
        let start = Instant::now();
        let n = base.vertex_count();
        debug_assert_eq!(target.len(), n);
        let usable = |v: usize| base.is_used(v) && base.normals[v] != DVec3::ZERO;
        let limits: Vec<(f64, f64)> = (0..n)
            .into_par_iter()
            .map(|v| {
                if !usable(v) || target[v] <= 0.0 {
                    return (0.0, 0.0);
                }
                match rule {
                    OffsetRule::Voronoi => (
                        voronoi_limit(base, v, 1.0, target[v]),
                        voronoi_limit(base, v, -1.0, target[v]),
                    ),
                    OffsetRule::CrossingsOnly => (target[v], target[v]),
                }
            })
            .collect();
        let (outer, inner): (Vec<f64>, Vec<f64>) = limits.into_iter().unzip();
        let report = OffsetReport {
            vertices: (0..n).filter(|&v| base.is_used(v)).count(),
            limited_by_voronoi: (0..n)
                .filter(|&v| usable(v))
                .map(|v| (outer[v] < target[v]) as usize + (inner[v] < target[v]) as usize)
                .sum(),
            ..Default::default()
        };
        let mut offsets = Offsets {
            outer,
            inner,
            report,
        };
        offsets.shrink_crossings(base, target)?;
        offsets.finish_report(base, target);
        offsets.report.seconds = start.elapsed().as_secs_f64();
        Ok(offsets)
    }

    /// Step 2, the crossing check: shrinks the ε of the vertices of crossing offset triangles,
    /// round after round, and zeroes what still crosses after the last round.
    fn shrink_crossings(&mut self, base: &Base, target: &[f64]) -> Result<(), EnvelopeError> {
        let n = base.vertex_count();
        let before: Vec<(f64, f64)> = self
            .outer
            .iter()
            .copied()
            .zip(self.inner.iter().copied())
            .collect();
        let mut pending: Option<Vec<bool>> = None;
        let mut set = Envelope::new(base, &self.outer, &self.inner)?;
        for round in 0..=ROUNDS {
            if round > 0 {
                set.update(base, &self.outer, &self.inner);
            }
            let crossing =
                crossing_triangles(base, &set, &self.outer, &self.inner, pending.as_deref());
            let count = crossing.iter().filter(|&&c| c).count();
            if count == 0 {
                break;
            }
            if round == ROUNDS {
                self.report.zeroed_after_rounds = count;
                self.zero_crossing(base, &mut set, &crossing);
                break;
            }
            self.report.crossing_rounds += 1;
            let moved_vertex = self.shrink_round(base, target, &crossing);
            // Next round: the triangles touching a moved vertex.
            pending = Some(touching(base, &moved_vertex));
        }
        self.report.limited_by_crossings = (0..n)
            .map(|v| {
                (self.outer[v] < before[v].0) as usize + (self.inner[v] < before[v].1) as usize
            })
            .sum();
        Ok(())
    }

    /// One round: the ε of every vertex side of a crossing triangle shrinks once (however many
    /// crossings it is in), to zero below 10⁻⁴ of its target. Returns the vertices that moved.
    fn shrink_round(&mut self, base: &Base, target: &[f64], crossing: &[bool]) -> Vec<bool> {
        let n = base.vertex_count();
        let mut moved = [vec![false; n], vec![false; n]];
        for (i, _) in crossing.iter().enumerate().filter(|(_, &c)| c) {
            let (side, t) = (i / base.tris.len(), i % base.tris.len());
            for &v in &base.tris[t] {
                let v = v as usize;
                if moved[side][v] {
                    continue;
                }
                moved[side][v] = true;
                let e = if side == 0 {
                    &mut self.outer[v]
                } else {
                    &mut self.inner[v]
                };
                *e *= SHRINK;
                if *e < target[v] * 1e-4 {
                    *e = 0.0;
                }
            }
        }
        (0..n).map(|v| moved[0][v] || moved[1][v]).collect()
    }

    /// After the last round: the ε of every vertex of a crossing triangle, on its side, set to
    /// zero, and what crosses even then counted as unresolved (it is left as it is: zeroing
    /// more only spreads the kinks).
    fn zero_crossing(&mut self, base: &Base, set: &mut Envelope, crossing: &[bool]) {
        let mut moved = vec![false; base.vertex_count()];
        for (i, _) in crossing.iter().enumerate().filter(|(_, &c)| c) {
            let (side, t) = (i / base.tris.len(), i % base.tris.len());
            for &v in &base.tris[t] {
                let e = if side == 0 {
                    &mut self.outer
                } else {
                    &mut self.inner
                };
                e[v as usize] = 0.0;
                moved[v as usize] = true;
            }
        }
        set.update(base, &self.outer, &self.inner);
        let only = touching(base, &moved);
        self.report.unresolved_crossings =
            crossing_triangles(base, set, &self.outer, &self.inner, Some(&only))
                .iter()
                .filter(|&&c| c)
                .count();
    }

    /// The sides left at zero and the mean fraction of the targets kept.
    fn finish_report(&mut self, base: &Base, target: &[f64]) {
        let (outer, inner) = (&self.outer, &self.inner);
        let n = base.vertex_count();
        self.report.zero_sides = (0..n)
            .filter(|&v| base.is_used(v) && target[v] > 0.0)
            .map(|v| (outer[v] == 0.0) as usize + (inner[v] == 0.0) as usize)
            .sum();
        let (mut sum, mut count) = (0.0, 0usize);
        for v in 0..n {
            if base.is_used(v) && target[v] > 0.0 {
                sum += (outer[v] + inner[v]) / target[v];
                count += 2;
            }
        }
        self.report.mean_fraction = if count > 0 { sum / count as f64 } else { 0.0 };
    }

    /// The envelope: both offset surfaces, searchable.
    pub fn envelope(&self, base: &Base) -> Result<Envelope, EnvelopeError> {
        Envelope::new(base, &self.outer, &self.inner)
    }
}

/// The largest `s` in `[0, target]` (found by the test at `target`, else by bisection) for which
/// the point of the input nearest to `v + side·s·n(v)` lies on a triangle around `v`.
fn voronoi_limit(base: &Base, v: usize, side: f64, target: f64) -> f64 {
    let (p, n) = (base.pos[v], base.normals[v]);
    let star = base.star(v);
    let passes = |s: f64| {
        let x = p + n * (side * s);
        let nearest = base.distance.closest(x);
        if star.contains(&(nearest.triangle as u32)) {
            return true;
        }
        let own = star
            .iter()
            .map(|&t| point_triangle_distance(x, &base.corners(t as usize)))
            .fold(f64::INFINITY, f64::min);
        nearest.distance >= own - base.tol
    };
    if passes(target) {
        return target;
    }
    let (mut lo, mut hi) = (0.0, target);
    for _ in 0..BISECTIONS {
        let mid = 0.5 * (lo + hi);
        if passes(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// Offset vertex ids: `v` outside, `V + v` inside, or `v` for both when both ε are zero (the two
/// offsets meet there, at the input vertex).
#[inline]
fn inner_id(v: usize, n: usize, outer: &[f64], inner: &[f64]) -> u32 {
    if outer[v] == 0.0 && inner[v] == 0.0 {
        v as u32
    } else {
        (n + v) as u32
    }
}

/// Both offset surfaces, each in its own BVH: triangle `t` outside, `F + t` inside.
pub(crate) struct Envelope {
    outer: TriangleSet,
    inner: TriangleSet,
    faces: u32,
}

impl Envelope {
    fn new(base: &Base, outer: &[f64], inner: &[f64]) -> Result<Envelope, EnvelopeError> {
        let (corners, ids) = offset_triangles(base, outer, inner);
        let f = base.tris.len();
        Ok(Envelope {
            outer: TriangleSet::new(&corners[..f], &ids[..f], base.tol)?,
            inner: TriangleSet::new(&corners[f..], &ids[f..], base.tol)?,
            faces: f as u32,
        })
    }

    /// Moves the offsets to new per-vertex ε (the trees keep their shape).
    fn update(&mut self, base: &Base, outer: &[f64], inner: &[f64]) {
        let (corners, ids) = offset_triangles(base, outer, inner);
        let f = self.faces as usize;
        self.outer.update(&corners[..f], &ids[..f]);
        self.inner.update(&corners[f..], &ids[f..]);
    }

    /// Whether `t` touches either offset surface.
    pub fn touches(&self, t: &[DVec3; 3]) -> bool {
        self.outer.touches(t, |_, _| false) || self.inner.touches(t, |_, _| false)
    }

    /// Calls `found(index)` for every offset triangle touching `t` whose vertex ids do not
    /// make `skip` true.
    fn each_touching(
        &self,
        t: &[DVec3; 3],
        skip: impl Fn(&[u32; 3]) -> bool,
        mut found: impl FnMut(u32),
    ) {
        self.outer.each_touching(t, |ids, _| skip(ids), &mut found);
        self.inner
            .each_touching(t, |ids, _| skip(ids), |j| found(j + self.faces));
    }
}

/// For each offset triangle (outer `t`, inner `F + t`): whether it has a vertex in `moved`.
fn touching(base: &Base, moved: &[bool]) -> Vec<bool> {
    (0..2 * base.tris.len())
        .map(|i| {
            base.tris[i % base.tris.len()]
                .iter()
                .any(|&v| moved[v as usize])
        })
        .collect()
}

/// The corners of every offset triangle (outer `t`, inner `F + t`) at the ε given, and their
/// vertex ids (see [`inner_id`]).
fn offset_triangles(base: &Base, outer: &[f64], inner: &[f64]) -> (Vec<[DVec3; 3]>, Vec<[u32; 3]>) {
    let n = base.vertex_count();
    let f = base.tris.len();
    let up = |v: u32| base.pos[v as usize] + base.normals[v as usize] * outer[v as usize];
    let down = |v: u32| base.pos[v as usize] - base.normals[v as usize] * inner[v as usize];
    let mut corners = Vec::with_capacity(2 * f);
    let mut ids = Vec::with_capacity(2 * f);
    for tri in &base.tris {
        corners.push(tri.map(up));
        ids.push(*tri);
    }
    for tri in &base.tris {
        corners.push(tri.map(down));
        ids.push(tri.map(|v| inner_id(v as usize, n, outer, inner)));
    }
    (corners, ids)
}

/// For each offset triangle (outer `t`, inner `F + t`): whether it crosses a triangle of either
/// offset that shares no vertex with it, or turned against its input triangle. Only the
/// triangles marked in `only` are tested (all when `None`); a crossing marks both triangles.
fn crossing_triangles(
    base: &Base,
    set: &Envelope,
    outer: &[f64],
    inner: &[f64],
    only: Option<&[bool]>,
) -> Vec<bool> {
    let (corners, ids) = offset_triangles(base, outer, inner);
    let f = base.tris.len();
    let found: Vec<Vec<u32>> = (0..2 * f)
        .into_par_iter()
        .map(|i| {
            let mut hits = Vec::new();
            if only.is_some_and(|o| !o[i]) {
                return hits;
            }
            let input = base.corners(i % f);
            let n_in = (input[1] - input[0]).cross(input[2] - input[0]);
            let c = &corners[i];
            let n_off = (c[1] - c[0]).cross(c[2] - c[0]);
            if n_in.length_squared() > 0.0 && n_in.dot(n_off) <= 0.0 {
                hits.push(i as u32);
            }
            let mine = ids[i];
            set.each_touching(
                c,
                |other| other.iter().any(|v| mine.contains(v)),
                |j| {
                    hits.push(i as u32);
                    hits.push(j);
                },
            );
            hits
        })
        .collect();
    let mut crossing = vec![false; 2 * f];
    for i in found.into_iter().flatten() {
        crossing[i as usize] = true;
    }
    crossing
}
