//! The λ|μ passes of [`super::smooth`] (Taubin 1995), run as fused sweeps over the corner
//! planes: the λ pass of plane `p + 1` is followed at once by the μ pass of plane `p`, so each
//! pair reads the displacements once and writes them once, the λ results living in three
//! plane buffers.
//!
//! Work is on displacements from each vertex's start (its corner − ½, in grid space): a
//! neighbour's start differs from the vertex's by one spacing along the link, so the mean of
//! the neighbours is the mean of their displacements plus a constant per set of links, and
//! the box is `±half` around 0. Neighbours along ±x are the previous and next vertices
//! (vertices are in raster order of their corners and a link's far end is a vertex); only
//! those along ±y and ±z are stored, found by merging corner rows.

use rayon::prelude::*;
use voxlod_core::glam::{BVec3A, Vec3, Vec3A};

use crate::surface_nets::{SharedSurface, VertexKind};

/// Where the vertices of each corner row and plane start (vertices are in raster order of
/// their corners).
pub(super) struct Layout {
    /// Row `k (ny + 1) + j` holds vertices `rows[r]..rows[r + 1]`.
    rows: Vec<u32>,
    /// Corner rows per plane (`ny + 1`).
    per_plane: usize,
    /// Corner planes (`nz + 1`).
    planes: usize,
}

impl Layout {
    /// Finds where each corner row starts. Cost: O(vertices), one parallel pass over the
    /// corners (the rows' first vertices found where the row changes), then O(rows).
    pub(super) fn new(surface: &SharedSurface) -> Layout {
        let [_, ny, nz] = surface.dims;
        let per_plane = ny + 1;
        let key = |c: &[u32; 3]| c[2] as usize * per_plane + c[1] as usize;
        let corners = &surface.corners;
        // (row, its first vertex) wherever the row changes, in order.
        let changes: Vec<(usize, u32)> = (0..corners.len())
            .into_par_iter()
            .with_min_len(1 << 16)
            .filter(|&v| v == 0 || key(&corners[v]) != key(&corners[v - 1]))
            .map(|v| (key(&corners[v]), v as u32))
            .collect();
        let total = per_plane * (nz + 1);
        let mut rows = vec![corners.len() as u32; total + 1];
        let mut next = 0;
        for (row, first) in changes {
            // Rows `next..=row` (empty ones before it included) start at `first`.
            rows[next..=row].fill(first);
            next = row + 1;
        }
        Layout {
            rows,
            per_plane,
            planes: nz + 1,
        }
    }

    /// Corner planes.
    pub(super) fn planes(&self) -> usize {
        self.planes
    }

    /// The first vertex of corner plane `k` (`k` up to `planes`, which gives the count).
    pub(super) fn plane_start(&self, k: usize) -> usize {
        self.rows[k * self.per_plane] as usize
    }

    fn row(&self, k: usize, j: usize) -> std::ops::Range<usize> {
        let r = k * self.per_plane + j;
        self.rows[r] as usize..self.rows[r + 1] as usize
    }

    /// Plane ranges `[a, b)` of about `size` planes covering every plane, and the vertex
    /// offsets where they start (one more than ranges, the last the vertex count).
    pub(super) fn tasks(&self, size: usize) -> (Vec<(usize, usize)>, Vec<usize>) {
        let size = size.max(1);
        let tasks: Vec<(usize, usize)> = (0..self.planes)
            .step_by(size)
            .map(|a| (a, (a + size).min(self.planes)))
            .collect();
        let mut bounds: Vec<usize> = tasks.iter().map(|t| self.plane_start(t.0)).collect();
        bounds.push(self.plane_start(self.planes));
        (tasks, bounds)
    }
}

/// Splits `data` at `bounds` (increasing, the first 0 and the last `data.len()`).
pub(super) fn split_at_bounds<'a, T>(mut data: &'a mut [T], bounds: &[usize]) -> Vec<&'a mut [T]> {
    let mut parts = Vec::with_capacity(bounds.len().saturating_sub(1));
    for w in bounds.windows(2) {
        let (part, rest) = std::mem::take(&mut data).split_at_mut(w[1] - w[0]);
        parts.push(part);
        data = rest;
    }
    parts
}

