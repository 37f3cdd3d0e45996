//! Volumes and their restoring for [`super::smooth`] (module docs there, step 5): each label's
//! volume by the divergence theorem, the volume gradients at the vertices between two labels,
//! the labels' Gram matrix and its conjugate-gradient solve.
//!
//! Every sum over triangles or vertices is exact in fixed point (`sums.rs`) and counts only
//! what an [`Owned`] box of corners holds, so the results depend neither on the number of
//! threads nor on whether the map is meshed whole or block by block.

use rayon::prelude::*;
use voxlod_core::glam::Vec3;
use voxlod_core::memory;

use super::relax::Layout;
use super::sums::{summed, PairRuns, PairSums, Quantum};
use super::{Frame, Pressure, SmoothingOptions};
use crate::surface_nets::{LabelSlots, SharedSurface, VertexKind};
use crate::LabelsError;

/// Triangles per chunk of the volume sums.
const TRIANGLE_CHUNK: usize = 1 << 15;
/// Vertices per chunk of the Gram sums.
const VERTEX_CHUNK: usize = 1 << 14;
/// Corner planes per chunk of the gradient pass, counted from the whole map's first plane.
const GRADIENT_PLANES: u32 = 4;

/// The corners a sum counts, in the whole map's numbering (`lo..hi` per axis): the triangles
/// whose smallest corner (per axis the least of their three) and the vertices whose corner lie
/// there. A map meshed block by block counts each triangle and vertex in exactly one block.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Owned {
    /// The first corner held.
    pub lo: [u32; 3],
    /// One past the last corner held, per axis.
    pub hi: [u32; 3],
}

impl Owned {
    /// Every corner.
    pub const ALL: Owned = Owned {
        lo: [0; 3],
        hi: [u32::MAX; 3],
    };

    fn holds(&self, c: [u32; 3]) -> bool {
        (0..3).all(|a| (self.lo[a]..self.hi[a]).contains(&c[a]))
    }
}

/// Whether `owned` holds triangle `t` (its smallest corner, `offset` added).
#[inline]
fn holds_triangle(surface: &SharedSurface, owned: &Owned, t: [u32; 3]) -> bool {
    let [a, b, c] = t.map(|v| surface.corners[v as usize]);
    let low: [u32; 3] = std::array::from_fn(|i| a[i].min(b[i]).min(c[i]) + surface.offset[i]);
    owned.holds(low)
}

/// Whether `owned` holds vertex `v` (its corner, `offset` added).
#[inline]
fn holds_vertex(surface: &SharedSurface, owned: &Owned, v: usize) -> bool {
    let c = surface.corners[v];
    owned.holds(std::array::from_fn(|i| c[i] + surface.offset[i]))
}

/// Per label pair `[inside, outside]`, the signed volume its owned triangles enclose with the
/// grid's origin (grid space, which has the world's volumes up to the direction's
/// determinant, ±1). Cost: O(triangles), parallel.
pub(super) fn pair_volumes(
    surface: &SharedSurface,
    frame: &Frame,
    q: &[Vec3],
    owned: &Owned,
) -> PairSums {
    let quantum = Quantum::volume(frame.spacing);
    let all = *owned == Owned::ALL;
    surface
        .triangles
        .par_chunks(TRIANGLE_CHUNK)
        .zip(surface.sides.par_chunks(TRIANGLE_CHUNK))
        .fold(PairRuns::default, |mut runs, (tris, sides)| {
            for (t, s) in tris.iter().zip(sides) {
                if !all && !holds_triangle(surface, owned, *t) {
                    continue;
                }
                let [a, b, c] = t.map(|v| q[v as usize].as_dvec3());
                runs.add(*s, quantum.fixed(a.dot(b.cross(c)) / 6.0));
            }
            runs
        })
        .reduce(PairRuns::default, PairRuns::joined)
        .sums(&quantum)
}

