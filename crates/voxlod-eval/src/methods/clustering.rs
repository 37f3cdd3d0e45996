//! What the two clustering methods share (not a method itself): the search space of their
//! cells, and the one level of a single-level run.

use voxlod::clustering::Level;
use voxlod::core::PolyMesh;

use super::SearchLimits;
use super::{ParameterGrid, SearchSpace};

/// Cells across the longest side from 1 to [`SearchLimits::max_cells`], starting at 64;
/// triangle counts grow about as the square of the cells.
pub(super) fn cells_space(limits: &SearchLimits) -> SearchSpace {
    SearchSpace {
        lowest: 1.0,
        highest: limits.max_cells as f64,
        first: 64.0,
        first_at_budget: false,
        exponent: 2.0,
        grid: ParameterGrid::Integers,
    }
}

/// The one level a single-level clustering run made.
pub(super) fn first_level(levels: Vec<Level>) -> PolyMesh {
    levels.into_iter().next().expect("one level asked for").mesh
}
