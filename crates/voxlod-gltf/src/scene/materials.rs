//! A glTF document's metallic-roughness materials and images, as `voxlod_asset` holds them:
//! factors, the five texture slots with their texture coordinate set, sampler and
//! `KHR_texture_transform` (read from the JSON, since the `gltf` crate gives the transform of
//! two slots only), `KHR_materials_emissive_strength`, alpha mode and sidedness; images as their
//! encoded bytes (from a buffer view, a data URI or a file beside the glTF file), their media
//! type as declared or recognised from the bytes. Cost: linear in the images' bytes.

use std::path::Path;
use std::sync::Arc;

use gltf::texture::{MagFilter, WrappingMode};
use gltf::Document;
use serde_json::Value;
use voxlod_asset::{AlphaMode, Image, Material, Sampler, TextureRef, TextureTransform, Wrap};

use super::buffers::uri_bytes;
use crate::GltfError;

/// Every material of the document, in order.
pub(crate) fn materials(doc: &Document, json: &Value) -> Vec<Material> {
    doc.materials()
        .map(|m| {
            let i = m.index().unwrap_or(0);
            let j = &json["materials"][i];
            let pbr = m.pbr_metallic_roughness();
            let slot = |t: Option<gltf::texture::Info>, path: &[&str]| {
                t.map(|t| texture_ref(&t.texture(), t.tex_coord(), at(j, path)))
            };
            Material {
                name: m.name().unwrap_or_default().to_string(),
                base_color: pbr.base_color_factor(),
                base_color_texture: slot(
                    pbr.base_color_texture(),
                    &["pbrMetallicRoughness", "baseColorTexture"],
                ),
                metallic: pbr.metallic_factor(),
                roughness: pbr.roughness_factor(),
                metallic_roughness_texture: slot(
                    pbr.metallic_roughness_texture(),
                    &["pbrMetallicRoughness", "metallicRoughnessTexture"],
                ),
                normal_texture: m
                    .normal_texture()
                    .map(|t| texture_ref(&t.texture(), t.tex_coord(), at(j, &["normalTexture"]))),
                normal_scale: m.normal_texture().map_or(1.0, |t| t.scale()),
                occlusion_texture: m.occlusion_texture().map(|t| {
                    texture_ref(&t.texture(), t.tex_coord(), at(j, &["occlusionTexture"]))
                }),
                occlusion_strength: m.occlusion_texture().map_or(1.0, |t| t.strength()),
                emissive: m.emissive_factor(),
                emissive_strength: j["extensions"]["KHR_materials_emissive_strength"]
                    ["emissiveStrength"]
                    .as_f64()
                    .map_or(1.0, |s| s as f32),
                emissive_texture: slot(m.emissive_texture(), &["emissiveTexture"]),
                alpha_mode: match m.alpha_mode() {
                    gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
                    gltf::material::AlphaMode::Mask => AlphaMode::Mask,
                    gltf::material::AlphaMode::Blend => AlphaMode::Blend,
                },
                alpha_cutoff: m.alpha_cutoff().unwrap_or(0.5),
                double_sided: m.double_sided(),
            }
        })
        .collect()
}

/// Gives each texture whose `KHR_texture_basisu` extension names a KTX2 image and that has no
/// `source` that image as its `source`, so the `gltf` crate's validation takes it and the image
/// is read with its bytes unchanged. A texture with both keeps its fallback `source`; its KTX2
/// image stays among the images, used by no texture, with a warning naming both.
/// Cost: linear in the textures.
pub(crate) fn basisu_sources(json: &mut Value) -> Vec<String> {
    let mut warnings = Vec::new();
    let textures = json
        .get_mut("textures")
        .and_then(Value::as_array_mut)
        .into_iter()
        .flatten();
    for (t, texture) in textures.enumerate() {
        let Some(ktx2) = texture["extensions"]["KHR_texture_basisu"]["source"].as_u64() else {
            continue;
        };
        match texture["source"].as_u64() {
            Some(fallback) => warnings.push(format!(
                "texture {t}: its fallback image {fallback} is read; its KTX2 image {ktx2} \
                 (KHR_texture_basisu) is kept but no texture uses it"
            )),
            None => texture["source"] = Value::from(ktx2),
        }
    }
    warnings
}

