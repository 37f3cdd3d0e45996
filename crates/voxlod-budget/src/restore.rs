//! Lost parts restored (our addition to §5): a part of the input lying apart from everything a
//! candidate kept (a small closed part that the filter erased, or that a collapse flattened
//! away) comes back beside it as its own collapse to a few triangles, taken from the
//! candidate's share of the budget. One lost part far from the rest sets the two-sided
//! Hausdorff distance by itself (a CT surface's stray bright voxels, a bolt beside a plate);
//! four triangles carry it back.
//!
//! Which parts: the input's connected parts that are closed manifolds and whose point lies
//! farther from the candidate than the candidate's own shape distance (module `measure`: such
//! a part sets the Hausdorff distance), farthest first, while they use at most [`SHARE`] of the budget. Each comes back
//! as a tetrahedron on four of its own vertices spread as far apart as a greedy choice finds
//! (the farthest from its centre, the farthest from that, the farthest from their line, the
//! farthest from their plane): genus 0, so no handle is added. The candidate is collapsed
//! again to make room; the twin competes like any other candidate (crossings and all promises
//! are checked there).
//!
//! Cost: one closest-point structure of the candidate and one query per part; each part's
//! tetrahedron is made once per run, O(V) in its vertices.

use std::sync::OnceLock;

use voxlod_core::components::submesh;
use voxlod_core::glam::DVec3;
use voxlod_core::Bounds;
use voxlod_core::{mesh_topology, TriangleMesh};
use voxlod_metrics::MeshDistance;

use crate::candidate::Candidate;
use crate::input::Input;
use crate::voxel::collapsed;

/// A candidate has lost parts worth restoring where its Hausdorff distance is more than this
/// many times its shape distance.
pub const LOST: f64 = 2.0;
/// The share of the budget restored parts may use at most.
pub const SHARE: f64 = 0.25;
/// The share of the budget the stand-ins of [`stood_in`] may use at most.
pub const STOOD_SHARE: f64 = 0.5;
/// Inputs with more parts than this get none restored.
pub const MAX_PARTS: usize = 10_000;

/// The input's parts as restorable stand-ins, made on first use: each closed part's point and
/// its tetrahedron (`None` for a part that cannot be restored), and the parts ranked by the
/// diagonal of their boxes, largest first.
#[derive(Default)]
pub struct StandIns(OnceLock<Parts>);

/// What [`StandIns`] holds once made.
#[derive(Default)]
struct Parts {
    stand_ins: Vec<Option<StandIn>>,
    by_size: Vec<usize>,
}

/// One part's stand-in.
pub struct StandIn {
    point: DVec3,
    mesh: TriangleMesh,
}

impl StandIns {
    fn get(&self, input: &Input) -> &Parts {
        self.0.get_or_init(|| {
            if input.parts.len() < 2 || input.parts.len() > MAX_PARTS {
                return Parts::default();
            }
            let diagonal = |triangles: &[u32]| {
                let corners = triangles
                    .iter()
                    .flat_map(|&t| input.mesh.triangles[t as usize]);
                let points = corners.map(|v| &input.mesh.positions[v as usize]);
                Bounds::from_points(points).diagonal()
            };
            let sizes: Vec<f64> = input.parts.iter().map(|p| diagonal(p)).collect();
            let mut by_size: Vec<usize> = (0..sizes.len()).collect();
            by_size.sort_by(|&a, &b| sizes[b].total_cmp(&sizes[a]));
            Parts {
                stand_ins: input.parts.iter().map(|p| stand_in(input, p)).collect(),
                by_size,
            }
        })
    }
}

/// The stand-in of the part made of `triangles`, if it is closed and has four vertices that
/// span a volume.
fn stand_in(input: &Input, triangles: &[u32]) -> Option<StandIn> {
    let part = submesh(&input.mesh, triangles);
    if !mesh_topology(&part).is_closed_manifold() {
        return None;
    }
    let p: Vec<DVec3> = part.positions.iter().map(|v| v.as_dvec3()).collect();
    let centre = p.iter().sum::<DVec3>() / p.len() as f64;
    let farthest = |score: &dyn Fn(DVec3) -> f64| {
        p.iter()
            .copied()
            .max_by(|a, b| score(*a).total_cmp(&score(*b)))
    };
    let a = farthest(&|x| x.distance_squared(centre))?;
    let b = farthest(&|x| x.distance_squared(a))?;
    let line = (b - a).normalize_or_zero();
    let c = farthest(&|x| (x - a).reject_from_normalized(line).length_squared())?;
    let normal = (b - a).cross(c - a).normalize_or_zero();
    let d = farthest(&|x| (x - a).dot(normal).abs())?;
    let volume = (b - a).cross(c - a).dot(d - a) / 6.0;
    if volume.abs() <= f64::EPSILON * p.len() as f64 {
        return None;
    }
    let mut mesh = TriangleMesh::new(
        [a, b, c, d].map(|v| v.as_vec3()).to_vec(),
        vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    );
    if mesh.signed_volume() < 0.0 {
        mesh.flip_orientation();
    }
    Some(StandIn { point: a, mesh })
}

