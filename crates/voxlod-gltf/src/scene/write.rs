//! Levels of an asset with their looks as one glTF 2.0 binary (`.glb`).
//!
//! **Layout**: each level is one mesh with one primitive per material it uses (its vertices
//! compacted per primitive), attributes `POSITION` (with bounds), `NORMAL`, `TANGENT`,
//! `TEXCOORD_0`, `TEXCOORD_1` and `COLOR_0` (float RGBA) where the level has them, `u16` or
//! `u32` indices. Materials equal across levels are written once; images are embedded as they
//! were read (PNG, JPEG, KTX2 bytes unchanged; one copy for images the levels share), with
//! their samplers and `KHR_texture_transform`. Two ways to hold the levels, [`Layout`]:
//! - `MsftLod`: node 0 draws the finest level and lists the others with `MSFT_lod`, with
//!   `MSFT_screencoverage` in its extras; the scene holds node 0 only (engines with the
//!   extension switch levels; others draw the finest);
//! - `LodNodes`: the scene holds one node per level named `LOD0`, `LOD1`, … (the names
//!   Blender's, Unity's and Unreal's importers turn into LOD groups; a plain viewer shows them
//!   all, one over the other).
//!
//! Beyond the papers: the file format is glTF's; the layouts are the engines' conventions.
//! Cost: linear in the levels' size.

use std::collections::HashMap;
use std::sync::Arc;

use serde_json::{json, Value};
use voxlod_asset::{AlphaMode, Asset, Material, TextureRef, Wrap};
use voxlod_core::glam::{Vec2, Vec3, Vec4};

use crate::chain::{declare_lod, to_glb};
use crate::GltfError;

/// How the levels sit in the file.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Layout {
    /// One node with `MSFT_lod` naming the coarser levels' nodes.
    #[default]
    MsftLod,
    /// One scene node per level, named `LOD0`, `LOD1`, …
    LodNodes,
}

/// Options of [`asset_glb`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AssetGlbOptions {
    /// How the levels sit in the file.
    pub layout: Layout,
    /// `MSFT_screencoverage`, one per level, finest first; empty for the default (each level's
    /// share of the finest level's triangles, square-rooted and halved; 0 for the last).
    pub coverages: Vec<f64>,
    /// The name of the asset (the root's `asset.extras` and the nodes' names' prefix).
    pub name: String,
}

/// The `.glb` bytes of the levels, finest first. Refuses no level, an invalid level, or
/// coverages that do not match the levels.
pub fn asset_glb(levels: &[Asset], options: &AssetGlbOptions) -> Result<Vec<u8>, GltfError> {
    if levels.is_empty() {
        return Err(GltfError::InvalidChain("no level to write".into()));
    }
    for (k, level) in levels.iter().enumerate() {
        level
            .validate()
            .map_err(|e| GltfError::InvalidChain(format!("level {k}: {e}")))?;
        if level.mesh.triangles.is_empty() {
            return Err(GltfError::InvalidChain(format!(
                "level {k} has no triangles"
            )));
        }
    }
    let coverages = coverages(levels, &options.coverages)?;
    let mut doc = Writer::default();
    for (k, level) in levels.iter().enumerate() {
        let mesh = doc.mesh(level, k)?;
        let name = match options.layout {
            Layout::LodNodes => format!("LOD{k}"),
            Layout::MsftLod if options.name.is_empty() => format!("level {k}"),
            Layout::MsftLod => format!("{} level {k}", options.name),
        };
        doc.nodes.push(json!({"name": name, "mesh": mesh,
            "extras": {"voxlod": {"level": k, "triangles": level.mesh.triangles.len()}}}));
    }
    let mut root = doc.finish(&options.name);
    match options.layout {
        Layout::MsftLod => {
            root["scenes"] = json!([{"nodes": [0]}]);
            declare_lod(&mut root, levels.len(), &coverages);
            if levels.len() >= 2 {
                let used = root.as_object_mut().and_then(|o| {
                    o.entry("extensionsUsed")
                        .or_insert_with(|| json!([]))
                        .as_array_mut()
                });
                if let Some(list) = used {
                    list.push(json!("MSFT_lod"));
                }
            }
        }
        Layout::LodNodes => {
            root["scenes"] = json!([{"nodes": (0..levels.len()).collect::<Vec<_>>()}])
        }
    }
    to_glb(&root, doc.bin)
}

