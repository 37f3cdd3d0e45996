//! The asset: one mesh in world space that carries its looks, with the materials and images it
//! uses. Every primitive of every node instance of a scene goes into the one mesh (node
//! transforms applied, instances repeated), because a level of detail is made of the whole
//! asset at once; [`Part`] remembers where each primitive went, and the material per triangle
//! splits the mesh back into primitives when it is written.
//!
//! Vertices are not welded: a vertex on a texture seam, a normal crease or a material border
//! appears once per side, as glTF stores it, so that a level made from the input's own vertices
//! (meshoptimizer's `simplifyWithAttributes` treats vertices at one position as a seam, as
//! Varshney et al. keep the levels' vertices a subset of the input's) keeps every side's
//! attributes. The geometry-only stages take [`AssetMesh::geometry`].

use std::sync::Arc;

use serde::{Deserialize, Serialize};
use voxlod_core::glam::{Vec2, Vec3, Vec4};
use voxlod_core::TriangleMesh;

use crate::AssetError;

/// An asset: its mesh, the materials its triangles name and the images those use.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Asset {
    /// Every primitive of every node instance, in world space.
    pub mesh: AssetMesh,
    /// The materials; [`AssetMesh::material`] indexes them.
    pub materials: Vec<Material>,
    /// The images; [`TextureRef::image`] indexes them.
    pub images: Vec<Image>,
    /// Where each primitive of the input went in the mesh, in reading order.
    pub parts: Vec<Part>,
}

/// A triangle mesh with per-vertex attributes and a material per triangle. An attribute is
/// either empty (the asset has none) or holds one value per vertex.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AssetMesh {
    /// Vertex positions, in world units.
    pub positions: Vec<Vec3>,
    /// Three vertex indices per triangle, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
    /// Unit shading normals.
    pub normals: Vec<Vec3>,
    /// Tangents: xyz unit, w ±1 the bitangent's sign (glTF's `TANGENT`).
    pub tangents: Vec<Vec4>,
    /// Texture coordinate sets 0 and 1 (glTF's `TEXCOORD_0`, `TEXCOORD_1`), with v pointing
    /// down the image as glTF has it.
    pub uv: [Vec<Vec2>; 2],
    /// Linear RGBA vertex colours (glTF's `COLOR_0`).
    pub colors: Vec<Vec4>,
    /// The material of each triangle, an index into [`Asset::materials`]; empty when the asset
    /// has no materials.
    pub material: Vec<u32>,
}

/// Where one primitive of the input went in [`Asset::mesh`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Part {
    /// The node's name, or its mesh's, or `node N`.
    pub name: String,
    /// Its triangles are `first_triangle..first_triangle + triangle_count`.
    pub first_triangle: u32,
    /// How many triangles it has.
    pub triangle_count: u32,
}

/// How a material's alpha is used (glTF's `alphaMode`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "UPPERCASE")]
pub enum AlphaMode {
    /// Alpha ignored.
    #[default]
    Opaque,
    /// Drawn where alpha is at least [`Material::alpha_cutoff`].
    Mask,
    /// Blended.
    Blend,
}

/// A physically based metallic-roughness material, as glTF 2.0 defines it, with the
/// `KHR_materials_emissive_strength` factor. Colour factors are linear.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Material {
    /// Its name (may be empty).
    pub name: String,
    /// Base colour factor, linear RGBA.
    pub base_color: [f32; 4],
    /// Base colour texture (sRGB), multiplied by the factor and the vertex colour.
    pub base_color_texture: Option<TextureRef>,
    /// Metalness factor in 0..=1.
    pub metallic: f32,
    /// Roughness factor in 0..=1.
    pub roughness: f32,
    /// Roughness in green, metalness in blue.
    pub metallic_roughness_texture: Option<TextureRef>,
    /// Tangent-space normal map.
    pub normal_texture: Option<TextureRef>,
    /// The normal map's xy scale.
    pub normal_scale: f32,
    /// Ambient occlusion in red.
    pub occlusion_texture: Option<TextureRef>,
    /// How much of the occlusion applies, 0..=1.
    pub occlusion_strength: f32,
    /// Emissive factor, linear RGB.
    pub emissive: [f32; 3],
    /// Multiplies the emissive factor (`KHR_materials_emissive_strength`; 1 without it).
    pub emissive_strength: f32,
    /// Emissive texture (sRGB).
    pub emissive_texture: Option<TextureRef>,
    /// How alpha is used.
    pub alpha_mode: AlphaMode,
    /// The cutoff of [`AlphaMode::Mask`].
    pub alpha_cutoff: f32,
    /// Whether back faces are drawn.
    pub double_sided: bool,
}

