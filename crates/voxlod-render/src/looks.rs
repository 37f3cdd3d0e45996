//! Assets drawn with their looks ([`AssetItem`]): the colour of a sample is the material's
//! base colour factor × the vertex colour × the base colour texture (glTF 2.0 §3.9.2), lit
//! like every mesh of the scene (two-sided Lambert from the interpolated vertex normals, or
//! flat from the face when the asset has none), written linear and encoded sRGB by
//! [`crate::Image::to_png`].
//!
//! Vertex colours and texture coordinates are interpolated perspective-correctly (weights
//! `λ_k w_k / Σ λ_j w_j` with the vertices' 1/w), the texture read bilinearly (or nearest, as the
//! sampler says) with its wrap modes and `KHR_texture_transform`, from the one decoded level
//! (no mipmaps: a texture minified far aliases; supersampling averages it). Alpha follows the
//! material's mode: ignored (`OPAQUE`), the sample dropped below the cutoff (`MASK`, writing
//! neither colour nor depth), or blended after everything opaque in storage order with no depth
//! write (`BLEND`; a single-sided blended triangle seen from its back is culled). A triangle without a material takes glTF's default, white. Where the asset
//! comes with its normal maps ([`AssetItem::with_normal_maps`]) and has normals and tangents,
//! a sample is shaded from its normal bent by the map (glTF 2.0 §3.9.3), as a viewer such as
//! three.js draws it, rather than from the vertices' shades. Metalness, roughness, occlusion and
//! emissive maps are not drawn.
//!
//! Plain meshes ([`crate::MeshItem`]) do not pass through here: their fill stays the
//! shade-times-palette loop of [`crate::raster::raster_triangle`].
//!
//! Cost: per covered sample, one texture read (four texels) and the interpolation of the
//! attributes the asset has.

use glam::{Vec2, Vec3, Vec4};
use voxlod_asset::texture::{bend_normal, decode_base_colours, Texels};
use voxlod_asset::{AlphaMode, Asset, AssetError, Material};

use crate::RenderError;

/// An asset to draw with its looks, and the decoded base colour texture of each of its
/// materials.
#[derive(Clone, Copy, Debug)]
pub struct AssetItem<'a> {
    /// The asset (validated when the scene is drawn).
    pub asset: &'a Asset,
    /// One entry per material of the asset, `None` where the material has no base colour
    /// texture or it could not be decoded (its factor stands in); or empty: factors only.
    pub textures: &'a [Option<Texels>],
    /// One entry per material, its normal map decoded as data
    /// (`voxlod_asset::texture::decode_normal_maps`); or empty: no normal map drawn.
    pub normal_maps: &'a [Option<Texels>],
}

/// The decoded base colour textures of an asset's materials, for [`AssetItem::textures`], and
/// a warning for each image that could not be decoded (KTX2, WebP, corrupt bytes: the factor
/// stands in). Fails only when the memory budget refuses an image.
pub fn decode_textures(asset: &Asset) -> Result<(Vec<Option<Texels>>, Vec<String>), RenderError> {
    decode_base_colours(asset).map_err(|e| match e {
        AssetError::Core(c) => RenderError::Core(c),
        other => RenderError::Invalid(other.to_string()),
    })
}

/// The normal maps of an asset's materials decoded as data, for
/// [`AssetItem::with_normal_maps`], and a warning for each image that could not be decoded
/// (its normal map is not drawn). Fails only when the memory budget refuses an image.
pub fn decode_normal_maps(
    asset: &Asset,
) -> Result<(Vec<Option<Texels>>, Vec<String>), RenderError> {
    voxlod_asset::texture::decode_normal_maps(asset).map_err(|e| match e {
        AssetError::Core(c) => RenderError::Core(c),
        other => RenderError::Invalid(other.to_string()),
    })
}

