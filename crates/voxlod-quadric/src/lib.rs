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
//! place, [`QuadricOptions::lock_border`]; with [`QuadricOptions::holes_may_close`], it may have
//! fewer boundary loops, its holes closed, and no more handles). And no two of its triangles cross
//! ([`voxlod_core::crossing_pairs`]) beyond as many pairs as the input has: a level without
//! self-intersections stays without.
//!
//! **How it is enforced.** Every result of meshoptimizer is checked with [`mesh_topology`] and
//! for crossing triangles (module `folds`), and rejected if it breaks any of the above. After
//! a rejection the next attempt asks for less,
//! halfway between the asked count and the last accepted mesh's, and starts from that accepted
//! mesh; after an accepted step that fell short of the budget the next attempt starts from it
//! and asks for the budget again. A rejection in which some components lost their shape
//! (meshoptimizer collapses a small closed piece, such as a blob the voxel stage left, to a
//! flat pair or to nothing, or closes a handle of one) instead locks those components' vertices
//! (meshoptimizer's `vertex_lock`) and asks again: they stay as they are, and the rest of the
//! mesh can still reach the budget. A component lost its shape when its Euler characteristic
//! changed or fewer than four of its triangles are left (fewer than a closed surface needs).
//! In a large component only the ring around each pinch is locked. A rejection for crossing
//! triangles (a collapse folded one sheet through another close to it) locks the vertices
//! around the new crossing triangles the same way (module `folds`). A rejected pass that asked
//! for the budget and stopped above it ends the run with locks: what held that pass back (its
//! locks, meshoptimizer's own refusals) holds the next one too, and a rejection only adds
//! locks (on the 93 inputs of the budget bench, no such run reached the budget after one; 8 %
//! of the locked runs' passes came after it). When the run with locks still stops above the
//! budget, a run without them (the request halved after a rejection) is tried as well, and the
//! smaller result kept. Its first pass would be the locked run's first over again (no lock is
//! set before a rejection), so it starts where that pass left off; where that pass was
//! rejected, it stops at its own first rejection: what it adds then is the collapse in two
//! steps, halfway and then to the budget (of the 23 such runs that reached the budget on those
//! inputs, 20 did so in those two passes, and the halvings beyond them were 57 % of the runs'
//! passes). So the simplification ratchets down through accepted meshes only, until the budget
//! is reached, the distance limit stops the collapses, or the attempts
//! ([`QuadricOptions::max_attempts`]) run out.
//!
//! **The distance limit** is meshoptimizer's own error estimate (`ErrorAbsolute`: in mesh
//! units), the square root of the quadric error of the collapses. It bounds how far a vertex
//! moved from the planes of its original neighbourhood, not the two-sided Hausdorff distance;
//! [`Simplified::error_bound`] adds up the estimates of the accepted steps, and each step is given
//! only what the steps before left of [`QuadricOptions::max_error`]. Measure the distance to the
//! input (voxlod-metrics) where it matters.
//!
//! Cost: each attempt is one meshoptimizer pass, O(F log F), one topology check, O(F log F), and
//! one count of crossing pairs, O(F) on all threads; at most [`QuadricOptions::max_attempts`]
//! of each. Memory O(V + F).

use rustc_hash::FxHashMap as HashMap;

mod drop_parts;
mod folds;

pub use drop_parts::{simplify_dropping_parts, PartsOptions, PartsSimplified};

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
    /// meshoptimizer passes at most (accepted or rejected) of each ratchet: the one with locks,
    /// then, where that stopped short of the budget after a rejection, the plain one.
    pub max_attempts: usize,
    /// Keep the border vertices of an open mesh where they are (meshoptimizer's `LockBorder`),
    /// so that openings keep their exact rim.
    pub lock_border: bool,
    /// Openings may close: a pass may leave fewer boundary loops than the input has (a scan's
    /// small holes collapse shut along their rims), as long as every other part of the
    /// guarantee holds and the genus does not rise ([`keeps_topology_or_closes_holes`]).
    /// Off, the boundary loops are kept as they are.
    pub holes_may_close: bool,
}

