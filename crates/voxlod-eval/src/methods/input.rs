//! What the methods run on: the input mesh, and what some of them need made from it once and
//! shared (the input as a filterable solid for the voxel pipeline; the input as a consistently
//! oriented manifold for simplification envelopes, repaired if need be).
//!
//! Cost: the solid is [`MeshSolid::new`] (a BVH over the triangles and an inside-out test);
//! the manifold check is linear in the triangles, and the repair (only for an input that fails
//! it) about the same.

use std::borrow::Cow;

use voxlod::core::TriangleMesh;
use voxlod::envelope::{check_manifold, manifold_problems, repair_for_envelope, ManifoldProblems};
use voxlod::sampling::{MeshSolid, SamplingError};

use super::{Method, RunFailure};

/// What a method needs made from the input before its first run ([`super::Simplifier::needs`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Needs {
    /// The input as a solid to filter ([`MeshSolid`]).
    pub solid: bool,
    /// The input as a consistently oriented manifold: the input itself when it is one, else a
    /// repaired copy. A method that needs it is left out when the input cannot be made one.
    pub manifold: bool,
}

impl Needs {
    /// What any of `methods` needs.
    pub fn of(methods: &[Method]) -> Needs {
        methods
            .iter()
            .map(|m| m.simplifier().needs())
            .fold(Needs::default(), |a, b| Needs {
                solid: a.solid || b.solid,
                manifold: a.manifold || b.manifold,
            })
    }
}

/// The input of every run, with what [`Needs`] asked to be made from it.
pub struct MethodInput<'a> {
    mesh: &'a TriangleMesh,
    lines_per_radius: usize,
    solid: Option<MeshSolid>,
    /// The manifold, or why the input cannot be made one (the repaired copy's problems);
    /// `None` when not asked for.
    manifold: Option<Result<Cow<'a, TriangleMesh>, ManifoldProblems>>,
    manifold_notes: Vec<String>,
}

impl<'a> MethodInput<'a> {
    /// Makes what `needs` asks for from `mesh`. `lines_per_radius` is the voxel pipeline's
    /// quadrature lines per filter radius (see `voxlod lod --help`).
    ///
    /// Fails only when the solid is asked for and `mesh` cannot be sampled as one; an input that
    /// cannot be made a manifold is reported by [`MethodInput::manifold`].
    pub fn prepare(
        mesh: &'a TriangleMesh,
        needs: Needs,
        lines_per_radius: usize,
    ) -> Result<MethodInput<'a>, SamplingError> {
        let solid = if needs.solid {
            Some(MeshSolid::new(mesh)?)
        } else {
            None
        };
        let mut manifold_notes = Vec::new();
        let manifold = needs.manifold.then(|| {
            manifold_input(mesh).map(|(manifold, notes)| {
                manifold_notes = notes;
                manifold
            })
        });
        Ok(MethodInput {
            mesh,
            lines_per_radius,
            solid,
            manifold,
            manifold_notes,
        })
    }

    /// The input mesh: what the levels are measured against and clustering simplifies.
    pub fn mesh(&self) -> &'a TriangleMesh {
        self.mesh
    }

    /// Quadrature lines per filter radius of the voxel pipeline.
    pub fn lines_per_radius(&self) -> usize {
        self.lines_per_radius
    }

    /// The input as a solid.
    pub fn solid(&self) -> Result<&MeshSolid, RunFailure> {
        self.solid
            .as_ref()
            .ok_or(RunFailure::NotPrepared("as a solid"))
    }

    /// The input as a consistently oriented manifold, or why it cannot be made one.
    pub fn manifold(&self) -> Result<&TriangleMesh, RunFailure> {
        match &self.manifold {
            None => Err(RunFailure::NotPrepared("as a manifold")),
            Some(Ok(mesh)) => Ok(mesh),
            Some(Err(problems)) => Err(RunFailure::NotManifold(problems.clone())),
        }
    }

    /// What making the manifold changed, for the report (empty when the input was one).
    pub fn manifold_notes(&self) -> &[String] {
        &self.manifold_notes
    }

    /// Why a method with `needs` cannot run on this input (the input could not be made a
    /// manifold), or `None` when it can.
    pub fn unmet(&self, needs: Needs) -> Option<String> {
        match &self.manifold {
            Some(Err(problems)) if needs.manifold => {
                Some(RunFailure::NotManifold(problems.clone()).to_string())
            }
            _ => None,
        }
    }
}

/// The mesh the envelope simplifies: the input, or the input cut into a consistently oriented
/// manifold (with a note of what changed); or why neither can be had.
fn manifold_input(
    mesh: &TriangleMesh,
) -> Result<(Cow<'_, TriangleMesh>, Vec<String>), ManifoldProblems> {
    let problems = match check_manifold(mesh) {
        Ok(()) => return Ok((Cow::Borrowed(mesh), Vec::new())),
        Err(e) => e.to_string(),
    };
    let (repaired, repair) = repair_for_envelope(mesh);
    let left = manifold_problems(&repaired);
    if !left.is_empty() {
        return Err(left);
    }
    Ok((
        Cow::Owned(repaired),
        vec![format!(
            "The input is not a consistently oriented manifold ({problems}); the envelope \
             simplified a repaired copy ({repair}) and was measured against the input."
        )],
    ))
}
