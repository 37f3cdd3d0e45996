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
//! restoring rounds O(triangles) each plus a sparse solve over the labels. Every sum is taken
//! in an order fixed by the surface, so the result does not depend on the number of threads.

mod relax;
mod restore;

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
/// with [`LabelsError::InvalidOption`] on options out of range, or when the memory limit
/// refuses the work arrays (about 34 bytes per vertex beside the surface, then 20 while the
/// volumes are restored).
///
/// Cost: per λ|μ pair one parallel sweep over the vertices; a few passes over the triangles
/// for the volumes and each restoring round. The result does not depend on the number of
/// threads.
pub fn smooth(
    surface: &mut SharedSurface,
    options: &SmoothingOptions,
) -> Result<SmoothingReport, LabelsError> {
    options.check()?;
    let n = surface.positions.len();
    memory::check_allocation(
        "smoothing's work arrays",
        memory::bytes_of::<[u32; 7]>(n) + memory::bytes_of::<u16>(n),
    )?;
    let world = surface.world;
    let frame = Frame {
        spacing: world.spacing.as_vec3(),
        origin: world.origin,
        to_world: world.direction,
        to_grid: world.direction.inverse(),
        half: (world.spacing * options.constraint).as_vec3(),
    };
    // The positions' buffer holds grid-space positions, then serves as the second buffer of
    // the displacements, then holds the result.
    let mut q = std::mem::take(&mut surface.positions);
    q.par_iter_mut()
        .for_each(|p| *p = (frame.to_grid * (p.as_dvec3() - frame.origin)).as_vec3());
    let (labels, slots, before) = restore::labels_and_volumes(surface, &q);
    let layout = relax::Layout::new(surface);
    if options.iterations > 0 {
        let mut d: Vec<Vec3> = q
            .par_iter()
            .zip(surface.corners.par_iter())
            .map(|(p, &c)| *p - frame.start(c))
            .collect();
        let moves = relax::moves(surface);
        let near = relax::neighbours(surface, &layout, &moves);
        let factors = [options.lambda as f32, options.mu() as f32];
        let steps = relax::Steps::new(frame.spacing, frame.half, factors);
        relax::relax(
            &layout,
            &moves,
            &near,
            &steps,
            &mut d,
            &mut q,
            options.iterations,
        );
        drop((moves, near));
        d.par_iter_mut()
            .zip(surface.corners.par_iter())
            .for_each(|(p, &c)| *p += frame.start(c));
        q = d;
    }
    let turned = if options.turn_diagonals {
        turn_diagonals(&mut surface.triangles, &q)
    } else {
        0
    };
    let (rounds, measured) = if options.keep_volume {
        restore::restore(surface, &layout, &frame, &mut q, &slots, &before, options)?
    } else {
        (0, None)
    };
    let after =
        measured.unwrap_or_else(|| restore::label_volumes(surface, &q, &slots, labels.len()));
    let constrained = constrained(surface, &frame, &q);
    q.par_iter_mut()
        .for_each(|g| *g = (frame.origin + frame.to_world * g.as_dvec3()).as_vec3());
    surface.positions = q;
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
