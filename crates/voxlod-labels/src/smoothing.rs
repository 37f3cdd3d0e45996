//! Smoothing of a [`SharedSurface`] that keeps it shared and keeps each label's volume.
//!
//! 1. Taubin's λ|μ filter (Taubin 1995, "A signal processing approach to fair surface design";
//!    the pass-band form of Taubin, Zhang and Golub 1996, "Optimal surface smoothing as filter
//!    design": `1/λ + 1/μ = k_PB`), run on the shared vertices, so both labels of an interface
//!    see the same moved vertex. A vertex's neighbours are the corners its quad edges lead to;
//!    the weights are uniform.
//! 2. Sharp boundaries as Frisken 2022 (§3.2) keeps them: a vertex on a junction curve of three
//!    or more labels ([`VertexKind::Curve`]) is smoothed with its two junction neighbours only,
//!    so it slides along the curve and the junction does not shrink across the interfaces; a
//!    vertex where junction curves meet or end ([`VertexKind::Fixed`]) stays. A vertex on the
//!    volume's border keeps its border coordinate(s): it slides in the border plane, along the
//!    border edge, or stays at a border corner.
//! 3. Each vertex is kept within its constraint box, `constraint` voxels on each side of the
//!    corner it started at (½: within its voxel's reach, the box of surface nets).
//! 4. The diagonal of every quad is turned to the shorter one (as `vtkSurfaceNets3D`'s minimum
//!    edge triangulation), once for both labels.
//! 5. Beyond the papers: the volumes restored. The filter cuts convex voxel corners and fills
//!    concave ones, and the boxes and junctions hold it, so a label's volume drifts (by a few
//!    percent on small or thin labels). With `keep_volume`, each label `L` gets a pressure
//!    `p_L` (the background's is 0) and every vertex between exactly two labels `A` and `B`
//!    moves by `(p_A − p_B) · g`, where `g` is the gradient of `A`'s volume at that vertex (so
//!    minus that of `B`): a minimal move along the surface's normals that keeps the vertex
//!    shared. The pressures solve the linear system `G p = ΔV` (`G_LM = Σ_v g_vL · g_vM`, sparse
//!    over neighbouring labels) by conjugate gradients; a few rounds take care of the boxes and
//!    the non-linearity. Junction, fixed and border-locked coordinates do not move in this step.
//!
//! Work is in grid space (index × spacing, before the map's direction cosines); positions are
//! written back in the world. Cost per iteration O(vertices) in parallel; the restoring rounds
//! O(triangles) each plus a sparse solve over the labels.

use rayon::prelude::*;
use rustc_hash::FxHashMap;
use voxlod_core::glam::{DMat3, DVec3, Vec3};
use voxlod_core::{memory, CoreError};

use crate::surface_nets::{SharedSurface, VertexKind};
use crate::LabelsError;

/// How [`smooth`] smooths.
#[derive(Clone, Debug, PartialEq)]
pub struct SmoothingOptions {
    /// λ|μ pairs (each pair is two passes over the vertices). 0 leaves the positions alone
    /// (the volumes are still measured, the diagonals still turned).
    pub iterations: usize,
    /// The shrinking step, in (0, 1).
    pub lambda: f64,
    /// Taubin's pass-band frequency `k_PB` in (0, 1/λ): the inflating step is `μ = 1 / (k_PB −
    /// 1/λ)`. Smaller keeps more of the shape's low frequencies.
    pub pass_band: f64,
    /// Half the side of each vertex's box, in voxels (per axis, scaled by the spacing).
    pub constraint: f64,
    /// Turn each quad's diagonal to the shorter one after smoothing.
    pub turn_diagonals: bool,
    /// Restore each label's volume to what it was before smoothing (module docs, step 5).
    pub keep_volume: bool,
    /// Relative volume error at which restoring stops.
    pub volume_tolerance: f64,
    /// Most restoring rounds.
    pub restore_rounds: usize,
}

impl Default for SmoothingOptions {
    fn default() -> Self {
        SmoothingOptions {
            iterations: 8,
            lambda: 0.5,
            pass_band: 0.1,
            constraint: 0.5,
            turn_diagonals: true,
            keep_volume: true,
            volume_tolerance: 1e-4,
            restore_rounds: 4,
        }
    }
}

