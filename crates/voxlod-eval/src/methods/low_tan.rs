//! Floating-cell weight-controlled vertex clustering (Low and Tan 1997), without thick edges,
//! [`FloatingCellOptions::single`]. Its parameter is the cells across the input's longest side.
//! Its output keeps the dangling edges and isolated points of collapsed triangles.
//!
//! Cost: O(V log V) for sorting the vertices by weight, then about linear in the input;
//! milliseconds for tens of thousands of triangles.

use voxlod::clustering::{low_tan, FloatingCellOptions};
use voxlod::core::PolyMesh;

use super::clustering::{cells_space, first_level};
use super::SearchLimits;
use super::{MethodInput, RunFailure, SearchSpace, Simplifier};

/// Low–Tan floating-cell clustering (`low-tan`).
#[derive(Clone, Copy, Debug, Default)]
pub struct LowTan;

impl Simplifier for LowTan {
    fn name(&self) -> &'static str {
        "low-tan"
    }

    fn description(&self) -> &'static str {
        "floating-cell vertex clustering (Low and Tan 1997)"
    }

    fn parameter_name(&self) -> &'static str {
        "cells"
    }

    fn search_space(&self, limits: &SearchLimits) -> SearchSpace {
        cells_space(limits)
    }

    fn run(&self, input: &MethodInput, cells: f64) -> Result<PolyMesh, RunFailure> {
        let options = FloatingCellOptions::single(cells as u32).with_thick_edges(false);
        Ok(first_level(low_tan(input.mesh(), &options)?))
    }
}