/// Each of `labels`' enclosed volume from `pairs` (inside labels add, outside ones
/// subtract), by slot.
fn volumes_of(pairs: &PairSums, labels: &LabelSlots, count: usize) -> Vec<f64> {
    let mut volumes = vec![0i128; count];
    for &([inside, outside], v) in &pairs.sums {
        if let Some(i) = labels.get(inside) {
            volumes[i] += v;
        }
        if let Some(o) = labels.get(outside) {
            volumes[o] -= v;
        }
    }
    volumes.iter().map(|&v| v as f64 * pairs.unit).collect()
}

/// What the restoring moves: the surface, its corner rows and its frame.
pub(super) struct Restoring<'a> {
    pub surface: &'a SharedSurface,
    pub layout: &'a Layout,
    pub frame: &'a Frame,
}

/// The labels' volumes to restore: the labels (sorted), their slots, and their volumes before
/// smoothing by slot.
pub(super) struct Targets {
    pub labels: Vec<u32>,
    pub slots: LabelSlots,
    pub volumes: Vec<f64>,
}

impl Targets {
    /// The labels other than 0 of the pairs' volumes `before` smoothing, and their volumes.
    pub(super) fn of(before: &PairSums) -> Targets {
        let labels = before.labels();
        let slots = LabelSlots::new(&labels);
        let volumes = volumes_of(before, &slots, labels.len());
        Targets {
            labels,
            slots,
            volumes,
        }
    }

    /// Each label's volume from the pairs' volumes `pairs`, by slot.
    pub(super) fn measure(&self, pairs: &PairSums) -> Vec<f64> {
        volumes_of(pairs, &self.slots, self.labels.len())
    }
}

impl Restoring<'_> {
    /// Restores the labels' volumes to the targets by solving a pressure per round (at most
    /// `options.restore_rounds`); returns the rounds run and, when the last round found them
    /// within the tolerance, the volumes it measured.
    pub(super) fn restore(
        &self,
        q: &mut [Vec3],
        targets: &Targets,
        options: &SmoothingOptions,
    ) -> Result<(usize, Option<Vec<f64>>), LabelsError> {
        check_memory(q.len())?;
        for round in 0..options.restore_rounds {
            // The first round always moves vertices (smoothing has changed the volumes), so its
            // gradients come in the same pass over the triangles as its volumes.
            let mut ready = None;
            let volumes = if round == 0 {
                let g = gradients(self.surface, self.layout, self.frame, q, &Owned::ALL);
                let volumes = targets.measure(&g.volumes);
                ready = Some(g);
                volumes
            } else {
                let pairs = pair_volumes(self.surface, self.frame, q, &Owned::ALL);
                targets.measure(&pairs)
            };
            if within_tolerance(&targets.volumes, &volumes, options.volume_tolerance) {
                return Ok((round, Some(volumes)));
            }
            let g = ready.unwrap_or_else(|| {
                gradients(self.surface, self.layout, self.frame, q, &Owned::ALL)
            });
            let weights = gram_weights(self.surface, self.frame, &g, &Owned::ALL);
            let pressure = solve(&targets.labels, &targets.volumes, &volumes, &weights);
            self.apply(q, &g, &pressure);
        }
        Ok((options.restore_rounds, None))
    }

    /// One round with a pressure solved elsewhere: the gradients at `q`, then the move.
    pub(super) fn apply_given(
        &self,
        q: &mut [Vec3],
        pressure: &Pressure,
    ) -> Result<(), LabelsError> {
        check_memory(q.len())?;
        let g = gradients(self.surface, self.layout, self.frame, q, &Owned::ALL);
        self.apply(q, &g, pressure);
        Ok(())
    }

    /// Moves every vertex between exactly two labels `A` (its gradient's) and `B` by
    /// `(p_A − p_B) g`, on the axes where its box has room, and keeps it in its box.
    fn apply(&self, q: &mut [Vec3], g: &Gradients, pressure: &Pressure) {
        let (surface, frame) = (self.surface, self.frame);
        let slots = LabelSlots::new(&pressure.labels);
        q.par_iter_mut().enumerate().for_each(|(v, p)| {
            let [inside, outside] = g.sides[v];
            let flags = surface.flags[v];
            if inside == u32::MAX || flags.kind() != VertexKind::Surface || !flags.has_two_labels()
            {
                return;
            }
            let at = |l: u32| slots.get(l).map_or(0.0, |s| pressure.values[s]);
            let h = g.gradient[v] * mask(frame.half(flags.border_axes()));
            let moved = *p + h * (at(inside) - at(outside)) as f32;
            let (start, half) = (
                frame.start(surface.corners[v]),
                frame.half(flags.border_axes()),
            );
            *p = moved.clamp(start - half, start + half);
        });
    }
}

