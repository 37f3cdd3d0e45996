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
//! written back in the world. The λ|μ passes run on displacements from the vertices' corners,
//! fused into wavefront sweeps over the corner planes (`smoothing/relax.rs`); the volumes,
//! gradients and Gram matrix are in `smoothing/restore.rs`. Cost: O(vertices) per pass in
//! parallel, the displacements read and written once per sweep of several passes; the
//! restoring rounds O(triangles) each plus a sparse solve over the labels. The restoring's sums
//! are exact in fixed point (`smoothing/sums.rs`), so the result depends neither on the number
//! of threads nor on whether the map is smoothed whole or block by block: a block placed in
//! the map ([`SharedSurface::offset`]) with a wide enough margin gives its inner vertices the
//! whole map's positions bit for bit, once its pressures are the whole map's
//! ([`restoring_sums`], [`restoring_pressure`], [`SmoothingOptions::pressures`]; the blockwise
//! route of `voxlod.dask.labels`). That is beyond the papers.

mod relax;
mod restore;
mod sums;

pub use restore::Owned;
pub use sums::PairSums;

use rayon::prelude::*;
use voxlod_core::glam::{DMat3, DVec3, Vec3};
use voxlod_core::memory;

use crate::surface_nets::SharedSurface;
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
    /// The restoring's pressures, one per round, solved elsewhere: the blockwise route solves
    /// them over the whole map ([`restoring_sums`], [`restoring_pressure`]) and each block
    /// applies them, in order, instead of solving over its own labels. `None` solves here.
    pub pressures: Option<Vec<Pressure>>,
}

/// One restoring round's pressure per label (module docs, step 5); labels not listed (the
/// background among them) have 0.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Pressure {
    /// The labels, increasing.
    pub labels: Vec<u32>,
    /// Each label's pressure.
    pub values: Vec<f64>,
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
            pressures: None,
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
        let bad = |option: &'static str, value: f64, problem: &str| {
            Err(LabelsError::InvalidOption {
                option,
                value: value.to_string(),
                problem: problem.to_string(),
            })
        };
        if !(self.lambda > 0.0 && self.lambda < 1.0) {
            return bad("smoothing lambda", self.lambda, "must be in (0, 1)");
        }
        if !(self.pass_band > 0.0 && self.pass_band < 1.0 / self.lambda) {
            return bad(
                "smoothing pass band",
                self.pass_band,
                "must be in (0, 1/lambda)",
            );
        }
        if !(self.constraint >= 0.0 && self.constraint.is_finite()) {
            return bad(
                "smoothing constraint",
                self.constraint,
                "must be a finite number of voxels, at least 0",
            );
        }
        if self.volume_tolerance.is_nan() || self.volume_tolerance < 0.0 {
            return bad(
                "smoothing volume tolerance",
                self.volume_tolerance,
                "must be at least 0",
            );
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
    /// The surface's first corner in the whole map ([`SharedSurface::offset`]).
    offset: [u32; 3],
    spacing: Vec3,
    /// The spacing, unrounded.
    grid_spacing: DVec3,
    origin: DVec3,
    to_world: DMat3,
    half: Vec3,
}

