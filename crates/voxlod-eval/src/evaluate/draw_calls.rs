//! Draw calls: how many times a renderer must switch material to draw a mesh, the cost a scene
//! proxy removes. A mesh is drawn in one call per material its triangles use; the evaluation
//! reports it for the input and for every level ([`super::CurvePoint::draw_calls`]).

use voxlod_asset::Asset;

/// Draw calls of `asset` as given: one per material its triangles use, one where it has no
/// material (a bare mesh still takes one call). Cost: O(T log T) for T triangles.
///
/// # Example
///
/// ```
/// use voxlod_eval::evaluate::draw_calls;
///
/// let scene = voxlod_testkit::assets::three_part_scene();
/// assert_eq!(draw_calls(&scene), 3); // three spheres, a material each
/// assert_eq!(draw_calls(&voxlod_asset::Asset::default()), 1);
/// ```
pub fn draw_calls(asset: &Asset) -> usize {
    let mut used: Vec<u32> = asset.mesh.material.clone();
    used.sort_unstable();
    used.dedup();
    used.len().max(1)
}
