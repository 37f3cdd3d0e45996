//! A static set of triangles that query triangles must not touch: the two offset surfaces of the
//! envelope. The triangles go into an obvhs BVH (built from their boxes, widened by the contact
//! tolerance and one `f32` rounding); a query descends the nodes whose box the query triangle
//! overlaps (box against box, then the separating-axis test `TriangleBoxTest`, set up once per
//! query) and runs the exact test `triangles_intersect` on the triangles of the leaves it reaches.
//!
//! The paper (§4.3) finds the triangles near a prism with an octree; a BVH over triangle boxes
//! does the same job with no tuning. The set never changes during a simplification (the offsets
//! are fixed for a given ε), so it is built once per level.
//!
//! Cost: building is O(F log F) for F triangles, about 120 bytes per triangle (corners in `f64`
//! in leaf order, their vertex ids, the nodes). A query visits the O(log F) nodes on the way
//! down plus those the query triangle actually crosses; a triangle lying between the offsets
//! crosses few.

use std::time::Duration;

use glam::{DVec3, Vec3A};
use obvhs::{aabb::Aabb, bvh2::Bvh2, BvhBuildParams};
use rayon::prelude::*;
use voxlod_core::memory::{bytes_of, check_allocation};
use voxlod_core::CoreError;

use super::geometry::{triangles_intersect, TriangleBoxTest};

/// Build settings: obvhs's fast build (a little reinsertion pays off over the many queries of
/// a level) with small leaves (the exact test is the costly part).
const BUILD: BvhBuildParams = BvhBuildParams {
    max_prims_per_leaf: 4,
    collapse_traversal_cost: 3.0,
    ..BvhBuildParams::fast_build()
};

/// Peak bytes per triangle of a build (boxes, PLOC nodes and scratch, then what is kept).
const BUILD_BYTES_PER_TRIANGLE: usize = 260;

/// Triangles indexed for "does this triangle touch any of them" queries.
pub(crate) struct TriangleSet {
    bvh: Bvh2,
    /// Corners in leaf order: a leaf holds slots `first_index..first_index + prim_count`.
    slot_corners: Vec<[DVec3; 3]>,
    /// Vertex ids of each slot's triangle (for skipping neighbours that share a vertex).
    slot_ids: Vec<[u32; 3]>,
    /// The caller's index of each slot's triangle.
    slot_triangle: Vec<u32>,
    /// Contact tolerance, in the mesh's units.
    tol: f64,
}

impl TriangleSet {
    /// Indexes `corners[i]` (with vertex ids `ids[i]`). `tol` is the contact tolerance.
    pub fn new(corners: &[[DVec3; 3]], ids: &[[u32; 3]], tol: f64) -> Result<Self, CoreError> {
        debug_assert_eq!(corners.len(), ids.len());
        check_allocation(
            &format!(
                "the envelope search structure for {} triangles",
                corners.len()
            ),
            bytes_of::<[u8; BUILD_BYTES_PER_TRIANGLE]>(corners.len()),
        )?;
        let boxes: Vec<Aabb> = corners.par_iter().map(|t| padded_box(t, tol)).collect();
        let mut time = Duration::ZERO;
        let bvh = obvhs::bvh2::builder::build_bvh2(&boxes, BUILD, &mut time);
        drop(boxes);
        let slot_triangle = bvh.primitive_indices.clone();
        let slot_corners = slot_triangle
            .par_iter()
            .map(|&t| corners[t as usize])
            .collect();
        let slot_ids = slot_triangle.iter().map(|&t| ids[t as usize]).collect();
        Ok(TriangleSet {
            bvh,
            slot_corners,
            slot_ids,
            slot_triangle,
            tol,
        })
    }

    /// Moves the triangles to `corners`, with vertex ids `ids` (same count and order as when
    /// built): the leaves' boxes are recomputed and the tree refitted, its shape kept. O(F).
    pub fn update(&mut self, corners: &[[DVec3; 3]], ids: &[[u32; 3]]) {
        debug_assert_eq!(corners.len(), self.slot_triangle.len());
        self.slot_corners
            .par_iter_mut()
            .zip(self.slot_ids.par_iter_mut())
            .zip(self.slot_triangle.par_iter())
            .for_each(|((c, i), &t)| {
                *c = corners[t as usize];
                *i = ids[t as usize];
            });
        let (slots, tol) = (&self.slot_corners, self.tol);
        self.bvh.nodes.par_iter_mut().for_each(|node| {
            if node.is_leaf() {
                let first = node.first_index as usize;
                let mut b = padded_box(&slots[first], tol);
                for t in &slots[first + 1..first + node.prim_count as usize] {
                    b = b.union(&padded_box(t, tol));
                }
                node.set_aabb(b);
            }
        });
        self.bvh.refit_all();
    }

    /// Whether `query` touches any indexed triangle for which `skip(ids, index)` is false.
    pub fn touches(&self, query: &[DVec3; 3], skip: impl Fn(&[u32; 3], u32) -> bool) -> bool {
        let mut hit = false;
        self.visit(query, |slot| {
            let s = slot as usize;
            if skip(&self.slot_ids[s], self.slot_triangle[s]) {
                return true;
            }
            if triangles_intersect(query, &self.slot_corners[s], self.tol) {
                hit = true;
                return false;
            }
            true
        });
        hit
    }

