//! Levels of an asset with their looks as one glTF 2.0 binary (`.glb`).
//!
//! **Layout**: each level is one mesh with one primitive per material it uses (its vertices
//! compacted per primitive), attributes `POSITION` (with bounds), `NORMAL`, `TANGENT`,
//! `TEXCOORD_0`, `TEXCOORD_1` and `COLOR_0` (float RGBA) where the level has them, `u16` or
//! `u32` indices. Materials equal across levels are written once; images are embedded as they
//! were read (PNG, JPEG, KTX2 bytes unchanged; one copy for images the levels share), with
//! their samplers and `KHR_texture_transform`; a KTX2 image's texture names it through
//! `KHR_texture_basisu` (no `source`), which the file then requires. Two ways to hold the levels, [`Layout`]:
//! - `MsftLod`: node 0 draws the finest level and lists the others with `MSFT_lod`, with
//!   `MSFT_screencoverage` in its extras; the scene holds node 0 only (engines with the
//!   extension switch levels; others draw the finest);
//! - `LodNodes`: the scene holds one node per level named `LOD0`, `LOD1`, … (the names
//!   Blender's, Unity's and Unreal's importers turn into LOD groups; a plain viewer shows them
//!   all, one over the other).
//!
//! With [`Compression::Meshopt`] every attribute and index stream is quantized
//! (`KHR_mesh_quantization`; which attribute how, and within what error, in `scene::columns`:
//! texture coordinates outside 0..=1 stay float) and encoded with meshoptimizer
//! (`EXT_meshopt_compression`, codecs and buffer layout as the plain chain writes them,
//! [`crate::encode`]): the GLB's buffer holds the encoded views and the images, a second
//! buffer without data (`fallback: true`) gives the decoded views their place, and every level
//! node carries the positions' dequantizing uniform scale and translation (one grid over every
//! level). Both extensions are then required.
//!
//! Beyond the papers: the file format is glTF's; the layouts are the engines' conventions.
//! Cost: linear in the levels' size; with compression, the encoders are linear too.

use std::collections::HashMap;
use std::sync::Arc;

use serde_json::{json, Value};
use voxlod_asset::{AlphaMode, Asset, Material, TextureRef, Wrap};
use voxlod_core::glam::{DVec3, Vec3};

use super::columns::Columns;
use crate::chain::{declare_lod, to_glb, Compression};
use crate::streams::{Quantization, Stream, StreamKind};
use crate::GltfError;

/// The media type of KTX2 images, whose textures name them through `KHR_texture_basisu`.
const KTX2: &str = "image/ktx2";

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
    /// Float attributes ([`Compression::None`]), or quantized and meshopt-encoded
    /// ([`Compression::Meshopt`], see `scene::columns` for each attribute's storage and error).
    /// Compression pays from a few hundred vertices on: each view's extension object and the
    /// codec's fixed tail cost about 200 bytes, so two quads come out larger (2.9 kB plain,
    /// 4.7 kB compressed) while Spot's geometry shrinks to 0.41 of its size.
    pub compression: Compression,
    /// The world point the levels' positions are relative to ([`crate::SceneRead::origin`]),
    /// added to every level node's translation (in `f64`, as glTF's JSON keeps it).
    pub origin: DVec3,
}

