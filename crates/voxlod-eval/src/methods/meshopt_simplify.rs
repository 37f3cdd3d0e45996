//! meshoptimizer's `simplify` (quadric edge collapse, through the `meshopt` crate) run on the
//! input as it is: the reference geometric simplifier. No topology check and no distance limit,
//! so it shows what plain quadric simplification reaches; the budget pipeline's quadric stage
//! (crate voxlod-quadric) adds the checks. Its parameter is the triangle count asked of
//! meshoptimizer, which it reaches unless collapses run out (the search then keeps the nearest).
//!
//! Cost: O(F log F), tens of milliseconds for tens of thousands of triangles.

use voxlod::core::PolyMesh;
use voxlod_quadric::simplify_unchecked;

use super::SearchLimits;
use super::{target_count_space, MethodInput, RunFailure, SearchSpace, Simplifier};

/// meshoptimizer `simplify` on the input (`meshopt-simplify`).
#[derive(Clone, Copy, Debug, Default)]
pub struct MeshoptSimplify;

impl Simplifier for MeshoptSimplify {
    fn name(&self) -> &'static str {
        "meshopt-simplify"
    }

    fn description(&self) -> &'static str {
        "quadric edge collapse (meshoptimizer simplify, Garland and Heckbert 1997)"
    }

    fn parameter_name(&self) -> &'static str {
        "target-triangles"
    }

    fn search_space(&self, _limits: &SearchLimits) -> SearchSpace {
        target_count_space()
    }

    fn run(&self, input: &MethodInput, target: f64) -> Result<PolyMesh, RunFailure> {
        let (mesh, _) = simplify_unchecked(input.mesh(), target as usize, false)?;
        Ok(PolyMesh::from(mesh))
    }
}