/// `candidate` with the input's lost parts beside it (module docs), or `None` where it lost
/// none that can come back.
pub fn with_parts_restored(
    candidate: &Candidate,
    input: &Input,
    stand_ins: &StandIns,
    budget: usize,
) -> Option<Candidate> {
    let shape = candidate.quick?.shape;
    let parts = &stand_ins.get(input).stand_ins;
    if parts.is_empty() {
        return None;
    }
    let closest = MeshDistance::new(&candidate.mesh).ok()?;
    let mut lost: Vec<(f64, &StandIn)> = parts
        .iter()
        .flatten()
        .map(|s| (closest.distance(s.point), s))
        .filter(|(d, _)| *d > shape)
        .collect();
    lost.sort_by(|a, b| b.0.total_cmp(&a.0));
    let share = (SHARE * budget as f64) as usize;
    let mut restored = Vec::new();
    let mut used = 0;
    for (_, s) in lost {
        if used + s.mesh.triangle_count() > share {
            break;
        }
        used += s.mesh.triangle_count();
        restored.push(&s.mesh);
    }
    if restored.is_empty() {
        return None;
    }
    let room = budget.saturating_sub(used).max(4);
    let cell = input.cell();
    let rest = if candidate.triangles() > room {
        collapsed(candidate.method, candidate.mesh.clone(), room, cell, None)
            .into_iter()
            .next()?
            .mesh
    } else {
        candidate.mesh.clone()
    };
    let mut mesh = rest;
    for part in &restored {
        let base = mesh.positions.len() as u32;
        mesh.positions.extend(&part.positions);
        mesh.triangles
            .extend(part.triangles.iter().map(|t| t.map(|v| v + base)));
    }
    mesh.normals.clear();
    let mut twin = Candidate::new(candidate.method, mesh);
    twin.resolution = candidate.resolution;
    twin.iso = candidate.iso;
    (twin.staged, twin.fitted) = (candidate.staged, candidate.fitted);
    twin.fill = candidate.fill;
    twin.parts_dropped = candidate.parts_dropped;
    twin.parts_restored = restored.len();
    Some(twin)
}

/// The input's collapse with its smaller parts stood in for (our addition): every part but the
/// `keep` largest (by box diagonal) that has a tetrahedron comes back as that tetrahedron, and
/// the kept parts are collapsed together to the rest of the budget. Where a budget cannot
/// carry every part of a many-part input as a closed surface (a ring of tori around a body, a
/// machine of small screws), this keeps each part's place and size at four triangles where a
/// voxel level would merge them and a collapse would stall. `None` where fewer than two parts
/// have stand-ins or they would take more than [`STOOD_SHARE`] of the budget.
pub fn stood_in(
    input: &Input,
    stand_ins: &StandIns,
    budget: usize,
    keep: usize,
) -> Option<Candidate> {
    let Parts {
        stand_ins: parts,
        by_size,
    } = stand_ins.get(input);
    if parts.len() < 2 {
        return None;
    }
    // Ranked by size, largest first: the first `keep` (and any without a stand-in) are kept.
    let is_kept = |rank: usize, i: usize| rank < keep || parts[i].is_none();
    let ranked = || by_size.iter().copied().enumerate();
    let kept: Vec<usize> = ranked()
        .filter(|&(r, i)| is_kept(r, i))
        .map(|(_, i)| i)
        .collect();
    let small: Vec<&StandIn> = ranked()
        .filter(|&(r, i)| !is_kept(r, i))
        .filter_map(|(_, i)| parts[i].as_ref())
        .collect();
    let used: usize = small.iter().map(|s| s.mesh.triangle_count()).sum();
    if small.len() < 2 || used as f64 > STOOD_SHARE * budget as f64 {
        return None;
    }
    let kept_triangles: Vec<u32> = kept
        .iter()
        .flat_map(|&i| input.parts[i].iter().copied())
        .collect();
    let big = submesh(&input.mesh, &kept_triangles);
    let room = budget.saturating_sub(used).max(4);
    let (mut mesh, _) = voxlod_quadric::simplify_unchecked(&big, room, false).ok()?;
    mesh.remove_unreferenced_vertices();
    for s in &small {
        let base = mesh.positions.len() as u32;
        mesh.positions.extend(&s.mesh.positions);
        mesh.triangles
            .extend(s.mesh.triangles.iter().map(|t| t.map(|v| v + base)));
    }
    mesh.normals.clear();
    let mut candidate = Candidate::new(crate::candidate::Method::Collapse, mesh);
    candidate.parts_restored = small.len();
    Some(candidate)
}
