//! Shell candidates: the voxel level of a surface that has no inside.
//!
//! An open sheet, a model of open parts or a triangle soup bounds no solid: sampled as one,
//! its holes are capped across and a sheet thinner than a voxel filters away. Here its
//! surface is thickened instead: the density at a sample is a ramp of its unsigned distance
//! `d` to the input, `ρ = clamp(1/2 + (t − d) / 2w, 0, 1)`, with half-thickness `t` and ramp
//! half-width `w` in voxels (module `shell_density`), and the level is contoured at
//! 1/2: a closed, oriented surface at distance `t` on both sides of the input that follows it
//! wherever it goes and merges sheets closer than `2t` (a morphological dilation: the low-pass
//! that removes what is narrower than the voxel, our counterpart for surfaces of He et al.
//! 1995 §3's filter of solids). Then collapsed to the budget with its topology kept, as the
//! voxel candidates are.
//!
//! Cost: the shell's density (module `shell_density`), marching cubes and a checked quadric
//! collapse.

use voxlod_contouring::triangle_estimate::resolution_for_triangles;
use voxlod_contouring::{marching_cubes, ContourOptions};
use voxlod_metrics::MeshDistance;
use voxlod_sampling::level_grid;

use crate::candidate::{Candidate, Method};
use crate::input::Input;
use crate::shell_density::{shell_density, HALF_THICKNESS, RAMP};
use crate::voxel::{collapsed, COARSEST, HEADROOM};
use crate::BudgetError;

/// Finest shell grid: its cost grows with the samples near the surface.
pub const FINEST_SHELL: usize = 256;

/// The shell candidates of `budget`, with the input's closest-point structure `closest`;
/// none where the shell's level is empty or cannot be collapsed.
pub fn shell_candidates(
    input: &Input,
    closest: &MeshDistance,
    budget: usize,
    max_error: Option<f64>,
) -> Result<Vec<Candidate>, BudgetError> {
    // Two sides: half the triangles each.
    let want = (HEADROOM * budget as f64 / 2.0) as usize;
    let resolution = resolution_for_triangles(&input.mesh, want)
        .unwrap_or(COARSEST)
        .clamp(COARSEST, FINEST_SHELL);
    let voxel = input.voxel(resolution);
    let (t, w) = (HALF_THICKNESS * voxel, RAMP * voxel);
    let grid = level_grid(&input.bounds, resolution, t + w)?;
    let density = shell_density(&grid, closest, t, w)?;
    let mesh = marching_cubes(&density, &ContourOptions::geometry_only(0.5)).map_err(|e| {
        BudgetError::NoLevel {
            budget,
            why: format!("marching cubes of the shell: {e}"),
        }
    })?;
    let collapsed = collapsed(Method::Shell, mesh, budget, voxel, max_error);
    Ok(collapsed
        .into_iter()
        .map(|c| c.at(resolution, 0.5))
        .collect())
}
