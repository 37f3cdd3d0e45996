//! What the source shows at a point of one of its triangles, as glTF 2.0's metallic-roughness
//! material defines it (§3.9): base colour = vertex colour × factor × texture (linear, the
//! texture's sRGB undone), the shading normal (interpolated, bent by the normal map in the
//! source's tangent frame), occlusion (1 + strength × (texture − 1)), roughness and metalness
//! (factors × the texture's green and blue), emissive (factor × strength × texture).
//!
//! Textures are decoded once each (`voxlod_asset::texture`) and kept as mipmaps
//! ([`crate::mipmaps`]): a look is asked for a footprint, the size of the bake's texel on the
//! surface, and each texture is sampled at the level whose texels are that large on the source
//! triangle, so that a finely tiled texture is averaged rather than aliased. Colour textures
//! are sampled in linear light, data textures (normal, metallic-roughness, occlusion) in their
//! stored values. An image that cannot be decoded is named in [`SourceLooks::warnings`] and its
//! slot's factor stands in. A source with a normal map and no tangents gets MikkTSpace
//! tangents on the coordinate set of its first normal map, as glTF asks of a viewer.
//!
//! Cost: decoding each image once; a look costs a few texture samples.

use voxlod_asset::texture::{bend_normal, decode_at};
use voxlod_asset::{AlphaMode, Asset, AssetError, Material, TextureRef};
use voxlod_core::glam::{Vec2, Vec3, Vec4};

use crate::mipmaps::{texels_per_unit, Mipmaps};
use crate::tangents::mikktspace;
use crate::BakeError;

/// The source's looks at one point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Look {
    /// Linear RGBA.
    pub base: Vec4,
    /// Unit shading normal, in world space.
    pub normal: Vec3,
    /// Ambient occlusion, 0..=1.
    pub occlusion: f32,
    /// Roughness, 0..=1.
    pub roughness: f32,
    /// Metalness, 0..=1.
    pub metallic: f32,
    /// Linear emitted colour (may exceed 1).
    pub emissive: Vec3,
}

/// Which looks the source has beyond a base colour and normals.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Channels {
    /// Metallic-roughness textures, or materials that differ in those factors.
    pub metallic_roughness: bool,
    /// Occlusion textures.
    pub occlusion: bool,
    /// Emissive materials.
    pub emissive: bool,
    /// Materials that are not opaque.
    pub alpha: bool,
}

/// A source asset ready to be looked at (see the module documentation).
pub struct SourceLooks<'a> {
    asset: &'a Asset,
    /// Decoded images with their mipmaps, as colour (linear) and as data (stored values), by
    /// image index.
    colour: Vec<Option<Mipmaps>>,
    data: Vec<Option<Mipmaps>>,
    tangents: Vec<Vec4>,
    /// The looks the source has.
    pub channels: Channels,
    /// Images that could not be decoded.
    pub warnings: Vec<String>,
}

impl<'a> SourceLooks<'a> {
    /// Decodes the images `asset`'s materials use. Fails on an invalid asset or a memory
    /// refusal; an image that cannot be decoded is a warning.
    pub fn new(asset: &'a Asset) -> Result<Self, BakeError> {
        asset.validate()?;
        let mut looks = SourceLooks {
            asset,
            colour: vec![None; asset.images.len()],
            data: vec![None; asset.images.len()],
            tangents: asset.mesh.tangents.clone(),
            channels: channels(&asset.materials),
            warnings: Vec::new(),
        };
        for material in &asset.materials {
            for slot in [&material.base_color_texture, &material.emissive_texture] {
                looks.load(slot, false)?;
            }
            for slot in [
                &material.normal_texture,
                &material.metallic_roughness_texture,
                &material.occlusion_texture,
            ] {
                looks.load(slot, true)?;
            }
        }
        let normal_map = asset
            .materials
            .iter()
            .find_map(|m| m.normal_texture.as_ref());
        if let Some(slot) = normal_map {
            let mesh = &asset.mesh;
            if mesh.tangents.is_empty() && !mesh.normals.is_empty() {
                let uv = &mesh.uv[set_of(slot)];
                looks.tangents = mikktspace(&mesh.positions, &mesh.normals, uv, &mesh.triangles);
            }
        }
        Ok(looks)
    }