impl<'a> AssetItem<'a> {
    /// `asset` with `textures` (from [`decode_textures`], or empty).
    pub fn new(asset: &'a Asset, textures: &'a [Option<Texels>]) -> AssetItem<'a> {
        AssetItem {
            asset,
            textures,
            normal_maps: &[],
        }
    }

    /// The item with its materials' normal maps drawn (one entry per material, or empty).
    pub fn with_normal_maps(self, normal_maps: &'a [Option<Texels>]) -> AssetItem<'a> {
        AssetItem {
            normal_maps,
            ..self
        }
    }

    /// Whether triangle `tri` is drawn blended (its material's mode is `BLEND`).
    #[inline]
    pub(crate) fn blends(&self, tri: usize) -> bool {
        self.asset
            .material_of(tri)
            .is_some_and(|m| m.alpha_mode == AlphaMode::Blend)
    }

    /// Whether triangle `tri` is culled where its back faces the camera: its material is
    /// blended and single-sided (glTF 2.0 §3.9.4: back-face culling unless `doubleSided`).
    /// Opaque and masked triangles are not culled: the depth test hides a closed mesh's back
    /// faces, where blended ones, drawn without depth writes, would show through its front.
    #[inline]
    pub(crate) fn culls_back(&self, tri: usize) -> bool {
        self.asset
            .material_of(tri)
            .is_some_and(|m| m.alpha_mode == AlphaMode::Blend && !m.double_sided)
    }

    pub(crate) fn check(&self, i: usize) -> Result<(), RenderError> {
        self.asset
            .validate()
            .map_err(|e| RenderError::Invalid(format!("asset {i}: {e}")))?;
        let m = self.asset.materials.len();
        for (t, what) in [
            (self.textures.len(), "textures"),
            (self.normal_maps.len(), "normal maps"),
        ] {
            if t != 0 && t != m {
                return Err(RenderError::Invalid(format!(
                    "asset {i}: {t} {what} for {m} materials"
                )));
            }
        }
        Ok(())
    }

    /// The shader of triangle `tri`: its vertices' attributes gathered once; `lit` shades a
    /// unit normal (for a normal-mapped triangle's samples).
    #[inline]
    pub(crate) fn triangle(&self, tri: usize, lit: Lit) -> TriangleLooks<'a> {
        static DEFAULT: std::sync::OnceLock<Material> = std::sync::OnceLock::new();
        let mesh = &self.asset.mesh;
        let corners = mesh.triangles[tri].map(|v| v as usize);
        let material = match self.asset.material_of(tri) {
            Some(m) => m,
            None => DEFAULT.get_or_init(Material::default),
        };
        let colors = (!mesh.colors.is_empty()).then(|| corners.map(|v| mesh.colors[v]));
        let texture = material.base_color_texture.as_ref().and_then(|slot| {
            let (texels, uv) = self.mapped(tri, slot, self.textures, corners)?;
            Some((texels, slot, uv))
        });
        TriangleLooks {
            factor: Vec4::from(material.base_color),
            colors,
            texture,
            bumps: self.bumps(tri, material, corners).map(|b| (b, lit)),
            mode: material.alpha_mode,
            cutoff: material.alpha_cutoff,
        }
    }

    /// The decoded texture of `slot` for triangle `tri` (from `maps`, one per material) and
    /// its corners' coordinates in the slot's set; `None` where either is missing.
    fn mapped(
        &self,
        tri: usize,
        slot: &voxlod_asset::TextureRef,
        maps: &'a [Option<Texels>],
        corners: [usize; 3],
    ) -> Option<(&'a Texels, [Vec2; 3])> {
        let mesh = &self.asset.mesh;
        let k = mesh.material.get(tri).copied()? as usize;
        let texels = maps.get(k)?.as_ref()?;
        let set = slot
            .transform
            .and_then(|t| t.tex_coord)
            .unwrap_or(slot.tex_coord);
        let uv = mesh.uv.get(set as usize).filter(|uv| !uv.is_empty())?;
        Some((texels, corners.map(|v| uv[v])))
    }

    /// What the normal map of triangle `tri` needs, where it is drawn: the map, its slot and
    /// scale, and the corners' coordinates, normals and tangents.
    fn bumps(&self, tri: usize, material: &'a Material, corners: [usize; 3]) -> Option<Bumps<'a>> {
        let mesh = &self.asset.mesh;
        let slot = material.normal_texture.as_ref()?;
        let (texels, uv) = self.mapped(tri, slot, self.normal_maps, corners)?;
        let n = mesh.positions.len();
        if mesh.normals.len() != n || mesh.tangents.len() != n {
            return None;
        }
        Some(Bumps {
            texels,
            slot,
            scale: material.normal_scale,
            uv,
            normals: corners.map(|v| mesh.normals[v]),
            tangents: corners.map(|v| mesh.tangents[v]),
        })
    }
}

