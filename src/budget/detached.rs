//! Detached parts restored (our addition to §5; issue 12, item 3): a part of the input lying
//! apart from everything a level kept, which the filter erased because it is small or thin,
//! comes back as its own quadric collapse to a few triangles, taken from the voxel level's share
//! of the budget.
//!
//! Why: one lost part far from the rest sets the two-sided Hausdorff distance by itself. The CT
//! head's bone surface (threshold 1500) has a wire of bright samples along the scan's edge,
//! 60 mm from the skull: every method drops it, and it alone holds the distance at 18 % of the
//! diagonal. Four triangles carry it back.
//!
//! Which parts: the input's connected components that are closed manifolds of genus 0 (so no
//! handle is added: the level keeps the genus of its voxel level), lying outside the (closed)
//! level with a box that meets no box of its triangles, and, collapsed, the same of the level
//! re-simplified with their triangles taken out (so they can neither cross nor nest in it).
//! Farthest from the level first, while they use at most a quarter of the budget. Each collapses to four triangles if its shape
//! allows ([`voxlod_quadric::simplify_to_budget`], topology kept). Every quadric candidate of
//! the search with parts apart gets such a twin, which competes like any other (step 4): kept
//! only where it measures closer (the measure gives every input part a point of its own, so a
//! tiny lost part counts).
//!
//! Cost: the input's components once per run (a union-find, O(F)); per quadric candidate, a box
//! test of every part against its triangles (O(P T); inputs of more than [`MAX_PARTS`] parts are
//! left as they are), and for the parts apart, their topology and collapse (small parts), one
//! more quadric stage and one more distance measurement.

use std::sync::{Arc, OnceLock};

use voxlod_core::components::{submesh, triangle_components};
use voxlod_core::parity::point_inside;
use voxlod_core::{mesh_topology, Bounds, TriangleMesh};
use voxlod_quadric::{simplify_dropping_parts, simplify_to_budget, PartsOptions, QuadricOptions};

use super::candidate::Candidate;
use super::context::BudgetContext;
use super::Stage;
use crate::lod::LodLevel;

/// The fewest triangles a closed genus-0 part collapses to: a tetrahedron.
const STAND_IN_TRIANGLES: usize = 4;
/// The share of the budget that restored parts may use at most.
const SHARE: f64 = 0.25;
/// Inputs with more parts than this get none restored: each candidate tests every part against
/// its triangles, and a budget affords a few dozen tetrahedra at most.
const MAX_PARTS: usize = 10_000;

/// One connected component of the input, and its box.
pub(crate) struct InputPart {
    mesh: TriangleMesh,
    bounds: Bounds,
}

/// The input's components (welded), split once per run; empty without a mesh input or with a
/// single component.
pub(crate) type InputParts = Arc<OnceLock<Vec<InputPart>>>;

impl BudgetContext<'_> {
    /// The input's parts (module docs), split on first use (shared with the context of the
    /// filled input, which has no welded input of its own).
    pub(super) fn input_parts(&self) -> &[InputPart] {
        self.parts.get_or_init(|| {
            let Some((mesh, topology)) = &self.welded else {
                return Vec::new();
            };
            if !(2..=MAX_PARTS).contains(&topology.components) {
                return Vec::new();
            }
            triangle_components(mesh)
                .iter()
                .map(|triangles| {
                    let part = submesh(mesh, triangles);
                    InputPart {
                        bounds: part.bounds(),
                        mesh: part,
                    }
                })
                .collect()
        })
    }
}

