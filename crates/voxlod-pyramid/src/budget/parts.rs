//! The input's connected components, each with its stand-in: the part collapsed to a few
//! triangles, made once per run on first use (module `detached`, step 6 of [`super`]). Cost:
//! one topology check and one quadric collapse per part that is ever apart from a level.

use std::sync::{Arc, OnceLock};

use voxlod_core::{mesh_topology, TriangleMesh};
use voxlod_quadric::{simplify_to_budget, QuadricOptions};

/// The fewest triangles a closed genus-0 part collapses to: a tetrahedron.
pub(super) const STAND_IN_TRIANGLES: usize = 4;

/// The input's components (welded), split once per run; empty without a mesh input or with a
/// single component.
pub(crate) type InputParts = Arc<OnceLock<Vec<InputPart>>>;

/// One connected component of the input, and its stand-in, collapsed on first use.
pub(crate) struct InputPart {
    pub(super) mesh: TriangleMesh,
    stand_in: OnceLock<Option<TriangleMesh>>,
}

impl InputPart {
    /// The part `mesh`, its stand-in not yet made.
    pub(super) fn new(mesh: TriangleMesh) -> InputPart {
        InputPart {
            mesh,
            stand_in: OnceLock::new(),
        }
    }

    /// The part collapsed towards [`STAND_IN_TRIANGLES`], topology kept; `None` unless the part
    /// is a closed manifold of genus 0 whose collapse succeeds (computed once per run).
    pub(super) fn stand_in(&self) -> Option<&TriangleMesh> {
        let collapse = || {
            let topology = mesh_topology(&self.mesh);
            if !topology.is_closed_manifold() || topology.genus != Some(0) {
                return None;
            }
            let options = QuadricOptions::budget(f64::INFINITY);
            let done = simplify_to_budget(&self.mesh, STAND_IN_TRIANGLES, &options).ok()?;
            Some(done.mesh).filter(|m| !m.is_empty())
        };
        self.stand_in.get_or_init(collapse).as_ref()
    }
}