impl SmoothingOptions {
    /// No smoothing at all, the blocky surface kept (volumes still measured).
    pub fn none() -> Self {
        SmoothingOptions {
            iterations: 0,
            turn_diagonals: false,
            keep_volume: false,
            ..Self::default()
        }
    }

    /// The inflating step μ.
    pub fn mu(&self) -> f64 {
        1.0 / (self.pass_band - 1.0 / self.lambda)
    }

    fn check(&self) -> Result<(), LabelsError> {
        let bad = |what: String| Err(LabelsError::Core(CoreError::InvalidGrid(what)));
        if !(self.lambda > 0.0 && self.lambda < 1.0) {
            return bad(format!("smoothing lambda {} is not in (0, 1)", self.lambda));
        }
        if !(self.pass_band > 0.0 && self.pass_band < 1.0 / self.lambda) {
            return bad(format!(
                "smoothing pass band {} is not in (0, 1/lambda)",
                self.pass_band
            ));
        }
        if !(self.constraint >= 0.0 && self.constraint.is_finite()) {
            return bad(format!("smoothing constraint {} voxels", self.constraint));
        }
        if self.volume_tolerance.is_nan() || self.volume_tolerance < 0.0 {
            return bad(format!("volume tolerance {}", self.volume_tolerance));
        }
        Ok(())
    }
}

/// One label's volume before and after smoothing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VolumeChange {
    /// The label.
    pub label: u32,
    /// Its enclosed volume before (for an unsmoothed surface: voxel count × voxel volume).
    pub before: f64,
    /// After.
    pub after: f64,
}

impl VolumeChange {
    /// `after / before − 1`.
    pub fn relative(&self) -> f64 {
        self.after / self.before - 1.0
    }
}

/// What [`smooth`] did.
#[derive(Clone, Debug, PartialEq)]
pub struct SmoothingReport {
    /// λ|μ pairs run.
    pub iterations: usize,
    /// Volume-restoring rounds run.
    pub restore_rounds: usize,
    /// Every label's volume change, by label.
    pub volumes: Vec<VolumeChange>,
    /// The label whose volume changed most (relatively).
    pub worst: Option<VolumeChange>,
    /// Vertices that end on a face of their box.
    pub constrained_vertices: usize,
    /// Quads whose diagonal was turned.
    pub turned_diagonals: usize,
}

/// Where each vertex may go: its start (the corner, in grid space) and its box's half sides.
struct Frame {
    spacing: Vec3,
    origin: DVec3,
    to_world: DMat3,
    to_grid: DMat3,
    half: Vec3,
}

impl Frame {
    fn start(&self, corner: [u32; 3]) -> Vec3 {
        (Vec3::new(corner[0] as f32, corner[1] as f32, corner[2] as f32) - 0.5) * self.spacing
    }

    /// The box's half sides of a vertex with these border axes (0 along them).
    fn half(&self, border: u8) -> Vec3 {
        Vec3::select(
            voxlod_core::glam::BVec3::new(border & 1 != 0, border & 2 != 0, border & 4 != 0),
            Vec3::ZERO,
            self.half,
        )
    }
}