    /// Decodes the slot's image once, as colour or as data.
    fn load(&mut self, slot: &Option<TextureRef>, as_data: bool) -> Result<(), BakeError> {
        let Some(slot) = slot else { return Ok(()) };
        let store = if as_data {
            &mut self.data
        } else {
            &mut self.colour
        };
        if store[slot.image].is_some() {
            return Ok(());
        }
        match decode_at(self.asset, slot.image) {
            Ok(mut texels) => {
                if as_data {
                    for t in &mut texels.rgba {
                        *t = Vec4::new(
                            linear_to_srgb(t.x),
                            linear_to_srgb(t.y),
                            linear_to_srgb(t.z),
                            t.w,
                        );
                    }
                }
                let levels = voxlod_core::memory::bytes_of::<Vec4>(texels.rgba.len() / 3 + 1);
                let what = format!("the mipmaps of image {}", slot.image);
                voxlod_core::memory::check_allocation(&what, levels)?;
                store[slot.image] = Some(Mipmaps::new(texels));
            }
            Err(AssetError::Core(e)) => return Err(e.into()),
            Err(e) => self
                .warnings
                .push(format!("{e}: its material's factor stands in")),
        }
        Ok(())
    }

    /// The looks at the point with barycentric `weights` on source triangle `t`, its textures
    /// averaged over a patch `footprint` across (world units; 0 samples them at a point);
    /// `facing` is the normal used where the source has none.
    pub fn at(&self, t: usize, weights: [f32; 3], facing: Vec3, footprint: f32) -> Look {
        let mesh = &self.asset.mesh;
        let corners = mesh.triangles[t].map(|v| v as usize);
        let mix4 = |values: &[Vec4]| self.mixed(t, weights, values);
        let mix3 = |values: &[Vec3]| self.mixed(t, weights, values);
        let geometric = {
            let [a, b, c] = corners.map(|v| mesh.positions[v]);
            (b - a).cross(c - a).try_normalize().unwrap_or(facing)
        };
        let mut normal = if mesh.normals.is_empty() {
            geometric
        } else {
            mix3(&mesh.normals).try_normalize().unwrap_or(geometric)
        };
        let Some(material) = self.asset.material_of(t) else {
            let d = Material::default();
            return Look {
                base: self.vertex_colour(t, weights),
                normal,
                occlusion: 1.0,
                roughness: d.roughness,
                metallic: d.metallic,
                emissive: Vec3::ZERO,
            };
        };
        // A double-sided material seen from its back shades with its normal reversed (glTF
        // §3.9.4): the side a viewer of the level sees is the one facing along `facing`.
        if material.double_sided && geometric.dot(facing) < 0.0 {
            normal = -normal;
        }
        let sample = |slot: &Option<TextureRef>, store: &[Option<Mipmaps>]| {
            self.sample(t, weights, slot, store, footprint)
        };
        if let Some(m) = sample(&material.normal_texture, &self.data) {
            if !self.tangents.is_empty() {
                let tangent = mix4(&self.tangents);
                normal = bend_normal(normal, tangent, m, material.normal_scale);
            }
        }
        let base = self.base(t, weights, material, footprint);
        let mr = sample(&material.metallic_roughness_texture, &self.data).unwrap_or(Vec4::ONE);
        let occlusion = sample(&material.occlusion_texture, &self.data)
            .map_or(1.0, |o| 1.0 + material.occlusion_strength * (o.x - 1.0));
        let emissive = Vec3::from(material.emissive)
            * material.emissive_strength
            * sample(&material.emissive_texture, &self.colour).map_or(Vec3::ONE, |e| e.truncate());
        Look {
            base,
            normal,
            occlusion: occlusion.clamp(0.0, 1.0),
            roughness: (material.roughness * mr.y).clamp(0.0, 1.0),
            metallic: (material.metallic * mr.z).clamp(0.0, 1.0),
            emissive,
        }
    }
}

