//! Welding coincident vertices: every group of vertices with exactly the same coordinates
//! becomes one vertex. STL files store each triangle with its own three corners, so a closed
//! STL model is only watertight once this has run. Cost: O(V) expected, one pass with a fast
//! (Fx) hash map keyed by the coordinates' bits.
//!
//! Before welding, [`zero_rounding_noise`] may set coordinates within [`ZERO_NOISE`] of the
//! model's diagonal of zero to zero: CAD exporters write the rounding of their own arithmetic
//! there (2.7·10⁻¹⁶ where a neighbouring facet has 0), which in `f32` survives only near zero
//! (elsewhere the format's precision absorbs it) and would leave such a model open along every
//! edge it touches.

use glam::Vec3;
use rustc_hash::FxHashMap;

use crate::TriangleMesh;

/// Coordinates closer to zero than this fraction of the model's diagonal are zero for
/// [`zero_rounding_noise`]: far below any feature (a nanometre on a metre-long part), far above
/// the noise.
pub const ZERO_NOISE: f64 = 1e-8;

/// Sets to zero every coordinate of `mesh` within [`ZERO_NOISE`] of its diagonal of zero (module
/// docs); how many it set. Cost: O(V).
///
/// ```
/// use voxlod_core::{glam::Vec3, weld::{weld_vertices, zero_rounding_noise}, TriangleMesh};
///
/// let mut mesh = TriangleMesh::new(
///     vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(2.7e-16, 0.0, 0.0), Vec3::X, Vec3::Y],
///     vec![[0, 1, 2], [3, 2, 1]],
/// );
/// assert_eq!(zero_rounding_noise(&mut mesh), 1);
/// assert_eq!(weld_vertices(&mut mesh).vertices_after, 3);
/// ```
pub fn zero_rounding_noise(mesh: &mut TriangleMesh) -> usize {
    let near = (ZERO_NOISE * mesh.bounds().diagonal()) as f32;
    let mut set = 0;
    for p in &mut mesh.positions {
        for c in [&mut p.x, &mut p.y, &mut p.z] {
            if *c != 0.0 && c.abs() < near {
                *c = 0.0;
                set += 1;
            }
        }
    }
    set
}

/// Outcome of [`weld_vertices`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct WeldReport {
    /// Vertices before welding.
    pub vertices_before: usize,
    /// Vertices after welding: the distinct coordinates.
    pub vertices_after: usize,
}

fn key(p: Vec3) -> [u32; 3] {
    // +0.0 and -0.0 are the same point.
    let canon = |x: f32| if x == 0.0 { 0u32 } else { x.to_bits() };
    [canon(p.x), canon(p.y), canon(p.z)]
}

/// Merges vertices with identical coordinates, keeping the first of each group and the order of
/// first appearance. Normals of merged vertices are dropped (they would disagree); recompute
/// them if needed. Triangles are renumbered; none is removed.
pub fn weld_vertices(mesh: &mut TriangleMesh) -> WeldReport {
    let before = mesh.positions.len();
    let mut first: FxHashMap<[u32; 3], u32> =
        FxHashMap::with_capacity_and_hasher(before, Default::default());
    let mut remap = Vec::with_capacity(before);
    let mut positions = Vec::new();
    for &p in &mesh.positions {
        let next = positions.len() as u32;
        let id = *first.entry(key(p)).or_insert_with(|| {
            positions.push(p);
            next
        });
        remap.push(id);
    }
    if positions.len() != before {
        mesh.normals.clear();
    }
    mesh.positions = positions;
    for tri in &mut mesh.triangles {
        for v in tri.iter_mut() {
            *v = remap[*v as usize];
        }
    }
    WeldReport {
        vertices_before: before,
        vertices_after: mesh.positions.len(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{mesh_topology, test_shapes::unit_cube};

    #[test]
    fn welding_a_soup_closes_it() {
        let cube = unit_cube();
        let mut soup = TriangleMesh::default();
        for t in 0..cube.triangles.len() {
            let base = soup.positions.len() as u32;
            for &v in &cube.triangles[t] {
                soup.positions.push(cube.positions[v as usize]);
            }
            soup.triangles.push([base, base + 1, base + 2]);
        }
        // -0.0 must weld with 0.0
        soup.positions[0].x = -0.0;
        assert_eq!(mesh_topology(&soup).boundary_edges, 36);
        let report = weld_vertices(&mut soup);
        assert_eq!(report.vertices_before, 36);
        assert_eq!(report.vertices_after, 8);
        let t = mesh_topology(&soup);
        assert!(t.is_closed_manifold());
        assert_eq!(t.genus, Some(0));
    }
}