/// Fails when the memory limit refuses a round's work arrays for `vertices` vertices (a
/// gradient and a label pair each).
pub(super) fn check_memory(vertices: usize) -> Result<(), LabelsError> {
    memory::check_allocation("volume restoring", memory::bytes_of::<[u32; 5]>(vertices))?;
    Ok(())
}

/// Whether every label's volume is within `tolerance` (relative) of its target.
pub(super) fn within_tolerance(target: &[f64], volumes: &[f64], tolerance: f64) -> bool {
    let worst = (target.iter().zip(volumes))
        .map(|(t, v)| ((t - v) / t).abs())
        .fold(0.0, f64::max);
    worst <= tolerance
}

/// The pressures of `labels` (sorted) that restore `volumes` to `target` (by slot) along the
/// gradients whose Gram weights are `weights`.
pub(super) fn solve(
    labels: &[u32],
    target: &[f64],
    volumes: &[f64],
    weights: &PairSums,
) -> Pressure {
    let error: Vec<f64> = target.iter().zip(volumes).map(|(t, v)| t - v).collect();
    let slots = LabelSlots::new(labels);
    let gram = Gram::from_pairs(weights, &slots, labels.len());
    Pressure {
        labels: labels.to_vec(),
        values: gram.solve(&error),
    }
}

/// 1 on the axes where the box has room, 0 elsewhere.
fn mask(half: Vec3) -> Vec3 {
    Vec3::select(half.cmpgt(Vec3::ZERO), Vec3::ONE, Vec3::ZERO)
}

/// What [`gradients`] gives.
pub(super) struct Gradients {
    /// Per vertex, the gradient of the volume of the inside label of its last triangle.
    gradient: Vec<Vec3>,
    /// Per vertex, that triangle's two labels (`[u32::MAX; 2]` for a vertex without triangles).
    sides: Vec<[u32; 2]>,
    /// The label pairs' volumes over the owned triangles, as [`pair_volumes`] gives them.
    pub volumes: PairSums,
}

/// Per vertex its gradient and labels ([`Gradients`]), and the pairs' volumes over the
/// triangles `owned` holds. The gradients are meaningful for the vertices between exactly two
/// labels (the only ones the callers use): such a vertex has every triangle between the same
/// two, in the same order. Cost: O(triangles), parallel over chunks of [`GRADIENT_PLANES`]
/// corner planes of the whole map in two colours (a chunk's triangles touch its planes and the
/// next chunk's first, so chunks of one colour write apart). A vertex's terms are added in an
/// order fixed by the whole map's chunks, so a block of the map gives its vertices the same
/// gradients bit for bit.
pub(super) fn gradients(
    surface: &SharedSurface,
    layout: &Layout,
    frame: &Frame,
    q: &[Vec3],
    owned: &Owned,
) -> Gradients {
    let n = q.len();
    let mut gradient = vec![Vec3::ZERO; n];
    let mut sides = vec![[u32::MAX; 2]; n];
    let planes = layout.planes();
    let chunks = plane_chunks(planes, surface.offset[2]);
    let by_plane = surface.triangle_plane_starts();
    let quantum = Quantum::volume(frame.spacing);
    let all = *owned == Owned::ALL;
    let mut volumes = PairRuns::default();
    for colour in 0..2 {
        let picked: Vec<(usize, usize)> = (chunks.iter().copied())
            .filter(|&(a, _)| (a as u32 + surface.offset[2]) / GRADIENT_PLANES % 2 == colour)
            .collect();
        let windows: Vec<(usize, usize)> = picked
            .iter()
            .map(|&(a, b)| {
                (
                    layout.plane_start(a),
                    layout.plane_start((b + 1).min(planes)),
                )
            })
            .collect();
        let g_parts = split_windows(&mut gradient, &windows);
        let s_parts = split_windows(&mut sides, &windows);
        let runs = g_parts
            .into_par_iter()
            .zip(s_parts)
            .zip(picked)
            .zip(windows)
            .map(|(((g, s), (a, b)), (first, _))| {
                let mut runs = PairRuns::default();
                for t in by_plane[a]..by_plane[b] {
                    let tri = surface.triangles[t];
                    let [a, b, e] = tri.map(|v| q[v as usize]);
                    let area = (b - a).cross(e - a) / 6.0;
                    let pair = surface.sides[t];
                    for v in tri {
                        g[v as usize - first] += area;
                        s[v as usize - first] = pair;
                    }
                    if all || holds_triangle(surface, owned, tri) {
                        let [a, b, e] = [a, b, e].map(|p| p.as_dvec3());
                        runs.add(pair, quantum.fixed(a.dot(b.cross(e)) / 6.0));
                    }
                }
                runs
            })
            .reduce(PairRuns::default, PairRuns::joined);
        volumes = volumes.joined(runs);
    }
    Gradients {
        gradient,
        sides,
        volumes: volumes.sums(&quantum),
    }
}

