//! Back-to-front order of several objects, each with its own volume buffer (paper §3: "One
//! simple solution is to perform the sorting on bounding boxes of the volume buffers … A more
//! accurate and efficient sorting algorithm is to take advantage of the volume buffers …, since
//! intersections among the regularly partitioned volume buffers are easy to compute").
//!
//! Objects may be placed (the layers of oblique or flipped scans, [`CellTriangles::placement`]):
//! boxes are then the world boxes around the placed ones, and buffers are merged on a shared
//! lattice only when their placements are the same.
//!
//! 1. Each object's box is the box of its occupied cells (tighter than its whole buffer).
//! 2. Objects whose boxes overlap are grouped (transitively). Inside a group the buffers are
//!    merged into one lattice and traversed together, so triangles of different objects that
//!    share a cell are sorted against each other like those of one object: the exact
//!    interleaving. This is exact when the buffers share a lattice (same spacing, origins a whole
//!    number of cells apart), as copies of one object or buffers cut from one scene grid do.
//!    Otherwise the group is re-binned on the coarsest spacing by triangle centroid, which is
//!    only approximate for triangles that straddle the new cells; [`SceneOrder`] counts such
//!    groups.
//! 3. Groups have disjoint boxes; for two boxes separated along an axis, the side of the
//!    separating slab the eye is on says which may hide the other. Groups are then sorted
//!    topologically, farthest first, a cycle (possible for long boxes) broken at the farthest.
//!
//! Cost: O(G² + B²) for G groups of B boxes, plus the per-group traversal of [`crate::order`].

use glam::{DVec3, Vec3};
use voxlod_core::{Bounds, Grid, Placement};

use crate::order::{view_order, CellTriangles, View};
use crate::LayersError;

/// The order of several objects' triangles: (object, triangle) pairs, back to front.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SceneOrder {
    /// Every triangle of every object, as (object, triangle), back to front.
    pub order: Vec<(u32, u32)>,
    /// Groups of objects with overlapping boxes (objects alone count as a group).
    pub groups: usize,
    /// Groups of several objects whose buffers were merged on a shared lattice (exact).
    pub merged_groups: usize,
    /// Groups of several objects whose lattices differ (re-binned by centroid: approximate).
    pub approximate_groups: usize,
}

/// Box of the occupied cells, or `None` for an object without triangles.
fn occupied_box(obj: &CellTriangles) -> Option<Bounds> {
    let [cx, cy, _] = obj.cell_dims();
    let mut lo = [usize::MAX; 3];
    let mut hi = [0usize; 3];
    for &c in obj.cells {
        let c = c as usize;
        let ijk = [c % cx, (c / cx) % cy, c / (cx * cy)];
        for a in 0..3 {
            lo[a] = lo[a].min(ijk[a]);
            hi[a] = hi[a].max(ijk[a]);
        }
    }
    if obj.cells.is_empty() {
        return None;
    }
    let g = &obj.grid;
    let cells = Bounds::new(
        g.position(lo[0] as f64, lo[1] as f64, lo[2] as f64),
        g.position(hi[0] as f64 + 1.0, hi[1] as f64 + 1.0, hi[2] as f64 + 1.0),
    );
    Some(placed_box(&cells, &obj.placement))
}

/// The axis-aligned box around a grid-space box moved by `placement`.
fn placed_box(b: &Bounds, placement: &Placement) -> Bounds {
    if placement.is_identity() {
        return *b;
    }
    let mut out = Bounds::EMPTY;
    for corner in 0..8 {
        let pick = |axis: usize| {
            if corner >> axis & 1 == 0 {
                b.min[axis]
            } else {
                b.max[axis]
            }
        };
        let p = DVec3::new(pick(0), pick(1), pick(2));
        out.grow(placement.linear * p + placement.translation);
    }
    out
}

fn boxes_overlap(a: &Bounds, b: &Bounds) -> bool {
    (0..3).all(|i| a.min[i] < b.max[i] && b.min[i] < a.max[i])
}

/// Whether `a` may hide part of `b` and `b` part of `a`, from the separating axes of the boxes.
fn may_hide(a: &Bounds, b: &Bounds, view: &View) -> (bool, bool) {
    let (mut a_hides, mut b_hides) = (true, true);
    for i in 0..3 {
        for (lower, upper, lower_is_a) in [(a, b, true), (b, a, false)] {
            if lower.max[i] > upper.min[i] {
                continue;
            }
            // The slab between lower.max and upper.min separates them. Rays are monotone
            // along axis i, so the box on the eye's side is the only one that can hide.
            let (lower_may, upper_may) = match *view {
                View::Orthographic { direction } => {
                    let d = direction[i];
                    (d > 0.0, d < 0.0)
                }
                View::Perspective { eye } => {
                    let e = eye[i];
                    (
                        e < upper.min[i] && e <= lower.max[i],
                        e > lower.max[i] && e >= upper.min[i],
                    )
                }
            };
            let (x_may, y_may) = if lower_is_a {
                (lower_may, upper_may)
            } else {
                (upper_may, lower_may)
            };
            a_hides &= x_may;
            b_hides &= y_may;
        }
    }
    (a_hides, b_hides)
}