/// Smooths `surface` in place (module docs) and reports the volumes. Volumes are measured
/// against those the surface had when called (for a fresh surface, the voxel volumes). Fails
/// on options out of range or when the memory limit refuses the work arrays (about 60 bytes
/// per vertex).
pub fn smooth(
    surface: &mut SharedSurface,
    options: &SmoothingOptions,
) -> Result<SmoothingReport, LabelsError> {
    options.check()?;
    let n = surface.positions.len();
    memory::check_allocation("smoothing's work arrays", memory::bytes_of::<[u32; 15]>(n))?;
    let world = surface.world;
    let to_world = world.direction;
    let frame = Frame {
        spacing: world.spacing.as_vec3(),
        origin: world.origin,
        to_world,
        to_grid: to_world.inverse(),
        half: (world.spacing * options.constraint).as_vec3(),
    };
    let mut q: Vec<Vec3> = surface
        .positions
        .par_iter()
        .map(|p| (frame.to_grid * (p.as_dvec3() - frame.origin)).as_vec3())
        .collect();
    let labels = surface.labels();
    let before = label_volumes(surface, &q, &labels);
    let neighbours = neighbours(surface);
    let mut next = q.clone();
    let factors = [options.lambda as f32, options.mu() as f32];
    for _ in 0..options.iterations {
        for f in factors {
            relax(surface, &frame, &neighbours, &q, &mut next, f);
            std::mem::swap(&mut q, &mut next);
        }
    }
    drop((next, neighbours));
    let turned = if options.turn_diagonals {
        turn_diagonals(&mut surface.triangles, &q)
    } else {
        0
    };
    let mut rounds = 0;
    if options.keep_volume {
        rounds = restore(surface, &frame, &mut q, &labels, &before, options)?;
    }
    let after = label_volumes(surface, &q, &labels);
    let constrained = constrained(surface, &frame, &q);
    surface
        .positions
        .par_iter_mut()
        .zip(q.par_iter())
        .for_each(|(p, g)| *p = (frame.origin + frame.to_world * g.as_dvec3()).as_vec3());
    let volumes: Vec<VolumeChange> = labels
        .iter()
        .zip(before.iter().zip(&after))
        .map(|(&label, (&before, &after))| VolumeChange {
            label,
            before,
            after,
        })
        .collect();
    let worst = volumes
        .iter()
        .copied()
        .max_by(|a, b| a.relative().abs().total_cmp(&b.relative().abs()));
    Ok(SmoothingReport {
        iterations: options.iterations,
        restore_rounds: rounds,
        volumes,
        worst,
        constrained_vertices: constrained,
        turned_diagonals: turned,
    })
}

/// Each vertex's neighbour along each of its links (`u32::MAX` elsewhere). Vertices are
/// numbered in raster order of their corners, so a corner's vertex is found by a binary search
/// within its corner row. Cost: O(vertices · log(vertices per row)), parallel.
fn neighbours(surface: &SharedSurface) -> Vec<[u32; 6]> {
    let [_, ny, nz] = surface.dims;
    let row = |c: [u32; 3]| c[2] as usize * (ny + 1) + c[1] as usize;
    let mut starts = vec![0u32; (ny + 1) * (nz + 1) + 1];
    for &c in &surface.corners {
        starts[row(c) + 1] += 1;
    }
    for r in 1..starts.len() {
        starts[r] += starts[r - 1];
    }
    let corners = &surface.corners;
    (0..corners.len())
        .into_par_iter()
        .map(|v| {
            let links = surface.flags[v].links();
            let c = corners[v];
            std::array::from_fn(|d| {
                if links >> d & 1 == 0 {
                    return u32::MAX;
                }
                let mut t = c;
                t[d / 2] = if d % 2 == 1 {
                    t[d / 2] + 1
                } else {
                    t[d / 2].wrapping_sub(1)
                };
                let r = row(t);
                if r + 1 >= starts.len() {
                    return u32::MAX;
                }
                let (lo, hi) = (starts[r] as usize, starts[r + 1] as usize);
                corners[lo..hi]
                    .binary_search_by_key(&t[0], |w| w[0])
                    .map_or(u32::MAX, |n| (lo + n) as u32)
            })
        })
        .collect()
}

/// One pass of the filter with step `factor`, from `q` into `next`, boxes applied.
fn relax(
    surface: &SharedSurface,
    frame: &Frame,
    neighbours: &[[u32; 6]],
    q: &[Vec3],
    next: &mut [Vec3],
    factor: f32,
) {
    next.par_iter_mut().enumerate().for_each(|(v, out)| {
        let flags = surface.flags[v];
        let directions = match flags.kind() {
            VertexKind::Surface => flags.links(),
            VertexKind::Curve => flags.junctions(),
            VertexKind::Fixed => 0,
        };
        let (mut sum, mut count) = (Vec3::ZERO, 0u32);
        for (d, &w) in neighbours[v].iter().enumerate() {
            if directions >> d & 1 == 1 && w != u32::MAX {
                sum += q[w as usize];
                count += 1;
            }
        }
        if count == 0 {
            *out = q[v];
            return;
        }
        let moved = q[v] + factor * (sum / count as f32 - q[v]);
        let (start, half) = (
            frame.start(surface.corners[v]),
            frame.half(flags.border_axes()),
        );
        *out = moved.clamp(start - half, start + half);
    });
}

