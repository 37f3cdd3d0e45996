//! Where a proxy's surface point finds the source: a ray cast from the point along its normal
//! both ways, through an obvhs BVH over the source's triangles, the nearest hit within the
//! cage distance on a triangle that faces the same side as the proxy (a back face seen from
//! the proxy is the inside of another part, or the far side of a thin one), or that a viewer
//! sees from both sides (the caller says which: a leaf card of a double-sided material), and
//! shows
//! something there (a caller's test: an alpha-masked texel below its cutoff is passed, the
//! any-hit test of alpha-tested ray tracing); where no ray hits, the source's nearest point
//! (`voxlod_metrics::MeshDistance`), on a triangle facing the proxy's side where one is nearly
//! as near (beside a source edge, both faces are).
//!
//! Cost: building is O(N log N) for N source triangles (two BVHs: obvhs's for rays, the
//! closest-point one); a query is two ray traversals, O(log N) typically, plus a closest-
//! point query where both miss.

use std::time::Duration;

use obvhs::aabb::Aabb;
use obvhs::bvh2::builder::build_bvh2;
use obvhs::bvh2::Bvh2;
use obvhs::ray::{Ray, RayHit};
use obvhs::triangle::Triangle;
use obvhs::BvhBuildParams;
use voxlod_core::glam::{Vec3, Vec3A};
use voxlod_core::memory::{bytes_of, check_allocation};
use voxlod_core::TriangleMesh;
use voxlod_metrics::{closest_point_on_triangle, MeshDistance};

use crate::BakeError;

/// Whether the source shows nothing at a point (source triangle, barycentric weights).
pub type Clear<'a> = dyn Fn(usize, [f32; 3]) -> bool + Sync + 'a;

/// The source point a proxy point stands for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Found {
    /// The source triangle.
    pub triangle: usize,
    /// Barycentric weights of the point on it.
    pub weights: [f32; 3],
    /// Whether a ray found it (else it is the nearest point).
    pub hit: bool,
}

/// The source's triangles prepared for [`Cast::find`].
pub struct Cast {
    bvh: Bvh2,
    /// Triangles in the BVH's primitive order.
    slots: Vec<Triangle>,
    /// Unit geometric normal of each slot.
    slot_normal: Vec<Vec3A>,
    /// The source triangle of each slot.
    slot_triangle: Vec<u32>,
    /// The slot of each source triangle.
    triangle_slot: Vec<u32>,
    /// Whether each slot is seen from both sides (a double-sided material, glTF §3.9.4):
    /// it counts facing either way.
    slot_two_sided: Vec<bool>,
    nearest: MeshDistance,
}

/// Where no ray hits, a triangle facing the level's side is taken over the nearest one when it
/// is at most this many times as far (a point beside a source edge is as near to the faces on
/// both sides of it).
const NEAR_ENOUGH: f32 = 1.25;

/// Bytes per source triangle of the ray BVH while it is built (boxes, nodes, triangles).
const BUILD_BYTES_PER_TRIANGLE: usize = 256;

impl Cast {
    /// Prepares `source`. Refuses an empty mesh, an index out of range, a coordinate not
    /// finite or a mesh too large for the memory available.
    pub fn new(source: &TriangleMesh) -> Result<Cast, BakeError> {
        let nearest = MeshDistance::new(source)?;
        check_allocation(
            &format!(
                "the ray-cast structure of {} triangles",
                source.triangles.len()
            ),
            bytes_of::<[u8; BUILD_BYTES_PER_TRIANGLE]>(source.triangles.len()),
        )?;
        let triangles: Vec<Triangle> = source
            .triangles
            .iter()
            .map(|t| {
                let [v0, v1, v2] = t.map(|v| Vec3A::from(source.positions[v as usize]));
                Triangle { v0, v1, v2 }
            })
            .collect();
        let mut build_time = Duration::ZERO;
        let bvh = build_bvh2(&triangles, BvhBuildParams::fast_build(), &mut build_time);
        let slot_triangle = bvh.primitive_indices.clone();
        let slots: Vec<Triangle> = slot_triangle
            .iter()
            .map(|&t| triangles[t as usize])
            .collect();
        let slot_normal = slots.iter().map(|t| t.compute_normal()).collect();
        let mut triangle_slot = vec![0u32; slot_triangle.len()];
        for (slot, &t) in slot_triangle.iter().enumerate() {
            triangle_slot[t as usize] = slot as u32;
        }
        let slot_two_sided = vec![false; slots.len()];
        Ok(Cast {
            bvh,
            slots,
            slot_normal,
            slot_triangle,
            triangle_slot,
            slot_two_sided,
            nearest,
        })
    }

    /// The same, with the source triangles for which `two_sided(triangle)` holds seen from
    /// both sides: a viewer sees a double-sided leaf card from its back too, so a ray from the
    /// proxy that meets its back has found it.
    pub fn with_two_sided(mut self, two_sided: impl Fn(usize) -> bool) -> Cast {
        self.slot_two_sided = (self.slot_triangle.iter())
            .map(|&t| two_sided(t as usize))
            .collect();
        self
    }

    /// Whether `slot` faces along `facing`, or is seen from both sides.
    fn faces(&self, slot: usize, facing: Vec3A) -> bool {
        self.slot_two_sided[slot] || self.slot_normal[slot].dot(facing) > 0.0
    }

