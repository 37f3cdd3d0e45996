//! The budget pipeline of `voxlod lod --triangles` (the facade's [`voxlod::lod_by_budget`]): for
//! a mesh, crate `voxlod-budget`'s portfolio, whose level for the budget is the candidate
//! measured closest to the input among the input's own collapses (meshoptimizer's, as gltfpack
//! runs it, and its checked and uncrossed forms) and voxel levels (He et al. 1995, §5: the voxel
//! method as the first stage before a geometric simplifier) that keeps the levels' promises,
//! unless its outline is worse than the input's collapse's. Its parameter is the budget itself,
//! asked alone (a chain of budgets, as `lod` makes it, hands each level down to the next), which
//! the pipeline reaches within 10 % or says why not.
//!
//! Cost: a chain of one budget, about a second for tens of thousands of triangles.

use voxlod::core::PolyMesh;
use voxlod::{BudgetOptions, Source};

use super::SearchLimits;
use super::{target_count_space, MethodInput, RunFailure, SearchSpace, Simplifier};

/// The budget pipeline on the input (`budget`).
#[derive(Clone, Copy, Debug, Default)]
pub struct BudgetPipeline;

impl Simplifier for BudgetPipeline {
    fn name(&self) -> &'static str {
        "budget"
    }

    fn description(&self) -> &'static str {
        "the closest of the input's collapses and voxel levels (He et al. 1995, §5) that keeps the promises"
    }

    fn parameter_name(&self) -> &'static str {
        "target-triangles"
    }

    fn search_space(&self, _limits: &SearchLimits) -> SearchSpace {
        target_count_space()
    }

    fn run(&self, input: &MethodInput, target: f64) -> Result<PolyMesh, RunFailure> {
        let options = BudgetOptions::for_triangles(&[target as usize]);
        let lod = voxlod::lod_by_budget(&Source::Mesh(input.mesh()), &options)
            .map_err(RunFailure::Pipeline)?;
        let level = lod.levels.into_iter().next();
        Ok(PolyMesh::from(level.map(|l| l.mesh).unwrap_or_default()))
    }
}