/// The JSON at a path of keys.
fn at<'a>(v: &'a Value, path: &[&str]) -> &'a Value {
    path.iter().fold(v, |v, k| &v[*k])
}

/// A texture slot: its image, coordinate set, sampler and transform (from the slot's JSON).
fn texture_ref(t: &gltf::Texture, tex_coord: u32, slot: &Value) -> TextureRef {
    let s = t.sampler();
    let wrap = |w: WrappingMode| match w {
        WrappingMode::ClampToEdge => Wrap::ClampToEdge,
        WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
        WrappingMode::Repeat => Wrap::Repeat,
    };
    let x = &slot["extensions"]["KHR_texture_transform"];
    let pair = |v: &Value, d: f32| [0, 1].map(|k| v[k].as_f64().map_or(d, |f| f as f32));
    let transform = x.is_object().then(|| TextureTransform {
        offset: pair(&x["offset"], 0.0),
        rotation: x["rotation"].as_f64().unwrap_or(0.0) as f32,
        scale: pair(&x["scale"], 1.0),
        tex_coord: x["texCoord"].as_u64().map(|k| k as u32),
    });
    TextureRef {
        image: t.source().index(),
        tex_coord,
        transform,
        sampler: Sampler {
            wrap_u: wrap(s.wrap_s()),
            wrap_v: wrap(s.wrap_t()),
            linear: s.mag_filter() != Some(MagFilter::Nearest),
        },
    }
}

/// Every image's encoded bytes and media type. Read from the JSON rather than through
/// `gltf::Image::source`, which panics on an image with a view and no media type, or with
/// neither a view nor a URI (gltf 1.4.1); such images are errors here.
pub(crate) fn images(
    doc: &Document,
    json: &Value,
    buffers: &[Vec<u8>],
    base: Option<&Path>,
) -> Result<Vec<Image>, GltfError> {
    let declared = json["images"].as_array().map_or(&[][..], Vec::as_slice);
    declared
        .iter()
        .enumerate()
        .map(|(i, image)| {
            let here = |e: GltfError| match e {
                GltfError::Invalid(m) => GltfError::Invalid(format!("image {i}: {m}")),
                other => other,
            };
            let (bytes, name) = match (image["bufferView"].as_u64(), image["uri"].as_str()) {
                (Some(v), _) => {
                    let view = doc.views().nth(v as usize).ok_or_else(|| {
                        GltfError::Invalid(format!("image {i}: buffer view {v} does not exist"))
                    })?;
                    let buffer = &buffers[view.buffer().index()];
                    let end = view.offset().checked_add(view.length());
                    let bytes =
                        end.and_then(|e| buffer.get(view.offset()..e))
                            .ok_or_else(|| {
                                GltfError::Invalid(format!(
                                    "image {i}: its view reaches beyond its buffer"
                                ))
                            })?;
                    (bytes.to_vec(), String::new())
                }
                (None, Some(uri)) => {
                    let name = if uri.starts_with("data:") {
                        String::new()
                    } else {
                        uri.to_string()
                    };
                    (uri_bytes(uri, base).map_err(here)?, name)
                }
                (None, None) => {
                    return Err(GltfError::Invalid(format!(
                        "image {i} has neither a buffer view nor a URI"
                    )))
                }
            };
            let mime = image["mimeType"]
                .as_str()
                .map(str::to_string)
                .or_else(|| sniff(&bytes))
                .unwrap_or_default();
            let name = image["name"].as_str().map(str::to_string).unwrap_or(name);
            Ok(Image {
                name,
                mime,
                bytes: Arc::new(bytes),
            })
        })
        .collect()
}

/// The media type the bytes' signature gives.
fn sniff(bytes: &[u8]) -> Option<String> {
    let kind = if bytes.starts_with(b"\x89PNG\r\n\x1a\n") {
        "image/png"
    } else if bytes.starts_with(&[0xFF, 0xD8, 0xFF]) {
        "image/jpeg"
    } else if bytes.starts_with(b"\xABKTX 20\xBB") {
        "image/ktx2"
    } else if bytes.len() >= 12 && &bytes[..4] == b"RIFF" && &bytes[8..12] == b"WEBP" {
        "image/webp"
    } else {
        return None;
    };
    Some(kind.to_string())
}