    /// The source point for the proxy point `p` with unit normal `n`: the nearest hit of the
    /// rays from `p` along `n` and `−n` within `cage`, on a triangle facing along `n` and not
    /// `clear` there (`clear(triangle, weights)`: an alpha-masked texel the source shows
    /// nothing at, which a ray passes as a viewer's would); else the nearest point of the
    /// source.
    pub fn find(&self, p: Vec3, n: Vec3, cage: f32, clear: &Clear<'_>) -> Found {
        let forward = self.first_hit(p, n, n, cage, clear);
        let backward = self.first_hit(p, -n, n, cage, clear);
        let best = match (forward, backward) {
            (Some(a), Some(b)) => Some(if a.1 <= b.1 { a } else { b }),
            (a, b) => a.or(b),
        };
        if let Some((found, _)) = best {
            return found;
        }
        let near = self.nearest.closest(p.as_dvec3());
        let slot = self
            .nearest_facing(p, n, near.distance as f32 * NEAR_ENOUGH)
            .unwrap_or(self.triangle_slot[near.triangle] as usize);
        let tri = &self.slots[slot];
        let corners = [tri.v0, tri.v1, tri.v2].map(|v| v.as_dvec3());
        let point = closest_point_on_triangle(p.as_dvec3(), corners).as_vec3();
        Found {
            triangle: self.slot_triangle[slot] as usize,
            weights: barycentric([tri.v0, tri.v1, tri.v2].map(Vec3::from), point),
            hit: false,
        }
    }

    /// The slot nearest to `p` among those facing along `n` within `reach` of it.
    fn nearest_facing(&self, p: Vec3, n: Vec3, reach: f32) -> Option<usize> {
        let reach = reach + f32::EPSILON * p.abs().max_element().max(1.0);
        let query = Aabb::new(Vec3A::from(p) - reach, Vec3A::from(p) + reach);
        let (facing, p64) = (Vec3A::from(n), p.as_dvec3());
        let mut best: Option<(usize, f64)> = None;
        self.bvh.aabb_traverse(query, |bvh, node| {
            let node = &bvh.nodes[node as usize];
            for slot in node.first_index as usize..(node.first_index + node.prim_count) as usize {
                if !self.faces(slot, facing) {
                    continue;
                }
                let tri = &self.slots[slot];
                let q =
                    closest_point_on_triangle(p64, [tri.v0, tri.v1, tri.v2].map(|v| v.as_dvec3()));
                let d = q.distance(p64);
                if d <= reach as f64 && best.is_none_or(|b| d < b.1) {
                    best = Some((slot, d));
                }
            }
            true
        });
        best.map(|b| b.0)
    }

    /// The first source point a ray from `p` along `direction` meets within `length` on a
    /// triangle facing along `facing` (or seen from both sides) and not `clear` there, with
    /// its distance along the ray.
    pub fn first_hit(
        &self,
        p: Vec3,
        direction: Vec3,
        facing: Vec3,
        length: f32,
        clear: &Clear<'_>,
    ) -> Option<(Found, f32)> {
        let (slot, t) = self.cast(p, direction, facing, length, clear)?;
        let tri = &self.slots[slot];
        let found = Found {
            triangle: self.slot_triangle[slot] as usize,
            weights: barycentric([tri.v0, tri.v1, tri.v2].map(Vec3::from), p + direction * t),
            hit: true,
        };
        Some((found, t))
    }

    /// The nearest slot a ray from `p` along `direction` meets within `cage` whose normal
    /// faces along `facing` and which is not `clear` where the ray meets it, with the
    /// distance.
    fn cast(
        &self,
        p: Vec3,
        direction: Vec3,
        facing: Vec3,
        cage: f32,
        clear: &Clear<'_>,
    ) -> Option<(usize, f32)> {
        let ray = Ray::new(Vec3A::from(p), Vec3A::from(direction), 0.0, cage);
        let facing = Vec3A::from(facing);
        let mut hit = RayHit::none();
        let found = self.bvh.ray_traverse(ray, &mut hit, |ray, slot| {
            if !self.faces(slot, facing) {
                return f32::INFINITY;
            }
            let t = self.slots[slot].intersect(ray);
            if t.is_finite() {
                let tri = &self.slots[slot];
                let at = barycentric([tri.v0, tri.v1, tri.v2].map(Vec3::from), p + direction * t);
                if clear(self.slot_triangle[slot] as usize, at) {
                    return f32::INFINITY;
                }
            }
            t
        });
        found.then_some((hit.primitive_id as usize, hit.t))
    }
}

/// Barycentric weights of `point` (on or near the triangle), clamped to the triangle; a
/// degenerate triangle gives its first corner.
pub fn barycentric([a, b, c]: [Vec3; 3], point: Vec3) -> [f32; 3] {
    // Each weight is the signed area of the sub-triangle opposite its corner, measured along
    // the triangle's normal, over the whole area.
    let normal = (b - a).cross(c - a);
    let whole = normal.length_squared();
    if whole.is_nan() || whole <= f32::MIN_POSITIVE {
        return [1.0, 0.0, 0.0];
    }
    let area = |u: Vec3, v: Vec3| ((u - point).cross(v - point).dot(normal) / whole).max(0.0);
    let w = [area(b, c), area(c, a), area(a, b)];
    let sum = w[0] + w[1] + w[2];
    if sum > 0.0 {
        w.map(|w| w / sum)
    } else {
        [1.0, 0.0, 0.0]
    }
}