/// Per vertex, the directions it is smoothed along (bits 0–5, −x +x −y +y −z +z: all its links
/// on an interface, its two junction links on a junction curve, none where curves meet) and
/// its border axes (bits 6–8).
pub(super) fn moves(surface: &SharedSurface) -> Vec<u16> {
    surface
        .flags
        .par_iter()
        .map(|f| {
            let directions = match f.kind() {
                VertexKind::Surface => f.links(),
                VertexKind::Curve => f.junctions(),
                VertexKind::Fixed => 0,
            };
            directions as u16 | (f.border_axes() as u16) << 6
        })
        .collect()
}

/// Each vertex's neighbours along −y, +y, −z, +z where `moves` uses them (`u32::MAX`
/// elsewhere), by merging each corner row with the four rows beside it in one walk. Cost:
/// O(vertices), parallel over planes.
pub(super) fn neighbours(surface: &SharedSurface, layout: &Layout, moves: &[u16]) -> Vec<[u32; 4]> {
    let mut out = vec![[u32::MAX; 4]; moves.len()];
    let (tasks, bounds) = layout.tasks(8);
    let parts = split_at_bounds(&mut out, &bounds);
    parts
        .into_par_iter()
        .zip(tasks)
        .zip(bounds.par_iter())
        .for_each(|((part, (a, b)), &first)| {
            for k in a..b {
                for j in 0..layout.per_plane {
                    let empty = 0..0;
                    let beside = [
                        if j > 0 {
                            layout.row(k, j - 1)
                        } else {
                            empty.clone()
                        },
                        if j + 1 < layout.per_plane {
                            layout.row(k, j + 1)
                        } else {
                            empty.clone()
                        },
                        if k > 0 {
                            layout.row(k - 1, j)
                        } else {
                            empty.clone()
                        },
                        if k + 1 < layout.planes {
                            layout.row(k + 1, j)
                        } else {
                            empty
                        },
                    ];
                    merge_rows(surface, moves, layout.row(k, j), beside, first, part);
                }
            }
        });
    out
}

/// Finds, for each vertex of row `own` that moves along direction `slot + 2`, the vertex of
/// row `beside[slot]` at the same x (a pointer per row beside, all rows sorted by x).
fn merge_rows(
    surface: &SharedSurface,
    moves: &[u16],
    own: std::ops::Range<usize>,
    beside: [std::ops::Range<usize>; 4],
    first: usize,
    part: &mut [[u32; 4]],
) {
    let corners = &surface.corners;
    let mut at = beside.clone().map(|r| r.start);
    for v in own {
        let m = moves[v] >> 2 & 15;
        if m == 0 {
            continue;
        }
        let x = corners[v][0];
        for slot in 0..4 {
            if m >> slot & 1 == 0 {
                continue;
            }
            let end = beside[slot].end;
            let mut w = at[slot];
            while w < end && corners[w][0] < x {
                w += 1;
            }
            at[slot] = w;
            if w < end && corners[w][0] == x {
                part[v - first][slot] = w as u32;
            }
        }
    }
}

/// What a step needs beside the vertex, per factor `f` (λ, μ): per set of directions
/// `f / count` and `f / count` times the sum of the neighbours' start offsets, and per set of
/// border axes the box's half sides.
pub(super) struct Steps {
    factors: [f32; 2],
    scales: [[f32; 7]; 2],
    shifts: [[Vec3A; 64]; 2],
    halves: [Vec3A; 8],
}

