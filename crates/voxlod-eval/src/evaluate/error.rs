//! Why an evaluation could not be made, and how its messages write a method's parameter.

use voxlod::metrics::MetricsError;
use voxlod::render::RenderError;
use voxlod::sampling::SamplingError;

use crate::methods::{Method, RunFailure};

/// Why an evaluation could not be made.
#[derive(Debug, thiserror::Error)]
pub enum EvaluateError {
    /// The input cannot be measured: broken indices or coordinates, or no area.
    #[error("the input mesh: {0}")]
    Input(#[from] MetricsError),
    /// The voxel methods cannot sample the input as a solid.
    #[error("the input mesh cannot be sampled as a solid: {0}")]
    Solid(SamplingError),
    /// [`EvaluateOptions::budgets`] gives no triangle count for this input.
    #[error("no budgets: give at least one triangle count above 0 (the input has {triangles} triangles)")]
    NoBudgets {
        /// The input's triangles.
        triangles: usize,
    },
    /// [`EvaluateOptions::methods`] is empty.
    #[error("no methods to evaluate")]
    NoMethods,
    /// A run of a method failed.
    #[error("{method} at {parameter} {}: {source}", parameter_text(*.value))]
    Run {
        /// The method.
        method: Method,
        /// Its parameter's name.
        parameter: &'static str,
        /// The parameter's value.
        value: f64,
        /// What failed.
        source: RunFailure,
    },
    /// The input's silhouettes cannot be rendered.
    #[error("the input mesh cannot be rendered: {0}")]
    InputRender(RenderError),
    /// A level's silhouettes cannot be rendered.
    #[error("{method} at {parameter} {}: rendering the level: {source}", parameter_text(*.value))]
    Render {
        /// The method.
        method: Method,
        /// Its parameter's name.
        parameter: &'static str,
        /// The parameter's value.
        value: f64,
        /// What failed.
        source: RenderError,
    },
    /// A level's distance to the input cannot be measured.
    #[error("{method} at {parameter} {}: measuring the level: {source}", parameter_text(*.value))]
    Distance {
        /// The method.
        method: Method,
        /// Its parameter's name.
        parameter: &'static str,
        /// The parameter's value.
        value: f64,
        /// What failed.
        source: MetricsError,
    },
}

/// A parameter as a person writes it: whole numbers plain, ε percentages to three places.
pub fn parameter_text(x: f64) -> String {
    if x.fract() == 0.0 {
        format!("{x:.0}")
    } else {
        format!("{x:.3}")
    }
}