impl Frame {
    /// Where corner `corner` of the surface starts, in grid space: the whole map's corner
    /// `corner + offset`, at index `− ½` (rounded once, as the nets place it).
    fn start(&self, corner: [u32; 3]) -> Vec3 {
        let c: [f64; 3] = std::array::from_fn(|a| (corner[a] + self.offset[a]) as f64);
        ((DVec3::from(c) - 0.5) * self.grid_spacing).as_vec3()
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

/// Smooths `surface` in place (module docs) and reports the volumes. Smoothing starts from the
/// surface as the nets make it, every vertex at its corner (the positions it holds are
/// replaced), so the volumes before are the voxel volumes. With
/// [`SmoothingOptions::pressures`], the restoring applies them rather than solving its own.
/// Fails with [`LabelsError::InvalidOption`] on options out of range, or when the memory limit
/// refuses the work arrays (about 34 bytes per vertex beside the surface, then 20 while the
/// volumes are restored).
///
/// Cost: per λ|μ pair one parallel sweep over the vertices; a few passes over the triangles
/// for the volumes and each restoring round. The result does not depend on the number of
/// threads, and a block of a map cut with a wide enough margin (`voxlod.dask.labels`) gives
/// its inner vertices the whole map's positions bit for bit.
pub fn smooth(
    surface: &mut SharedSurface,
    options: &SmoothingOptions,
) -> Result<SmoothingReport, LabelsError> {
    let (frame, layout, mut q) = start(surface, options)?;
    let before = restore::pair_volumes(surface, &frame, &q, &restore::Owned::ALL);
    let targets = restore::Targets::of(&before);
    let turned = relax_and_turn(surface, options, &frame, &layout, &mut q);
    let restoring = restore::Restoring {
        surface,
        layout: &layout,
        frame: &frame,
    };
    let (rounds, measured) = match (options.keep_volume, &options.pressures) {
        (false, _) => (0, None),
        (true, None) => restoring.restore(&mut q, &targets, options)?,
        (true, Some(given)) => {
            for pressure in given {
                restoring.apply_given(&mut q, pressure)?;
            }
            (given.len(), None)
        }
    };
    let after = measured.unwrap_or_else(|| {
        targets.measure(&restore::pair_volumes(
            surface,
            &frame,
            &q,
            &restore::Owned::ALL,
        ))
    });
    let constrained = constrained(surface, &frame, &q);
    place(surface, &frame, q);
    let volumes: Vec<VolumeChange> = (targets.labels.iter())
        .zip(targets.volumes.iter().zip(&after))
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

/// The frame, the corner rows and the vertices at their corners (grid space, in the buffer of
/// the surface's positions, taken from it until [`place`] gives it back), after checking the
/// options and the memory the work needs.
fn start(
    surface: &mut SharedSurface,
    options: &SmoothingOptions,
) -> Result<(Frame, relax::Layout, Vec<Vec3>), LabelsError> {
    options.check()?;
    let n = surface.corners.len();
    memory::check_allocation(
        "smoothing's work arrays",
        memory::bytes_of::<[u32; 7]>(n) + memory::bytes_of::<u16>(n),
    )?;
    let world = surface.world;
    let frame = Frame {
        offset: surface.offset,
        spacing: world.spacing.as_vec3(),
        grid_spacing: world.spacing,
        origin: world.origin,
        to_world: world.direction,
        half: (world.spacing * options.constraint).as_vec3(),
    };
    let mut q = std::mem::take(&mut surface.positions);
    q.resize(n, Vec3::ZERO);
    q.par_iter_mut()
        .zip(surface.corners.par_iter())
        .for_each(|(p, &c)| *p = frame.start(c));
    let layout = relax::Layout::new(surface);
    Ok((frame, layout, q))
}

/// The grid-space positions `q` moved into the world and given back to the surface.
fn place(surface: &mut SharedSurface, frame: &Frame, mut q: Vec<Vec3>) {
    q.par_iter_mut()
        .for_each(|g| *g = (frame.origin + frame.to_world * g.as_dvec3()).as_vec3());
    surface.positions = q;
}

/// The λ|μ passes on `q`, then the diagonals turned; returns how many turned.
fn relax_and_turn(
    surface: &mut SharedSurface,
    options: &SmoothingOptions,
    frame: &Frame,
    layout: &relax::Layout,
    q: &mut Vec<Vec3>,
) -> usize {
    if options.iterations > 0 {
        let mut d = vec![Vec3::ZERO; q.len()];
        let moves = relax::moves(surface);
        let near = relax::neighbours(surface, layout, &moves);
        let factors = [options.lambda as f32, options.mu() as f32];
        let steps = relax::Steps::new(frame.spacing, frame.half, factors);
        relax::relax(layout, &moves, &near, &steps, &mut d, q, options.iterations);
        drop((moves, near));
        d.par_iter_mut()
            .zip(surface.corners.par_iter())
            .for_each(|(p, &c)| *p += frame.start(c));
        *q = d;
    }
    if options.turn_diagonals {
        turn_diagonals(&mut surface.triangles, q)
    } else {
        0
    }
}

/// What one block of a map adds to the restoring's sums over the whole map (module
/// `smoothing/sums.rs`): over the triangles and vertices `owned` holds, the label pairs'
/// volumes before smoothing, and after smoothing and the rounds of
/// [`SmoothingOptions::pressures`] so far, the pairs' volumes and Gram weights.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RestoringSums {
    /// The pairs' volumes before smoothing.
    pub before: PairSums,
    /// The pairs' volumes now.
    pub volumes: PairSums,
    /// The pairs' Gram weights now.
    pub weights: PairSums,
}

/// The restoring's sums of `surface` (a block of a map, [`SharedSurface::offset`] placing it,
/// cut with a margin wide enough that the vertices `owned` holds and their neighbours move as
/// in the whole map): smoothed as [`smooth`] smooths, the given pressures applied, then summed.
/// The blocks' sums added ([`PairSums::merged`]) are the whole map's, so
/// [`restoring_pressure`] solves the round the whole map would. The surface is left smoothed
/// with the given pressures.
pub fn restoring_sums(
    surface: &mut SharedSurface,
    options: &SmoothingOptions,
    owned: Owned,
) -> Result<RestoringSums, LabelsError> {
    let (frame, layout, mut q) = start(surface, options)?;
    let before = restore::pair_volumes(surface, &frame, &q, &owned);
    relax_and_turn(surface, options, &frame, &layout, &mut q);
    let restoring = restore::Restoring {
        surface,
        layout: &layout,
        frame: &frame,
    };
    for pressure in options.pressures.iter().flatten() {
        restoring.apply_given(&mut q, pressure)?;
    }
    restore::check_memory(q.len())?;
    let g = restore::gradients(surface, &layout, &frame, &q, &owned);
    let weights = restore::gram_weights(surface, &frame, &g, &owned);
    place(surface, &frame, q);
    Ok(RestoringSums {
        before,
        volumes: g.volumes,
        weights,
    })
}

/// The next round's pressure from the whole map's sums ([`restoring_sums`] of every block,
/// merged), or `None` when every label's volume is within `options.volume_tolerance` of its
/// volume before smoothing (the restoring stops). As the round [`smooth`] solves.
pub fn restoring_pressure(sums: &RestoringSums, options: &SmoothingOptions) -> Option<Pressure> {
    let targets = restore::Targets::of(&sums.before);
    let volumes = targets.measure(&sums.volumes);
    if restore::within_tolerance(&targets.volumes, &volumes, options.volume_tolerance) {
        return None;
    }
    Some(restore::solve(
        &targets.labels,
        &targets.volumes,
        &volumes,
        &sums.weights,
    ))
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