/// Corner planes `[a, b)` of a block whose first plane is the whole map's `first`, cut where
/// the whole map's planes are multiples of [`GRADIENT_PLANES`].
fn plane_chunks(planes: usize, first: u32) -> Vec<(usize, usize)> {
    let mut chunks = Vec::new();
    let mut a = 0;
    while a < planes {
        let into = (a as u32 + first) % GRADIENT_PLANES;
        let b = (a + (GRADIENT_PLANES - into) as usize).min(planes);
        chunks.push((a, b));
        a = b;
    }
    chunks
}

/// The Gram weights per label pair `(A, B)`: `Σ g·(m∘g)` over the vertices `owned` holds
/// that lie between exactly `A` and `B` and may move (a surface vertex whose box has room),
/// `m` the axes with room. Cost: O(vertices), parallel.
pub(super) fn gram_weights(
    surface: &SharedSurface,
    frame: &Frame,
    g: &Gradients,
    owned: &Owned,
) -> PairSums {
    let quantum = Quantum::weight(frame.spacing);
    let all = *owned == Owned::ALL;
    (0..g.gradient.len().div_ceil(VERTEX_CHUNK))
        .into_par_iter()
        .fold(PairRuns::default, |mut runs, c| {
            let end = ((c + 1) * VERTEX_CHUNK).min(g.gradient.len());
            for v in c * VERTEX_CHUNK..end {
                let flags = surface.flags[v];
                let half = frame.half(flags.border_axes());
                let mobile = flags.kind() == VertexKind::Surface
                    && flags.has_two_labels()
                    && half != Vec3::ZERO;
                if g.sides[v][0] == u32::MAX || !mobile {
                    continue;
                }
                if !all && !holds_vertex(surface, owned, v) {
                    continue;
                }
                let d = g.gradient[v];
                runs.add(g.sides[v], quantum.fixed(d.dot(d * mask(half)) as f64));
            }
            runs
        })
        .reduce(PairRuns::default, PairRuns::joined)
        .sums(&quantum)
}

/// The disjoint, increasing `windows` of `data` as mutable slices.
fn split_windows<'a, T>(mut data: &'a mut [T], windows: &[(usize, usize)]) -> Vec<&'a mut [T]> {
    let mut parts = Vec::with_capacity(windows.len());
    let mut at = 0;
    for &(start, end) in windows {
        let rest = std::mem::take(&mut data);
        let (_, rest) = rest.split_at_mut(start - at);
        let (part, rest) = rest.split_at_mut(end - start);
        parts.push(part);
        data = rest;
        at = end;
    }
    parts
}

