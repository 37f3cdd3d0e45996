//! The budget pipeline of `voxlod lod --triangles` (the facade's [`voxlod::budget`]): the voxel
//! resolution that filters away what the budget cannot afford, the caps over an open input's
//! holes cut, then the geometric stage that measures closer to the input (quadric collapse or
//! simplification envelopes), neighbouring resolutions searched (He et al. 1995, §5: the voxel
//! method as the first stage before a geometric simplifier). Its parameter is the budget
//! itself, which the pipeline reaches within 10 % or says why not.
//!
//! Cost: per budget, two to five samplings of the input as a solid and one to three geometric
//! stages, each measured; about a second for tens of thousands of triangles.

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
        "voxel resolution for the budget, then quadric collapse or envelopes (He et al. 1995, §5)"
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