/// `chosen` (a quadric candidate from `level`) with the input's detached parts restored beside
/// it (module docs), the level re-simplified to make room; `None` where no part is apart.
pub(super) fn with_detached_parts(
    ctx: &BudgetContext,
    level: &LodLevel,
    chosen: &Candidate,
    budget: usize,
    error: Option<f64>,
) -> Option<Candidate> {
    if chosen.stage != Stage::Quadric || mesh_topology(&chosen.mesh).boundary_edges > 0 {
        return None;
    }
    let stand_ins = stand_ins(ctx.input_parts(), &Obstacle::new(&chosen.mesh), budget);
    if stand_ins.is_empty() {
        return None;
    }
    let reserved: usize = stand_ins.iter().map(TriangleMesh::triangle_count).sum();
    let options = PartsOptions {
        quadric: QuadricOptions::budget(error.unwrap_or(f64::INFINITY)),
        ..PartsOptions::default()
    };
    let done = simplify_dropping_parts(&level.mesh, budget - reserved, &options).ok()?;
    let mut mesh = done.simplified.mesh;
    let kept = Obstacle::new(&mesh);
    let clear: Vec<&TriangleMesh> = stand_ins.iter().filter(|s| kept.clear_of(s)).collect();
    clear.iter().for_each(|s| append(&mut mesh, s));
    Some(Candidate {
        distance: ctx.measure(&mesh),
        mesh,
        stage: Stage::Quadric,
        error_bound: done.simplified.error_bound,
        parts_dropped: done.dropped_parts,
        parts_restored: clear.len(),
        iso: chosen.iso,
    })
}

/// A closed level as an obstacle for the parts put beside it: its triangles' boxes, and the
/// level for the inside test.
struct Obstacle<'m> {
    level: &'m TriangleMesh,
    boxes: Vec<Bounds>,
}

impl<'m> Obstacle<'m> {
    fn new(level: &'m TriangleMesh) -> Self {
        let boxes = (0..level.triangle_count())
            .map(|t| {
                let mut b = Bounds::EMPTY;
                level.corners(t).into_iter().for_each(|p| b.grow(p));
                b
            })
            .collect();
        Obstacle { level, boxes }
    }

    /// Whether `part` cannot meet the level (its box meets no triangle's box) and lies outside
    /// it (its first vertex, by parity).
    fn clear_of(&self, part: &TriangleMesh) -> bool {
        let b = part.bounds();
        let point = part.positions[part.triangles[0][0] as usize].as_dvec3();
        !self.boxes.iter().any(|t| t.intersects(&b))
            && !point_inside(self.level, 0..self.level.triangle_count(), point)
    }

    /// The distance from `b`'s centre to the level's nearest vertex.
    fn distance(&self, b: &Bounds) -> f64 {
        let centre = b.center();
        (self.level.positions.iter())
            .map(|p| p.as_dvec3().distance(centre))
            .fold(f64::INFINITY, f64::min)
    }
}

/// The collapsed parts clear of the level, farthest first, within the budget's share.
fn stand_ins(parts: &[InputPart], level: &Obstacle, budget: usize) -> Vec<TriangleMesh> {
    let mut apart: Vec<(f64, &InputPart)> = parts
        .iter()
        .filter(|p| level.clear_of(&p.mesh))
        .map(|p| (level.distance(&p.bounds), p))
        .collect();
    apart.sort_by(|a, b| b.0.total_cmp(&a.0));
    let share = (SHARE * budget as f64) as usize;
    let mut out = Vec::new();
    let mut used = 0;
    for (_, part) in apart {
        if used + STAND_IN_TRIANGLES > share {
            break;
        }
        let topology = mesh_topology(&part.mesh);
        if !topology.is_closed_manifold() || topology.genus != Some(0) {
            continue;
        }
        let options = QuadricOptions::budget(f64::INFINITY);
        let Ok(done) = simplify_to_budget(&part.mesh, STAND_IN_TRIANGLES, &options) else {
            continue;
        };
        let count = done.mesh.triangle_count();
        if used + count <= share && level.clear_of(&done.mesh) {
            used += count;
            out.push(done.mesh);
        }
    }
    out
}

/// `part` appended to `mesh` (its own vertices).
fn append(mesh: &mut TriangleMesh, part: &TriangleMesh) {
    let base = mesh.positions.len() as u32;
    mesh.positions.extend_from_slice(&part.positions);
    mesh.triangles
        .extend(part.triangles.iter().map(|t| t.map(|v| v + base)));
    if !mesh.normals.is_empty() {
        mesh.compute_vertex_normals();
    }
}