impl Default for QuadricOptions {
    /// No distance limit, 12 attempts, border locked.
    fn default() -> Self {
        QuadricOptions {
            max_error: f64::INFINITY,
            max_attempts: 12,
            lock_border: true,
            holes_may_close: false,
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

    /// The default with a distance limit in mesh units, 24 attempts (locks take some) and the
    /// border free to collapse along itself (the openings keep their number, not every rim vertex): for a triangle budget,
    /// where a rim's vertices are better spent elsewhere.
    pub fn budget(max_error: f64) -> Self {
        QuadricOptions {
            max_error,
            max_attempts: 24,
            lock_border: false,
            holes_may_close: false,
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
    /// As [`Stop::Topology`], the last attempt rejected because it made triangles cross (it
    /// kept the topology, but folded one sheet through another: module docs).
    Crossings,
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
    /// Of those, the ones whose result broke the topology or made triangles cross and was thrown
    /// away.
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
    let (mut result, first) = ratchet(current.clone(), &reference, budget, options, None);
    if let (false, true, Some(first)) = (result.stop == Stop::Budget, result.rejected > 0, first) {
        // Locks keep what they lock at full detail, which can itself stop the collapses short of
        // the budget: the plain ratchet (halving the request after a rejection) then decides.
        // Its first pass would be the locked one's over again (no lock is set before a
        // rejection), so it starts where that pass left off.
        let (plain, _) = ratchet(current, &reference, budget, options, Some(first));
        if plain.mesh.triangle_count() < result.mesh.triangle_count() {
            result = Simplified {
                attempts: result.attempts + plain.attempts,
                rejected: result.rejected + plain.rejected,
                ..plain
            };
        }
    }
    if !mesh.normals.is_empty() {
        result.mesh.compute_vertex_normals();
    }
    Ok(result)
}

/// The ratchet of the module docs from `current` (unused vertices dropped): with the locks of
/// components that lost their shape and around folds where `first` is `None`, and then also
/// the outcome of its first pass; without locks, starting after `first`, where given.
fn ratchet(
    current: TriangleMesh,
    reference: &Topology,
    budget: usize,
    options: &QuadricOptions,
    first: Option<FirstPass>,
) -> (Simplified, Option<FirstPass>) {
    let locking = first.is_none();
    let mut result = Simplified {
        topology: reference.clone(),
        mesh: current,
        error_bound: 0.0,
        attempts: 0,
        rejected: 0,
        stop: Stop::Topology,
    };
    let mut ask = budget;
    // Every step keeps the vertex buffer (meshoptimizer only drops vertices), so that the locks
    // stay valid; unused vertices are dropped at the end.
    let mut locked = vec![false; result.mesh.positions.len()];
    // Whether the last rejection was a fold (module `folds`) rather than a topology change.
    let mut folded = false;
    let mut folds = folds::Folds::default();
    let mut seen = None;
    // Where the locked run's first pass was rejected, this run stops at its first rejection
    // (module docs).
    let after_rejection = matches!(first, Some(FirstPass::Rejected(_)));
    match first {
        Some(FirstPass::Accepted(mesh, topology, error)) => {
            result.attempts = 1;
            (result.mesh, result.topology, result.error_bound) = (mesh, topology, error);
        }
        Some(FirstPass::Rejected(fold)) => {
            (result.attempts, result.rejected, folded) = (1, 1, fold);
            let Some(next) = halved(ask, result.mesh.triangle_count()) else {
                return (finished(result, folded, budget), None);
            };
            ask = next;
        }
        None => {}
    }
    while result.mesh.triangle_count() > budget && result.attempts < options.max_attempts {
        let room = (options.max_error - result.error_bound).max(0.0);
        result.attempts += 1;
        let (candidate, error) = collapse(&result.mesh, ask, room, options.lock_border, &locked);
        if candidate.triangle_count() >= result.mesh.triangle_count() {
            result.stop = Stop::DistanceLimit;
            break;
        }
        let topology = mesh_topology(&candidate);
        let verdict = judged(
            &result.mesh,
            &candidate,
            &topology,
            reference,
            options,
            &mut folds,
        );
        if locking && result.attempts == 1 {
            seen = Some(FirstPass::of(&verdict, &candidate, &topology, error));
        }
        if let Verdict::Accepted = verdict {
            result.mesh = candidate;
            result.topology = topology;
            result.error_bound += error;
            ask = budget;
            folded = false;
            continue;
        }
        result.rejected += 1;
        folded = matches!(verdict, Verdict::Crossing(_));
        // Asked for the budget, the pass stopped above it: what held it back holds on, and
        // more locks only hold more (module docs).
        if locking && ask == budget && candidate.triangle_count() > budget {
            break;
        }
        let locks = locking
            && match &verdict {
                Verdict::Crossing(triangles) => {
                    folds::lock_around(&result.mesh, &candidate, triangles, &mut locked)
                }
                _ => lock_changed_components(&result.mesh, &candidate, &mut locked),
            };
        if locks {
            continue;
        }
        if after_rejection {
            break;
        }
        match halved(ask, result.mesh.triangle_count()) {
            Some(next) => ask = next,
            None => break,
        }
    }
    (finished(result, folded, budget), seen)
}

/// What the ratchet makes of the pass from `before` to `after` (whose topology is `topology`),
/// against the input's `reference` topology and the crossings `folds` has counted.
fn judged(
    before: &TriangleMesh,
    after: &TriangleMesh,
    topology: &Topology,
    reference: &Topology,
    options: &QuadricOptions,
    folds: &mut folds::Folds,
) -> Verdict {
    let kept = match options.holes_may_close {
        true => keeps_topology_or_closes_holes(reference, topology),
        false => keeps_topology(reference, topology),
    };
    match kept {
        false => Verdict::Topology,
        true => match folds.check(before, after) {
            Ok(()) => Verdict::Accepted,
            Err(crossing) => Verdict::Crossing(crossing),
        },
    }
}

/// A ratchet's `result` with its reason to stop settled (`folded`: the last rejection was a
/// fold) and its unused vertices dropped.
fn finished(mut result: Simplified, folded: bool, budget: usize) -> Simplified {
    if folded && result.stop == Stop::Topology {
        result.stop = Stop::Crossings;
    }
    if result.mesh.triangle_count() <= budget {
        result.stop = Stop::Budget;
    }
    result.mesh.remove_unreferenced_vertices();
    result
}

/// The request after a rejected one (`ask`, from a mesh of `have` triangles): halfway back to
/// `have`; `None` where that is no collapse at all.
fn halved(ask: usize, have: usize) -> Option<usize> {
    let next = ask + (have - ask) / 2;
    (next + 1 < have).then_some(next)
}

/// How a ratchet's first pass ended, which the ratchet without locks would repeat: accepted (the
/// mesh, its topology and meshoptimizer's error estimate), or rejected (for a fold, or for the
/// topology).
enum FirstPass {
    Accepted(TriangleMesh, Topology, f64),
    Rejected(bool),
}

impl FirstPass {
    /// The first pass that made `mesh` (of `topology`, meshoptimizer's estimate `error`),
    /// judged `verdict`.
    fn of(verdict: &Verdict, mesh: &TriangleMesh, topology: &Topology, error: f64) -> FirstPass {
        match verdict {
            Verdict::Accepted => FirstPass::Accepted(mesh.clone(), topology.clone(), error),
            _ => FirstPass::Rejected(matches!(verdict, Verdict::Crossing(_))),
        }
    }
}

/// What the ratchet makes of a meshoptimizer pass.
enum Verdict {
    /// The topology kept and no crossing pair added: the pass is the new accepted mesh.
    Accepted,
    /// The topology broken (module docs).
    Topology,
    /// Crossing pairs added; the triangles of the result blamed for them (module `folds`).
    Crossing(Vec<u32>),
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
    clean_with_its_parts(before, after)
        && after.boundary_loops == before.boundary_loops
        && after.genus == before.genus
        && after.euler_characteristic == before.euler_characteristic
}

/// [`keeps_topology`], but for the boundary loops, of which `after` may have fewer, and the
/// Euler characteristic that follows from them: the same components, no non-manifold or
/// degenerate element, no more handles. (Per component, χ = 2 − 2g − b: a hole closed raises χ
/// by one at the same genus.)
pub fn keeps_topology_or_closes_holes(before: &Topology, after: &Topology) -> bool {
    let handles = |t: &Topology| t.genus.unwrap_or(i64::MAX);
    clean_with_its_parts(before, after)
        && after.boundary_loops <= before.boundary_loops
        && after.genus.is_some()
        && handles(after) <= handles(before)
}

/// Whether `after` has no non-manifold edge or vertex, no degenerate or duplicate triangle, no
/// inconsistently oriented edge where `before` had none, and `before`'s components.
fn clean_with_its_parts(before: &Topology, after: &Topology) -> bool {
    after.non_manifold_edges == 0
        && after.non_manifold_vertices == 0
        && after.degenerate_triangles == 0
        && after.duplicate_triangles == 0
        && (before.inconsistent_edges > 0 || after.inconsistent_edges == 0)
        && after.components == before.components
}

/// Locks the vertices of `before`'s components that lost their shape in `after` (both over
/// the same vertices; module docs); whether any was newly locked.
fn lock_changed_components(
    before: &TriangleMesh,
    after: &TriangleMesh,
    locked: &mut [bool],
) -> bool {
    let mut parent: Vec<u32> = (0..before.positions.len() as u32).collect();
    for &[a, b, c] in &before.triangles {
        for (u, w) in [(a, b), (b, c)] {
            let (ru, rw) = (root(&mut parent, u), root(&mut parent, w));
            parent[ru as usize] = rw;
        }
    }
    let shape_before = component_shapes(before, &mut parent);
    let shape_after = component_shapes(after, &mut parent);
    // A small component is locked whole; in a large one only the corners of the non-manifold
    // edges and duplicate triangles that the pass made are.
    let small = before.triangles.len() / 8;
    let lost = |r: u32| {
        let (b, a) = (shape_before[r as usize], shape_after[r as usize]);
        match (b.1 > 0, a.1 > 0) {
            (true, true) => b.1 <= small && (a.0 != b.0 || (a.1 < 4 && a.1 < b.1)),
            (true, false) => true,
            _ => false,
        }
    };
    let mut any = false;
    for &v in before.triangles.as_flattened() {
        let r = root(&mut parent, v);
        if !locked[v as usize] && lost(r) {
            locked[v as usize] = true;
            any = true;
        }
    }
    let mut pinched = vec![false; before.positions.len()];
    for v in pinched_corners(after) {
        pinched[v as usize] = true;
    }
    // The pinch's corners survived the pass; the vertex that collapsed onto them is among
    // their neighbours in `before`, so their whole ring is locked.
    for &[a, b, c] in &before.triangles {
        if [a, b, c].iter().any(|&v| pinched[v as usize]) {
            for v in [a, b, c] {
                any |= !locked[v as usize];
                locked[v as usize] = true;
            }
        }
    }
    any
}

/// The corners of `mesh`'s triangles that have an edge shared by more than two triangles or
/// that repeat another triangle's vertices.
fn pinched_corners(mesh: &TriangleMesh) -> Vec<u32> {
    let mut uses: HashMap<(u32, u32), Vec<usize>> = HashMap::default();
    let mut seen: HashMap<[u32; 3], usize> = HashMap::default();
    let mut corners = Vec::new();
    for (t, &[a, b, c]) in mesh.triangles.iter().enumerate() {
        for (u, w) in [(a, b), (b, c), (c, a)] {
            uses.entry((u.min(w), u.max(w))).or_default().push(t);
        }
        let mut key = [a, b, c];
        key.sort_unstable();
        if let Some(&other) = seen.get(&key) {
            corners.extend(mesh.triangles[other]);
            corners.extend([a, b, c]);
        } else {
            seen.insert(key, t);
        }
    }
    for triangles in uses.values().filter(|t| t.len() > 2) {
        corners.extend(triangles.iter().flat_map(|&t| mesh.triangles[t]));
    }
    corners
}

/// The root of `v` in the union-find forest `parent`, halving the path.
fn root(parent: &mut [u32], mut v: u32) -> u32 {
    while parent[v as usize] != v {
        parent[v as usize] = parent[parent[v as usize] as usize];
        v = parent[v as usize];
    }
    v
}

/// Per component (by its root in `parent`, indexed by vertex): Euler characteristic V − E + F
/// and triangle count of `mesh`'s triangles in it; `(0, 0)` where no triangle has that root.
/// Cost: a sort of the edges.
fn component_shapes(mesh: &TriangleMesh, parent: &mut [u32]) -> Vec<(i64, usize)> {
    let mut shapes = vec![(0i64, 0usize); parent.len()];
    let mut counted = vec![false; parent.len()];
    let mut edges = Vec::with_capacity(3 * mesh.triangles.len());
    for &[a, b, c] in &mesh.triangles {
        let shape = &mut shapes[root(parent, a) as usize];
        shape.0 += 1;
        shape.1 += 1;
        for v in [a, b, c] {
            if !std::mem::replace(&mut counted[v as usize], true) {
                shape.0 += 1;
            }
        }
        edges.extend(
            [(a, b), (b, c), (c, a)].map(|(u, w)| ((u.min(w) as u64) << 32) | u.max(w) as u64),
        );
    }
    edges.sort_unstable();
    edges.dedup();
    for edge in edges {
        shapes[root(parent, (edge >> 32) as u32) as usize].0 -= 1;
    }
    shapes
}

/// One meshoptimizer pass towards `target` triangles within `max_error` (mesh units), with
/// the `locked` vertices kept: the result over the same vertices and meshoptimizer's error
/// estimate in mesh units. A `target` at or above the mesh's triangle count returns the mesh
/// as it is with error 0, without calling meshoptimizer (which aborts the process when asked
/// for more indices than it is given).
fn collapse(
    mesh: &TriangleMesh,
    target: usize,
    max_error: f64,
    lock_border: bool,
    locked: &[bool],
) -> (TriangleMesh, f64) {
    if target >= mesh.triangle_count() {
        return (mesh.clone(), 0.0);
    }
    let positions = positions_of(mesh);
    let vertices = adapter(&positions);
    let mut flags = SimplifyOptions::ErrorAbsolute;
    if lock_border {
        flags |= SimplifyOptions::LockBorder;
    }
    let mut error = 0.0f32;
    let (indices, limit) = (mesh.triangles.as_flattened(), error_limit(max_error));
    let indices = if locked.iter().any(|&l| l) {
        meshopt::simplify_with_locks(
            indices,
            &vertices,
            locked,
            target * 3,
            limit,
            flags,
            Some(&mut error),
        )
    } else {
        meshopt::simplify(
            indices,
            &vertices,
            target * 3,
            limit,
            flags,
            Some(&mut error),
        )
    };
    (triangles_of(mesh, &indices), error as f64)
}

/// The triangles of a meshoptimizer index list over `mesh`'s vertices.
fn triangles_of(mesh: &TriangleMesh, indices: &[u32]) -> TriangleMesh {
    let triangles = indices
        .chunks_exact(3)
        .map(|t| [t[0], t[1], t[2]])
        .collect();
    TriangleMesh::new(mesh.positions.clone(), triangles)
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
    let mut out = triangles_of(mesh, indices);
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
/// `evaluate`, not a stage of the pipeline. The result's unused vertices are dropped. A budget
/// at or above the mesh's triangle count returns its triangles unchanged (meshoptimizer is not
/// called: it aborts the process when asked for more indices than it is given).
pub fn simplify_sloppy(mesh: &TriangleMesh, budget: usize) -> Result<TriangleMesh, QuadricError> {
    check_basic(mesh, budget)?;
    if budget >= mesh.triangle_count() {
        return Ok(compact(mesh, mesh.triangles.as_flattened()));
    }
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
/// estimate in mesh units; a budget at or above the mesh's triangle count returns its triangles
/// unchanged with error 0.
pub fn simplify_unchecked(
    mesh: &TriangleMesh,
    budget: usize,
    lock_border: bool,
) -> Result<(TriangleMesh, f64), QuadricError> {
    check_basic(mesh, budget)?;
    let (mut out, error) = collapse(mesh, budget, f64::INFINITY, lock_border, &[]);
    out.remove_unreferenced_vertices();
    Ok((out, error))
}

#[cfg(test)]
mod tests {
    use super::*;
    use voxlod_core::glam::Vec3;
    use voxlod_testkit::shapes::{icosphere, torus};

    /// A sphere (χ = 2), a torus (χ = 0) and a lone triangle (χ = 1) in one mesh: each
    /// component's Euler characteristic and triangle count under its root.
    #[test]
    fn component_shapes_counts_each_part_on_its_own() {
        let mut mesh = icosphere(1);
        let sphere_vertices = mesh.positions.len() as u32;
        let ring = torus(8, 6, 3.0, 0.5);
        let offset = mesh.positions.len() as u32;
        mesh.positions.extend(&ring.positions);
        (mesh.triangles).extend(ring.triangles.iter().map(|t| t.map(|v| v + offset)));
        let lone = mesh.positions.len() as u32;
        mesh.positions
            .extend([Vec3::ZERO, Vec3::X, Vec3::Y].map(|p| p + 9.0));
        mesh.triangles.push([lone, lone + 1, lone + 2]);
        let mut parent: Vec<u32> = (0..mesh.positions.len() as u32).collect();
        for &[a, b, c] in &mesh.triangles {
            for (u, w) in [(a, b), (b, c)] {
                let (ru, rw) = (root(&mut parent, u), root(&mut parent, w));
                parent[ru as usize] = rw;
            }
        }
        let shapes = component_shapes(&mesh, &mut parent);
        let at = |parent: &mut [u32], v: u32| shapes[root(parent, v) as usize];
        assert_eq!(at(&mut parent, 0), (2, 80));
        assert_eq!(at(&mut parent, sphere_vertices), (0, 96));
        assert_eq!(at(&mut parent, lone), (1, 1));
        assert_eq!(shapes.iter().filter(|s| s.1 > 0).count(), 3);
    }

    /// Budgets at, just above and far above the input's count: each returns every triangle.
    #[test]
    fn a_budget_above_the_input_returns_the_whole_mesh() {
        let sphere = icosphere(3);
        let ring = torus(24, 12, 1.0, 0.3);
        for (mesh, count) in [(&sphere, 1280), (&ring, 576)] {
            assert_eq!(mesh.triangle_count(), count);
            for budget in [count, count + 1, 10 * count] {
                let sloppy = simplify_sloppy(mesh, budget).unwrap();
                assert_eq!(sloppy.triangles, mesh.triangles, "sloppy {budget}");
                let (collapsed, error) = simplify_unchecked(mesh, budget, false).unwrap();
                assert_eq!(collapsed.triangles, mesh.triangles, "unchecked {budget}");
                assert_eq!(error, 0.0);
            }
        }
    }

    /// A rejected request is followed by one halfway back to the mesh's count, while that is
    /// still a collapse.
    #[test]
    fn halved_goes_halfway_back_while_that_collapses_anything() {
        assert_eq!(halved(300, 16_880), Some(8_590));
        assert_eq!(halved(8_590, 16_880), Some(12_735));
        assert_eq!(halved(10, 13), Some(11));
        assert_eq!(halved(10, 12), None);
        assert_eq!(halved(11, 12), None);
    }

    /// Below the input's count meshoptimizer still runs and reduces.
    #[test]
    fn a_budget_below_the_input_still_simplifies() {
        let mesh = icosphere(3);
        assert!(simplify_sloppy(&mesh, 1000).unwrap().triangle_count() <= 1000);
        let (collapsed, _) = simplify_unchecked(&mesh, 1000, false).unwrap();
        assert!(collapsed.triangle_count() <= 1000);
    }

    /// A sphere with small holes: 20 triangles taken out along its triangle list (neighbours
    /// in it share a hole).
    fn holed_sphere() -> TriangleMesh {
        let mut mesh = icosphere(4);
        let step = mesh.triangles.len() / 20;
        let holes: Vec<usize> = (0..20).map(|k| k * step).collect();
        let mut k = 0;
        mesh.triangles.retain(|_| {
            k += 1;
            !holes.contains(&(k - 1))
        });
        mesh
    }

    #[test]
    fn holes_may_close_only_where_asked_and_nothing_else_changes() {
        let mesh = holed_sphere();
        let before = mesh_topology(&mesh);
        let loops = before.boundary_loops;
        assert!(loops >= 10 && before.genus == Some(0), "{before:?}");
        let options = |holes_may_close| QuadricOptions {
            holes_may_close,
            ..QuadricOptions::budget(f64::INFINITY)
        };
        let kept = simplify_to_budget(&mesh, 200, &options(false)).unwrap();
        assert_eq!(kept.topology.boundary_loops, loops);
        let closed = simplify_to_budget(&mesh, 200, &options(true)).unwrap();
        let t = mesh_topology(&closed.mesh);
        assert!(t.boundary_loops < loops, "{t:?}");
        assert!(
            t.is_manifold() && t.components == 1 && t.genus == Some(0),
            "{t:?}"
        );
        assert!(closed.mesh.triangle_count() <= kept.mesh.triangle_count());
        assert!(keeps_topology_or_closes_holes(&before, &t));
        assert!(!keeps_topology(&before, &t));
        // More holes than before, or more handles, are refused either way.
        let opened = Topology {
            boundary_loops: loops + 1,
            ..before.clone()
        };
        let handled = Topology {
            genus: Some(1),
            ..before.clone()
        };
        assert!(!keeps_topology_or_closes_holes(&before, &opened));
        assert!(!keeps_topology_or_closes_holes(&before, &handled));
    }
}
