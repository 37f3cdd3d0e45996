//! An asset as one coloured, textured PLY (binary little-endian, through `ply-rs-bw`), as
//! [`crate::read_asset`], MeshLab, Open3D and trimesh read it:
//!
//! - `vertex`: `float x y z`, `float nx ny nz` (when the asset has normals), `uchar red green
//!   blue` sRGB (and `uchar alpha` when an alpha is below 1) when it has colours or its
//!   materials' base colour factors are not all white, `float texture_u texture_v` (v up the
//!   image: `1 − v` of the asset's) when it has texture coordinates;
//! - `face`: `list uchar int vertex_indices`;
//! - `comment TextureFile NAME` for the base colour texture, written beside the PLY.
//!
//! PLY has no materials: each vertex's colour is its colour times its material's base colour
//! factor (the vertices split per material block, so that each has one), which keeps the
//! looks of untextured materials. One texture only: the first textured material's base colour
//! texture; other materials' textures and every other slot are warnings.
//!
//! Cost: linear in the asset, one element at a time through `ply-rs-bw`'s writer.

use std::path::Path;

use ply_rs_bw::ply::{
    Addable, ElementDef, Encoding, Header, PropertyAccess, PropertyDef, PropertyType, ScalarType,
};
use ply_rs_bw::writer::Writer;
use voxlod_asset::Asset;
use voxlod_core::glam::{Vec2, Vec3, Vec4};

use super::{blocks, linear_to_srgb, AssetFile, AssetFiles, Textures};
use crate::IoError;

/// One vertex as the writer asks for its properties.
#[derive(Default)]
struct VertexOut {
    position: Vec3,
    normal: Vec3,
    /// sRGB bytes.
    color: [u8; 4],
    /// As stored: v up.
    uv: Vec2,
}

impl PropertyAccess for VertexOut {
    fn new() -> Self {
        VertexOut::default()
    }

    fn get_float(&self, name: &str) -> Option<f32> {
        Some(match name {
            "x" => self.position.x,
            "y" => self.position.y,
            "z" => self.position.z,
            "nx" => self.normal.x,
            "ny" => self.normal.y,
            "nz" => self.normal.z,
            "texture_u" => self.uv.x,
            "texture_v" => self.uv.y,
            _ => return None,
        })
    }

    fn get_uchar(&self, name: &str) -> Option<u8> {
        let k = ["red", "green", "blue", "alpha"]
            .iter()
            .position(|c| *c == name)?;
        Some(self.color[k])
    }
}

/// One triangle.
#[derive(Default)]
struct FaceOut {
    corners: [i32; 3],
}

impl PropertyAccess for FaceOut {
    fn new() -> Self {
        FaceOut::default()
    }

    fn get_list_int(&self, name: &str) -> Option<&[i32]> {
        (name == "vertex_indices").then_some(&self.corners[..])
    }
}

/// The PLY and its texture.
pub(crate) fn files(path: &Path, asset: &Asset) -> Result<AssetFiles, IoError> {
    let m = &asset.mesh;
    let mut warnings = Vec::new();
    let blocks = blocks(asset);
    let vertices: usize = blocks.iter().map(|b| b.vertices.len()).sum();
    if vertices > i32::MAX as usize {
        return Err(IoError::unsupported(
            path,
            format!("{vertices} vertices do not fit PLY's int indices"),
        ));
    }
    let looks = Looks::of(asset, &blocks);
    let texture = texture(asset, &mut warnings);
    if !m.uv[1].is_empty() {
        warnings.push("PLY holds one texture coordinate set: set 1 was left out".to_string());
    }
    let textures = Textures::of(&asset.images);
    let texture_name = texture.map(|k| textures.names[k].as_str());
    let (header, vertex_def, face_def) = header(asset, vertices, &looks, texture_name);
    let io = |e: std::io::Error| IoError::unsupported(path, format!("cannot encode: {e}"));
    let mut bytes = Vec::with_capacity(vertices * 40 + m.triangles.len() * 13 + 512);
    Writer::<VertexOut>::new()
        .write_header(&mut bytes, &header)
        .map_err(io)?;
    write_vertices(&mut bytes, asset, &blocks, &vertex_def).map_err(io)?;
    write_faces(&mut bytes, &blocks, &face_def).map_err(io)?;
    let mut carries = vec!["triangles".to_string()];
    for (present, what) in [
        (!m.normals.is_empty(), "normals"),
        (looks.colored, "vertex colours"),
        (!m.uv[0].is_empty(), "texture coordinates"),
    ] {
        if present {
            carries.push(what.to_string());
        }
    }
    let mut files = vec![AssetFile {
        path: path.to_path_buf(),
        bytes,
        carries,
    }];
    if let Some(k) = texture {
        files.push(textures.file(path, &asset.images, k));
    }
    Ok(AssetFiles { files, warnings })
}

/// Whether the vertices carry colours (their own, or their material's factor), and alpha.
struct Looks {
    colored: bool,
    alpha: bool,
}

impl Looks {
    fn of(asset: &Asset, blocks: &[super::Block]) -> Looks {
        let m = &asset.mesh;
        let colored = !m.colors.is_empty() || blocks.iter().any(|b| factor(asset, b) != Vec4::ONE);
        let alpha = colored
            && blocks.iter().any(|b| {
                let f = factor(asset, b);
                b.vertices
                    .iter()
                    .any(|&v| colour(asset, v as usize, f).w < 1.0)
            });
        Looks { colored, alpha }
    }
}