/// Turns each quad (a pair of triangles sharing a diagonal) to its shorter diagonal; returns
/// how many turned. Ties keep the diagonal.
fn turn_diagonals(triangles: &mut [[u32; 3]], q: &[Vec3]) -> usize {
    triangles
        .par_chunks_mut(2)
        .map(|pair| {
            let [t0, t1] = [pair[0], pair[1]];
            let Some(lone) = (0..3).find(|&c| !t1.contains(&t0[c])) else {
                return 0;
            };
            let Some(&d) = t1.iter().find(|v| !t0.contains(v)) else {
                return 0;
            };
            let [x, y, z] = [t0[lone], t0[(lone + 1) % 3], t0[(lone + 2) % 3]];
            let at = |v: u32| q[v as usize];
            if at(x).distance_squared(at(d)) < at(y).distance_squared(at(z)) * (1.0 - 1e-6) {
                pair[0] = [x, y, d];
                pair[1] = [x, d, z];
                1
            } else {
                0
            }
        })
        .sum()
}

/// The index of `label` in the sorted `labels`.
#[inline]
fn slot(labels: &[u32], label: u32) -> Option<usize> {
    labels.binary_search(&label).ok()
}

/// Each label's enclosed volume (grid space, which has the world's volumes up to the
/// direction's determinant, ±1), by the divergence theorem over its triangles.
fn label_volumes(surface: &SharedSurface, q: &[Vec3], labels: &[u32]) -> Vec<f64> {
    surface
        .triangles
        .par_chunks(1 << 14)
        .zip(surface.sides.par_chunks(1 << 14))
        .fold(
            || vec![0.0f64; labels.len()],
            |mut acc, (tris, sides)| {
                let mut last = ([u32::MAX; 2], [None, None]);
                for (t, s) in tris.iter().zip(sides) {
                    if *s != last.0 {
                        last = (*s, [slot(labels, s[0]), slot(labels, s[1])]);
                    }
                    let [a, b, c] = t.map(|v| q[v as usize].as_dvec3());
                    let v = a.dot(b.cross(c)) / 6.0;
                    if let Some(i) = last.1[0] {
                        acc[i] += v;
                    }
                    if let Some(o) = last.1[1] {
                        acc[o] -= v;
                    }
                }
                acc
            },
        )
        .reduce(
            || vec![0.0f64; labels.len()],
            |mut a, b| {
                a.iter_mut().zip(b).for_each(|(x, y)| *x += y);
                a
            },
        )
}

/// Vertices on a face of their box (on an axis where the box has room).
fn constrained(surface: &SharedSurface, frame: &Frame, q: &[Vec3]) -> usize {
    q.par_iter()
        .enumerate()
        .filter(|&(v, p)| {
            let half = frame.half(surface.flags[v].border_axes());
            let off = (*p - frame.start(surface.corners[v])).abs();
            (0..3).any(|a| half[a] > 0.0 && off[a] >= half[a] * (1.0 - 1e-5))
        })
        .count()
}

/// Restores the labels' volumes to `target` (module docs, step 5); returns the rounds run.
fn restore(
    surface: &SharedSurface,
    frame: &Frame,
    q: &mut [Vec3],
    labels: &[u32],
    target: &[f64],
    options: &SmoothingOptions,
) -> Result<usize, LabelsError> {
    memory::check_allocation("volume restoring", memory::bytes_of::<[u32; 4]>(q.len()))?;
    for round in 0..options.restore_rounds {
        let volumes = label_volumes(surface, q, labels);
        let error: Vec<f64> = target.iter().zip(&volumes).map(|(t, v)| t - v).collect();
        let worst = error
            .iter()
            .zip(target)
            .map(|(e, t)| (e / t).abs())
            .fold(0.0, f64::max);
        if worst <= options.volume_tolerance {
            return Ok(round);
        }
        let (gradient, sides) = gradients(surface, q);
        let gram = Gram::assemble(
            &gradient,
            &sides,
            labels,
            |v| {
                let flags = surface.flags[v];
                flags.kind() == VertexKind::Surface
                    && flags.has_two_labels()
                    && frame.half(flags.border_axes()) != Vec3::ZERO
            },
            |v| mask(frame.half(surface.flags[v].border_axes())),
        );
        let pressure = gram.solve(&error);
        q.par_iter_mut().enumerate().for_each(|(v, p)| {
            let [inside, outside] = sides[v];
            let flags = surface.flags[v];
            if inside == u32::MAX || flags.kind() != VertexKind::Surface || !flags.has_two_labels()
            {
                return;
            }
            let at = |l: u32| slot(labels, l).map_or(0.0, |s| pressure[s]);
            let h = gradient[v] * mask(frame.half(flags.border_axes()));
            let moved = *p + h * (at(inside) - at(outside)) as f32;
            let (start, half) = (
                frame.start(surface.corners[v]),
                frame.half(flags.border_axes()),
            );
            *p = moved.clamp(start - half, start + half);
        });
    }
    Ok(options.restore_rounds)
}

