//! Volumes and their restoring for [`super::smooth`] (module docs there, step 5): each label's
//! volume by the divergence theorem, the volume gradients at the vertices between two labels,
//! the labels' Gram matrix and its conjugate-gradient solve.
//!
//! Every sum is taken in an order fixed by the surface alone (fixed chunks reduced in order),
//! so the results do not depend on the number of threads.

use rayon::prelude::*;
use rustc_hash::FxHashMap;
use voxlod_core::glam::Vec3;
use voxlod_core::memory;

use super::relax::Layout;
use super::{Frame, SmoothingOptions};
use crate::surface_nets::{LabelSlots, SharedSurface, VertexKind};
use crate::LabelsError;

/// Triangles per chunk of the volume sums.
const TRIANGLE_CHUNK: usize = 1 << 15;
/// Vertices per chunk of the Gram sums.
const VERTEX_CHUNK: usize = 1 << 14;
/// Corner planes per chunk of the gradient pass.
const GRADIENT_PLANES: usize = 4;

/// Per label pair `[inside, outside]`, the signed volume its triangles enclose with the origin
/// (grid space, which has the world's volumes up to the direction's determinant, ±1), summed
/// per run of one pair within fixed chunks of triangles; the chunks' sums in chunk order.
/// Cost: O(triangles), parallel.
fn pair_volumes(surface: &SharedSurface, q: &[Vec3]) -> Vec<PairSums> {
    surface
        .triangles
        .par_chunks(TRIANGLE_CHUNK)
        .zip(surface.sides.par_chunks(TRIANGLE_CHUNK))
        .map(|(tris, sides)| {
            let mut runs = PairRuns::default();
            for (t, s) in tris.iter().zip(sides) {
                let [a, b, c] = t.map(|v| q[v as usize].as_dvec3());
                runs.add(*s, a.dot(b.cross(c)) / 6.0);
            }
            runs.sums()
        })
        .collect()
}

/// Each label's enclosed volume from [`pair_volumes`] (inside labels add, outside ones
/// subtract), by slot.
fn volumes_of(pairs: &[PairSums], labels: &LabelSlots, count: usize) -> Vec<f64> {
    let mut volumes = vec![0.0f64; count];
    for &([inside, outside], v) in pairs.iter().flatten() {
        if let Some(i) = labels.get(inside) {
            volumes[i] += v;
        }
        if let Some(o) = labels.get(outside) {
            volumes[o] -= v;
        }
    }
    volumes
}

/// Each label's enclosed volume, by slot (`count` labels). Cost: O(triangles), parallel, the
/// sums in an order fixed by the surface.
pub(super) fn label_volumes(
    surface: &SharedSurface,
    q: &[Vec3],
    labels: &LabelSlots,
    count: usize,
) -> Vec<f64> {
    volumes_of(&pair_volumes(surface, q), labels, count)
}

/// The labels other than 0 that have triangles (sorted), their slots, and their volumes, in
/// one pass over the triangles.
pub(super) fn labels_and_volumes(
    surface: &SharedSurface,
    q: &[Vec3],
) -> (Vec<u32>, LabelSlots, Vec<f64>) {
    let pairs = pair_volumes(surface, q);
    let mut labels: Vec<u32> = pairs
        .iter()
        .flatten()
        .flat_map(|(p, _)| p.iter().copied())
        .filter(|&l| l != 0)
        .collect();
    labels.sort_unstable();
    labels.dedup();
    let slots = LabelSlots::new(&labels);
    let volumes = volumes_of(&pairs, &slots, labels.len());
    (labels, slots, volumes)
}

