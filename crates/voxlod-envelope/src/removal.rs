//! Vertex removal between the offset surfaces (paper §7, with the greedy order of §6.2–6.3).
//!
//! The mesh is kept complete at every step (§6.3's cure for cracks). A step removes one vertex
//! `v` and the triangles around it, and fills the hole, whose corners are `v`'s neighbours, with
//! triangles on those original vertices (`best_triangulation`, max–min aspect ratio). It is
//! accepted only if
//!
//! - `v` is an inner vertex (border vertices are kept: the border stays exact), not fixed by a
//!   sharp edge (§6.5) or a zero offset, with at most `max_valence` neighbours;
//! - its triangles project one-to-one on the plane of their area-weighted normal (a fan winding
//!   once around `v`) and every new triangle keeps its orientation in that projection, so the
//!   new triangles tile the same disk without folding over;
//! - no new diagonal is already an edge of the mesh (for `k = 3`, the new triangle is not already
//!   a face), so the mesh stays a manifold of the same topology;
//! - every new triangle has an aspect ratio of at least `min_aspect` and faces the same side as
//!   the hole (positive dot product with its normal);
//! - **no new triangle touches either offset surface** (the envelope);
//! - no new triangle touches a triangle of the current mesh that shares no vertex with it
//!   (the `live` BVH: inside one thick shell, around a sharp crease, a big new triangle could
//!   otherwise cut through the mesh beyond its hole);
//! - every input vertex the hole covered, `v` included, is within its target ε of the new
//!   triangles (the guard: the input-to-output half of the guarantee, checked where it is cheap).
//!
//! A triangle that fails is forbidden and the hole is planned again, until a triangulation
//! passes or none is left. The guard is checked first, with a quick covering estimate (each
//! covered vertex projected on the hole's plane, exact distances only when that estimate exceeds
//! ε): a triangle whose covered vertex no new triangle comes within ε of is forbidden before
//! any envelope query is spent on the plan.
//!
//! Order (§6.2): each vertex removed so far is *covered* by one current triangle, the one its
//! fibre (the line along its normal) crosses, as in §5. A removal's priority is the largest
//! number of input vertices one of its new triangles would cover ([`RemovalOrder::Coverage`],
//! the paper's "triangle that covers the largest number of vertices first"), ties broken by the
//! smaller deviation; [`RemovalOrder::Deviation`] takes the smallest deviation (largest distance
//! of a covered vertex from the new triangles, relative to its ε) first. Priorities come from
//! the planning without envelope queries, kept in a binary heap with a stamp per vertex; the
//! popped vertex is evaluated in full. When a vertex is removed its neighbours are re-planned
//! and pushed again, so a refused vertex is retried exactly when its neighbourhood has changed.
//! §6.4's estimate: at each acceptance, the ratio of the first priority popped since the last
//! acceptance to the accepted one; α is the largest ratio and d the largest cover.
//!
//! Deviation from the paper: §7 removes vertices but says little about how; the projection,
//! manifold and crossing tests, the max–min aspect retriangulation and the guard are ours.
//!
//! Cost: per attempt O(k³) for planning plus one envelope query per proposed triangle (a BVH
//! descent) plus the covered vertices times k; each removal re-plans about six neighbours.
//! Memory: the triangle array with a free list, each vertex's live triangles, each triangle's
//! covered vertices and the live BVH, O(V + F).

use std::collections::BinaryHeap;

use glam::{DVec2, DVec3};
use rayon::prelude::*;
use serde::Serialize;
use voxlod_core::TriangleMesh;

use super::base::Base;
use super::geometry::{point_triangle_distance, triangles_intersect, CrossingTest};
use super::live::LiveSet;
use super::offsets::Envelope;
use super::retriangulate::best_triangulation;

/// Which removal the greedy heuristic tries first.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum RemovalOrder {
    /// The new triangle covering the most input vertices first (§6.2–6.3).
    #[default]
    Coverage,
    /// The smallest deviation from the input first.
    Deviation,
}

/// Largest valence a removable vertex may have (the triangulation tables are k³).
pub const MAX_VALENCE: usize = 32;

/// Removals evaluated together (in parallel): the best entries of the heap whose closed
/// one-rings are disjoint. Fixed, so that the result does not depend on the number of threads.
/// Evaluating independent removals together gives the same result as one after the other,
/// except that a neighbour re-planned after an earlier removal of the batch cannot overtake a
/// later one, and a triangle from an earlier removal of the batch is checked for crossings
/// separately.
const BATCH: usize = 16;

/// Heap entries looked at to fill a batch.
const LOOKAHEAD: usize = 64;

/// Smallest |cos| between a new triangle's normal and the hole's normal.
const MIN_FACING: f64 = 1e-3;

