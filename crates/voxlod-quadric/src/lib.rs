//! Quadric edge collapse to a triangle budget, keeping the topology: the geometric stage that the
//! paper proposes after the voxel stage (He et al. 1995, §5: "the voxel-based method can be used
//! as a first step … followed by a geometric simplification").
//!
//! The collapses are meshoptimizer's (`meshopt_simplify`, Garland–Heckbert quadrics with a
//! distance limit), through the `meshopt` crate. meshoptimizer keeps the result looking like the
//! input but does not promise a manifold: a collapse across a thin tunnel can pinch two sheets
//! together (a non-manifold edge or vertex), close a handle, or flatten a small component. This
//! crate adds that promise (our addition, not meshoptimizer's and not the paper's):
//!
//! **Guarantee.** The result of [`simplify_to_budget`] is the input itself or a mesh whose
//! [`mesh_topology`] has, compared to the input's: no non-manifold edge or vertex, no degenerate
//! or duplicate triangle, no inconsistently oriented edge (where the input had none), and the same
//! components, boundary loops and genus. So a closed manifold level stays closed, manifold and of
//! the same genus, and an open one keeps its openings (its border vertices are also locked in
//! place, [`QuadricOptions::lock_border`]).
//!
//! **How it is enforced.** Every result of meshoptimizer is checked with [`mesh_topology`] and
//! rejected if it breaks any of the above. After a rejection the next attempt asks for less,
//! halfway between the asked count and the last accepted mesh's, and starts from that accepted
//! mesh; after an accepted step that fell short of the budget the next attempt starts from it
//! and asks for the budget again. So the simplification ratchets down through accepted meshes
//! only, until the budget is reached, the distance limit stops the collapses, or the attempts
//! ([`QuadricOptions::max_attempts`]) run out.
//!
//! **The distance limit** is meshoptimizer's own error estimate (`ErrorAbsolute`: in mesh
//! units), the square root of the quadric error of the collapses. It bounds how far a vertex
//! moved from the planes of its original neighbourhood, not the two-sided Hausdorff distance;
//! [`Simplified::error_bound`] adds up the estimates of the accepted steps, and each step is given
//! only what the steps before left of [`QuadricOptions::max_error`]. Measure the distance to the
//! input (voxlod-metrics) where it matters.
//!
//! Cost: each attempt is one meshoptimizer pass, O(F log F), and one topology check, O(F log F);
//! at most [`QuadricOptions::max_attempts`] of each. Memory O(V + F).

use meshopt::{SimplifyOptions, VertexDataAdapter};
use serde::Serialize;
use thiserror::Error;
use voxlod_core::{mesh_topology, CoreError, Topology, TriangleMesh};

/// Why the quadric stage refused to run.
#[derive(Debug, Error)]
pub enum QuadricError {
    /// A mesh without triangles.
    #[error("the mesh has no triangles")]
    EmptyMesh,
    /// A mesh with bad coordinates or indices.
    #[error(transparent)]
    InvalidMesh(#[from] CoreError),
    /// A triangle budget of zero.
    #[error("the triangle budget must be at least 1")]
    ZeroBudget,
    /// A distance limit that is negative or NaN.
    #[error("the distance limit must be zero or positive (got {0})")]
    InvalidDistance(f64),
    /// A mesh whose topology cannot be kept because it is not a manifold to begin with.
    #[error("the mesh is not a manifold ({0} non-manifold edges, {1} non-manifold vertices): the quadric stage keeps a manifold's topology and needs one")]
    NotManifold(usize, usize),
}

/// How [`simplify_to_budget`] runs.
#[derive(Clone, Debug, PartialEq)]
pub struct QuadricOptions {
    /// The largest distance, in mesh units, that meshoptimizer's error estimate may reach, over
    /// all steps (`f64::INFINITY`: no limit, the budget alone decides).
    pub max_error: f64,
    /// meshoptimizer passes at most (accepted or rejected).
    pub max_attempts: usize,
    /// Keep the border vertices of an open mesh where they are (meshoptimizer's `LockBorder`),
    /// so that openings keep their exact rim.
    pub lock_border: bool,
}

impl Default for QuadricOptions {
    /// No distance limit, 12 attempts, border locked.
    fn default() -> Self {
        QuadricOptions {
            max_error: f64::INFINITY,
            max_attempts: 12,
            lock_border: true,
        }
    }
}

impl QuadricOptions {
    /// The default with a distance limit in mesh units.
    pub fn bounded(max_error: f64) -> Self {
        QuadricOptions {
            max_error,
            ..Self::default()
        }
    }

