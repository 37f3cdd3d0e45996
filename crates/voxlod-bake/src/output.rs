//! A baked level as an asset: its atlas mesh (positions, normals, MikkTSpace tangents,
//! texture coordinates set 0), one material and its textures encoded by [`crate::encode`]
//! (PNG, or JPEG on request), which `voxlod_gltf::asset_glb` writes unchanged.
//!
//! The material: base colour texture (RGBA where the source has alpha, else RGB), normal
//! texture, an occlusion-roughness-metallic texture serving both slots where the source has
//! either (else the source's first material's factors), an emissive texture where the source
//! emits (the emissive strength restoring values above 1); alpha mode blend where a source
//! material blends or the texels' opacity was measured by view rays ([`crate::opacity`]), else
//! mask where one masks, else opaque; double-sided where any source material is and the level
//! is open (a closed level's back faces are its inside: drawn, a blended level would show
//! them through its front).
//!
//! With [`ImageFormat::Jpeg`] the base colour, ORM and emissive textures are JPEG (`.jpg`,
//! `image/jpeg`); the normal map stays PNG (JPEG's block artefacts would show as shading
//! faults), and so does a base colour whose alpha the material uses (mask or blend: JPEG has
//! no alpha), with a warning saying why.
//!
//! Cost: linear in the texels (the encoding).

use std::sync::Arc;

use voxlod_asset::{AlphaMode, Asset, AssetMesh, Image, Material, Sampler, TextureRef, Wrap};
use voxlod_core::glam::Vec4;

use crate::encode::{encode, ImageFormat};
use crate::source::Channels;
use crate::{Atlas, BakeError};

/// One texel's baked values, 8-bit, as the textures store them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TexelValues {
    /// Base colour, sRGB, with linear alpha.
    pub base: [u8; 4],
    /// Tangent-space normal, (n + 1) / 2.
    pub normal: [u8; 4],
    /// Occlusion, roughness, metalness.
    pub orm: [u8; 4],
    /// Emissive, sRGB, over the material's emissive strength.
    pub emissive: [u8; 4],
}

/// The baked texels and what they hold.
pub struct Textures<'a> {
    /// Texels across.
    pub width: u32,
    /// Texels down.
    pub height: u32,
    /// Row by row from the top.
    pub values: &'a [TexelValues],
    /// Which textures to write beyond base colour and normal.
    pub channels: Channels,
    /// Whether the base colour's alpha is an opacity measured by view rays (drawn blended).
    pub opacity_measured: bool,
    /// Whether the level has an open edge (it may be seen from its back).
    pub level_open: bool,
    /// What the emissive texture's 1 stands for.
    pub emissive_scale: f32,
    /// How the colour-like textures are encoded (the normal map is PNG either way).
    pub format: ImageFormat,
}

/// The level as an asset with its baked material (see the module documentation), and the
/// warnings of its encoding (a base colour kept PNG for its alpha). Fails where a texture
/// cannot be encoded.
pub fn proxy_asset(
    atlas: &Atlas,
    tangents: &[Vec4],
    textures: &Textures,
    source: &Asset,
) -> Result<(Asset, Vec<String>), BakeError> {
    let mut images = Vec::new();
    let mut slot = |name: &'static str,
                    what: &'static str,
                    channels: usize,
                    format: ImageFormat,
                    pick: fn(&TexelValues) -> [u8; 4]| {
        let bytes = encoded(textures, what, channels, format, pick)?;
        images.push(Image {
            name: format!("{name}.{}", format.extension()),
            mime: format.mime().into(),
            bytes: Arc::new(bytes),
        });
        Ok::<_, BakeError>(Some(TextureRef {
            image: images.len() - 1,
            tex_coord: 0,
            transform: None,
            sampler: Sampler {
                wrap_u: Wrap::ClampToEdge,
                wrap_v: Wrap::ClampToEdge,
                linear: true,
            },
        }))
    };
    let c = textures.channels;
    let colour = textures.format;
    let (base_format, warnings) = base_colour_format(colour, c.alpha);
    let alpha_channels = if c.alpha { 4 } else { 3 };
    let first = source.materials.first().cloned().unwrap_or_default();
    let mut material = Material {
        name: "baked".into(),
        base_color_texture: slot(
            "base_color",
            "base colour",
            alpha_channels,
            base_format,
            |v| v.base,
        )?,
        normal_texture: slot("normal", "normal", 3, ImageFormat::Png, |v| v.normal)?,
        metallic: first.metallic,
        roughness: first.roughness,
        alpha_mode: alpha_mode(&source.materials, textures.opacity_measured),
        alpha_cutoff: first.alpha_cutoff,
        double_sided: textures.level_open && source.materials.iter().any(|m| m.double_sided),
        ..Material::default()
    };
    if c.metallic_roughness || c.occlusion {
        let orm = slot("occlusion_roughness_metallic", "ORM", 3, colour, |v| v.orm)?;
        if c.occlusion {
            material.occlusion_texture = orm.clone();
        }
        (material.metallic, material.roughness) = (1.0, 1.0);
        material.metallic_roughness_texture = orm;
    }
    if c.emissive {
        material.emissive_texture = slot("emissive", "emissive", 3, colour, |v| v.emissive)?;
        material.emissive = [1.0; 3];
        material.emissive_strength = textures.emissive_scale;
    }
    let n = atlas.triangles.len();
    let asset = Asset {
        mesh: AssetMesh {
            positions: atlas.positions.clone(),
            triangles: atlas.triangles.clone(),
            normals: atlas.normals.clone(),
            tangents: tangents.to_vec(),
            uv: [atlas.uv.clone(), Vec::new()],
            colors: Vec::new(),
            material: vec![0; n],
        },
        materials: vec![material],
        images,
        parts: Vec::new(),
    };
    Ok((asset, warnings))
}

/// The base colour texture's format when the others are in `format`: PNG where `alpha` is
/// used and `format` is not PNG (JPEG has no alpha channel), with a warning saying so.
fn base_colour_format(format: ImageFormat, alpha: bool) -> (ImageFormat, Vec<String>) {
    if !alpha || format == ImageFormat::Png {
        return (format, Vec::new());
    }
    let why = "the base colour texture stays PNG: the material masks or blends by its alpha, \
               which JPEG cannot store";
    (ImageFormat::Png, vec![why.to_string()])
}

/// The alpha mode of a proxy of these materials, its opacity measured by view rays or not.
fn alpha_mode(materials: &[Material], opacity_measured: bool) -> AlphaMode {
    let any = |mode| materials.iter().any(|m| m.alpha_mode == mode);
    if opacity_measured || any(AlphaMode::Blend) {
        AlphaMode::Blend
    } else if any(AlphaMode::Mask) {
        AlphaMode::Mask
    } else {
        AlphaMode::Opaque
    }
}

/// One texture encoded in `format`: the first `channels` of each texel's `pick`.
fn encoded(
    textures: &Textures,
    what: &'static str,
    channels: usize,
    format: ImageFormat,
    pick: fn(&TexelValues) -> [u8; 4],
) -> Result<Vec<u8>, BakeError> {
    let raw: Vec<u8> = textures
        .values
        .iter()
        .flat_map(|v| pick(v).into_iter().take(channels))
        .collect();
    encode(
        &raw,
        textures.width,
        textures.height,
        channels,
        format,
        what,
    )
}
