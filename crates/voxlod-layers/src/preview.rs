//! Drawing layered shells: every layer in one colour with its own alpha, blended in a stored
//! back-to-front order (the preview of `voxlod layers`, and the antialiasing comparison).
//!
//! Cost: one render of the concatenated layers, O(triangles + pixels).

use voxlod_core::TriangleMesh;
use voxlod_render::{render, Camera, Image, MeshItem, RenderOptions, Scene};

use crate::LayersError;

/// Draws layered shells blended in `order`: layer `l` in `color` with alpha `alphas[l]`.
pub fn render_layered(
    mesh: &TriangleMesh,
    triangle_layer: &[u16],
    alphas: &[f32],
    order: &[u32],
    color: [f32; 3],
    camera: &Camera,
    options: &RenderOptions,
) -> Result<Image, LayersError> {
    let palette = alphas
        .iter()
        .map(|&a| [color[0], color[1], color[2], a])
        .collect();
    Ok(render(
        &Scene {
            meshes: vec![MeshItem::blended(mesh, palette, triangle_layer, order)],
            ..Default::default()
        },
        camera,
        options,
    )?)
}