impl Default for Material {
    /// glTF's default material: white, fully metallic and rough, opaque, one-sided.
    fn default() -> Self {
        Material {
            name: String::new(),
            base_color: [1.0; 4],
            base_color_texture: None,
            metallic: 1.0,
            roughness: 1.0,
            metallic_roughness_texture: None,
            normal_texture: None,
            normal_scale: 1.0,
            occlusion_texture: None,
            occlusion_strength: 1.0,
            emissive: [0.0; 3],
            emissive_strength: 1.0,
            emissive_texture: None,
            alpha_mode: AlphaMode::Opaque,
            alpha_cutoff: 0.5,
            double_sided: false,
        }
    }
}

impl Material {
    /// Every texture the material uses, with the slot's name.
    pub fn textures(&self) -> impl Iterator<Item = (&'static str, &TextureRef)> {
        [
            ("baseColorTexture", &self.base_color_texture),
            ("metallicRoughnessTexture", &self.metallic_roughness_texture),
            ("normalTexture", &self.normal_texture),
            ("occlusionTexture", &self.occlusion_texture),
            ("emissiveTexture", &self.emissive_texture),
        ]
        .into_iter()
        .filter_map(|(name, t)| t.as_ref().map(|t| (name, t)))
    }

    /// The material without its textures, for a surface that has no texture coordinates of
    /// the input's (a voxel or clustering level): its factors kept, the base colour factor
    /// white since the level's vertex colours carry it.
    pub fn untextured(&self) -> Material {
        Material {
            name: self.name.clone(),
            base_color: [1.0; 4],
            metallic: self.metallic,
            roughness: self.roughness,
            emissive: self.emissive,
            emissive_strength: self.emissive_strength,
            alpha_mode: self.alpha_mode,
            alpha_cutoff: self.alpha_cutoff,
            double_sided: self.double_sided,
            ..Material::default()
        }
    }
}

/// A material's use of an image.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TextureRef {
    /// Index into [`Asset::images`].
    pub image: usize,
    /// Which texture coordinate set it reads (0 or 1).
    #[serde(default)]
    pub tex_coord: u32,
    /// `KHR_texture_transform`, when the slot has one.
    #[serde(default)]
    pub transform: Option<TextureTransform>,
    /// How it wraps and filters.
    #[serde(default)]
    pub sampler: Sampler,
}

/// `KHR_texture_transform`: texture coordinates scaled, then rotated, then offset.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct TextureTransform {
    /// Added last.
    pub offset: [f32; 2],
    /// Counter-clockwise rotation in radians (in the image's u-right, v-down frame, as the
    /// extension defines it).
    pub rotation: f32,
    /// Applied first.
    pub scale: [f32; 2],
    /// The texture coordinate set that replaces the slot's own, if given.
    pub tex_coord: Option<u32>,
}

impl TextureTransform {
    /// The coordinates the texture is read at for the vertex coordinates `uv`.
    pub fn apply(&self, uv: Vec2) -> Vec2 {
        let s = Vec2::new(uv.x * self.scale[0], uv.y * self.scale[1]);
        let (sin, cos) = self.rotation.sin_cos();
        let r = Vec2::new(cos * s.x + sin * s.y, -sin * s.x + cos * s.y);
        r + Vec2::from(self.offset)
    }
}

/// How a texture wraps outside 0..1 (glTF's sampler wrap modes).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Wrap {
    /// Tiles (glTF's default).
    #[default]
    Repeat,
    /// Tiles mirrored.
    MirroredRepeat,
    /// Clamps to the edge.
    ClampToEdge,
}

/// A texture's sampler: wrap per axis and whether it is magnified smoothly.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Sampler {
    /// Wrap along u.
    pub wrap_u: Wrap,
    /// Wrap along v.
    pub wrap_v: Wrap,
    /// Nearest (false) or linear (true) magnification.
    pub linear: bool,
}

impl Default for Sampler {
    fn default() -> Self {
        Sampler {
            wrap_u: Wrap::Repeat,
            wrap_v: Wrap::Repeat,
            linear: true,
        }
    }
}

/// An image as the file stores it: encoded bytes (PNG, JPEG, KTX2, …), copied to the output
/// unchanged and decoded only where a stage samples it.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Its name or file name (may be empty).
    pub name: String,
    /// Its media type: `image/png`, `image/jpeg`, `image/ktx2`, …
    pub mime: String,
    /// The encoded bytes, shared between the levels that write them.
    pub bytes: Arc<Vec<u8>>,
}

