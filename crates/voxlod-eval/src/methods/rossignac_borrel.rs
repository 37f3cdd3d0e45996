//! Uniform-grid vertex clustering with weighted centres of mass (Rossignac and Borrel 1993),
//! [`ClusterOptions::smoothing`]. Its parameter is the cells across the input's longest side.
//! Its output keeps the dangling edges and isolated points of collapsed triangles.
//!
//! Cost: linear in the input, milliseconds for tens of thousands of triangles.

use voxlod::clustering::{rossignac_borrel, ClusterOptions};
use voxlod::core::PolyMesh;

use super::clustering::{cells_space, first_level};
use super::SearchLimits;
use super::{MethodInput, RunFailure, SearchSpace, Simplifier};

/// Rossignac–Borrel vertex clustering (`rossignac-borrel`).
#[derive(Clone, Copy, Debug, Default)]
pub struct RossignacBorrel;

impl Simplifier for RossignacBorrel {
    fn name(&self) -> &'static str {
        "rossignac-borrel"
    }

    fn description(&self) -> &'static str {
        "uniform-grid vertex clustering (Rossignac and Borrel 1993)"
    }

    fn parameter_name(&self) -> &'static str {
        "cells"
    }

    fn search_space(&self, limits: &SearchLimits) -> SearchSpace {
        cells_space(limits)
    }

    fn run(&self, input: &MethodInput, cells: f64) -> Result<PolyMesh, RunFailure> {
        let options = ClusterOptions::smoothing(cells as u32);
        Ok(first_level(rossignac_borrel(input.mesh(), &options)?))
    }
}