/// What one level's run did.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct RemovalReport {
    /// Vertices removed in this level.
    pub removed: usize,
    /// Full evaluations (heap pops that were not stale).
    pub attempts: usize,
    /// Batches of removals evaluated together (`attempts / batches` is the mean batch size).
    pub batches: usize,
    /// Refused: the vertex is fixed (border, sharp edge, zero offset, no normal) or gone.
    pub refused_fixed: usize,
    /// Refused: too many neighbours, or a link that is not one closed cycle.
    pub refused_valence: usize,
    /// Refused: the star does not project one-to-one on the hole's plane.
    pub refused_not_flat: usize,
    /// Refused: no triangulation of the hole is left (every one folds, is too thin, would
    /// repeat an edge or was forbidden).
    pub refused_no_triangulation: usize,
    /// Refused: a new triangle touches an offset surface.
    pub refused_envelope: usize,
    /// New triangles that would cut through the current mesh outside the hole.
    pub refused_crossing: usize,
    /// Refused: a covered input vertex would be farther than its ε from the new triangles.
    pub refused_guard: usize,
    /// Re-evaluations not queued because every triangulation of the hole leaves, by the quick
    /// estimate, a covered vertex beyond its ε.
    pub pruned: usize,
    /// Envelope queries (one per proposed triangle).
    pub envelope_tests: usize,
    /// §6.4: the largest ratio of the first priority popped since the last acceptance to the
    /// accepted one (coverage order only; 1 otherwise).
    pub alpha: f64,
    /// §6.4: the largest number of input vertices a triangle covers.
    pub max_cover: usize,
    /// Wall time of the removals.
    pub seconds: f64,
}

/// The quick covering estimate of a planned triangulation.
struct Estimate {
    owner: Vec<(u32, u8)>,
    counts: Vec<u32>,
    deviation: f64,
    /// A new triangle over a covered vertex that no new triangle comes within ε of, and that
    /// vertex.
    blamed: Option<(usize, u32)>,
}

/// What a refusal was for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Refusal {
    Fixed,
    Valence,
    NotFlat,
    NoTriangulation,
    Envelope,
    Crossing,
    Guard,
}

/// A removal ready to apply.
struct Candidate {
    /// The new triangles, as vertex ids.
    triangles: Vec<[u32; 3]>,
    /// For each covered input vertex (the removed vertex included), the index of its new triangle.
    owner: Vec<(u32, u8)>,
    cover: u32,
    /// Largest distance of a covered vertex from the new triangles over its ε.
    deviation: f64,
    envelope_tests: usize,
}

impl Candidate {
    fn key(&self, order: RemovalOrder) -> u64 {
        // Larger keys pop first: more cover, then less deviation.
        let dev = u32::MAX - (self.deviation.max(0.0) as f32).to_bits();
        match order {
            RemovalOrder::Coverage => ((self.cover as u64) << 32) | dev as u64,
            RemovalOrder::Deviation => dev as u64,
        }
    }
}

/// A triangulation of a hole that passed the checks asked for.
struct Plan {
    /// The new triangles, as positions in the hole's link.
    chosen: Vec<[usize; 3]>,
    /// The quick covering estimate of `chosen`.
    estimate: Estimate,
    /// The covered input vertices, the last one blamed first.
    covered: Vec<u32>,
    /// Envelope tests spent.
    tests: usize,
}

/// The removal heap: (priority key, vertex, the vertex's stamp when pushed).
type Heap = BinaryHeap<(u64, u32, u32)>;

impl RemovalReport {
    /// Counts one refusal under its reason.
    fn count_refusal(&mut self, refusal: Refusal) {
        *match refusal {
            Refusal::Fixed => &mut self.refused_fixed,
            Refusal::Valence => &mut self.refused_valence,
            Refusal::NotFlat => &mut self.refused_not_flat,
            Refusal::NoTriangulation => &mut self.refused_no_triangulation,
            Refusal::Envelope => &mut self.refused_envelope,
            Refusal::Crossing => &mut self.refused_crossing,
            Refusal::Guard => &mut self.refused_guard,
        } += 1;
    }
}

/// The hole a removal leaves: the link of the removed vertex, projected on the plane of the
/// star's area-weighted normal through it.
struct Hole {
    /// The neighbours, in order around the vertex.
    link: Vec<u32>,
    /// The removed vertex's position.
    centre: DVec3,
    /// Unit normal of the plane.
    normal: DVec3,
    /// Orthonormal axes of the plane.
    e1: DVec3,
    e2: DVec3,
    /// The link on the plane, relative to `centre`.
    flat: Vec<DVec2>,
    /// The largest squared distance of a link vertex from `centre` on the plane.
    scale2: f64,
}