/// The sparse symmetric matrix `G` of the restoring step, over the labels.
struct Gram {
    /// Row starts into `columns` and `values`.
    rows: Vec<usize>,
    columns: Vec<u32>,
    values: Vec<f64>,
}

impl Gram {
    /// `G_LM = Σ_v g_vL · (m_v ∘ g_vM)` from the per-pair weights ([`gram_weights`]): the weight
    /// `w` of a pair `(A, B)` adds to `G_AA` and `G_BB` and is subtracted from `G_AB` and
    /// `G_BA`; the entries are summed in fixed point before they become numbers.
    fn from_pairs(weights: &PairSums, labels: &LabelSlots, count: usize) -> Gram {
        let mut entries: Vec<((u32, u32), i128)> = Vec::with_capacity(weights.sums.len() * 4);
        for &([inside, outside], w) in &weights.sums {
            let (a, b) = (labels.get(inside), labels.get(outside));
            if let Some(a) = a {
                entries.push(((a as u32, a as u32), w));
            }
            if let Some(b) = b {
                entries.push(((b as u32, b as u32), w));
            }
            if let (Some(a), Some(b)) = (a, b) {
                entries.push(((a as u32, b as u32), -w));
                entries.push(((b as u32, a as u32), -w));
            }
        }
        summed(&mut entries);
        let mut rows = vec![0usize; count + 1];
        for ((r, _), _) in &entries {
            rows[*r as usize + 1] += 1;
        }
        for r in 0..count {
            rows[r + 1] += rows[r];
        }
        Gram {
            rows,
            columns: entries.iter().map(|e| e.0 .1).collect(),
            values: entries.iter().map(|e| e.1 as f64 * weights.unit).collect(),
        }
    }

    fn times(&self, x: &[f64]) -> Vec<f64> {
        (0..self.rows.len() - 1)
            .map(|r| {
                (self.rows[r]..self.rows[r + 1])
                    .map(|e| self.values[e] * x[self.columns[e] as usize])
                    .sum()
            })
            .collect()
    }

    fn diagonal(&self) -> Vec<f64> {
        (0..self.rows.len() - 1)
            .map(|r| {
                (self.rows[r]..self.rows[r + 1])
                    .find(|&e| self.columns[e] as usize == r)
                    .map_or(0.0, |e| self.values[e])
            })
            .collect()
    }

    /// `G p = b` by Jacobi-preconditioned conjugate gradients; labels without a mobile vertex
    /// (a zero row) get 0. At most 500 iterations, relative residual 1e-10.
    fn solve(&self, b: &[f64]) -> Vec<f64> {
        let n = b.len();
        let diagonal = self.diagonal();
        let free: Vec<bool> = diagonal.iter().map(|&d| d > 0.0).collect();
        let inverse: Vec<f64> = diagonal
            .iter()
            .map(|&d| if d > 0.0 { 1.0 / d } else { 0.0 })
            .collect();
        let dot = |x: &[f64], y: &[f64]| -> f64 { x.iter().zip(y).map(|(a, b)| a * b).sum() };
        let mut x = vec![0.0; n];
        let mut r: Vec<f64> = (0..n).map(|i| if free[i] { b[i] } else { 0.0 }).collect();
        let mut z: Vec<f64> = r.iter().zip(&inverse).map(|(r, m)| r * m).collect();
        let mut p = z.clone();
        let mut rz = dot(&r, &z);
        let limit = dot(&r, &r).sqrt() * 1e-10;
        for _ in 0..500 {
            if dot(&r, &r).sqrt() <= limit || rz == 0.0 {
                break;
            }
            let gp = self.times(&p);
            let step = rz / dot(&p, &gp);
            if !step.is_finite() {
                break;
            }
            for i in 0..n {
                x[i] += step * p[i];
                r[i] -= step * gp[i];
            }
            z = r.iter().zip(&inverse).map(|(r, m)| r * m).collect();
            let next = dot(&r, &z);
            let beta = next / rz;
            rz = next;
            for i in 0..n {
                p[i] = z[i] + beta * p[i];
            }
        }
        x
    }
}
