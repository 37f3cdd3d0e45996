//! Shell candidates: the voxel level of a surface that has no inside.
//!
//! An open sheet, a model of open parts or a triangle soup bounds no solid: sampled as one,
//! its holes are capped across and a sheet thinner than a voxel filters away. Here its
//! surface is thickened instead: the density at a sample is a ramp of its unsigned distance
//! `d` to the input, `ρ = clamp(1/2 + (t − d) / 2w, 0, 1)`, with half-thickness `t` and ramp
//! half-width `w` in voxels ([`HALF_THICKNESS`], [`RAMP`]), and the level is contoured at
//! 1/2: a closed, oriented surface at distance `t` on both sides of the input that follows it
//! wherever it goes and merges sheets closer than `2t` (a morphological dilation: the low-pass
//! that removes what is narrower than the voxel, our counterpart for surfaces of He et al.
//! 1995 §3's filter of solids). Then collapsed to the budget with its topology kept, as the
//! voxel candidates are.
//!
//! Cost: one closest-point query per block of [`BLOCK`]³ samples, which clears the blocks far
//! from the surface, and one per sample of the others (O(log F) each, on all threads);
//! marching cubes and a checked quadric collapse.

use rayon::prelude::*;
use voxlod_contouring::triangle_estimate::resolution_for_triangles;
use voxlod_contouring::{marching_cubes, ContourOptions};
use voxlod_core::{memory, Grid, Volume};
use voxlod_metrics::MeshDistance;
use voxlod_sampling::level_grid;

use crate::candidate::{Candidate, Method};
use crate::input::Input;
use crate::voxel::{collapsed, COARSEST, HEADROOM};
use crate::BudgetError;

/// Half-thickness of the shell, in voxels: enough for marching cubes to see both sides apart.
pub const HALF_THICKNESS: f64 = 0.75;
/// Half-width of the density's ramp across the shell's surface, in voxels.
pub const RAMP: f64 = 0.5;
/// Finest shell grid: its cost grows with the samples near the surface.
pub const FINEST_SHELL: usize = 256;
/// Side of the blocks cleared by one query.
const BLOCK: usize = 4;

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
    let voxel = input.bounds.longest_extent() / resolution as f64;
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

/// The ramp density of the module docs on `grid`: half-thickness `t`, ramp half-width `w`.
pub fn shell_density(
    grid: &Grid,
    closest: &MeshDistance,
    t: f64,
    w: f64,
) -> Result<Volume, BudgetError> {
    let [nx, ny, nz] = grid.dims;
    memory::check_allocation(
        &format!("the shell's {nx}x{ny}x{nz} grid"),
        memory::bytes_of::<f32>(grid.len()),
    )?;
    let reach = t + w;
    let block_half_diagonal = 0.5 * 3f64.sqrt() * (BLOCK - 1) as f64 * grid.spacing[0];
    let mut values = vec![0f32; grid.len()];
    values
        .par_chunks_mut(nx * ny * BLOCK)
        .enumerate()
        .for_each(|(slab, out)| {
            let k0 = slab * BLOCK;
            let k1 = (k0 + BLOCK).min(nz);
            for j0 in (0..ny).step_by(BLOCK) {
                for i0 in (0..nx).step_by(BLOCK) {
                    let (i1, j1) = ((i0 + BLOCK).min(nx), (j0 + BLOCK).min(ny));
                    let centre = grid.position(
                        0.5 * (i0 + i1 - 1) as f64,
                        0.5 * (j0 + j1 - 1) as f64,
                        0.5 * (k0 + k1 - 1) as f64,
                    );
                    if closest
                        .closest_within(centre, reach + block_half_diagonal)
                        .is_none()
                    {
                        continue;
                    }
                    for k in k0..k1 {
                        for j in j0..j1 {
                            for i in i0..i1 {
                                let p = grid.position(i as f64, j as f64, k as f64);
                                let Some(d) = closest.distance_within(p, reach) else {
                                    continue;
                                };
                                let rho = (0.5 + (t - d) / (2.0 * w)).clamp(0.0, 1.0);
                                out[((k - k0) * ny + j) * nx + i] = rho as f32;
                            }
                        }
                    }
                }
            }
        });
    Ok(Volume::from_vec(*grid, values)?)
}