impl Steps {
    /// For a grid of this spacing, boxes of these half sides (both in grid units) and the
    /// factors λ and μ.
    pub(super) fn new(spacing: Vec3, half: Vec3, factors: [f32; 2]) -> Steps {
        let offsets: [Vec3A; 64] = std::array::from_fn(|mask: usize| {
            (0..6).fold(Vec3A::ZERO, |acc, d| {
                if mask >> d & 1 == 0 {
                    return acc;
                }
                let mut e = Vec3A::ZERO;
                e[d / 2] = if d % 2 == 1 { 1.0 } else { -1.0 };
                acc + e * Vec3A::from(spacing)
            })
        });
        let scale = |f: f32, n: u32| if n == 0 { 0.0 } else { f / n as f32 };
        let scales = factors.map(|f| std::array::from_fn(|n| scale(f, n as u32)));
        let shifts = factors.map(|f| {
            std::array::from_fn(|mask: usize| offsets[mask] * scale(f, mask.count_ones()))
        });
        let halves = std::array::from_fn(|border: usize| {
            Vec3A::from(Vec3::select(
                voxlod_core::glam::BVec3::new(border & 1 != 0, border & 2 != 0, border & 4 != 0),
                Vec3::ZERO,
                half,
            ))
        });
        Steps {
            factors,
            scales,
            shifts,
            halves,
        }
    }

    /// Vertex `v`'s displacement after a step of factor `f` (`which`: 0 for λ, 1 for μ)
    /// towards the mean of its neighbours along its directions, kept in its box:
    /// `(1 − f) d + (f / n) Σ (d_w + offset_w)`; `get(direction, neighbour, used)` gives a
    /// neighbour's displacement (anything finite when not `used`). A vertex without
    /// directions keeps its displacement. Branch-free over the six directions (their number
    /// varies from vertex to vertex, which a loop over the set ones would mispredict), the
    /// terms summed as a tree (short dependency chains: the step is latency-bound).
    #[inline(always)]
    fn step(
        &self,
        v: usize,
        m: u16,
        near: &[u32; 4],
        d: Vec3A,
        which: usize,
        get: impl Fn(usize, usize, bool) -> Vec3A,
    ) -> Vec3A {
        let directions = (m & 63) as usize;
        if directions == 0 {
            return d;
        }
        let far = [
            v.wrapping_sub(1),
            v + 1,
            near[0] as usize,
            near[1] as usize,
            near[2] as usize,
            near[3] as usize,
        ];
        let term = |dir: usize| {
            let used = directions >> dir & 1 == 1;
            let x = get(dir, far[dir], used);
            Vec3A::select(BVec3A::splat(used), x, Vec3A::ZERO)
        };
        let sum = (term(0) + term(1)) + (term(2) + term(3)) + (term(4) + term(5));
        let kept = d * (1.0 - self.factors[which]) + self.shifts[which][directions];
        let half = self.halves[(m >> 6) as usize & 7];
        (kept + sum * self.scales[which][directions.count_ones() as usize]).clamp(-half, half)
    }
}

/// Bytes of plane buffers one task of a sweep may hold.
const SWEEP_BUFFERS: usize = 16 << 20;

/// Runs `pairs` λ|μ pairs on the displacements `d`, using `spare` (as long) as the second
/// buffer; the result is left in `d`. The passes are fused into sweeps of several passes
/// (as many as [`SWEEP_BUFFERS`] allows, up to every pass): each task of a sweep runs the
/// passes as a wavefront over its planes, pass `s` on plane `w − s`, so the displacements
/// are read and written once per sweep and the passes in between stay in three plane
/// buffers each. Cost: one read and one write of the displacements per sweep, the passes
/// recomputed on `passes − 1 − s` planes each side of a task for pass `s`.
#[allow(clippy::too_many_arguments)]
pub(super) fn relax(
    layout: &Layout,
    moves: &[u16],
    near: &[[u32; 4]],
    steps: &Steps,
    d: &mut Vec<Vec3>,
    spare: &mut Vec<Vec3>,
    pairs: usize,
) {
    let planes = layout.planes();
    let widest = (0..planes)
        .map(|k| layout.plane_start(k + 1) - layout.plane_start(k))
        .max()
        .unwrap_or(0)
        .max(1);
    let fit = SWEEP_BUFFERS / (3 * widest * std::mem::size_of::<Vec3A>());
    let per_sweep = (fit / 2).clamp(1, pairs.max(1));
    let mut left = pairs;
    while left > 0 {
        let now = per_sweep.min(left);
        let passes = 2 * now;
        let size = (planes / (2 * rayon::current_num_threads())).max(8 * passes);
        let (tasks, bounds) = layout.tasks(size);
        let parts = split_at_bounds(spare, &bounds);
        let from = &d[..];
        parts
            .into_par_iter()
            .zip(&tasks)
            .for_each(|(out, &(a, b))| {
                Sweep {
                    layout,
                    moves,
                    near,
                    steps,
                    from,
                }
                .run(a, b, passes, widest, out)
            });
        std::mem::swap(d, spare);
        left -= now;
    }
}