/// Restores the labels' volumes to `target`; returns the rounds run and, when the last round
/// found them within the tolerance, the volumes it measured.
pub(super) fn restore(
    surface: &SharedSurface,
    layout: &Layout,
    frame: &Frame,
    q: &mut [Vec3],
    labels: &LabelSlots,
    target: &[f64],
    options: &SmoothingOptions,
) -> Result<(usize, Option<Vec<f64>>), LabelsError> {
    memory::check_allocation("volume restoring", memory::bytes_of::<[u32; 5]>(q.len()))?;
    for round in 0..options.restore_rounds {
        // The first round always moves vertices (smoothing has changed the volumes), so its
        // gradients come in the same pass over the triangles as its volumes.
        let mut ready = None;
        let volumes = if round == 0 {
            let (gradient, sides, pairs) = gradients(surface, layout, q);
            ready = Some((gradient, sides));
            volumes_of(&pairs, labels, target.len())
        } else {
            label_volumes(surface, q, labels, target.len())
        };
        let error: Vec<f64> = target.iter().zip(&volumes).map(|(t, v)| t - v).collect();
        let worst = error
            .iter()
            .zip(target)
            .map(|(e, t)| (e / t).abs())
            .fold(0.0, f64::max);
        if worst <= options.volume_tolerance {
            return Ok((round, Some(volumes)));
        }
        let mobile = |v: usize| {
            let flags = surface.flags[v];
            flags.kind() == VertexKind::Surface
                && flags.has_two_labels()
                && frame.half(flags.border_axes()) != Vec3::ZERO
        };
        let (gradient, sides) = ready.unwrap_or_else(|| {
            let (gradient, sides, _) = gradients(surface, layout, q);
            (gradient, sides)
        });
        let gram = Gram::assemble(&gradient, &sides, labels, target.len(), mobile, |v| {
            mask(frame.half(surface.flags[v].border_axes()))
        });
        let pressure = gram.solve(&error);
        q.par_iter_mut().enumerate().for_each(|(v, p)| {
            let [inside, outside] = sides[v];
            let flags = surface.flags[v];
            if inside == u32::MAX || flags.kind() != VertexKind::Surface || !flags.has_two_labels()
            {
                return;
            }
            let at = |l: u32| labels.get(l).map_or(0.0, |s| pressure[s]);
            let h = gradient[v] * mask(frame.half(flags.border_axes()));
            let moved = *p + h * (at(inside) - at(outside)) as f32;
            let (start, half) = (
                frame.start(surface.corners[v]),
                frame.half(flags.border_axes()),
            );
            *p = moved.clamp(start - half, start + half);
        });
    }
    Ok((options.restore_rounds, None))
}

/// 1 on the axes where the box has room, 0 elsewhere.
fn mask(half: Vec3) -> Vec3 {
    Vec3::select(half.cmpgt(Vec3::ZERO), Vec3::ONE, Vec3::ZERO)
}

/// Per vertex, the gradient of the volume of the inside label of its last triangle, and that
/// triangle's two labels (`[u32::MAX; 2]` for a vertex without triangles); and, as
/// [`pair_volumes`] gives them, the label pairs' volumes summed per chunk of planes, the chunks
/// in order. The gradients are meaningful for the vertices between exactly two labels (the
/// only ones the callers use): such a vertex has every triangle between the same two, in the
/// same order. Cost: O(triangles), parallel over chunks of corner planes in two colours (a
/// chunk's triangles touch its planes and the next chunk's first, so chunks of one colour
/// write apart); the sums in an order fixed by the surface.
fn gradients(surface: &SharedSurface, layout: &Layout, q: &[Vec3]) -> Gradients {
    let n = q.len();
    let mut gradient = vec![Vec3::ZERO; n];
    let mut sides = vec![[u32::MAX; 2]; n];
    let planes = layout.planes();
    let chunks: Vec<(usize, usize)> = (0..planes)
        .step_by(GRADIENT_PLANES)
        .map(|a| (a, (a + GRADIENT_PLANES).min(planes)))
        .collect();
    let by_plane = surface.triangle_plane_starts();
    let triangle_starts: Vec<usize> = chunks
        .iter()
        .map(|&(a, _)| by_plane[a])
        .chain(std::iter::once(surface.triangles.len()))
        .collect();
    let mut chunk_sums = Vec::with_capacity(chunks.len());
    for colour in 0..2 {
        let picked: Vec<usize> = (colour..chunks.len()).step_by(2).collect();
        let windows: Vec<(usize, usize)> = picked
            .iter()
            .map(|&c| {
                let (a, b) = chunks[c];
                (
                    layout.plane_start(a),
                    layout.plane_start((b + 1).min(planes)),
                )
            })
            .collect();
        let g_parts = split_windows(&mut gradient, &windows);
        let s_parts = split_windows(&mut sides, &windows);
        let sums: Vec<(usize, PairSums)> = g_parts
            .into_par_iter()
            .zip(s_parts)
            .zip(picked)
            .zip(windows)
            .map(|(((g, s), c), (first, _))| {
                let mut runs = PairRuns::default();
                for t in triangle_starts[c]..triangle_starts[c + 1] {
                    let tri = surface.triangles[t];
                    let [a, b, e] = tri.map(|v| q[v as usize]);
                    let area = (b - a).cross(e - a) / 6.0;
                    let pair = surface.sides[t];
                    for v in tri {
                        g[v as usize - first] += area;
                        s[v as usize - first] = pair;
                    }
                    let [a, b, e] = [a, b, e].map(|p| p.as_dvec3());
                    runs.add(pair, a.dot(b.cross(e)) / 6.0);
                }
                (c, runs.sums())
            })
            .collect();
        chunk_sums.extend(sums);
    }
    chunk_sums.sort_unstable_by_key(|e| e.0);
    let pairs = chunk_sums.into_iter().map(|e| e.1).collect();
    (gradient, sides, pairs)
}