impl Hole {
    /// The hole of `v` with `link`; `None` when the star does not project one-to-one on the
    /// plane (a fold, or a fan winding around more than once).
    fn new(pos: &[DVec3], v: usize, link: Vec<u32>) -> Option<Hole> {
        let k = link.len();
        let pv = pos[v];
        let mut normal = DVec3::ZERO;
        for i in 0..k {
            normal += (pos[link[i] as usize] - pv).cross(pos[link[(i + 1) % k] as usize] - pv);
        }
        let normal = normal.normalize_or_zero();
        if normal == DVec3::ZERO {
            return None;
        }
        let (e1, e2) = normal.any_orthonormal_pair();
        let flat: Vec<DVec2> = link
            .iter()
            .map(|&w| {
                let d = pos[w as usize] - pv;
                DVec2::new(d.dot(e1), d.dot(e2))
            })
            .collect();
        let scale2 = flat.iter().map(|p| p.length_squared()).fold(0.0, f64::max);
        let mut winding = 0.0;
        for i in 0..k {
            let (a, b) = (flat[i], flat[(i + 1) % k]);
            if a.perp_dot(b) < -1e-12 * scale2 {
                return None;
            }
            winding += a.perp_dot(b).atan2(a.dot(b));
        }
        if winding > 2.5 * std::f64::consts::PI {
            return None;
        }
        Some(Hole {
            link,
            centre: pv,
            normal,
            e1,
            e2,
            flat,
            scale2,
        })
    }

    /// The quality of every triangle (i < m < j) of link positions, at `(i k + m) k + j`:
    /// aspect ratio times facing; NaN for a triangle that is flat or reversed on the plane,
    /// below `min_aspect`, or facing away from the hole.
    fn qualities(&self, pos: &[DVec3], min_aspect: f64) -> Vec<f64> {
        let (k, flat, scale2) = (self.link.len(), &self.flat, self.scale2);
        let corner = |i: usize| pos[self.link[i] as usize];
        let mut quality = vec![f64::NAN; k * k * k];
        for i in 0..k {
            for m in i + 1..k {
                for j in m + 1..k {
                    let area2 = (flat[m] - flat[i]).perp_dot(flat[j] - flat[i]);
                    if area2 <= 1e-10 * scale2 {
                        continue;
                    }
                    let (a, b, c) = (corner(i), corner(m), corner(j));
                    let n3 = (b - a).cross(c - a);
                    let l = n3.length();
                    let sum = (b - a).length_squared()
                        + (c - b).length_squared()
                        + (a - c).length_squared();
                    if l == 0.0 || sum == 0.0 {
                        continue;
                    }
                    let aspect = 2.0 * 3f64.sqrt() * l / sum;
                    let facing = n3.dot(self.normal) / l;
                    if aspect < min_aspect || facing < MIN_FACING {
                        continue;
                    }
                    quality[(i * k + m) * k + j] = aspect * facing;
                }
            }
        }
        quality
    }
}

/// The settings of one level's run.
pub(crate) struct RemovalSettings<'a> {
    /// Target ε of each input vertex (the guard's bound).
    pub target: &'a [f64],
    /// Vertices that must stay (border, sharp edges, zero offset, no normal).
    pub fixed: &'a [bool],
    /// Both offset surfaces: no new triangle may touch them.
    pub envelope: &'a Envelope,
    /// Which removal to try first.
    pub order: RemovalOrder,
    /// Smallest aspect ratio of a new triangle.
    pub min_aspect: f64,
    /// Vertices with more neighbours are kept.
    pub max_valence: usize,
}

/// The mesh being simplified, kept complete between steps and between the levels of a series.
pub(crate) struct Work<'a> {
    base: &'a Base,
    tris: Vec<[u32; 3]>,
    alive: Vec<bool>,
    free: Vec<u32>,
    /// Input vertices covered by each triangle (removed vertices nearest to it).
    covered: Vec<Vec<u32>>,
    /// Live triangles around each vertex.
    around: Vec<Vec<u32>>,
    removed: Vec<bool>,
    stamp: Vec<u32>,
    alive_count: usize,
    /// The live triangles in a BVH (rebuilt at the start of each level).
    live: Option<LiveSet>,
}