/// The coverages given, checked, or the default ones.
fn coverages(levels: &[Asset], given: &[f64]) -> Result<Vec<f64>, GltfError> {
    if !given.is_empty() {
        if given.len() != levels.len() || given.iter().any(|c| !(0.0..=1.0).contains(c)) {
            return Err(GltfError::InvalidChain(format!(
                "{} screen coverages in 0..=1 are needed, one per level; got {given:?}",
                levels.len()
            )));
        }
        return Ok(given.to_vec());
    }
    let finest = levels[0].mesh.triangles.len() as f64;
    let n = levels.len();
    Ok((0..n)
        .map(|k| {
            if k + 1 == n {
                0.0
            } else {
                0.5 * (levels[k + 1].mesh.triangles.len() as f64 / finest).sqrt()
            }
        })
        .collect())
}

/// The document under construction.
#[derive(Default)]
struct Writer {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
    meshes: Vec<Value>,
    nodes: Vec<Value>,
    materials: Vec<Material>,
    /// Images by the address of their shared bytes: their index in `images`.
    image_index: HashMap<*const Vec<u8>, usize>,
    images: Vec<(Arc<Vec<u8>>, String, String)>,
    transforms: bool,
}

impl Writer {
    /// Level `k`'s mesh, one primitive per material; returns its index.
    fn mesh(&mut self, level: &Asset, k: usize) -> Result<usize, GltfError> {
        let m = &level.mesh;
        let mut by_material: Vec<(Option<u32>, Vec<[u32; 3]>)> = Vec::new();
        for (t, tri) in m.triangles.iter().enumerate() {
            let key = m.material.get(t).copied();
            match by_material.iter_mut().find(|(k, _)| *k == key) {
                Some((_, list)) => list.push(*tri),
                None => by_material.push((key, vec![*tri])),
            }
        }
        let mut primitives = Vec::new();
        for (material, triangles) in by_material {
            let mut p = self.primitive(level, &triangles)?;
            if let Some(mat) = material {
                p["material"] = json!(self.material(&level.materials[mat as usize], level));
            }
            primitives.push(p);
        }
        self.meshes
            .push(json!({"name": format!("level {k}"), "primitives": primitives}));
        Ok(self.meshes.len() - 1)
    }

    /// One primitive of `triangles`, its vertices compacted.
    fn primitive(&mut self, level: &Asset, triangles: &[[u32; 3]]) -> Result<Value, GltfError> {
        let m = &level.mesh;
        let mut new_index: HashMap<u32, u32> = HashMap::new();
        let mut from: Vec<usize> = Vec::new();
        let indices: Vec<u32> = triangles
            .iter()
            .flatten()
            .map(|&v| {
                *new_index.entry(v).or_insert_with(|| {
                    from.push(v as usize);
                    (from.len() - 1) as u32
                })
            })
            .collect();
        let pick3 = |a: &[Vec3]| {
            from.iter()
                .flat_map(|&v| a[v].to_array())
                .collect::<Vec<f32>>()
        };
        let pick2 = |a: &[Vec2]| {
            from.iter()
                .flat_map(|&v| a[v].to_array())
                .collect::<Vec<f32>>()
        };
        let pick4 = |a: &[Vec4]| {
            from.iter()
                .flat_map(|&v| a[v].to_array())
                .collect::<Vec<f32>>()
        };
        let positions: Vec<Vec3> = from.iter().map(|&v| m.positions[v]).collect();
        let (lo, hi) = positions
            .iter()
            .fold((Vec3::MAX, Vec3::MIN), |(lo, hi), &p| {
                (lo.min(p), hi.max(p))
            });
        let mut attributes = json!({});
        let pos = self.floats(
            &pick3(&m.positions),
            "VEC3",
            Some((lo.to_array().to_vec(), hi.to_array().to_vec())),
        );
        attributes["POSITION"] = json!(pos);
        if !m.normals.is_empty() {
            let normals: Vec<f32> = from
                .iter()
                .flat_map(|&v| unit(m.normals[v]).to_array())
                .collect();
            attributes["NORMAL"] = json!(self.floats(&normals, "VEC3", None));
        }
        if !m.tangents.is_empty() {
            let t: Vec<f32> = from
                .iter()
                .flat_map(|&v| {
                    let t = m.tangents[v];
                    unit(t.truncate())
                        .extend(if t.w < 0.0 { -1.0 } else { 1.0 })
                        .to_array()
                })
                .collect();
            attributes["TANGENT"] = json!(self.floats(&t, "VEC4", None));
        }
        for (set, uv) in m.uv.iter().enumerate() {
            if !uv.is_empty() {
                attributes[format!("TEXCOORD_{set}")] =
                    json!(self.floats(&pick2(uv), "VEC2", None));
            }
        }
        if !m.colors.is_empty() {
            let c: Vec<f32> = pick4(&m.colors)
                .into_iter()
                .map(|x| x.clamp(0.0, 1.0))
                .collect();
            attributes["COLOR_0"] = json!(self.floats(&c, "VEC4", None));
        }
        let idx = self.indices(&indices, from.len());
        Ok(json!({"attributes": attributes, "indices": idx, "mode": 4}))
    }

