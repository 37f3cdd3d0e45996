//! One mesh reduced towards a triangle count by meshoptimizer's quadric edge collapse
//! (`meshopt_simplify`, Garland–Heckbert quadrics), kept only where its topology and volume
//! survive.
//!
//! meshoptimizer keeps the look of a mesh but not its topology: a collapse may pinch two sheets
//! together, flatten a small closed piece into a pair of triangles, or let it vanish. And with
//! locked vertices it reaches a count by any means: a dome whose rim is locked is flattened
//! onto its rim when asked for fewer triangles than the rim holds. Every result is therefore
//! measured and accepted only when, against the input, it has the same boundary (edges and
//! loops), components and Euler characteristic ([`mesh_topology`]), no more non-manifold edges
//! or vertices, inconsistent edges or duplicate triangles, no degenerate triangle, and a
//! signed volume within a given change (for a mesh with a locked border, the volume between
//! the two surfaces). A mesh of several components is reduced whole first; when that fails,
//! each component on its own with its share of the count and of the volume change. After a
//! failure a component is asked again: where the reduction folded it (an edge of more than two triangles, or used twice the
//! same way round) with the triangles around the fold locked, as `voxlod-quadric` does; after
//! another broken topology for twice the triangles; after too large a change of volume for as
//! many times more as the change was over (the distance to a reduction falls about as its
//! triangles grow). A component that fails [`ATTEMPTS`] times is kept as it was.
//!
//! Cost: one meshoptimizer pass, O(F log F), and one topology measure, O(F log F); after a
//! failure at most [`ATTEMPTS`] of each per component. Memory O(V + F).

use meshopt::{SimplifyOptions, VertexDataAdapter};
use voxlod_core::components::triangle_components;
use voxlod_core::glam::Vec3;
use voxlod_core::{mesh_topology, Topology, TriangleMesh};

/// meshoptimizer passes per component (after a first pass over a mesh of several).
const ATTEMPTS: usize = 6;

/// What a reduction aims at and must keep.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Aim {
    /// Triangles asked for.
    pub target: usize,
    /// The largest change of signed volume accepted, in world units cubed.
    pub volume: f64,
    /// Keep the mesh's border vertices (meshoptimizer's `LockBorder`).
    pub lock_border: bool,
}

impl Aim {
    /// This aim's share for a part of `part` of the mesh's `whole` triangles.
    fn share(self, part: usize, whole: usize) -> Aim {
        Aim {
            target: (part as u128 * self.target as u128 / whole as u128) as usize,
            volume: self.volume * part as f64 / whole as f64,
            ..self
        }
    }
}

/// What [`reduce`] made.
pub(crate) struct Reduced {
    /// The triangles, over the input's vertices (some of them no longer used).
    pub triangles: Vec<[u32; 3]>,
    /// Components kept as they were because every reduction broke their topology or volume.
    pub kept_parts: usize,
}

/// `mesh`'s triangles reduced towards `aim` with the `locked` vertices (indexed like
/// `mesh.positions`, or empty) kept where they are: the module's contract. Never asks for
/// fewer triangles than the mesh has locked vertices (a triangulation of a locked rim needs
/// about as many; asked for fewer, meshoptimizer flattens the mesh onto it). At or above the
/// mesh's count, its triangles as they are.
pub(crate) fn reduce(mesh: &TriangleMesh, locked: &[bool], aim: Aim) -> Reduced {
    let n = mesh.triangles.len();
    let aim = Aim {
        target: aim.target.max(locked.iter().filter(|&&l| l).count()),
        ..aim
    };
    if aim.target >= n {
        return Reduced {
            triangles: mesh.triangles.clone(),
            kept_parts: 0,
        };
    }
    let parts = triangle_components(mesh);
    if parts.len() > 1 {
        let whole = collapse(mesh, locked, aim);
        if verdict(mesh, &Measured::of(mesh), &whole, aim.volume) == Verdict::Sound {
            return Reduced {
                triangles: whole,
                kept_parts: 0,
            };
        }
    } else {
        let (triangles, kept) = reduce_part(mesh, locked, aim);
        return Reduced {
            triangles,
            kept_parts: kept as usize,
        };
    }
    let mut out = Reduced {
        triangles: Vec::with_capacity(aim.target),
        kept_parts: 0,
    };
    for part in parts {
        let (sub, sources) = compact(mesh, &part);
        let sub_locked: Vec<bool> = if locked.is_empty() {
            Vec::new()
        } else {
            sources.iter().map(|&v| locked[v as usize]).collect()
        };
        let (triangles, kept) = reduce_part(&sub, &sub_locked, aim.share(part.len(), n));
        out.kept_parts += kept as usize;
        let to_mesh = |t: [u32; 3]| t.map(|v| sources[v as usize]);
        out.triangles.extend(triangles.into_iter().map(to_mesh));
    }
    out
}

