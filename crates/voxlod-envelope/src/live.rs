//! The mesh being simplified, in a BVH that follows its changes: every removal takes its old
//! triangles out and puts the new ones in (obvhs's `remove_primitive` / `insert_primitive`, a
//! greedy sibling search with rotations). It answers "does this new triangle touch a triangle of
//! the current mesh that shares no vertex with it", which rules out the one kind of fold-over the
//! envelope and the hole's projection do not: a new triangle cutting through a part of the mesh
//! outside its hole, within the same shell (around sharp creases, where the shell is thick
//! compared with the triangles).
//!
//! Cost: a build over the current triangles at the start of each level (O(F log F)); O(depth)
//! per insertion and removal; a query as in [`super::obstacles`].

use std::time::Duration;

use glam::{DVec3, Vec3A};
use obvhs::{aabb::Aabb, bvh2::Bvh2, BvhBuildParams};

use super::geometry::{triangles_intersect, TriangleBoxTest};
use super::obstacles::padded_box;

const BUILD: BvhBuildParams = BvhBuildParams {
    max_prims_per_leaf: 1,
    collapse_traversal_cost: 1.0,
    ..BvhBuildParams::fast_build()
};

/// The current triangles (ids are the simplifier's triangle slots).
pub(crate) struct LiveSet {
    bvh: Bvh2,
    tol: f64,
}

impl LiveSet {
    /// Indexes the slots `t` with `alive[t]`.
    pub fn new(corners: impl Fn(u32) -> [DVec3; 3], alive: &[bool], tol: f64) -> LiveSet {
        let boxes: Vec<Aabb> = (0..alive.len() as u32)
            .map(|t| {
                if alive[t as usize] {
                    padded_box(&corners(t), tol)
                } else {
                    Aabb::new(Vec3A::ZERO, Vec3A::ZERO)
                }
            })
            .collect();
        let mut time = Duration::ZERO;
        let mut bvh = obvhs::bvh2::builder::build_bvh2(&boxes, BUILD, &mut time);
        for (t, &a) in alive.iter().enumerate() {
            if !a {
                bvh.remove_primitive(t as u32);
            }
        }
        LiveSet { bvh, tol }
    }

    /// Adds triangle `t` with these corners.
    pub fn insert(&mut self, t: u32, corners: &[DVec3; 3]) {
        self.bvh.insert_primitive(padded_box(corners, self.tol), t);
    }

    /// Takes triangle `t` out.
    pub fn remove(&mut self, t: u32) {
        self.bvh.remove_primitive(t);
    }

    /// Whether `query` touches a live triangle `t` for which `skip(t)` is false.
    pub fn touches(
        &self,
        query: &[DVec3; 3],
        corners: impl Fn(u32) -> [DVec3; 3],
        skip: impl Fn(u32) -> bool,
    ) -> bool {
        let nodes = &self.bvh.nodes;
        if nodes.is_empty() {
            return false;
        }
        let sat = TriangleBoxTest::new(query, self.tol);
        let overlaps = |index: usize| {
            let b = nodes[index].aabb();
            sat.overlaps(b.min, b.max)
        };
        if !overlaps(0) {
            return false;
        }
        let mut stack: Vec<u32> = Vec::with_capacity(64);
        stack.push(0);
        while let Some(index) = stack.pop() {
            let node = &nodes[index as usize];
            if node.is_leaf() {
                for slot in node.first_index..node.first_index + node.prim_count {
                    let t = self.bvh.primitive_indices[slot as usize];
                    if t == u32::MAX || skip(t) {
                        continue;
                    }
                    if triangles_intersect(query, &corners(t), self.tol) {
                        return true;
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
        false
    }
}