    /// A float accessor (with bounds when given); returns its index.
    fn floats(
        &mut self,
        values: &[f32],
        kind: &str,
        bounds: Option<(Vec<f32>, Vec<f32>)>,
    ) -> usize {
        let width = match kind {
            "VEC2" => 2,
            "VEC3" => 3,
            _ => 4,
        };
        let view = self.view(
            values.iter().flat_map(|x| x.to_le_bytes()).collect(),
            Some(34962),
        );
        let mut a = json!({"bufferView": view, "componentType": 5126, "type": kind, "count": values.len() / width});
        if let Some((lo, hi)) = bounds {
            a["min"] = json!(lo);
            a["max"] = json!(hi);
        }
        self.accessors.push(a);
        self.accessors.len() - 1
    }

    /// An index accessor, `u16` where the vertices allow; returns its index.
    fn indices(&mut self, indices: &[u32], vertices: usize) -> usize {
        let (bytes, component): (Vec<u8>, u32) = if vertices <= u16::MAX as usize {
            (
                indices
                    .iter()
                    .flat_map(|&i| (i as u16).to_le_bytes())
                    .collect(),
                5123,
            )
        } else {
            (
                indices.iter().flat_map(|&i| i.to_le_bytes()).collect(),
                5125,
            )
        };
        let view = self.view(bytes, Some(34963));
        self.accessors.push(json!({"bufferView": view, "componentType": component, "type": "SCALAR", "count": indices.len()}));
        self.accessors.len() - 1
    }