/// How a sample's unit normal is lit: `ambient + (1 − ambient) |n · light|`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Lit {
    pub(crate) light: Vec3,
    pub(crate) ambient: f32,
}

/// A normal-mapped triangle's map and corners.
pub(crate) struct Bumps<'a> {
    texels: &'a Texels,
    slot: &'a voxlod_asset::TextureRef,
    scale: f32,
    uv: [Vec2; 3],
    normals: [Vec3; 3],
    tangents: [Vec4; 3],
}

impl Bumps<'_> {
    /// The shade of the sample with weights `w`: its interpolated normal bent by the map.
    #[inline]
    fn shade(&self, w: [f32; 3], lit: Lit) -> f32 {
        let mix3 = |v: &[Vec3; 3]| v[0] * w[0] + v[1] * w[1] + v[2] * w[2];
        let Some(n) = mix3(&self.normals).try_normalize() else {
            return lit.ambient;
        };
        let t = self.tangents[0] * w[0] + self.tangents[1] * w[1] + self.tangents[2] * w[2];
        let uv = self.uv[0] * w[0] + self.uv[1] * w[1] + self.uv[2] * w[2];
        let m = self.texels.sample(self.slot, uv);
        let bent = bend_normal(n, t, m, self.scale);
        let ambient = lit.ambient.clamp(0.0, 1.0);
        ambient + (1.0 - ambient) * bent.dot(lit.light).abs()
    }
}

/// What one triangle's samples need: the material's factor, mode and cutoff, the corners'
/// colours and texture coordinates.
pub(crate) struct TriangleLooks<'a> {
    factor: Vec4,
    colors: Option<[Vec4; 3]>,
    texture: Option<(&'a Texels, &'a voxlod_asset::TextureRef, [Vec2; 3])>,
    bumps: Option<(Bumps<'a>, Lit)>,
    mode: AlphaMode,
    cutoff: f32,
}

impl TriangleLooks<'_> {
    /// The linear RGBA of a sample with perspective-correct weights `w` and Lambert `shade`
    /// (the normal map's instead, where it is drawn), or `None` where `MASK` drops it.
    #[inline]
    pub(crate) fn sample(&self, w: [f32; 3], shade: f32) -> Option<[f32; 4]> {
        let mut c = self.factor;
        if let Some(k) = &self.colors {
            c *= k[0] * w[0] + k[1] * w[1] + k[2] * w[2];
        }
        if let Some((texels, slot, uv)) = &self.texture {
            c *= texels.sample(slot, uv[0] * w[0] + uv[1] * w[1] + uv[2] * w[2]);
        }
        let alpha = match self.mode {
            AlphaMode::Opaque => 1.0,
            AlphaMode::Mask if c.w < self.cutoff => return None,
            AlphaMode::Mask => 1.0,
            AlphaMode::Blend => c.w.clamp(0.0, 1.0),
        };
        let shade = self
            .bumps
            .as_ref()
            .map_or(shade, |(b, lit)| b.shade(w, *lit));
        Some([c.x * shade, c.y * shade, c.z * shade, alpha])
    }
}