    /// Fewer attempts (4): for searches that try many levels and can afford to stop short.
    pub fn quick() -> Self {
        QuadricOptions {
            max_attempts: 4,
            ..Self::default()
        }
    }
}

/// Why the simplification stopped where it did.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Stop {
    /// The budget was reached.
    Budget,
    /// The distance limit stopped the collapses above the budget.
    DistanceLimit,
    /// Every further attempt broke the topology (or the attempts ran out) above the budget.
    Topology,
}

/// The result of [`simplify_to_budget`].
#[derive(Clone, Debug)]
pub struct Simplified {
    /// The simplified mesh (normals recomputed if the input had them).
    pub mesh: TriangleMesh,
    /// Its topology, which matches the input's as the module docs say.
    pub topology: Topology,
    /// The sum of meshoptimizer's error estimates of the accepted steps, in mesh units.
    pub error_bound: f64,
    /// meshoptimizer passes run.
    pub attempts: usize,
    /// Of those, the ones whose result broke the topology and was thrown away.
    pub rejected: usize,
    /// Why it stopped.
    pub stop: Stop,
}

/// Simplifies `mesh` towards `budget` triangles with meshoptimizer's quadric edge collapse,
/// keeping its topology as the module docs say.
pub fn simplify_to_budget(
    mesh: &TriangleMesh,
    budget: usize,
    options: &QuadricOptions,
) -> Result<Simplified, QuadricError> {
    let reference = check_input(mesh, budget, options)?;
    let mut current = mesh.clone();
    current.remove_unreferenced_vertices();
    let mut result = Simplified {
        topology: reference.clone(),
        mesh: current,
        error_bound: 0.0,
        attempts: 0,
        rejected: 0,
        stop: Stop::Topology,
    };
    let mut ask = budget;
    while result.mesh.triangle_count() > budget && result.attempts < options.max_attempts {
        let room = (options.max_error - result.error_bound).max(0.0);
        result.attempts += 1;
        let (candidate, error) = collapse(&result.mesh, ask, room, options.lock_border);
        if candidate.triangle_count() >= result.mesh.triangle_count() {
            result.stop = Stop::DistanceLimit;
            break;
        }
        let topology = mesh_topology(&candidate);
        if keeps_topology(&reference, &topology) {
            result.mesh = candidate;
            result.topology = topology;
            result.error_bound += error;
            ask = budget;
        } else {
            result.rejected += 1;
            let have = result.mesh.triangle_count();
            ask = ask + (have - ask) / 2;
            if ask + 1 >= have {
                break;
            }
        }
    }
    if result.mesh.triangle_count() <= budget {
        result.stop = Stop::Budget;
    }
    if !mesh.normals.is_empty() {
        result.mesh.compute_vertex_normals();
    }
    Ok(result)
}

/// Validates the arguments and returns the input's topology.
fn check_input(
    mesh: &TriangleMesh,
    budget: usize,
    options: &QuadricOptions,
) -> Result<Topology, QuadricError> {
    check_basic(mesh, budget)?;
    if options.max_error.is_nan() || options.max_error < 0.0 {
        return Err(QuadricError::InvalidDistance(options.max_error));
    }
    let topology = mesh_topology(mesh);
    if topology.non_manifold_edges > 0 || topology.non_manifold_vertices > 0 {
        return Err(QuadricError::NotManifold(
            topology.non_manifold_edges,
            topology.non_manifold_vertices,
        ));
    }
    Ok(topology)
}