fn depth_of(b: &Bounds, view: &View) -> f64 {
    match *view {
        View::Orthographic { direction } => b.center().dot(direction.normalize()),
        View::Perspective { eye } => (b.center() - eye).length(),
    }
}

fn find(parent: &mut [usize], x: usize) -> usize {
    let mut r = x;
    while parent[r] != r {
        r = parent[r];
    }
    let mut y = x;
    while parent[y] != r {
        let next = parent[y];
        parent[y] = r;
        y = next;
    }
    r
}

/// Orders the triangles of several objects back to front (see the module documentation).
pub fn scene_order(objects: &[CellTriangles], view: &View) -> Result<SceneOrder, LayersError> {
    view.check()?;
    let boxes: Vec<Option<Bounds>> = objects.iter().map(occupied_box).collect();
    let groups = overlap_groups(&boxes);
    let group_order = order_groups(&groups, &boxes, view);
    // Traverse each group.
    let mut out = SceneOrder {
        groups: groups.len(),
        ..Default::default()
    };
    for h in group_order {
        let members = &groups[h];
        if let [o] = members[..] {
            out.order.extend(
                view_order(&objects[o], view)?
                    .into_iter()
                    .map(|t| (o as u32, t)),
            );
            continue;
        }
        let (merged, exact) = merge(objects, members)?;
        if exact {
            out.merged_groups += 1;
        } else {
            out.approximate_groups += 1;
        }
        let obj = CellTriangles {
            grid: merged.grid,
            placement: merged.placement,
            positions: &merged.positions,
            triangles: &merged.triangles,
            cells: &merged.cells,
        };
        for t in view_order(&obj, view)? {
            let slot = merged.start.partition_point(|&s| s <= t) - 1;
            out.order
                .push((members[slot] as u32, t - merged.start[slot]));
        }
    }
    Ok(out)
}

/// Step 2: the objects that have an occupied box, grouped by overlapping boxes (transitively,
/// by union–find); each group lists its objects in increasing index. O(objects²).
fn overlap_groups(boxes: &[Option<Bounds>]) -> Vec<Vec<usize>> {
    let live: Vec<usize> = (0..boxes.len()).filter(|&o| boxes[o].is_some()).collect();
    let bx = |o: usize| boxes[o].expect("live object");
    let mut parent: Vec<usize> = (0..boxes.len()).collect();
    for (n, &a) in live.iter().enumerate() {
        for &b in &live[n + 1..] {
            if boxes_overlap(&bx(a), &bx(b)) {
                let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
                parent[ra] = rb;
            }
        }
    }
    let mut groups: Vec<Vec<usize>> = Vec::new();
    let mut group_of = vec![usize::MAX; boxes.len()];
    for &o in &live {
        let r = find(&mut parent, o);
        if group_of[r] == usize::MAX {
            group_of[r] = groups.len();
            groups.push(Vec::new());
        }
        groups[group_of[r]].push(o);
    }
    groups
}

/// Step 3: the groups in drawing order: a group that may hide another comes after it; among
/// the groups free to go, the farthest first; a cycle is broken at the farthest group left.
/// O(objects²) box tests.
fn order_groups(groups: &[Vec<usize>], boxes: &[Option<Bounds>], view: &View) -> Vec<usize> {
    let bx = |o: usize| boxes[o].expect("live object");
    let g = groups.len();
    let depth: Vec<f64> = groups
        .iter()
        .map(|m| {
            let b = m.iter().fold(Bounds::EMPTY, |acc, &o| acc.union(&bx(o)));
            depth_of(&b, view)
        })
        .collect();
    let mut before: Vec<Vec<usize>> = vec![Vec::new(); g]; // before[h] = groups drawn before h
    for x in 0..g {
        for y in x + 1..g {
            let (mut x_hides, mut y_hides) = (false, false);
            for &a in &groups[x] {
                for &b in &groups[y] {
                    let (ah, bh) = may_hide(&bx(a), &bx(b), view);
                    x_hides |= ah;
                    y_hides |= bh;
                }
            }
            match (x_hides, y_hides) {
                (true, false) => before[x].push(y),
                (false, true) => before[y].push(x),
                _ => {}
            }
        }
    }
    let mut by_depth: Vec<usize> = (0..g).collect();
    by_depth.sort_by(|&a, &b| depth[b].total_cmp(&depth[a]).then(a.cmp(&b)));
    let mut done = vec![false; g];
    let mut group_order = Vec::with_capacity(g);
    for _ in 0..g {
        let pick = by_depth
            .iter()
            .copied()
            .find(|&h| !done[h] && before[h].iter().all(|&p| done[p]))
            .or_else(|| by_depth.iter().copied().find(|&h| !done[h]))
            .expect("a group remains");
        done[pick] = true;
        group_order.push(pick);
    }
    group_order
}