impl AssetGlbOptions {
    /// The default options, compressed with meshopt over quantized attributes.
    pub fn meshopt() -> Self {
        AssetGlbOptions {
            compression: Compression::Meshopt,
            ..Default::default()
        }
    }
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
    let mut doc = Writer {
        grid: (options.compression == Compression::Meshopt).then(|| positions_grid(levels)),
        ..Writer::default()
    };
    for (k, level) in levels.iter().enumerate() {
        let mesh = doc.mesh(level, k)?;
        let name = match options.layout {
            Layout::LodNodes => format!("LOD{k}"),
            Layout::MsftLod if options.name.is_empty() => format!("level {k}"),
            Layout::MsftLod => format!("{} level {k}", options.name),
        };
        let mut node = json!({"name": name, "mesh": mesh,
            "extras": {"voxlod": {"level": k, "triangles": level.mesh.triangles.len()}}});
        if let Some(q) = &doc.grid {
            node["scale"] = json!([q.scale, q.scale, q.scale]);
        }
        let offset = doc
            .grid
            .as_ref()
            .map_or(DVec3::ZERO, |q| q.offset.as_dvec3());
        if offset + options.origin != DVec3::ZERO {
            node["translation"] = json!((offset + options.origin).to_array());
        }
        doc.nodes.push(node);
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

/// The grid compressed levels' positions are quantized on: the box of every level's vertices,
/// its longest side in `2^14 − 1` steps ([`Quantization::over`]).
pub fn positions_grid(levels: &[Asset]) -> Quantization {
    let (lo, hi) = levels
        .iter()
        .flat_map(|l| l.mesh.positions.iter())
        .fold((Vec3::MAX, Vec3::MIN), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
    Quantization::over(lo, hi)
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
    /// Whether a texture's image is KTX2 (`KHR_texture_basisu`, then required).
    basisu: bool,
    /// With compression: the positions' grid; the views' decoded layout takes
    /// `fallback_len` bytes of buffer 1.
    grid: Option<Quantization>,
    fallback_len: usize,
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

    /// One primitive of `triangles`: its vertices compacted, as floats or quantized.
    fn primitive(&mut self, level: &Asset, triangles: &[[u32; 3]]) -> Result<Value, GltfError> {
        let columns = Columns::gather(&level.mesh, triangles);
        let streams = match &self.grid {
            None => columns.plain(),
            Some(grid) => columns.quantized(grid)?,
        };
        let mut attributes = json!({});
        let mut indices = None;
        for (semantic, stream) in &streams {
            let accessor = self.stream(stream)?;
            match semantic {
                Some(name) => attributes[name.as_str()] = json!(accessor),
                None => indices = Some(accessor),
            }
        }
        Ok(json!({"attributes": attributes, "indices": indices, "mode": 4}))
    }

    /// A stream's buffer view (plain, or meshopt-encoded with its decoded layout in the
    /// fallback buffer) and accessor; returns the accessor's index.
    fn stream(&mut self, s: &Stream) -> Result<usize, GltfError> {
        let vertex = s.kind != StreamKind::Indices;
        let target = if vertex { 34962 } else { 34963 };
        let view = match self.grid {
            None => self.view(s.bytes.clone(), Some(target)),
            Some(_) => {
                let encoded = crate::encode::encode_stream(s)?;
                let at = self.align();
                self.bin.extend_from_slice(&encoded);
                let fallback_at = self.fallback_len;
                self.fallback_len = (fallback_at + s.bytes.len()).next_multiple_of(4);
                let mut v = json!({"buffer": 1, "byteOffset": fallback_at,
                    "byteLength": s.bytes.len(), "target": target,
                    "extensions": {"EXT_meshopt_compression":
                        crate::encode::view_extension(s, at, encoded.len())}});
                if vertex {
                    v["byteStride"] = json!(s.stride);
                }
                self.views.push(v);
                self.views.len() - 1
            }
        };
        let (_, kind) = s.kind.accessor_type();
        let mut a = json!({"bufferView": view, "componentType": s.component.code(),
            "type": kind, "count": s.count});
        if s.normalized {
            a["normalized"] = json!(true);
        }
        if let Some((lo, hi)) = s.bounds {
            let narrow = |b: [f64; 3]| b.map(|x| x as f32);
            a["min"] = json!(narrow(lo));
            a["max"] = json!(narrow(hi));
        }
        self.accessors.push(a);
        Ok(self.accessors.len() - 1)
    }

    /// Pads the binary chunk to 4 bytes; returns its length.
    fn align(&mut self) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        self.bin.len()
    }

    /// A buffer view of `bytes`, 4-aligned; returns its index.
    fn view(&mut self, bytes: Vec<u8>, target: Option<u32>) -> usize {
        self.align();
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
        let compressed = ["EXT_meshopt_compression", "KHR_mesh_quantization"];
        if self.grid.is_some() {
            used.extend(compressed);
        }
        if self.transforms {
            used.push("KHR_texture_transform");
        }
        if self.basisu {
            used.push("KHR_texture_basisu");
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
        let mut required: Vec<&str> = Vec::new();
        if self.basisu {
            required.push("KHR_texture_basisu");
        }
        if self.grid.is_some() {
            required.extend(compressed);
        }
        if !required.is_empty() {
            root["extensionsRequired"] = json!(required);
        }
        if self.grid.is_some() {
            root["buffers"] = json!([{"byteLength": self.bin.len()},
                {"byteLength": self.fallback_len,
                 "extensions": {"EXT_meshopt_compression": {"fallback": true}}}]);
        }
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
            let texture = if self.images[t.image].1 == KTX2 {
                self.basisu = true;
                json!({"extensions": {"KHR_texture_basisu": {"source": t.image}}, "sampler": s})
            } else {
                json!({"source": t.image, "sampler": s})
            };
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
