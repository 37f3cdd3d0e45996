//! Detached parts restored (our addition to §5): a part of the input lying
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
//! re-simplified with their triangles taken out (so they can neither cross nor nest in it);
//! farthest first, while they use at most a quarter of the budget, each collapsed to four
//! triangles if its shape allows ([`voxlod_quadric::simplify_to_budget`], topology kept).
//! Where the re-simplified level stalls above the budget less the parts' triangles (its
//! handles and necks may not collapse), only the farthest parts that keep the whole within
//! 10 % of the budget come back: on the CT bone surface at 1 000 triangles, the level at
//! resolution 24 stalls at 1 044 when asked for 812, and its twin with all 47 parts (1 232)
//! lost to one with the two farthest alone, which left the wire's long piece 49 mm away.
//! Every quadric candidate of the search with parts apart gets two or three twins: one
//! restores only the parts farther from the level than the level's own shape is from the input
//! (the Hausdorff distance of the area samples: nearer parts would not move the distance, and
//! their triangles may serve the level better); where a part left out still sets that twin's
//! distance (the lost parts' own area samples inflate the level's shape), one the parts
//! farther than the twin's shape; one every part that fits. They compete like any
//! other candidate (step 4), kept only where they measure closer (the measure gives every input
//! part a point of its own, so a tiny lost part counts).
//!
//! Cost: the input's components once per run (a union-find, O(F)); per quadric candidate, a box
//! test of every part against its triangles (O(P T); inputs of more than [`MAX_PARTS`] parts are
//! left as they are), and for the parts apart, up to three more quadric stages and distance
//! measurements; each part's topology and collapse once per run, when it is first apart.

use voxlod_core::components::submesh;
use voxlod_core::parity::point_inside;
use voxlod_core::{mesh_topology, Bounds, TriangleMesh};
use voxlod_metrics::MeshDistance;

use super::candidate::{most_fitting, Candidate};
use super::context::BudgetContext;
use super::geometric::collapse;
use super::parts::{InputPart, STAND_IN_TRIANGLES};
use super::Stage;
use crate::lod::LodLevel;

/// The share of the budget that restored parts may use at most.
const SHARE: f64 = 0.25;
/// Inputs with more parts than this get none restored: each candidate tests every part against
/// its triangles, and a budget affords a few dozen tetrahedra at most.
const MAX_PARTS: usize = 10_000;

impl BudgetContext<'_> {
    /// The input's parts (module docs), split on first use (shared with the context of the
    /// filled input, which has no welded input of its own).
    pub(super) fn input_parts(&self) -> &[InputPart] {
        self.parts.get_or_init(|| {
            let Some((mesh, _)) = &self.welded else {
                return Vec::new();
            };
            if !(2..=MAX_PARTS).contains(&self.part_triangles.len()) {
                return Vec::new();
            }
            (self.part_triangles.iter())
                .map(|triangles| InputPart::new(submesh(mesh, triangles)))
                .collect()
        })
    }
}

/// `chosen` (a quadric candidate from `level`) with the input's detached parts restored beside
/// it (module docs), the level re-simplified to make room: one twin with the parts farther from
/// the level than its own shape is off, one with the parts farther than that twin's shape where
/// a part left out still sets its distance, one with every part apart that fits the share (when
/// there are more); none where no part is apart.
pub(super) fn with_detached_parts(
    ctx: &BudgetContext,
    level: &LodLevel,
    chosen: &Candidate,
    budget: usize,
    error: Option<f64>,
) -> Vec<Candidate> {
    if chosen.stage != Stage::Quadric || mesh_topology(&chosen.mesh).boundary_edges > 0 {
        return Vec::new();
    }
    let Ok(nearest) = MeshDistance::new(&chosen.mesh) else {
        return Vec::new();
    };
    let obstacle = Obstacle::new(&chosen.mesh);
    let shape = chosen.distance.map_or(0.0, |d| d.shape);
    let apart =
        |farther_than| stand_ins(ctx.input_parts(), &obstacle, &nearest, farther_than, budget);
    let (far, all) = (apart(shape), apart(0.0));
    let mut twins: Vec<Candidate> = Vec::new();
    if !far.is_empty() {
        twins.extend(twin(ctx, level, chosen, &far, budget, error));
    }
    // Where a part left out still sets the far twin's distance (its Hausdorff above its own
    // shape, which the lost parts' area samples had inflated in `chosen`'s), a third twin
    // restores the parts farther than that shape.
    let still_off = (twins.last().and_then(|t| t.distance)).filter(|d| d.hausdorff > d.shape);
    if let Some(off) = still_off {
        let nearer = apart(off.shape);
        if nearer.len() > far.len() && nearer.len() < all.len() {
            twins.extend(twin(ctx, level, chosen, &nearer, budget, error));
        }
    }
    if !all.is_empty() && twins.last().is_none_or(|t| t.parts_restored < all.len()) {
        twins.extend(twin(ctx, level, chosen, &all, budget, error));
    }
    twins
}