    /// A buffer view of `bytes`, 4-aligned; returns its index.
    fn view(&mut self, bytes: Vec<u8>, target: Option<u32>) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let mut v = json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()});
        if let Some(t) = target {
            v["target"] = json!(t);
        }
        self.bin.extend_from_slice(&bytes);
        self.views.push(v);
        self.views.len() - 1
    }

    /// The material's index, written once for equal materials (with their images).
    fn material(&mut self, material: &Material, level: &Asset) -> usize {
        let mut copy = material.clone();
        for slot in [
            &mut copy.base_color_texture,
            &mut copy.metallic_roughness_texture,
            &mut copy.normal_texture,
            &mut copy.occlusion_texture,
            &mut copy.emissive_texture,
        ]
        .into_iter()
        .flatten()
        {
            slot.image = self.image(level, slot.image);
        }
        if let Some(k) = self.materials.iter().position(|m| *m == copy) {
            return k;
        }
        self.materials.push(copy);
        self.materials.len() - 1
    }

    /// The image's index in the file, written once for shared bytes.
    fn image(&mut self, level: &Asset, image: usize) -> usize {
        let img = &level.images[image];
        let key = Arc::as_ptr(&img.bytes);
        if let Some(&k) = self.image_index.get(&key) {
            return k;
        }
        if let Some(k) = self.images.iter().position(|(b, _, _)| **b == *img.bytes) {
            return k;
        }
        self.images
            .push((img.bytes.clone(), img.mime.clone(), img.name.clone()));
        self.image_index.insert(key, self.images.len() - 1);
        self.images.len() - 1
    }

    /// The document's JSON around the nodes, meshes, materials and images gathered.
    fn finish(&mut self, name: &str) -> Value {
        let mut textures = Vec::new();
        let mut samplers: Vec<Value> = Vec::new();
        let materials: Vec<Value> = std::mem::take(&mut self.materials)
            .iter()
            .map(|m| self.material_json(m, &mut textures, &mut samplers))
            .collect();
        let images: Vec<Value> = std::mem::take(&mut self.images)
            .into_iter()
            .map(|(bytes, mime, name)| {
                let view = self.view(bytes.to_vec(), None);
                let mut i = json!({"bufferView": view, "mimeType": mime});
                if !name.is_empty() {
                    i["name"] = json!(name);
                }
                i
            })
            .collect();
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let mut used: Vec<&str> = Vec::new();
        if self.transforms {
            used.push("KHR_texture_transform");
        }
        if materials
            .iter()
            .any(|m| m["extensions"]["KHR_materials_emissive_strength"].is_object())
        {
            used.push("KHR_materials_emissive_strength");
        }
        let mut root = json!({
            "asset": {"version": "2.0", "generator": format!("voxlod {}", env!("CARGO_PKG_VERSION"))},
            "extensionsUsed": used,
            "scene": 0,
            "nodes": self.nodes,
            "meshes": self.meshes,
            "accessors": self.accessors,
            "bufferViews": self.views,
            "buffers": [{"byteLength": self.bin.len()}],
        });
        if !name.is_empty() {
            root["asset"]["extras"] = json!({"name": name});
        }
        for (key, list) in [
            ("materials", materials),
            ("textures", textures),
            ("samplers", samplers),
            ("images", images),
        ] {
            if !list.is_empty() {
                root[key] = json!(list);
            }
        }
        if used.is_empty() {
            root.as_object_mut().map(|o| o.remove("extensionsUsed"));
        }
        root
    }

    /// One material's JSON; its textures and samplers appended to the lists.
    fn material_json(
        &mut self,
        m: &Material,
        textures: &mut Vec<Value>,
        samplers: &mut Vec<Value>,
    ) -> Value {
        let mut slot = |t: &TextureRef| -> Value {
            let sampler = json!({"magFilter": if t.sampler.linear { 9729 } else { 9728 },
                "wrapS": wrap(t.sampler.wrap_u), "wrapT": wrap(t.sampler.wrap_v)});
            let s = samplers
                .iter()
                .position(|x| *x == sampler)
                .unwrap_or_else(|| {
                    samplers.push(sampler);
                    samplers.len() - 1
                });
            let texture = json!({"source": t.image, "sampler": s});
            let index = textures
                .iter()
                .position(|x| *x == texture)
                .unwrap_or_else(|| {
                    textures.push(texture);
                    textures.len() - 1
                });
            let mut info = json!({"index": index, "texCoord": t.tex_coord});
            if let Some(x) = t.transform {
                self.transforms = true;
                let mut e = json!({"offset": x.offset, "rotation": x.rotation, "scale": x.scale});
                if let Some(c) = x.tex_coord {
                    e["texCoord"] = json!(c);
                }
                info["extensions"] = json!({"KHR_texture_transform": e});
            }
            info
        };
        let mut pbr = json!({"baseColorFactor": m.base_color, "metallicFactor": m.metallic, "roughnessFactor": m.roughness});
        let mut out =
            json!({"name": m.name, "emissiveFactor": m.emissive, "doubleSided": m.double_sided});
        if let Some(t) = &m.base_color_texture {
            pbr["baseColorTexture"] = slot(t);
        }
        if let Some(t) = &m.metallic_roughness_texture {
            pbr["metallicRoughnessTexture"] = slot(t);
        }
        if let Some(t) = &m.normal_texture {
            out["normalTexture"] = slot(t);
            out["normalTexture"]["scale"] = json!(m.normal_scale);
        }
        if let Some(t) = &m.occlusion_texture {
            out["occlusionTexture"] = slot(t);
            out["occlusionTexture"]["strength"] = json!(m.occlusion_strength);
        }
        if let Some(t) = &m.emissive_texture {
            out["emissiveTexture"] = slot(t);
        }
        out["pbrMetallicRoughness"] = pbr;
        match m.alpha_mode {
            AlphaMode::Opaque => {}
            AlphaMode::Mask => {
                out["alphaMode"] = json!("MASK");
                out["alphaCutoff"] = json!(m.alpha_cutoff);
            }
            AlphaMode::Blend => out["alphaMode"] = json!("BLEND"),
        }
        if m.emissive_strength != 1.0 {
            out["extensions"] = json!({"KHR_materials_emissive_strength": {"emissiveStrength": m.emissive_strength}});
        }
        out
    }
}

fn wrap(w: Wrap) -> u32 {
    match w {
        Wrap::Repeat => 10497,
        Wrap::MirroredRepeat => 33648,
        Wrap::ClampToEdge => 33071,
    }
}

/// A unit vector (the validator asks normals to be unit length); +z for a zero one.
fn unit(v: Vec3) -> Vec3 {
    let n = v.normalize_or_zero();
    if n == Vec3::ZERO {
        Vec3::Z
    } else {
        n
    }
}