    /// Calls `found(index)` for every indexed triangle that touches `query` and for which
    /// `skip(ids, index)` is false.
    pub fn each_touching(
        &self,
        query: &[DVec3; 3],
        skip: impl Fn(&[u32; 3], u32) -> bool,
        mut found: impl FnMut(u32),
    ) {
        self.visit(query, |slot| {
            let s = slot as usize;
            if !skip(&self.slot_ids[s], self.slot_triangle[s])
                && triangles_intersect(query, &self.slot_corners[s], self.tol)
            {
                found(self.slot_triangle[s]);
            }
            true
        });
    }

    /// Calls `leaf_slot` for every slot of every leaf whose box overlaps the query triangle
    /// (widened by the tolerance), until it returns false.
    fn visit(&self, query: &[DVec3; 3], mut leaf_slot: impl FnMut(u32) -> bool) {
        let nodes = &self.bvh.nodes;
        if nodes.is_empty() {
            return;
        }
        let qlo = query[0].min(query[1]).min(query[2]) - DVec3::splat(self.tol);
        let qhi = query[0].max(query[1]).max(query[2]) + DVec3::splat(self.tol);
        let sat = TriangleBoxTest::new(query, self.tol);
        let overlaps = |index: usize| {
            let b = nodes[index].aabb();
            sat.overlaps(b.min, b.max)
        };
        if !overlaps(0) {
            return;
        }
        let mut stack: Vec<u32> = Vec::with_capacity(64);
        stack.push(0);
        while let Some(index) = stack.pop() {
            let node = &nodes[index as usize];
            if node.is_leaf() {
                for slot in node.first_index..node.first_index + node.prim_count {
                    let t = &self.slot_corners[slot as usize];
                    let (lo, hi) = (t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2]));
                    if lo.cmpgt(qhi).any() || hi.cmplt(qlo).any() {
                        continue;
                    }
                    if !leaf_slot(slot) {
                        return;
                    }
                }
            } else {
                let left = node.first_index as usize;
                for child in [left, left + 1] {
                    if overlaps(child) {
                        stack.push(child as u32);
                    }
                }
            }
        }
    }
}

/// The `f32` box of `t`, widened by `tol` and by one `f32` rounding of its largest coordinate, so
/// that it holds the `f64` triangle and everything within `tol` of it.
pub(super) fn padded_box(t: &[DVec3; 3], tol: f64) -> Aabb {
    let lo = t[0].min(t[1]).min(t[2]);
    let hi = t[0].max(t[1]).max(t[2]);
    let pad = DVec3::splat(tol) + lo.abs().max(hi.abs()) * (2.0 * f32::EPSILON as f64);
    Aabb::new(
        Vec3A::from((lo - pad).as_vec3()),
        Vec3A::from((hi + pad).as_vec3()),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_crossing_triangles_only() {
        // A 20 x 20 grid of triangles in the plane z = 0.
        let mut corners = Vec::new();
        let mut ids = Vec::new();
        for i in 0..20 {
            for j in 0..20 {
                let (x, y) = (i as f64, j as f64);
                let id = |a: u32, b: u32| a * 21 + b;
                corners.push([
                    DVec3::new(x, y, 0.0),
                    DVec3::new(x + 1.0, y, 0.0),
                    DVec3::new(x, y + 1.0, 0.0),
                ]);
                ids.push([id(i, j), id(i + 1, j), id(i, j + 1)]);
            }
        }
        let set = TriangleSet::new(&corners, &ids, 1e-9).unwrap();
        let above = [
            DVec3::new(2.0, 2.0, 0.5),
            DVec3::new(9.0, 3.0, 0.5),
            DVec3::new(4.0, 8.0, 0.7),
        ];
        assert!(!set.touches(&above, |_, _| false));
        let through = [
            DVec3::new(2.2, 2.2, -0.5),
            DVec3::new(9.0, 3.0, 0.5),
            DVec3::new(4.0, 8.0, 0.7),
        ];
        assert!(set.touches(&through, |_, _| false));
        let mut found = Vec::new();
        set.each_touching(&through, |_, _| false, |t| found.push(t));
        assert!(!found.is_empty());
        // Brute force agrees.
        let mut brute: Vec<u32> = (0..corners.len() as u32)
            .filter(|&t| triangles_intersect(&through, &corners[t as usize], 1e-9))
            .collect();
        found.sort_unstable();
        brute.sort_unstable();
        assert_eq!(found, brute);
        // Skipping every triangle finds nothing.
        assert!(!set.touches(&through, |_, _| true));
        // Moved up by 2, the grid no longer meets the query, but meets it lifted by 2.
        let mut set = set;
        let lifted: Vec<[DVec3; 3]> = corners
            .iter()
            .map(|t| t.map(|p| p + DVec3::new(0.0, 0.0, 2.0)))
            .collect();
        set.update(&lifted, &ids);
        assert!(!set.touches(&through, |_, _| false));
        let through_up = through.map(|p| p + DVec3::new(0.0, 0.0, 2.0));
        assert!(set.touches(&through_up, |_, _| false));
    }
}
