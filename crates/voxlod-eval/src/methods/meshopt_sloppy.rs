//! meshoptimizer's `simplifySloppy` (vertex clustering on a grid it sizes for the count, through
//! the `meshopt` crate): a reference clustering method that reaches any count and keeps neither
//! topology nor manifoldness. Its parameter is the triangle count asked of meshoptimizer.
//!
//! Cost: O(F), milliseconds for tens of thousands of triangles.

use voxlod::core::PolyMesh;
use voxlod_quadric::simplify_sloppy;

use super::SearchLimits;
use super::{target_count_space, MethodInput, RunFailure, SearchSpace, Simplifier};

/// meshoptimizer `simplifySloppy` on the input (`meshopt-sloppy`).
#[derive(Clone, Copy, Debug, Default)]
pub struct MeshoptSloppy;

impl Simplifier for MeshoptSloppy {
    fn name(&self) -> &'static str {
        "meshopt-sloppy"
    }

    fn description(&self) -> &'static str {
        "grid vertex clustering sized for the count (meshoptimizer simplifySloppy)"
    }

    fn parameter_name(&self) -> &'static str {
        "target-triangles"
    }

    fn search_space(&self, _limits: &SearchLimits) -> SearchSpace {
        target_count_space()
    }

    fn run(&self, input: &MethodInput, target: f64) -> Result<PolyMesh, RunFailure> {
        Ok(PolyMesh::from(simplify_sloppy(
            input.mesh(),
            target as usize,
        )?))
    }
}