/// One component reduced towards `aim`, locking where a reduction folded it and asking for
/// more triangles after other failures (module docs); whether it was kept as it was after
/// [`ATTEMPTS`] failures.
fn reduce_part(part: &TriangleMesh, locked: &[bool], aim: Aim) -> (Vec<[u32; 3]>, bool) {
    let n = part.triangles.len();
    let before = Measured::of(part);
    let mut locks = locked.to_vec();
    let mut ask = aim;
    for _ in 0..ATTEMPTS {
        if ask.target >= n {
            return (part.triangles.clone(), false);
        }
        let triangles = collapse(part, &locks, ask);
        // A surface's distance to its reduction, and so the volume between them, falls about
        // as the triangles grow: ask for as many more as the volume was over, and a little.
        let more = match verdict(part, &before, &triangles, aim.volume) {
            Verdict::Sound => return (triangles, false),
            Verdict::Volume(over) => (1.2 * over).clamp(1.25, 4.0),
            Verdict::Topology if lock_folds(part, &triangles, &mut locks) => 1.0,
            Verdict::Topology => 2.0,
        };
        ask.target = (ask.target as f64 * more) as usize;
    }
    (part.triangles.clone(), true)
}

/// Locks, in `locks` (made as long as the mesh's vertices), every vertex of `mesh`'s
/// triangles around the folds of `after`: edges used by more than two triangles or twice the
/// same way round. Whether it found any.
fn lock_folds(mesh: &TriangleMesh, after: &[[u32; 3]], locks: &mut Vec<bool>) -> bool {
    let mut directed: Vec<(u32, u32)> = after
        .iter()
        .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
        .collect();
    directed.sort_unstable();
    let mut folds: Vec<u32> = directed
        .chunk_by(|a, b| a == b)
        .filter(|same| same.len() > 1)
        .flat_map(|same| [same[0].0, same[0].1])
        .collect();
    let mut undirected: Vec<(u32, u32)> = directed
        .iter()
        .map(|&(a, b)| (a.min(b), a.max(b)))
        .collect();
    undirected.sort_unstable();
    folds.extend(
        undirected
            .chunk_by(|a, b| a == b)
            .filter(|same| same.len() > 2)
            .flat_map(|same| [same[0].0, same[0].1]),
    );
    folds.sort_unstable();
    locks.resize(mesh.positions.len(), false);
    let mut found = false;
    for t in &mesh.triangles {
        if t.iter().any(|v| folds.binary_search(v).is_ok()) {
            for &v in t {
                found |= !locks[v as usize];
                locks[v as usize] = true;
            }
        }
    }
    found
}

/// What a reduction of a mesh must keep: its topology and signed volume.
struct Measured {
    topology: Topology,
    volume: f64,
}

impl Measured {
    fn of(mesh: &TriangleMesh) -> Measured {
        Measured {
            topology: mesh_topology(mesh),
            volume: signed_volume(&mesh.positions, &mesh.triangles),
        }
    }
}

/// Whether a reduction keeps what the mesh had.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Verdict {
    Sound,
    /// The volume changed by this many times what it may.
    Volume(f64),
    Topology,
}

/// Whether `after` (over `mesh`'s vertices) keeps what `mesh` had, `before`, its volume
/// changed by at most `volume` (the module's contract).
fn verdict(mesh: &TriangleMesh, before: &Measured, after: &[[u32; 3]], volume: f64) -> Verdict {
    let change = (signed_volume(&mesh.positions, after) - before.volume).abs();
    if !same_topology(&before.topology, &topology_of(mesh, after)) {
        Verdict::Topology
    } else if change > volume {
        Verdict::Volume(change / volume)
    } else {
        Verdict::Sound
    }
}