impl<'a> Work<'a> {
    /// The input itself, nothing removed yet.
    pub fn new(base: &'a Base) -> Work<'a> {
        let n = base.vertex_count();
        Work {
            base,
            tris: base.tris.clone(),
            alive: vec![true; base.tris.len()],
            free: Vec::new(),
            covered: vec![Vec::new(); base.tris.len()],
            around: (0..n).map(|v| base.star(v).to_vec()).collect(),
            removed: vec![false; n],
            stamp: vec![0; n],
            alive_count: base.tris.len(),
            live: None,
        }
    }

    /// Triangles of the current mesh.
    pub fn triangle_count(&self) -> usize {
        self.alive_count
    }

    /// Removes vertices until no removal passes (see the module documentation).
    pub fn run(&mut self, level: &RemovalSettings) -> RemovalReport {
        let start = std::time::Instant::now();
        let mut report = RemovalReport {
            alpha: 1.0,
            ..Default::default()
        };
        self.compact();
        let pos = &self.base.pos;
        let tris = &self.tris;
        self.live = Some(LiveSet::new(
            |t| tris[t as usize].map(|v| pos[v as usize]),
            &self.alive,
            self.base.tol,
        ));
        let mut heap = self.initial_heap(level);
        let mut first_cover: Option<u32> = None;
        // The vertices claimed by the batch being collected (`claim[v] == batch number`).
        let mut claim = vec![0u32; self.base.vertex_count()];
        let mut batch_number = 0u32;
        loop {
            batch_number += 1;
            let batch = self.next_batch(&mut heap, &mut claim, batch_number);
            if batch.is_empty() {
                break;
            }
            report.batches += 1;
            let results: Vec<Result<Candidate, (Refusal, usize)>> = if batch.len() == 1 {
                vec![self.evaluate(batch[0].1, level, true)]
            } else {
                batch
                    .par_iter()
                    .map(|&(_, v)| self.evaluate(v, level, true))
                    .collect()
            };
            let touched =
                self.apply_batch(&batch, results, level.order, &mut report, &mut first_cover);
            self.replan(touched, level, &mut heap, &mut report);
        }
        report.seconds = start.elapsed().as_secs_f64();
        report
    }

    /// Every removable vertex planned (without envelope queries), by priority.
    fn initial_heap(&self, level: &RemovalSettings) -> Heap {
        let order = level.order;
        let initial: Vec<(u64, u32)> = (0..self.base.vertex_count())
            .into_par_iter()
            .filter(|&v| !self.removed[v] && !level.fixed[v] && !self.around[v].is_empty())
            .filter_map(|v| {
                self.evaluate(v, level, false)
                    .ok()
                    .map(|c| (c.key(order), v as u32))
            })
            .collect();
        initial
            .into_iter()
            .map(|(key, v)| (key, v, self.stamp[v as usize]))
            .collect()
    }

    /// A batch: the best entries whose closed one-rings are disjoint, in heap order, as
    /// (key, vertex); an entry overlapping an earlier one waits for the next batch (at most
    /// [`LOOKAHEAD`] entries are looked at). Stale entries are dropped.
    fn next_batch(
        &self,
        heap: &mut Heap,
        claim: &mut [u32],
        batch_number: u32,
    ) -> Vec<(u64, usize)> {
        let mut batch: Vec<(u64, usize)> = Vec::with_capacity(BATCH);
        let mut deferred = Vec::new();
        let mut looked = 0;
        while batch.len() < BATCH && looked < LOOKAHEAD {
            let Some((key, v, stamp)) = heap.pop() else {
                break;
            };
            let v = v as usize;
            if self.removed[v] || stamp != self.stamp[v] {
                continue;
            }
            looked += 1;
            let ring = self.around[v]
                .iter()
                .flat_map(|&t| self.tris[t as usize])
                .chain(std::iter::once(v as u32));
            if ring.clone().any(|w| claim[w as usize] == batch_number) {
                deferred.push((key, v as u32, stamp));
                continue;
            }
            for w in ring {
                claim[w as usize] = batch_number;
            }
            batch.push((key, v));
        }
        heap.extend(deferred);
        batch
    }

    /// Applies the batch's accepted removals in order, refusing one whose new triangles cross
    /// a triangle an earlier removal of the batch made (the evaluations saw the mesh before the
    /// batch), and counts everything in `report`. Returns the neighbours of the removed vertices.
    fn apply_batch(
        &mut self,
        batch: &[(u64, usize)],
        results: Vec<Result<Candidate, (Refusal, usize)>>,
        order: RemovalOrder,
        report: &mut RemovalReport,
        first_cover: &mut Option<u32>,
    ) -> Vec<u32> {
        let mut touched = Vec::new();
        let mut batch_triangles: Vec<([u32; 3], [DVec3; 3])> = Vec::new();
        for (&(key, v), result) in batch.iter().zip(results) {
            report.attempts += 1;
            if first_cover.is_none() {
                *first_cover = Some((key >> 32) as u32);
            }
            let result = result.and_then(|c| {
                if self.crosses_any(&c.triangles, &batch_triangles) {
                    Err((Refusal::Crossing, c.envelope_tests))
                } else {
                    Ok(c)
                }
            });
            match result {
                Ok(candidate) => {
                    report.envelope_tests += candidate.envelope_tests;
                    if order == RemovalOrder::Coverage {
                        let top = first_cover.take().unwrap_or(candidate.cover).max(1);
                        report.alpha = report.alpha.max(top as f64 / candidate.cover.max(1) as f64);
                    }
                    report.max_cover = report.max_cover.max(candidate.cover as usize);
                    batch_triangles.extend(
                        candidate
                            .triangles
                            .iter()
                            .map(|t| (*t, t.map(|w| self.base.pos[w as usize]))),
                    );
                    touched.extend(self.apply(v, candidate));
                    report.removed += 1;
                }
                Err((refusal, tests)) => {
                    report.envelope_tests += tests;
                    report.count_refusal(refusal);
                }
            }
        }
        touched
    }

    /// Whether one of `triangles` crosses one of `others` that shares no vertex with it.
    fn crosses_any(&self, triangles: &[[u32; 3]], others: &[([u32; 3], [DVec3; 3])]) -> bool {
        triangles.iter().any(|t| {
            let corners = t.map(|w| self.base.pos[w as usize]);
            others.iter().any(|(ids, other)| {
                !ids.iter().any(|w| t.contains(w))
                    && triangles_intersect(&corners, other, self.base.tol)
            })
        })
    }

    /// Plans the `touched` vertices again (their neighbourhood changed) and queues those that
    /// pass, under a new stamp.
    fn replan(
        &mut self,
        mut touched: Vec<u32>,
        level: &RemovalSettings,
        heap: &mut Heap,
        report: &mut RemovalReport,
    ) {
        touched.sort_unstable();
        touched.dedup();
        for &w in &touched {
            self.stamp[w as usize] = self.stamp[w as usize].wrapping_add(1);
        }
        touched.retain(|&w| !level.fixed[w as usize] && !self.removed[w as usize]);
        let planned: Vec<Result<u64, Refusal>> = touched
            .par_iter()
            .map(|&w| {
                self.evaluate(w as usize, level, false)
                    .map(|c| c.key(level.order))
                    .map_err(|(r, _)| r)
            })
            .collect();
        for (&w, plan) in touched.iter().zip(planned) {
            match plan {
                Ok(key) => heap.push((key, w, self.stamp[w as usize])),
                Err(Refusal::Guard) => report.pruned += 1,
                Err(_) => {}
            }
        }
    }

    /// Renumbers the live triangles `0..F` in order, dropping the free slots.
    fn compact(&mut self) {
        let mut new_id = vec![u32::MAX; self.tris.len()];
        let mut next = 0u32;
        for (t, slot) in new_id.iter_mut().enumerate() {
            if self.alive[t] {
                *slot = next;
                next += 1;
            }
        }
        let keep = |t: &usize| self.alive[*t];
        self.tris = (0..self.tris.len())
            .filter(keep)
            .map(|t| self.tris[t])
            .collect();
        self.covered = (0..self.covered.len())
            .filter(keep)
            .map(|t| std::mem::take(&mut self.covered[t]))
            .collect();
        self.alive = vec![true; next as usize];
        self.free.clear();
        for list in &mut self.around {
            for t in list.iter_mut() {
                *t = new_id[*t as usize];
                debug_assert_ne!(*t, u32::MAX);
            }
        }
    }

    /// Plans the removal of `v`; with `full`, tests the envelope and the guard too. On refusal,
    /// the reason and the envelope tests spent.
    fn evaluate(
        &self,
        v: usize,
        level: &RemovalSettings,
        full: bool,
    ) -> Result<Candidate, (Refusal, usize)> {
        if self.removed[v] || level.fixed[v] {
            return Err((Refusal::Fixed, 0));
        }
        let star = &self.around[v];
        let k = star.len();
        if k < 3 || k > level.max_valence.min(MAX_VALENCE) {
            return Err((Refusal::Valence, 0));
        }
        let link = self.link(v).ok_or((Refusal::Valence, 0))?;
        let hole = Hole::new(&self.base.pos, v, link).ok_or((Refusal::NotFlat, 0))?;
        let diagonal_free = self
            .free_diagonals(v, &hole.link)
            .ok_or((Refusal::NoTriangulation, 0))?;
        let covered: Vec<u32> = std::iter::once(v as u32)
            .chain(
                star.iter()
                    .flat_map(|&t| self.covered[t as usize].iter().copied()),
            )
            .collect();
        let Plan {
            chosen,
            estimate,
            covered,
            tests,
        } = self.plan(v, &hole, &diagonal_free, covered, level, full)?;
        let link = &hole.link;
        let (owner, counts, deviation) = if full {
            self.assign_by_fibres(covered.into_iter(), &chosen, link, level)
                .map_err(|refusal| (refusal, tests))?
        } else {
            (estimate.owner, estimate.counts, estimate.deviation)
        };
        Ok(Candidate {
            triangles: chosen
                .iter()
                .map(|&[i, m, j]| [link[i], link[m], link[j]])
                .collect(),
            owner,
            cover: counts.into_iter().max().unwrap_or(0),
            deviation,
            envelope_tests: tests,
        })
    }

    /// The link of `v` in order (triangle (v, a, b) counter-clockwise gives a → b); `None`
    /// unless it is one closed cycle through every neighbour.
    fn link(&self, v: usize) -> Option<Vec<u32>> {
        let star = &self.around[v];
        let k = star.len();
        let pairs: Vec<(u32, u32)> = star
            .iter()
            .map(|&t| {
                let tri = self.tris[t as usize];
                let r = tri.iter().position(|&w| w as usize == v).unwrap_or(0);
                (tri[(r + 1) % 3], tri[(r + 2) % 3])
            })
            .collect();
        let mut link = Vec::with_capacity(k);
        link.push(pairs[0].0);
        let mut current = pairs[0].1;
        while link.len() < k {
            if link.contains(&current) {
                return None;
            }
            link.push(current);
            current = pairs.iter().find(|p| p.0 == current)?.1;
        }
        // Not a closed fan: a border vertex that was not marked, which cannot happen for a
        // checked manifold.
        (current == link[0]).then_some(link)
    }

    /// For each pair of link positions, whether a new edge may join them: not when the edge
    /// already exists outside `v`'s star; `None` when, for `k = 3`, the hole's triangle is
    /// already a face.
    fn free_diagonals(&self, v: usize, link: &[u32]) -> Option<Vec<bool>> {
        let k = link.len();
        let mut edge = vec![false; k * k];
        for i in 0..k {
            for &t in &self.around[link[i] as usize] {
                let tri = self.tris[t as usize];
                if tri.contains(&(v as u32)) {
                    continue;
                }
                if k == 3 && link.iter().all(|w| tri.contains(w)) {
                    return None;
                }
                for &w in &tri {
                    if let Some(j) = link.iter().position(|&x| x == w) {
                        if j != i {
                            edge[i * k + j] = true;
                            edge[j * k + i] = true;
                        }
                    }
                }
            }
        }
        Some(edge.iter().map(|&e| !e).collect())
    }

    /// The best triangulation of the hole that passes. A triangle is forbidden, and the
    /// triangulation planned again, when the quick covering estimate puts a covered vertex
    /// beyond its ε from the new triangles (blaming the triangle it projects into) and, with
    /// `full`, when it touches the envelope or cuts through the mesh. Returns the chosen
    /// triangles, their estimate, the covered vertices (the last offender first) and the
    /// envelope tests spent.
    fn plan(
        &self,
        v: usize,
        hole: &Hole,
        diagonal_free: &[bool],
        mut covered: Vec<u32>,
        level: &RemovalSettings,
        full: bool,
    ) -> Result<Plan, (Refusal, usize)> {
        let k = hole.link.len();
        let mut quality = hole.qualities(&self.base.pos, level.min_aspect);
        let mut chosen = Vec::with_capacity(k - 2);
        let mut tested = vec![false; k * k * k];
        let mut tests = 0;
        let mut last = Refusal::NoTriangulation;
        loop {
            if best_triangulation(k, &quality, diagonal_free, &mut chosen).is_none() {
                return Err((last, tests));
            }
            let frame = (hole.centre, hole.e1, hole.e2);
            let estimate =
                self.assign_by_projection(&covered, &chosen, &hole.link, &hole.flat, frame, level);
            if let Some((blamed, offender)) = estimate.blamed {
                // The same vertex is the likeliest to fail the next plan: check it first.
                if let Some(at) = covered.iter().position(|&u| u == offender) {
                    covered.swap(0, at);
                }
                let [i, m, j] = chosen[blamed];
                quality[(i * k + m) * k + j] = f64::NAN;
                last = Refusal::Guard;
                continue;
            }
            if !full {
                return Ok(Plan {
                    chosen,
                    estimate,
                    covered,
                    tests,
                });
            }
            match self.first_blocked(v, hole, &chosen, &mut tested, &mut tests, level) {
                Some((slot, refusal)) => {
                    quality[slot] = f64::NAN;
                    last = refusal;
                }
                None => {
                    return Ok(Plan {
                        chosen,
                        estimate,
                        covered,
                        tests,
                    })
                }
            }
        }
    }

    /// The first of the chosen triangles, largest first (the likeliest to leave the envelope),
    /// that touches the envelope or cuts through the mesh, as its quality slot and the refusal;
    /// triangles already `tested` are skipped, and each test is counted in `tests`.
    fn first_blocked(
        &self,
        v: usize,
        hole: &Hole,
        chosen: &[[usize; 3]],
        tested: &mut [bool],
        tests: &mut usize,
        level: &RemovalSettings,
    ) -> Option<(usize, Refusal)> {
        let (k, link) = (hole.link.len(), &hole.link);
        let corner = |i: usize| self.base.pos[link[i] as usize];
        let mut order: Vec<usize> = (0..chosen.len()).collect();
        order.sort_by_cached_key(|&c| {
            let [i, m, j] = chosen[c];
            let area2 = (corner(m) - corner(i))
                .cross(corner(j) - corner(i))
                .length_squared();
            std::cmp::Reverse((area2 as f32).to_bits())
        });
        for c in order {
            let [i, m, j] = chosen[c];
            let slot = (i * k + m) * k + j;
            if tested[slot] {
                continue;
            }
            tested[slot] = true;
            *tests += 1;
            let t = [corner(i), corner(m), corner(j)];
            if level.envelope.touches(&t) {
                return Some((slot, Refusal::Envelope));
            }
            if self.cuts_through(&t, [link[i], link[m], link[j]], v as u32) {
                return Some((slot, Refusal::Crossing));
            }
        }
        None
    }

    /// The covering of §5, for a removal that will be applied: a vertex is covered by the new
    /// triangle its fibre (the line along its normal) crosses, nearest first; a vertex whose
    /// fibre misses them all goes to the nearest triangle. Its distance is the fibre's length
    /// to the crossing when that is within its ε, else the exact distance to the new triangles;
    /// the guard refuses a distance beyond ε. Returns the owners, the count per new triangle
    /// and the largest distance over ε.
    #[allow(clippy::type_complexity)]
    fn assign_by_fibres(
        &self,
        covered: impl Iterator<Item = u32>,
        chosen: &[[usize; 3]],
        link: &[u32],
        level: &RemovalSettings,
    ) -> Result<(Vec<(u32, u8)>, Vec<u32>, f64), Refusal> {
        let pos = &self.base.pos;
        let tol = self.base.tol;
        let corners: Vec<[DVec3; 3]> = chosen
            .iter()
            .map(|t| t.map(|i| pos[link[i] as usize]))
            .collect();
        let crossings: Vec<Option<CrossingTest>> =
            corners.iter().map(|t| CrossingTest::new(t, tol)).collect();
        let nearest = |p: DVec3| {
            corners
                .iter()
                .enumerate()
                .map(|(i, t)| (i, point_triangle_distance(p, t)))
                .fold((0, f64::INFINITY), |a, b| if b.1 < a.1 { b } else { a })
        };
        let mut owner = Vec::new();
        let mut counts = vec![0u32; chosen.len()];
        let mut deviation: f64 = 0.0;
        for u in covered {
            let (p, n) = (pos[u as usize], self.base.normals[u as usize]);
            let target = level.target[u as usize];
            let fibre = crossings
                .iter()
                .enumerate()
                .filter_map(|(i, c)| c.and_then(|c| c.line(p, n)).map(|s| (i, s.abs())))
                .fold(None, |best: Option<(usize, f64)>, hit| match best {
                    Some(b) if b.1 <= hit.1 => Some(b),
                    _ => Some(hit),
                });
            let (best, dist) = match fibre {
                Some((i, s)) if s <= target + tol => (i, s),
                Some((i, _)) => (i, nearest(p).1),
                None => nearest(p),
            };
            if dist > target + tol {
                return Err(Refusal::Guard);
            }
            deviation = deviation.max(if target > 0.0 { dist / target } else { dist });
            counts[best] += 1;
            owner.push((u, best as u8));
        }
        Ok((owner, counts, deviation))
    }

    /// A quick estimate of the covering: each vertex goes to the new triangle that holds its
    /// projection on the hole's plane (or the one it is least outside of), and its distance is
    /// its distance to that triangle's plane; when that exceeds its ε, the exact distance to the
    /// nearest new triangle instead, and if even that exceeds ε the projected-into triangle is
    /// blamed.
    fn assign_by_projection(
        &self,
        covered: &[u32],
        chosen: &[[usize; 3]],
        link: &[u32],
        flat: &[DVec2],
        (origin, e1, e2): (DVec3, DVec3, DVec3),
        level: &RemovalSettings,
    ) -> Estimate {
        let pos = &self.base.pos;
        // Per new triangle: the three 2-D edge functions and the 3-D plane.
        type Plane = ([(DVec2, DVec2); 3], DVec3, DVec3);
        let tests: Vec<Plane> = chosen
            .iter()
            .map(|t| {
                let q = t.map(|i| flat[i]);
                let p = t.map(|i| pos[link[i] as usize]);
                let edges = [0, 1, 2].map(|e| (q[e], q[(e + 1) % 3] - q[e]));
                (
                    edges,
                    p[0],
                    (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero(),
                )
            })
            .collect();
        let mut estimate = Estimate {
            owner: Vec::with_capacity(covered.len()),
            counts: vec![0; chosen.len()],
            deviation: 0.0,
            blamed: None,
        };
        for &u in covered {
            let p = pos[u as usize];
            let d = p - origin;
            let x = DVec2::new(d.dot(e1), d.dot(e2));
            let mut best = (0, f64::NEG_INFINITY);
            for (i, (edges, _, _)) in tests.iter().enumerate() {
                let inside = edges
                    .iter()
                    .map(|&(a, e)| e.perp_dot(x - a))
                    .fold(f64::INFINITY, f64::min);
                if inside > best.1 {
                    best = (i, inside);
                    if inside >= 0.0 {
                        break;
                    }
                }
            }
            let (_, corner, normal) = tests[best.0];
            let mut dist = (p - corner).dot(normal).abs();
            let target = level.target[u as usize];
            let mut owner = best.0;
            if dist > target {
                // The projection may have picked the wrong triangle (around a crease): measure
                // exactly.
                for (i, t) in chosen.iter().enumerate() {
                    let d = point_triangle_distance(p, &t.map(|c| pos[link[c] as usize]));
                    if d < dist {
                        dist = d;
                        owner = i;
                    }
                }
                if dist > target + self.base.tol {
                    estimate.blamed = Some((best.0, u));
                    return estimate;
                }
            }
            estimate.deviation =
                estimate
                    .deviation
                    .max(if target > 0.0 { dist / target } else { dist });
            estimate.counts[owner] += 1;
            estimate.owner.push((u, owner as u8));
        }
        estimate
    }

    /// Whether the new triangle `t` (vertices `ids`) touches a current triangle that shares no
    /// vertex with it and is not around `v` (those go away).
    fn cuts_through(&self, t: &[DVec3; 3], ids: [u32; 3], v: u32) -> bool {
        let Some(live) = &self.live else {
            return false;
        };
        let pos = &self.base.pos;
        live.touches(
            t,
            |s| self.tris[s as usize].map(|w| pos[w as usize]),
            |s| {
                let o = self.tris[s as usize];
                o.contains(&v) || o.iter().any(|w| ids.contains(w))
            },
        )
    }

    /// Replaces `v`'s triangles by the candidate's; returns `v`'s former neighbours.
    fn apply(&mut self, v: usize, candidate: Candidate) -> Vec<u32> {
        let star = std::mem::take(&mut self.around[v]);
        let mut link = Vec::with_capacity(star.len());
        for &t in &star {
            self.alive[t as usize] = false;
            self.covered[t as usize].clear();
            self.free.push(t);
            if let Some(live) = &mut self.live {
                live.remove(t);
            }
            for w in self.tris[t as usize] {
                if w as usize != v {
                    self.around[w as usize].retain(|&x| x != t);
                    if !link.contains(&w) {
                        link.push(w);
                    }
                }
            }
        }
        self.removed[v] = true;
        let mut ids = Vec::with_capacity(candidate.triangles.len());
        for tri in &candidate.triangles {
            let id = match self.free.pop() {
                Some(id) => {
                    self.tris[id as usize] = *tri;
                    self.alive[id as usize] = true;
                    id
                }
                None => {
                    self.tris.push(*tri);
                    self.alive.push(true);
                    self.covered.push(Vec::new());
                    (self.tris.len() - 1) as u32
                }
            };
            for &w in tri {
                self.around[w as usize].push(id);
            }
            if let Some(live) = &mut self.live {
                live.insert(id, &tri.map(|w| self.base.pos[w as usize]));
            }
            ids.push(id);
        }
        for (u, i) in candidate.owner {
            self.covered[ids[i as usize] as usize].push(u);
        }
        self.alive_count = self.alive_count + candidate.triangles.len() - star.len();
        link
    }

    /// The current mesh on the input's vertices that remain, and for each of its vertices the
    /// input vertex it is. Normals are the input's when it has them, else the angle-weighted ones.
    pub fn snapshot(&self, input: &TriangleMesh) -> (TriangleMesh, Vec<u32>) {
        let n = self.base.vertex_count();
        let mut new_id = vec![u32::MAX; n];
        for (t, tri) in self.tris.iter().enumerate() {
            if self.alive[t] {
                for &v in tri {
                    new_id[v as usize] = 0;
                }
            }
        }
        // Kept vertices in input order.
        let mut vertex_map = Vec::new();
        for (v, slot) in new_id.iter_mut().enumerate() {
            if *slot == 0 {
                *slot = vertex_map.len() as u32;
                vertex_map.push(v as u32);
            }
        }
        let triangles: Vec<[u32; 3]> = self
            .tris
            .iter()
            .zip(&self.alive)
            .filter(|(_, &alive)| alive)
            .map(|(tri, _)| tri.map(|v| new_id[v as usize]))
            .collect();
        let positions = vertex_map
            .iter()
            .map(|&v| input.positions[v as usize])
            .collect();
        let normals = if input.normals.len() == input.positions.len() {
            vertex_map
                .iter()
                .map(|&v| input.normals[v as usize])
                .collect()
        } else {
            vertex_map
                .iter()
                .map(|&v| self.base.normals[v as usize].as_vec3())
                .collect()
        };
        (
            TriangleMesh {
                positions,
                normals,
                triangles,
            },
            vertex_map,
        )
    }
}