/// 1 on the axes where the box has room, 0 elsewhere.
fn mask(half: Vec3) -> Vec3 {
    Vec3::select(half.cmpgt(Vec3::ZERO), Vec3::ONE, Vec3::ZERO)
}

/// Per vertex between two labels, the gradient of its inside label's volume, and the two
/// labels (`[u32::MAX; 2]` for other vertices). A vertex between exactly two labels has every
/// triangle between the same two, in the same order.
fn gradients(surface: &SharedSurface, q: &[Vec3]) -> (Vec<Vec3>, Vec<[u32; 2]>) {
    let n = q.len();
    let mut gradient = vec![Vec3::ZERO; n];
    let mut sides = vec![[u32::MAX; 2]; n];
    for (t, s) in surface.triangles.iter().zip(&surface.sides) {
        let [a, b, c] = t.map(|v| q[v as usize]);
        let area = (b - a).cross(c - a) / 6.0;
        for &v in t {
            if surface.flags[v as usize].has_two_labels() {
                gradient[v as usize] += area;
                sides[v as usize] = *s;
            }
        }
    }
    (gradient, sides)
}

/// The sparse symmetric matrix `G` of the restoring step, over the labels.
struct Gram {
    /// Row starts into `columns` and `values`.
    rows: Vec<usize>,
    columns: Vec<u32>,
    values: Vec<f64>,
}

impl Gram {
    /// `G_LM = Σ_v g_vL · (m_v ∘ g_vM)` over the vertices `mobile` accepts, `m_v = mask(v)`.
    fn assemble(
        gradient: &[Vec3],
        sides: &[[u32; 2]],
        labels: &[u32],
        mobile: impl Fn(usize) -> bool + Sync,
        mask: impl Fn(usize) -> Vec3 + Sync,
    ) -> Gram {
        let entries: FxHashMap<(u32, u32), f64> = (0..gradient.len())
            .into_par_iter()
            .with_min_len(1 << 14)
            .fold(
                FxHashMap::default,
                |mut acc: FxHashMap<(u32, u32), f64>, v| {
                    let [inside, outside] = sides[v];
                    if inside == u32::MAX || !mobile(v) {
                        return acc;
                    }
                    let g = gradient[v];
                    let w = g.dot(g * mask(v)) as f64;
                    let (a, b) = (slot(labels, inside), slot(labels, outside));
                    if let Some(a) = a {
                        *acc.entry((a as u32, a as u32)).or_default() += w;
                    }
                    if let Some(b) = b {
                        *acc.entry((b as u32, b as u32)).or_default() += w;
                    }
                    if let (Some(a), Some(b)) = (a, b) {
                        *acc.entry((a as u32, b as u32)).or_default() -= w;
                        *acc.entry((b as u32, a as u32)).or_default() -= w;
                    }
                    acc
                },
            )
            .reduce(FxHashMap::default, |mut a, b| {
                for (k, v) in b {
                    *a.entry(k).or_default() += v;
                }
                a
            });
        let mut sorted: Vec<((u32, u32), f64)> = entries.into_iter().collect();
        sorted.sort_unstable_by_key(|e| e.0);
        let mut rows = vec![0usize; labels.len() + 1];
        for ((r, _), _) in &sorted {
            rows[*r as usize + 1] += 1;
        }
        for r in 0..labels.len() {
            rows[r + 1] += rows[r];
        }
        Gram {
            rows,
            columns: sorted.iter().map(|e| e.0 .1).collect(),
            values: sorted.iter().map(|e| e.1).collect(),
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
