//! Layered shells with baked looks ([`crate::looks`]) as binary glTF: the layout of
//! [`crate::glb`] with, for each layer with triangles, texture coordinates and a base colour
//! texture.
//!
//! **Additions to the layout** (everything [`crate::glb`] documents stays true, for the baked
//! layers' vertices):
//! - after the eight orders, buffer 0 holds the texture coordinates of every layer
//!   concatenated (a `VEC2` float per vertex, in the positions' order), then each layer's base
//!   colour image as the bake encoded it (PNG), each padded to four bytes;
//! - layer `i`'s primitive has `TEXCOORD_0`; its material's `baseColorTexture` is a texture
//!   of its own image, all textures sharing one sampler (linear, clamped to the edge); the
//!   base colour factor is `(1, 1, 1, alpha)`, so the texture is multiplied by the layer's
//!   blend alpha and nothing else ([`crate::GlbOptions::color`] is not used);
//! - the orders index the baked layers' vertices, which the atlas split at chart seams: the
//!   same triangles as the unbaked layers, in the same orders.
//!
//! Cost: linear in the layers' size and the images' bytes.

use gltf::json;
use gltf::json::validation::Checked;

use crate::extract::LayeredMesh;
use crate::glb_parts::{accessor, push_view};
use crate::looks::LayerLooks;
use crate::LayersError;

/// What a layer's primitive refers to for its looks.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LookParts {
    /// Its `TEXCOORD_0` accessor.
    pub texcoords: json::Index<json::Accessor>,
    /// Its base colour texture.
    pub texture: json::Index<json::Texture>,
}

/// Refuses `looks` that do not fit `layered`: one entry per layer, looks on every layer with
/// triangles, and texture coordinates one per vertex.
fn check_looks(layered: &LayeredMesh, looks: &[Option<LayerLooks>]) -> Result<(), LayersError> {
    let bad = |s: String| Err(LayersError::Invalid(s));
    if looks.len() != layered.layers.len() {
        return bad(format!(
            "looks for {} layers, not {}",
            looks.len(),
            layered.layers.len()
        ));
    }
    for (i, (layer, look)) in layered.layers.iter().zip(looks).enumerate() {
        let vertices = layer.mesh.positions.len();
        match look {
            None if layer.mesh.triangles.is_empty() => {}
            None => return bad(format!("layer {i} has triangles and no looks")),
            Some(l) if l.uv.len() != vertices => {
                return bad(format!(
                    "layer {i}: {} texture coordinates for {vertices} vertices",
                    l.uv.len()
                ))
            }
            Some(_) => {}
        }
    }
    Ok(())
}

/// Appends the texture coordinates and the images of `looks` to buffer 0 of `root` (bytes in
/// `bin`, which must be 4-aligned) with their views, accessors, images, textures and one
/// sampler; names prefixed by `prefix`. Per layer, what its primitive refers to (`None` for a
/// layer without triangles).
pub(crate) fn push_looks(
    root: &mut json::Root,
    bin: &mut Vec<u8>,
    layered: &LayeredMesh,
    looks: &[Option<LayerLooks>],
    prefix: &str,
) -> Result<Vec<Option<LookParts>>, LayersError> {
    use json::buffer::Target::ArrayBuffer;
    check_looks(layered, looks)?;
    let images: usize = looks
        .iter()
        .flatten()
        .map(|l| l.base_color.bytes.len() + 3)
        .sum();
    let bytes = layered.vertex_count() * 8 + images;
    voxlod_core::memory::check_allocation("the glTF buffer", (bin.len() + bytes) as u64)?;
    bin.reserve(bytes);
    let at = bin.len();
    for l in looks.iter().flatten() {
        for uv in &l.uv {
            bin.extend_from_slice(&uv.x.to_le_bytes());
            bin.extend_from_slice(&uv.y.to_le_bytes());
        }
    }
    let name = format!("{prefix}texture coordinates");
    let view = push_view(root, at..bin.len(), Some(8), Some(ArrayBuffer), &name);
    let sampler = root.push(json::texture::Sampler {
        mag_filter: Some(Checked::Valid(json::texture::MagFilter::Linear)),
        min_filter: Some(Checked::Valid(json::texture::MinFilter::LinearMipmapLinear)),
        name: Some(format!("{prefix}baked")),
        wrap_s: Checked::Valid(json::texture::WrappingMode::ClampToEdge),
        wrap_t: Checked::Valid(json::texture::WrappingMode::ClampToEdge),
        extensions: None,
        extras: None,
    });
    let mut first_vertex = 0usize;
    let mut out = Vec::with_capacity(looks.len());
    for (i, (layer, look)) in layered.layers.iter().zip(looks).enumerate() {
        let vertices = layer.mesh.positions.len();
        let parts = look.as_ref().map(|l| {
            let texcoords = root.push(accessor(
                view,
                first_vertex * 8,
                vertices,
                json::accessor::ComponentType::F32,
                json::accessor::Type::Vec2,
                None,
                format!("{prefix}layer {i} texture coordinates"),
            ));
            let texture = push_image(root, bin, l, sampler, &format!("{prefix}layer {i}"));
            LookParts { texcoords, texture }
        });
        if parts.is_some() {
            first_vertex += vertices;
        }
        out.push(parts);
    }
    Ok(out)
}

/// Layer `name`'s base colour image appended to `bin` (padded to four bytes) with its view,
/// image and texture.
fn push_image(
    root: &mut json::Root,
    bin: &mut Vec<u8>,
    look: &LayerLooks,
    sampler: json::Index<json::texture::Sampler>,
    name: &str,
) -> json::Index<json::Texture> {
    let at = bin.len();
    bin.extend_from_slice(&look.base_color.bytes);
    let view = push_view(
        root,
        at..bin.len(),
        None,
        None,
        &format!("{name} base colour"),
    );
    bin.resize(bin.len().next_multiple_of(4), 0);
    let image = root.push(json::Image {
        buffer_view: Some(view),
        mime_type: Some(json::image::MimeType(look.base_color.mime.clone())),
        name: Some(format!("{name} base colour")),
        uri: None,
        extensions: None,
        extras: None,
    });
    root.push(json::Texture {
        name: Some(format!("{name} base colour")),
        sampler: Some(sampler),
        source: image,
        extensions: None,
        extras: None,
    })
}

/// `material` made to take its look: the base colour texture, times white with the alpha
/// it has.
pub(crate) fn textured(material: &mut json::Material, look: &LookParts) {
    let pbr = &mut material.pbr_metallic_roughness;
    let alpha = pbr.base_color_factor.0[3];
    pbr.base_color_factor = json::material::PbrBaseColorFactor([1.0, 1.0, 1.0, alpha]);
    pbr.base_color_texture = Some(json::texture::Info {
        index: look.texture,
        tex_coord: 0,
        extensions: None,
        extras: None,
    });
}
