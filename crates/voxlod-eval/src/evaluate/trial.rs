//! One run of a method at one value of its parameter, timed.

use std::time::Instant;

use voxlod::core::PolyMesh;

use super::error::EvaluateError;
use crate::methods::{Method, MethodInput};

/// One run of a method.
pub(super) struct Trial {
    /// The parameter's step on its grid, and its value.
    pub step: i64,
    pub parameter: f64,
    /// Triangles, and for clustering the dangling edges and isolated points.
    pub level: PolyMesh,
    /// Time of the run.
    pub seconds: f64,
}

impl Trial {
    pub fn triangles(&self) -> usize {
        self.level.mesh.triangles.len()
    }
}

/// Runs `method` at `step`'s value.
pub(super) fn run_trial(
    method: Method,
    input: &MethodInput,
    step: i64,
    parameter: f64,
) -> Result<Trial, EvaluateError> {
    let start = Instant::now();
    let level = method
        .simplifier()
        .run(input, parameter)
        .map_err(|source| EvaluateError::Run {
            method,
            parameter: method.parameter_name(),
            value: parameter,
            source,
        })?;
    Ok(Trial {
        step,
        parameter,
        level,
        seconds: start.elapsed().as_secs_f64(),
    })
}