/// Refuses an empty or invalid mesh and a zero budget.
fn check_basic(mesh: &TriangleMesh, budget: usize) -> Result<(), QuadricError> {
    if mesh.is_empty() {
        return Err(QuadricError::EmptyMesh);
    }
    mesh.validate()?;
    if budget == 0 {
        return Err(QuadricError::ZeroBudget);
    }
    Ok(())
}

/// Whether `after` keeps what the module docs promise of `before`.
pub fn keeps_topology(before: &Topology, after: &Topology) -> bool {
    after.non_manifold_edges == 0
        && after.non_manifold_vertices == 0
        && after.degenerate_triangles == 0
        && after.duplicate_triangles == 0
        && (before.inconsistent_edges > 0 || after.inconsistent_edges == 0)
        && after.components == before.components
        && after.boundary_loops == before.boundary_loops
        && after.genus == before.genus
        && after.euler_characteristic == before.euler_characteristic
}

/// One meshoptimizer pass towards `target` triangles within `max_error` (mesh units): the
/// compacted result and meshoptimizer's error estimate in mesh units.
fn collapse(
    mesh: &TriangleMesh,
    target: usize,
    max_error: f64,
    lock_border: bool,
) -> (TriangleMesh, f64) {
    let positions = positions_of(mesh);
    let vertices = adapter(&positions);
    let mut flags = SimplifyOptions::ErrorAbsolute;
    if lock_border {
        flags |= SimplifyOptions::LockBorder;
    }
    let mut error = 0.0f32;
    let indices = meshopt::simplify(
        mesh.triangles.as_flattened(),
        &vertices,
        target * 3,
        error_limit(max_error),
        flags,
        Some(&mut error),
    );
    (compact(mesh, &indices), error as f64)
}

/// The vertex positions as meshoptimizer reads them: three packed `f32` each.
fn positions_of(mesh: &TriangleMesh) -> Vec<[f32; 3]> {
    mesh.positions.iter().map(|p| p.to_array()).collect()
}

/// meshoptimizer's view of packed positions.
fn adapter(positions: &[[f32; 3]]) -> VertexDataAdapter<'_> {
    VertexDataAdapter::new(meshopt::typed_to_bytes(positions), 12, 0)
        .expect("12-byte vertices: the stride divides the buffer and the offset is inside it")
}

/// The triangles of a meshoptimizer index list over `mesh`'s vertices, unused vertices dropped.
fn compact(mesh: &TriangleMesh, indices: &[u32]) -> TriangleMesh {
    let triangles = indices
        .chunks_exact(3)
        .map(|t| [t[0], t[1], t[2]])
        .collect();
    let mut out = TriangleMesh::new(mesh.positions.clone(), triangles);
    out.remove_unreferenced_vertices();
    out
}

/// meshoptimizer takes an `f32` limit; no limit is its largest value.
fn error_limit(max_error: f64) -> f32 {
    if max_error.is_finite() {
        max_error as f32
    } else {
        f32::MAX
    }
}

/// meshoptimizer's `simplifySloppy` (vertex clustering on a grid it searches for the count):
/// reaches any count, keeps neither topology nor manifoldness. A reference method for
/// `evaluate`, not a stage of the pipeline. The result's unused vertices are dropped.
pub fn simplify_sloppy(mesh: &TriangleMesh, budget: usize) -> Result<TriangleMesh, QuadricError> {
    check_basic(mesh, budget)?;
    let positions = positions_of(mesh);
    let vertices = adapter(&positions);
    let indices = meshopt::simplify_sloppy(
        mesh.triangles.as_flattened(),
        &vertices,
        budget * 3,
        f32::MAX,
        None,
    );
    Ok(compact(mesh, &indices))
}

/// meshoptimizer's `simplify` alone, as a reference method for `evaluate`: no topology check, no
/// distance limit, border locked only if asked. Returns the mesh and meshoptimizer's error
/// estimate in mesh units.
pub fn simplify_unchecked(
    mesh: &TriangleMesh,
    budget: usize,
    lock_border: bool,
) -> Result<(TriangleMesh, f64), QuadricError> {
    check_basic(mesh, budget)?;
    Ok(collapse(mesh, budget, f64::INFINITY, lock_border))
}
