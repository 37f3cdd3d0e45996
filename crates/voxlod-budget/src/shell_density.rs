//! The density of a thin shell around a surface with no inside (module `shell`): at a sample
//! of unsigned distance `d` to the surface, `ρ = clamp(1/2 + (t − d) / 2w, 0, 1)`, with
//! half-thickness `t` and ramp half-width `w` ([`HALF_THICKNESS`] and [`RAMP`] voxels), so
//! that the isodensity 1/2 lies at distance `t` on both sides of the surface.
//!
//! Cost: one closest-point query per block of [`BLOCK`]³ samples, which clears the blocks far
//! from the surface, and one per sample of the others (O(log F) each, on all threads).

use rayon::prelude::*;
use voxlod_core::{memory, Grid, Volume};
use voxlod_metrics::MeshDistance;

use crate::BudgetError;

/// Half-thickness of the shell, in voxels: enough for marching cubes to see both sides apart.
pub const HALF_THICKNESS: f64 = 0.75;
/// Half-width of the density's ramp across the shell's surface, in voxels.
pub const RAMP: f64 = 0.5;
/// Side of the blocks cleared by one query.
const BLOCK: usize = 4;

/// The ramp density of the module docs on `grid`, for the surface `closest`: half-thickness
/// `t`, ramp half-width `w`, in mesh units.
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
