//! Openings (step 2 of [`crate::budget`]): an open input mesh keeps its holes, so the caps that
//! sampling put over them are cut from each voxel level ([`crate::caps`]), unless the run asked
//! for closed levels. Cost: one pass over the level's triangles against the input's border.

use voxlod_core::mesh_topology;

use super::context::BudgetContext;
use crate::caps::cut_caps;
use crate::error::PyramidError;
use crate::lod::LodLevel;

impl BudgetContext<'_> {
    /// The level at `resolution` and the surface's isodensity with the caps over the input's
    /// holes cut (unless closed).
    pub(super) fn uncapped(
        &self,
        resolution: usize,
    ) -> Result<(LodLevel, usize, f64), PyramidError> {
        self.uncapped_at(resolution, self.level_options.iso)
    }

    /// [`BudgetContext::uncapped`] at isodensity `iso`.
    pub(super) fn uncapped_at(
        &self,
        resolution: usize,
        iso: f32,
    ) -> Result<(LodLevel, usize, f64), PyramidError> {
        let (mut level, seconds) = self.level_at(resolution, iso)?;
        let mut cut = 0;
        if let Some(border) = &self.border {
            let (mesh, n) = cut_caps(&level.mesh, border, 0.5 * level.plan.voxel_size);
            level.mesh = mesh;
            level.topology = mesh_topology(&level.mesh);
            cut = n;
        }
        Ok((level, cut, seconds))
    }
}