/// One task of a sweep.
struct Sweep<'a> {
    layout: &'a Layout,
    moves: &'a [u16],
    near: &'a [[u32; 4]],
    steps: &'a Steps,
    from: &'a [Vec3],
}

impl Sweep<'_> {
    /// The last of `passes` (at least 2) passes on planes `[a, b)` into `out` (which starts at
    /// plane `a`'s first vertex); `widest` is the most vertices of a plane.
    fn run(&self, a: usize, b: usize, passes: usize, widest: usize, out: &mut [Vec3]) {
        let planes = self.layout.planes();
        let reach = passes - 1;
        let lo = |s: usize| a.saturating_sub(reach - s);
        let hi = |s: usize| (b + reach - s).min(planes);
        let mut rings: Vec<[Vec<Vec3A>; 3]> = (0..reach)
            .map(|_| std::array::from_fn(|_| vec![Vec3A::ZERO; widest]))
            .collect();
        let first = self.layout.plane_start(a);
        for w in lo(0)..hi(reach) + reach {
            for s in 0..passes {
                let Some(p) = w.checked_sub(s) else { break };
                if p < lo(s) || p >= hi(s) {
                    continue;
                }
                let factor = s % 2;
                let (done, rest) = rings.split_at_mut(s);
                if s == reach {
                    let out = &mut out[self.layout.plane_start(p) - first..];
                    let store = |i: usize, x: Vec3A| out[i] = x.into();
                    self.next_pass(p, factor, &done[s - 1], store);
                } else {
                    let ring = &mut rest[0][p % 3];
                    let store = |i: usize, x: Vec3A| ring[i] = x;
                    match done.last() {
                        None => self.first_pass(p, factor, store),
                        Some(previous) => self.next_pass(p, factor, previous, store),
                    }
                }
            }
        }
    }

    /// A pass on plane `k` from the displacements; `store(i, x)` keeps the plane's `i`-th.
    fn first_pass(&self, k: usize, factor: usize, mut store: impl FnMut(usize, Vec3A)) {
        let start = self.layout.plane_start(k);
        let end = self.layout.plane_start(k + 1);
        let from = self.from;
        for v in start..end {
            let x = self.steps.step(
                v,
                self.moves[v],
                &self.near[v],
                from[v].into(),
                factor,
                |_, w, used| from[if used { w } else { v }].into(),
            );
            store(v - start, x);
        }
    }

    /// A pass on plane `k` from the previous pass's planes `k − 1`, `k`, `k + 1` in `ring`.
    fn next_pass(
        &self,
        k: usize,
        factor: usize,
        ring: &[Vec<Vec3A>; 3],
        mut store: impl FnMut(usize, Vec3A),
    ) {
        let start = self.layout.plane_start(k);
        let end = self.layout.plane_start(k + 1);
        let below = if k > 0 {
            self.layout.plane_start(k - 1)
        } else {
            0
        };
        let above = end;
        let (lo, at, hi) = (
            &ring[(k + 2) % 3][..],
            &ring[k % 3][..],
            &ring[(k + 1) % 3][..],
        );
        for v in start..end {
            let x = self.steps.step(
                v,
                self.moves[v],
                &self.near[v],
                at[v - start],
                factor,
                |dir, w, used| match dir {
                    4 => lo[if used { w - below } else { 0 }],
                    5 => hi[if used { w - above } else { 0 }],
                    _ => at[if used { w } else { v } - start],
                },
            );
            store(v - start, x);
        }
    }
}
