//! Why an evaluation could not be made, and how its messages write a method's parameter.
//!
//! An [`EvaluateError`] becomes the facade's `voxlod::Error` with the same message and the
//! class of what failed (`voxlod::Error::class`): a stage's failure keeps its stage's class,
//! what the evaluation or its methods were asked wrongly is a usage error.

use voxlod::envelope::EnvelopeError;
use voxlod::metrics::MetricsError;
use voxlod::portfolio::BudgetError;
use voxlod::quadric::QuadricError;
use voxlod::render::RenderError;
use voxlod::sampling::SamplingError;
use voxlod::InvalidOption;

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
    /// The scene proxy ([`super::PROXY`], [`voxlod::proxy`]) failed for a reason other than a
    /// budget it cannot reach (those are misses).
    #[error("proxy: {0}")]
    Proxy(voxlod::pyramid::PyramidError),
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

impl From<EvaluateError> for voxlod::Error {
    fn from(e: EvaluateError) -> voxlod::Error {
        use voxlod::Error;
        let run = |method: Method, parameter: &str, value: f64| {
            format!("{method} at {parameter} {}", parameter_text(value))
        };
        match e {
            EvaluateError::Input(e) => Error::from(e).context("the input mesh"),
            EvaluateError::Solid(e) => {
                Error::from(e).context("the input mesh cannot be sampled as a solid")
            }
            EvaluateError::NoBudgets { triangles } => InvalidOption::new(
                "budgets",
                "none",
                format!(
                    "no budgets: give at least one triangle count above 0 (the input has \
                     {triangles} triangles)"
                ),
            )
            .into(),
            EvaluateError::NoMethods => {
                InvalidOption::new("methods", "none", "no methods to evaluate").into()
            }
            EvaluateError::Run {
                method,
                parameter,
                value,
                source,
            } => run_failure(source, method, value).context(run(method, parameter, value)),
            EvaluateError::InputRender(e) => {
                Error::from(e).context("the input mesh cannot be rendered")
            }
            EvaluateError::Render {
                method,
                parameter,
                value,
                source,
            } => Error::from(source)
                .context("rendering the level")
                .context(run(method, parameter, value)),
            EvaluateError::Distance {
                method,
                parameter,
                value,
                source,
            } => Error::from(source)
                .context("measuring the level")
                .context(run(method, parameter, value)),
            EvaluateError::Proxy(e) => Error::from(e).context(super::PROXY.name()),
        }
    }
}

/// One run's failure as the facade's error: a stage's as its own; meshoptimizer's refusals of a
/// mesh as no level for the run's triangle target (bad input), of a parameter as a usage
/// error; a method that did not declare what it needs ([`crate::methods::Simplifier::needs`])
/// as a usage error of `methods`.
fn run_failure(failure: RunFailure, method: Method, value: f64) -> voxlod::Error {
    use voxlod::Error;
    match failure {
        RunFailure::Voxel(e) => e.into(),
        RunFailure::Clustering(e) => e.into(),
        RunFailure::Envelope(e) => e.into(),
        RunFailure::Pipeline(e) => e,
        RunFailure::Quadric(QuadricError::InvalidMesh(e)) => e.into(),
        RunFailure::Quadric(e @ (QuadricError::ZeroBudget | QuadricError::InvalidDistance(_))) => {
            InvalidOption::new(
                method.parameter_name(),
                parameter_text(value),
                e.to_string(),
            )
            .into()
        }
        RunFailure::Quadric(e) => Error::from(BudgetError::NoLevel {
            budget: value as usize,
            why: e.to_string(),
        }),
        RunFailure::NotPrepared(what) => InvalidOption::new(
            "methods",
            method,
            format!("needs the input prepared {what}, which its `needs` does not ask for"),
        )
        .into(),
        RunFailure::NotManifold(problems) => Error::from(EnvelopeError::NotManifold(problems))
            .context("the input is not a manifold even after repair"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use voxlod::envelope::ManifoldProblems;
    use voxlod::ErrorClass::{self, BadInput, Usage};

    #[test]
    fn each_failure_becomes_the_facade_error_of_its_class_with_its_words() {
        let method: Method = "rossignac-borrel".parse().unwrap();
        let run = |source: RunFailure| EvaluateError::Run {
            method,
            parameter: "cells",
            value: 8.0,
            source,
        };
        let not_manifold = ManifoldProblems {
            non_manifold_edges: 2,
            ..ManifoldProblems::default()
        };
        let cases: Vec<(EvaluateError, ErrorClass, bool)> = vec![
            (EvaluateError::NoMethods, Usage, false),
            (EvaluateError::NoBudgets { triangles: 12 }, Usage, false),
            (
                EvaluateError::Input(MetricsError::NoArea { triangles: 3 }),
                BadInput,
                true,
            ),
            (
                run(RunFailure::Quadric(QuadricError::EmptyMesh)),
                BadInput,
                false,
            ),
            (
                run(RunFailure::Quadric(QuadricError::ZeroBudget)),
                Usage,
                false,
            ),
            (run(RunFailure::NotPrepared("as a solid")), Usage, false),
            (run(RunFailure::NotManifold(not_manifold)), BadInput, true),
            (
                EvaluateError::Distance {
                    method,
                    parameter: "cells",
                    value: 8.0,
                    source: MetricsError::NoSamples,
                },
                Usage,
                true,
            ),
        ];
        for (e, class, same_words) in cases {
            let words = e.to_string();
            let e = voxlod::Error::from(e);
            assert_eq!(e.class(), class, "{e}");
            if same_words {
                assert_eq!(e.to_string(), words);
            }
        }
    }
}