/// The signed volume of `triangles` seen from the first vertex, in world units cubed (for a
/// closed mesh its volume; the difference of two surfaces with the same border is the volume
/// between them).
fn signed_volume(positions: &[Vec3], triangles: &[[u32; 3]]) -> f64 {
    let origin = positions
        .first()
        .map_or(Default::default(), |p| p.as_dvec3());
    triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| positions[v as usize].as_dvec3() - origin);
            a.dot(b.cross(c))
        })
        .sum::<f64>()
        / 6.0
}

/// Whether `after` keeps the topology `before` had (the module's contract).
fn same_topology(before: &Topology, after: &Topology) -> bool {
    after.degenerate_triangles == 0
        && after.boundary_edges == before.boundary_edges
        && after.boundary_loops == before.boundary_loops
        && after.components == before.components
        && after.euler_characteristic == before.euler_characteristic
        && after.non_manifold_edges <= before.non_manifold_edges
        && after.non_manifold_vertices <= before.non_manifold_vertices
        && after.inconsistent_edges <= before.inconsistent_edges
        && after.duplicate_triangles <= before.duplicate_triangles
}

/// The topology of `triangles` over `mesh`'s vertices.
fn topology_of(mesh: &TriangleMesh, triangles: &[[u32; 3]]) -> Topology {
    // The topology reads only the vertex count: the positions are not copied.
    let vertices = vec![Vec3::ZERO; mesh.positions.len()];
    mesh_topology(&TriangleMesh::new(vertices, triangles.to_vec()))
}

/// The mesh of `triangles` of `mesh` over the vertices they use (in order of first use), and
/// each vertex's index in `mesh`.
fn compact(mesh: &TriangleMesh, triangles: &[u32]) -> (TriangleMesh, Vec<u32>) {
    compact_triangles(
        &mesh.positions,
        triangles.iter().map(|&t| mesh.triangles[t as usize]),
    )
}

/// The mesh of `triangles` (indices into `positions`) over the vertices they use (in order of
/// first use), and each vertex's index in `positions`.
pub(crate) fn compact_triangles(
    positions: &[Vec3],
    triangles: impl ExactSizeIterator<Item = [u32; 3]>,
) -> (TriangleMesh, Vec<u32>) {
    let mut local = rustc_hash::FxHashMap::default();
    let mut sources = Vec::new();
    let mut out = Vec::with_capacity(triangles.len());
    for tri in triangles {
        out.push(tri.map(|v| {
            *local.entry(v).or_insert_with(|| {
                sources.push(v);
                sources.len() as u32 - 1
            })
        }));
    }
    let positions = sources.iter().map(|&v| positions[v as usize]).collect();
    (TriangleMesh::new(positions, out), sources)
}

/// One meshoptimizer pass towards `aim.target` triangles without an error limit; the
/// triangles over the same vertices. The target must be below the mesh's count
/// (meshoptimizer aborts the process when asked for more indices than it is given).
fn collapse(mesh: &TriangleMesh, locked: &[bool], aim: Aim) -> Vec<[u32; 3]> {
    let bytes = meshopt::typed_to_bytes(&mesh.positions);
    let vertices = VertexDataAdapter::new(bytes, std::mem::size_of::<Vec3>(), 0)
        .expect("packed 12-byte positions: the stride divides the buffer");
    let (target, flags) = (
        aim.target,
        if aim.lock_border {
            SimplifyOptions::LockBorder
        } else {
            SimplifyOptions::None
        },
    );
    let indices = mesh.triangles.as_flattened();
    let out = if locked.iter().any(|&l| l) {
        meshopt::simplify_with_locks(
            indices,
            &vertices,
            locked,
            target * 3,
            f32::MAX,
            flags,
            None,
        )
    } else {
        meshopt::simplify(indices, &vertices, target * 3, f32::MAX, flags, None)
    };
    out.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect()
}