impl SourceLooks<'_> {
    /// Whether triangle `t`'s material is double-sided (seen from its back too).
    pub fn double_sided(&self, t: usize) -> bool {
        self.asset.material_of(t).is_some_and(|m| m.double_sided)
    }

    /// Whether triangle `t`'s material lets light through somewhere (masks or blends by alpha).
    pub fn see_through(&self, t: usize) -> bool {
        self.asset
            .material_of(t)
            .is_some_and(|m| m.alpha_mode != AlphaMode::Opaque)
    }

    /// What a viewer sees at the point with barycentric `weights` on triangle `t`: the linear
    /// base colour (texture averaged over `footprint`) and its opacity: the base alpha where
    /// the material blends, 1 where it is opaque or masks (a masked texel below its cutoff is
    /// [`clear`](Self::clear), never seen).
    pub fn seen_colour(&self, t: usize, weights: [f32; 3], footprint: f32) -> Vec4 {
        let default;
        let material = match self.asset.material_of(t) {
            Some(m) => m,
            None => {
                default = Material::default();
                &default
            }
        };
        let base = self.base(t, weights, material, footprint);
        let opacity = match material.alpha_mode {
            AlphaMode::Blend => base.w.clamp(0.0, 1.0),
            _ => 1.0,
        };
        base.truncate().extend(opacity)
    }

    /// Whether the source shows nothing at the point with barycentric `weights` on triangle
    /// `t`: its material masks by alpha (glTF §3.9.4, `MASK`) and the base colour's alpha
    /// there, sampled at the point, is below the cutoff. Blended and opaque materials always
    /// show something.
    pub fn clear(&self, t: usize, weights: [f32; 3]) -> bool {
        match self.asset.material_of(t) {
            Some(m) if m.alpha_mode == AlphaMode::Mask => {
                self.base(t, weights, m, 0.0).w < m.alpha_cutoff
            }
            _ => false,
        }
    }

    /// `values` (one per vertex) interpolated at the point with barycentric `weights` on
    /// triangle `t`.
    fn mixed<T>(&self, t: usize, weights: [f32; 3], values: &[T]) -> T
    where
        T: Copy + std::ops::Mul<f32, Output = T> + std::iter::Sum,
    {
        let corners = self.asset.mesh.triangles[t];
        corners
            .iter()
            .zip(weights)
            .map(|(&v, w)| values[v as usize] * w)
            .sum()
    }

    /// The vertex colour at the point (white where the mesh has none).
    fn vertex_colour(&self, t: usize, weights: [f32; 3]) -> Vec4 {
        let colors = &self.asset.mesh.colors;
        match colors.is_empty() {
            true => Vec4::ONE,
            false => self.mixed(t, weights, colors),
        }
    }

    /// The base colour at the point: texture × factor × vertex colour (glTF §3.9.2), the
    /// texture averaged over `footprint`.
    fn base(&self, t: usize, weights: [f32; 3], material: &Material, footprint: f32) -> Vec4 {
        let texture = self.sample(
            t,
            weights,
            &material.base_color_texture,
            &self.colour,
            footprint,
        );
        self.vertex_colour(t, weights)
            * Vec4::from(material.base_color)
            * texture.unwrap_or(Vec4::ONE)
    }

    /// `slot`'s texture (decoded in `store`) at the point, averaged over a patch `footprint`
    /// across (world units); `None` where there is no slot or no image.
    fn sample(
        &self,
        t: usize,
        weights: [f32; 3],
        slot: &Option<TextureRef>,
        store: &[Option<Mipmaps>],
        footprint: f32,
    ) -> Option<Vec4> {
        let slot = slot.as_ref()?;
        let mipmaps = store[slot.image].as_ref()?;
        let mesh = &self.asset.mesh;
        let texels = footprint * texel_density(mesh, t, slot, mipmaps.size());
        let uv: Vec2 = self.mixed(t, weights, &mesh.uv[set_of(slot)]);
        Some(mipmaps.sample(slot, uv, texels))
    }
}

/// Texels of a `size` texture per world unit along source triangle `t`, through `slot`'s
/// coordinates and transform: the square root of its area in texels over its area in the
/// world (0 for a triangle without area).
fn texel_density(
    mesh: &voxlod_asset::AssetMesh,
    t: usize,
    slot: &TextureRef,
    (width, height): (usize, usize),
) -> f32 {
    let corners = mesh.triangles[t].map(|v| v as usize);
    let uv = corners.map(|v| {
        let at = mesh.uv[set_of(slot)][v];
        let at = slot.transform.map_or(at, |x| x.apply(at));
        at * Vec2::new(width as f32, height as f32)
    });
    texels_per_unit(corners.map(|v| mesh.positions[v]), uv)
}

/// The texture coordinate set a slot reads.
fn set_of(slot: &TextureRef) -> usize {
    slot.transform
        .and_then(|t| t.tex_coord)
        .unwrap_or(slot.tex_coord)
        .min(1) as usize
}

/// Which looks beyond base colour and normals the materials need baked.
fn channels(materials: &[Material]) -> Channels {
    let first = materials.first();
    Channels {
        metallic_roughness: materials.iter().any(|m| {
            m.metallic_roughness_texture.is_some()
                || first.is_some_and(|f| (f.metallic, f.roughness) != (m.metallic, m.roughness))
        }),
        occlusion: materials.iter().any(|m| m.occlusion_texture.is_some()),
        emissive: materials
            .iter()
            .any(|m| m.emissive.iter().any(|&e| e * m.emissive_strength > 0.0)),
        alpha: materials.iter().any(|m| m.alpha_mode != AlphaMode::Opaque),
    }
}

/// The sRGB transfer function (IEC 61966-2-1), the inverse of [`voxlod_asset::texture::srgb_to_linear`].
pub fn linear_to_srgb(c: f32) -> f32 {
    if c <= 0.003_130_8 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}