/// The base colour factor of a block's material (white without one).
fn factor(asset: &Asset, b: &super::Block) -> Vec4 {
    b.material.map_or(Vec4::ONE, |k| {
        Vec4::from(asset.materials[k as usize].base_color)
    })
}

/// Vertex `v`'s colour times `factor` (white without vertex colours).
fn colour(asset: &Asset, v: usize, factor: Vec4) -> Vec4 {
    asset.mesh.colors.get(v).copied().unwrap_or(Vec4::ONE) * factor
}

/// The binary little-endian header: the vertex element with what the asset carries, the face
/// element, the texture's name in a `TextureFile` comment.
fn header(
    asset: &Asset,
    vertices: usize,
    looks: &Looks,
    texture: Option<&str>,
) -> (Header, ElementDef, ElementDef) {
    let m = &asset.mesh;
    let mut header = Header::new();
    header.encoding = Encoding::BinaryLittleEndian;
    header.comments.push("written by voxlod".to_string());
    if let Some(name) = texture {
        header.comments.push(format!("TextureFile {name}"));
    }
    let float = || PropertyType::Scalar(ScalarType::Float);
    let uchar = || PropertyType::Scalar(ScalarType::UChar);
    let mut names: Vec<(&str, PropertyType)> = vec![("x", float()), ("y", float()), ("z", float())];
    if !m.normals.is_empty() {
        names.extend([("nx", float()), ("ny", float()), ("nz", float())]);
    }
    if looks.colored {
        names.extend([("red", uchar()), ("green", uchar()), ("blue", uchar())]);
        if looks.alpha {
            names.push(("alpha", uchar()));
        }
    }
    if !m.uv[0].is_empty() {
        names.extend([("texture_u", float()), ("texture_v", float())]);
    }
    let vertex_def = element("vertex", vertices, names);
    let indices = PropertyType::List(ScalarType::UChar, ScalarType::Int);
    let face_def = element("face", m.triangles.len(), vec![("vertex_indices", indices)]);
    header.elements.add(vertex_def.clone());
    header.elements.add(face_def.clone());
    (header, vertex_def, face_def)
}

/// Every block's vertices, colours in sRGB bytes, v flipped to PLY's upward convention.
fn write_vertices(
    bytes: &mut Vec<u8>,
    asset: &Asset,
    blocks: &[super::Block],
    vertex_def: &ElementDef,
) -> std::io::Result<()> {
    let m = &asset.mesh;
    let writer = Writer::<VertexOut>::new();
    for b in blocks {
        let f = factor(asset, b);
        for &v in &b.vertices {
            let v = v as usize;
            let c = colour(asset, v, f);
            let srgb = [c.x, c.y, c.z].map(|x| byte(linear_to_srgb(x)));
            let out = VertexOut {
                position: m.positions[v],
                normal: m.normals.get(v).copied().unwrap_or(Vec3::Z),
                color: [srgb[0], srgb[1], srgb[2], byte(c.w)],
                uv: m.uv[0]
                    .get(v)
                    .map_or(Vec2::ZERO, |t| Vec2::new(t.x, 1.0 - t.y)),
            };
            writer.write_little_endian_element(bytes, &out, vertex_def)?;
        }
    }
    Ok(())
}

/// Every block's triangles, its corners numbered after the blocks before it.
fn write_faces(
    bytes: &mut Vec<u8>,
    blocks: &[super::Block],
    face_def: &ElementDef,
) -> std::io::Result<()> {
    let writer = Writer::<FaceOut>::new();
    let mut first = 0i32;
    for b in blocks {
        for t in &b.triangles {
            let face = FaceOut {
                corners: t.map(|c| first + c as i32),
            };
            writer.write_little_endian_element(bytes, &face, face_def)?;
        }
        first += b.vertices.len() as i32;
    }
    Ok(())
}

/// The image of the PLY's one texture: the first material's base colour texture that reads
/// set 0 without a transform; a warning for every other texture slot of every material.
fn texture(asset: &Asset, warnings: &mut Vec<String>) -> Option<usize> {
    let mut chosen = None;
    for material in &asset.materials {
        for (slot, t) in material.textures() {
            let plain = t.tex_coord == 0 && t.transform.is_none();
            let base = slot == "baseColorTexture";
            match chosen {
                None if base && plain && !asset.mesh.uv[0].is_empty() => chosen = Some(t.image),
                Some(k) if base && plain && t.image == k => {}
                _ => warnings.push(format!(
                    "material '{}': its {slot} was left out (a PLY names one base colour \
                     texture, read through texture coordinate set 0)",
                    material.name
                )),
            }
        }
    }
    chosen
}

/// A value in 0..=1 as a byte, rounded.
fn byte(x: f32) -> u8 {
    (x.clamp(0.0, 1.0) * 255.0).round() as u8
}

fn element(name: &str, count: usize, properties: Vec<(&str, PropertyType)>) -> ElementDef {
    let mut def = ElementDef::new(name.to_string());
    def.count = count;
    for (p, t) in properties {
        def.properties.add(PropertyDef::new(p.to_string(), t));
    }
    def
}