/// Several objects on one lattice.
struct Merged {
    grid: Grid,
    placement: Placement,
    positions: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    cells: Vec<u32>,
    /// First triangle of each member.
    start: Vec<u32>,
}

/// Merges the members' buffers: on their shared lattice when they have one and the same
/// placement (exact), else on the coarsest spacing by placed triangle centroid, in the space of
/// the vertices.
fn merge(objects: &[CellTriangles], members: &[usize]) -> Result<(Merged, bool), LayersError> {
    let first = &objects[members[0]].grid;
    let placement = objects[members[0]].placement;
    let h = DVec3::from(first.spacing);
    let shared = members.iter().all(|&o| {
        let g = &objects[o].grid;
        objects[o].placement == placement
            && (0..3).all(|a| {
                let same = (g.spacing[a] - h[a]).abs() <= 1e-9 * h[a];
                let shift = (g.origin[a] - first.origin[a]) / h[a];
                same && (shift - shift.round()).abs() <= 1e-6
            })
    });
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    let mut spacing = DVec3::ZERO;
    for &o in members {
        let g = &objects[o].grid;
        let b = if shared {
            g.bounds()
        } else {
            placed_box(&g.bounds(), &objects[o].placement)
        };
        lo = lo.min(b.min);
        hi = hi.max(b.max);
        spacing = spacing.max(DVec3::from(g.spacing));
    }
    if shared {
        spacing = h;
    }
    let cells_per_axis = ((hi - lo) / spacing).round().max(DVec3::ONE);
    let cdims = [0, 1, 2].map(|a| cells_per_axis[a] as usize + usize::from(!shared));
    let total = cdims.iter().map(|&d| d as u64).product::<u64>();
    if total > u32::MAX as u64 {
        return Err(LayersError::Invalid(format!(
            "the merged buffer of {} objects would have {total} cells",
            members.len()
        )));
    }
    let grid = Grid::new(cdims.map(|d| d + 1), spacing.to_array(), lo.to_array())?;
    let mut m = Merged {
        grid,
        placement: if shared {
            placement
        } else {
            Placement::IDENTITY
        },
        positions: Vec::new(),
        triangles: Vec::new(),
        cells: Vec::new(),
        start: Vec::new(),
    };
    let lin = |ijk: [usize; 3]| (ijk[0] + cdims[0] * (ijk[1] + cdims[1] * ijk[2])) as u32;
    for &o in members {
        let obj = &objects[o];
        let base = m.positions.len() as u32;
        m.start.push(m.triangles.len() as u32);
        m.positions.extend_from_slice(obj.positions);
        m.triangles
            .extend(obj.triangles.iter().map(|t| t.map(|v| v + base)));
        if shared {
            let [cx, cy, _] = obj.cell_dims();
            let shift =
                [0, 1, 2].map(|a| ((obj.grid.origin[a] - lo[a]) / spacing[a]).round() as usize);
            m.cells.extend(obj.cells.iter().map(|&c| {
                let c = c as usize;
                lin([
                    c % cx + shift[0],
                    (c / cx) % cy + shift[1],
                    c / (cx * cy) + shift[2],
                ])
            }));
        } else {
            m.cells.extend(obj.triangles.iter().map(|t| {
                let centroid = t
                    .iter()
                    .map(|&v| obj.positions[v as usize].as_dvec3())
                    .sum::<DVec3>()
                    / 3.0;
                let f = (centroid - lo) / spacing;
                lin([0, 1, 2].map(|a| (f[a].floor().max(0.0) as usize).min(cdims[a] - 1)))
            }));
        }
    }
    Ok((m, shared))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn separated_boxes_hide_only_from_the_eye_side() {
        let a = Bounds::new(DVec3::ZERO, DVec3::ONE);
        let b = Bounds::new(DVec3::new(2.0, 0.0, 0.0), DVec3::new(3.0, 1.0, 1.0));
        let look = |d: DVec3| View::Orthographic { direction: d };
        assert_eq!(may_hide(&a, &b, &look(DVec3::X)), (true, false));
        assert_eq!(may_hide(&a, &b, &look(-DVec3::X)), (false, true));
        assert_eq!(may_hide(&a, &b, &look(DVec3::Y)), (false, false));
        let eye = |x: f64| View::Perspective {
            eye: DVec3::new(x, 0.5, 0.5),
        };
        assert_eq!(may_hide(&a, &b, &eye(-5.0)), (true, false));
        assert_eq!(may_hide(&a, &b, &eye(9.0)), (false, true));
        assert_eq!(may_hide(&a, &b, &eye(1.5)), (false, false));
    }
}
