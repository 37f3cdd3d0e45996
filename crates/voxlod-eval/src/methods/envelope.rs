//! Simplification envelopes (Varshney et al.): vertex removal while the surface stays between
//! two offsets of the input at distance ε, [`EnvelopeOptions::tight`]. Its parameter is ε in
//! percent of the input's bounding-box diagonal, a continuous parameter under which triangle
//! counts fall about as 1/ε on smooth surfaces: the search steps on a geometric grid (ratio
//! 2^¼). It simplifies the input itself, which must be a consistently oriented manifold: an
//! input that is not one is repaired first ([`super::MethodInput::manifold`]).
//!
//! Cost: that of [`simplify_envelope`], seconds for tens of thousands of triangles.

use voxlod::core::{PolyMesh, TriangleMesh};
use voxlod::envelope::{simplify_envelope, EnvelopeOptions, Epsilon};

use super::SearchLimits;
use super::{MethodInput, Needs, ParameterGrid, RunFailure, SearchSpace, Simplifier};

/// Simplification envelopes on the input (`envelope`).
#[derive(Clone, Copy, Debug, Default)]
pub struct Envelope;

impl Simplifier for Envelope {
    fn name(&self) -> &'static str {
        "envelope"
    }

    fn description(&self) -> &'static str {
        "simplification envelopes (Varshney et al. 1995)"
    }

    fn parameter_name(&self) -> &'static str {
        "epsilon-percent"
    }

    /// ε from 0.005 % to 25 % of the diagonal, starting at 1 %.
    fn search_space(&self, _limits: &SearchLimits) -> SearchSpace {
        SearchSpace {
            lowest: 0.005,
            highest: 25.0,
            first: 1.0,
            first_at_budget: false,
            exponent: -1.0,
            grid: ParameterGrid::Geometric {
                ratio: 2f64.powf(0.25),
            },
        }
    }

    fn needs(&self) -> Needs {
        Needs {
            manifold: true,
            ..Needs::default()
        }
    }

    fn run(&self, input: &MethodInput, percent: f64) -> Result<PolyMesh, RunFailure> {
        envelope_level(input.manifold()?, Epsilon::percent(percent))
    }
}

/// `mesh` simplified within `epsilon` by the tight envelope, without its own distance
/// measurement (the evaluation measures every level alike).
pub(super) fn envelope_level(
    mesh: &TriangleMesh,
    epsilon: Epsilon,
) -> Result<PolyMesh, RunFailure> {
    let options = EnvelopeOptions::tight().with_measure_samples(0);
    Ok(PolyMesh::from(
        simplify_envelope(mesh, epsilon, &options)?.mesh,
    ))
}