impl AssetMesh {
    /// The mesh as geometry only: positions and triangles (normals kept), for the stages that
    /// work on positions (marching cubes through the solid, clustering, envelopes, measures).
    pub fn geometry(&self) -> TriangleMesh {
        TriangleMesh {
            positions: self.positions.clone(),
            normals: self.normals.clone(),
            triangles: self.triangles.clone(),
        }
    }

    /// The mesh's attributes that are present, by glTF name.
    pub fn attribute_names(&self) -> Vec<&'static str> {
        let n = |v: usize, name| (v > 0).then_some(name);
        [
            n(self.normals.len(), "NORMAL"),
            n(self.tangents.len(), "TANGENT"),
            n(self.uv[0].len(), "TEXCOORD_0"),
            n(self.uv[1].len(), "TEXCOORD_1"),
            n(self.colors.len(), "COLOR_0"),
        ]
        .into_iter()
        .flatten()
        .collect()
    }
}

impl Asset {
    /// Checks the invariants: each attribute empty or one per vertex, one material per
    /// triangle (or none and no materials), indices in range, positions and attributes finite,
    /// texture references naming an image and a coordinate set the mesh has. The error names
    /// the first broken one. Cost: linear.
    pub fn validate(&self) -> Result<(), AssetError> {
        let mesh = &self.mesh;
        let n = mesh.positions.len();
        let bad = |s: String| Err(AssetError::Invalid(s));
        let lengths = [
            ("normals", mesh.normals.len()),
            ("tangents", mesh.tangents.len()),
            ("texture coordinates 0", mesh.uv[0].len()),
            ("texture coordinates 1", mesh.uv[1].len()),
            ("colours", mesh.colors.len()),
        ];
        for (what, len) in lengths {
            if len != 0 && len != n {
                return bad(format!("{len} {what} for {n} vertices"));
            }
        }
        if let Some(i) = mesh.positions.iter().position(|p| !p.is_finite()) {
            return bad(format!("vertex {i} is not finite: {}", mesh.positions[i]));
        }
        let finite = mesh.normals.iter().all(|v| v.is_finite())
            && mesh.tangents.iter().all(|v| v.is_finite())
            && mesh.uv.iter().flatten().all(|v| v.is_finite())
            && mesh.colors.iter().all(|v| v.is_finite());
        if !finite {
            return bad("a vertex attribute is not finite".into());
        }
        if let Some(t) = mesh
            .triangles
            .iter()
            .position(|t| t.iter().any(|&i| i as usize >= n))
        {
            return bad(format!(
                "triangle {t} names a vertex beyond the {n} vertices"
            ));
        }
        self.validate_materials()
    }

    fn validate_materials(&self) -> Result<(), AssetError> {
        let mesh = &self.mesh;
        let bad = |s: String| Err(AssetError::Invalid(s));
        let (m, t) = (mesh.material.len(), mesh.triangles.len());
        if !(m == t || (m == 0 && self.materials.is_empty())) {
            return bad(format!("{m} triangle materials for {t} triangles"));
        }
        if let Some(i) = mesh
            .material
            .iter()
            .position(|&k| k as usize >= self.materials.len())
        {
            return bad(format!(
                "triangle {i} names material {} of {}",
                mesh.material[i],
                self.materials.len()
            ));
        }
        // A material no triangle uses (a file's spare one) needs no texture coordinates.
        let mut used = vec![false; self.materials.len()];
        for &k in &mesh.material {
            used[k as usize] = true;
        }
        for (k, material) in self.materials.iter().enumerate() {
            for (slot, texture) in material.textures() {
                let set = texture
                    .transform
                    .and_then(|t| t.tex_coord)
                    .unwrap_or(texture.tex_coord);
                if texture.image >= self.images.len() {
                    return bad(format!("material {k}'s {slot} names a missing image"));
                }
                if set > 1 || (mesh.uv[set as usize].is_empty() && used[k]) {
                    return bad(format!(
                        "material {k}'s {slot} reads texture coordinates {set}, which the mesh \
                         does not have"
                    ));
                }
            }
        }
        Ok(())
    }

    /// The material of triangle `t`, if the asset has materials.
    pub fn material_of(&self, t: usize) -> Option<&Material> {
        self.mesh
            .material
            .get(t)
            .map(|&k| &self.materials[k as usize])
    }
}
