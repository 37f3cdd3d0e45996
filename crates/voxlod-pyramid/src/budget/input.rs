//! What the budget affords (step 0 of [`crate::budget`], our addition to §5): when the
//! marching-cubes level with about `B` triangles keeps the input's genus and components, the
//! input mesh itself is collapsed to the budget (quadric, topology kept). Cost: one resolution
//! search for `B` and one collapse of the input, O(F log F).

use voxlod_contouring::triangle_estimate::resolution_for_triangles;
use voxlod_quadric::{simplify_to_budget, QuadricOptions};

use super::candidate::Candidate;
use super::context::BudgetContext;
use super::{Stage, Then, COARSEST, FINEST, HEADROOM};
use crate::error::PyramidError;
use crate::lod::LodLevel;

impl BudgetContext<'_> {
    /// The input mesh collapsed towards `budget` when the budget affords the input's topology
    /// (module docs, step 0): the candidate, and the level that showed it.
    pub(super) fn input_candidate(
        &self,
        budget: usize,
        error: Option<f64>,
    ) -> Result<Option<(Candidate, LodLevel, f64)>, PyramidError> {
        let Some((input, topology)) = &self.welded else {
            return Ok(None);
        };
        // An open input under `closed` would keep its holes: the voxel levels close them.
        let closed_asked = topology.boundary_loops > 0 && self.border.is_none();
        if matches!(self.then, Then::None | Then::Envelope) || closed_asked {
            return Ok(None);
        }
        let (resolution, charged, _) = self.resolution_for(budget as f64)?;
        let (level, _, _) = self.uncapped(resolution)?;
        let t = &level.topology;
        let keeps =
            |level: Option<i64>, input: Option<i64>| level.zip(input).is_some_and(|(l, i)| l >= i);
        let removes_nothing = keeps(t.genus, topology.genus) && t.components >= topology.components;
        if level.mesh.is_empty() || !removes_nothing {
            return Ok(None);
        }
        let options = QuadricOptions::budget(error.unwrap_or(f64::INFINITY));
        let Ok(done) = simplify_to_budget(input, budget, &options) else {
            return Ok(None);
        };
        let candidate = Candidate {
            distance: self.measure(&done.mesh),
            mesh: done.mesh,
            stage: Stage::InputQuadric,
            error_bound: done.error_bound,
            parts_dropped: 0,
            parts_restored: 0,
            iso: self.level_options.iso,
            facts: Default::default(),
        };
        Ok(Some((candidate, level, charged)))
    }
}

/// Whether `candidate` (the input's own collapse) is measured closer to the input than half a
/// voxel of the resolution whose marching-cubes level would have `4 B` triangles: the accuracy
/// of that level's surface placement, which a geometric stage on it can only add to, so the
/// voxel search could not be expected to do better (module docs, step 0).
pub(super) fn closer_than_voxels(
    ctx: &BudgetContext,
    candidate: &Candidate,
    budget: usize,
) -> bool {
    let (Some(input), Some(distance)) = (ctx.input, &candidate.distance) else {
        return false;
    };
    let Some(resolution) = resolution_for_triangles(input, (HEADROOM * budget as f64) as usize)
    else {
        return false;
    };
    let voxel = ctx.source.bounds().longest_extent() / resolution.clamp(COARSEST, FINEST) as f64;
    distance.hausdorff <= 0.5 * voxel
}