/// Sums per label pair, sorted by pair.
type PairSums = Vec<([u32; 2], f64)>;

/// What [`gradients`] gives: per vertex the gradient and the labels, and the pairs' volumes
/// per chunk.
type Gradients = (Vec<Vec3>, Vec<[u32; 2]>, Vec<PairSums>);

/// Sums per label pair over runs of one pair, the runs' sums added per pair in their order.
#[derive(Default)]
struct PairRuns {
    sums: FxHashMap<[u32; 2], f64>,
    run: Option<([u32; 2], f64)>,
}

impl PairRuns {
    /// Adds `value` to `pair`'s current run (starting a new run for a new pair).
    fn add(&mut self, pair: [u32; 2], value: f64) {
        match &mut self.run {
            Some((p, sum)) if *p == pair => *sum += value,
            run => {
                if let Some((p, sum)) = run.take() {
                    *self.sums.entry(p).or_default() += sum;
                }
                *run = Some((pair, value));
            }
        }
    }

    /// The sums per pair, sorted by pair.
    fn sums(mut self) -> PairSums {
        if let Some((p, sum)) = self.run.take() {
            *self.sums.entry(p).or_default() += sum;
        }
        let mut out: Vec<([u32; 2], f64)> = self.sums.into_iter().collect();
        out.sort_unstable_by_key(|e| e.0);
        out
    }
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
    /// `G_LM = Σ_v g_vL · (m_v ∘ g_vM)` over the vertices `mobile` accepts, `m_v = mask(v)`:
    /// per label pair `(A, B)` the weight `w = Σ g·(m∘g)` over its vertices adds `w` to
    /// `G_AA` and `G_BB` and subtracts it from `G_AB` and `G_BA`. Weights are summed per run of
    /// one pair within fixed chunks of vertices, then per pair in chunk order.
    fn assemble(
        gradient: &[Vec3],
        sides: &[[u32; 2]],
        labels: &LabelSlots,
        count: usize,
        mobile: impl Fn(usize) -> bool + Sync,
        mask: impl Fn(usize) -> Vec3 + Sync,
    ) -> Gram {
        let chunks: Vec<PairSums> = (0..gradient.len().div_ceil(VERTEX_CHUNK))
            .into_par_iter()
            .map(|c| {
                let mut runs = PairRuns::default();
                let end = ((c + 1) * VERTEX_CHUNK).min(gradient.len());
                for v in c * VERTEX_CHUNK..end {
                    if sides[v][0] == u32::MAX || !mobile(v) {
                        continue;
                    }
                    let g = gradient[v];
                    runs.add(sides[v], g.dot(g * mask(v)) as f64);
                }
                runs.sums()
            })
            .collect();
        let mut pairs: Vec<([u32; 2], f64)> = chunks.into_iter().flatten().collect();
        pairs.sort_by_key(|e| e.0);
        pairs.dedup_by(|next, kept| {
            let same = next.0 == kept.0;
            if same {
                kept.1 += next.1;
            }
            same
        });
        Gram::from_pairs(&pairs, labels, count)
    }

    /// The matrix from per-pair weights (module docs of [`Gram::assemble`]).
    fn from_pairs(pairs: &[([u32; 2], f64)], labels: &LabelSlots, count: usize) -> Gram {
        let mut entries: Vec<((u32, u32), f64)> = Vec::with_capacity(pairs.len() * 4);
        for &([inside, outside], w) in pairs {
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
        entries.sort_by_key(|e| e.0);
        entries.dedup_by(|next, kept| {
            let same = next.0 == kept.0;
            if same {
                kept.1 += next.1;
            }
            same
        });
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
            values: entries.iter().map(|e| e.1).collect(),
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