/// The candidate of `level` re-simplified to `budget` less the triangles of `parts`, with the
/// parts still clear of it beside it.
fn twin(
    ctx: &BudgetContext,
    level: &LodLevel,
    chosen: &Candidate,
    parts: &[&TriangleMesh],
    budget: usize,
    error: Option<f64>,
) -> Option<Candidate> {
    let reserved: usize = parts.iter().map(|p| p.triangle_count()).sum();
    let done = collapse(level, budget - reserved, error)?;
    let mut mesh = done.simplified.mesh;
    let kept = Obstacle::new(&mesh);
    let room = most_fitting(budget).saturating_sub(mesh.triangle_count());
    let clear = fitting(parts.iter().copied().filter(|s| kept.clear_of(s)), room);
    clear.iter().for_each(|s| append(&mut mesh, s));
    Some(Candidate {
        distance: ctx.measure(&mesh),
        mesh,
        stage: Stage::Quadric,
        error_bound: done.simplified.error_bound,
        parts_dropped: done.dropped_parts,
        parts_restored: clear.len(),
        iso: chosen.iso,
        facts: Default::default(),
    })
}

/// The first of `parts` (farthest first) whose triangles, together, fit in `room`: where the
/// level re-simplified to make room stalls above its share, the nearest parts give way, so
/// that the twin stays within 10 % of the budget and keeps the parts that set the distance.
fn fitting<'p>(
    parts: impl Iterator<Item = &'p TriangleMesh>,
    room: usize,
) -> Vec<&'p TriangleMesh> {
    let mut used = 0;
    parts
        .filter(|part| {
            let fits = used + part.triangle_count() <= room;
            used += if fits { part.triangle_count() } else { 0 };
            fits
        })
        .collect()
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
        let Some(&[first, _, _]) = part.triangles.first() else {
            return false;
        };
        let b = part.bounds();
        let point = part.positions[first as usize].as_dvec3();
        !self.boxes.iter().any(|t| t.intersects(&b))
            && !point_inside(self.level, 0..self.level.triangle_count(), point)
    }
}

/// The stand-ins of the parts clear of the level and farther from it than `farther_than` (a
/// first vertex's distance, by `nearest`), farthest first, within the budget's share.
fn stand_ins<'p>(
    parts: &'p [InputPart],
    level: &Obstacle,
    nearest: &MeshDistance,
    farther_than: f64,
    budget: usize,
) -> Vec<&'p TriangleMesh> {
    let first = |m: &TriangleMesh| m.positions[m.triangles[0][0] as usize].as_dvec3();
    let mut apart: Vec<(f64, &InputPart)> = parts
        .iter()
        .map(|p| (nearest.distance(first(&p.mesh)), p))
        .filter(|(d, p)| *d > farther_than && level.clear_of(&p.mesh))
        .collect();
    apart.sort_by(|a, b| b.0.total_cmp(&a.0));
    let share = (SHARE * budget as f64) as usize;
    let mut out = Vec::new();
    let mut used = 0;
    for (_, part) in apart {
        if used + STAND_IN_TRIANGLES > share {
            break;
        }
        let Some(stand_in) = part.stand_in() else {
            continue;
        };
        let count = stand_in.triangle_count();
        if used + count <= share && level.clear_of(stand_in) {
            used += count;
            out.push(stand_in);
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

#[cfg(test)]
mod tests {
    use voxlod_core::glam::Vec3;
    use voxlod_core::TriangleMesh;

    use super::fitting;

    /// A part of `triangles` triangles (their shape does not matter to the count).
    fn part(triangles: usize) -> TriangleMesh {
        TriangleMesh::new(vec![Vec3::ZERO; 3], vec![[0, 1, 2]; triangles])
    }

    #[test]
    fn the_farthest_parts_that_fit_the_room_are_kept() {
        // Farthest first: 4, 4, 14, 4, 6 triangles, room for 13.
        let parts: Vec<TriangleMesh> = [4, 4, 14, 4, 6].map(part).into();
        let kept = fitting(parts.iter(), 13);
        let counts: Vec<usize> = kept.iter().map(|p| p.triangle_count()).collect();
        // The 14 cannot fit; the next 4 still does; then the 6 would overflow.
        assert_eq!(counts, vec![4, 4, 4]);
        assert!(std::ptr::eq(kept[2], &parts[3]));
    }

    #[test]
    fn the_parts_kept_never_overflow_the_room_and_all_come_back_with_room_for_all() {
        let parts: Vec<TriangleMesh> = [4, 6, 4, 4, 20, 4].map(part).into();
        let all: usize = parts.iter().map(|p| p.triangle_count()).sum();
        for room in 0..=all + 3 {
            let kept = fitting(parts.iter(), room);
            let used: usize = kept.iter().map(|p| p.triangle_count()).sum();
            assert!(used <= room, "room {room}: {used}");
            assert_eq!(kept.len() == parts.len(), room >= all, "room {room}");
        }
        assert!(fitting(parts.iter(), 3).is_empty());
    }
}
