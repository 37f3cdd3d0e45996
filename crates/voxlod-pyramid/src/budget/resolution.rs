//! The resolution search (step 1 of [`crate::budget`]): the finest voxel resolution whose
//! marching-cubes level has about the wanted count, probed from the estimate of
//! [`voxlod_contouring::triangle_estimate`] by scaling with the square root of the count's
//! ratio, at most five probes (each a sampling and marching cubes, built once per run).

use voxlod_contouring::triangle_estimate::resolution_for_triangles;

use super::context::BudgetContext;
use super::{COARSEST, FINEST, PROBE_TOLERANCE};
use crate::error::PyramidError;

impl BudgetContext<'_> {
    /// The resolution whose level has about `wanted` triangles (module docs, step 1), the
    /// seconds charged for the probes, and warnings for levels that vanished.
    pub(super) fn resolution_for(
        &self,
        wanted: f64,
    ) -> Result<(usize, f64, Vec<String>), PyramidError> {
        self.resolution_for_at(wanted, self.level_options.iso)
    }

    /// [`BudgetContext::resolution_for`] at isodensity `iso`.
    pub(super) fn resolution_for_at(
        &self,
        wanted: f64,
        iso: f32,
    ) -> Result<(usize, f64, Vec<String>), PyramidError> {
        let start = self
            .sampled
            .and_then(|mesh| resolution_for_triangles(mesh, wanted.round() as usize))
            .unwrap_or(32)
            .clamp(COARSEST, FINEST);
        let (mut resolution, mut charged, mut warnings) = (start, 0.0, Vec::new());
        for _ in 0..5 {
            let (level, seconds) = self.level_at(resolution, iso)?;
            charged += seconds;
            let got = level.mesh.triangle_count();
            let next = if got == 0 {
                warnings.push(format!(
                    "resolution {resolution}: the level vanished (parts thinner than a voxel); \
                     trying {}",
                    (resolution * 2).min(FINEST)
                ));
                resolution * 2
            } else {
                (resolution as f64 * (wanted / got as f64).sqrt()).round() as usize
            };
            let next = next.clamp(COARSEST, FINEST);
            if next == resolution
                || (got > 0 && (got as f64 / wanted - 1.0).abs() < PROBE_TOLERANCE)
            {
                break;
            }
            resolution = next;
        }
        Ok((resolution, charged, warnings))
    }
}

/// The coarsest resolution of the search's regular neighbours (about `2 B` triangles, for a
/// first resolution of about `4 B`); coarser ones are tried only while nothing fits.
pub(super) fn step_down(first: usize) -> usize {
    ((first as f64 * 0.5f64.sqrt()).round() as usize).clamp(COARSEST, FINEST)
}
