//! An asset as an OBJ with its MTL library and images, as [`crate::read_asset`] (through
//! `tobj`), Blender, MeshLab and trimesh read them.
//!
//! The OBJ: `mtllib NAME.mtl`, then per material block (see the parent module) `usemtl`, its
//! vertices as `v x y z` (with `r g b` sRGB when the asset has vertex colours: the extension
//! MeshLab, trimesh and `tobj` read), `vt u v` (v up the image: `1 − v` of the asset's) and
//! `vn`, and its faces `f v/vt/vn …` with absolute indices. Numbers are written in Rust's
//! shortest form that reads back as the same `f32`.
//!
//! The MTL, per material, with [`crate::read_asset`]'s table read backwards:
//!
//! | [`Material`] | MTL |
//! |---|---|
//! | base colour factor | `Kd` (linear, as read) and `d` (alpha) |
//! | roughness, metalness | `Pr`, `Pm` (the PBR extension of MTL) |
//! | emissive factor × strength | `Ke` (clamped to 1, as read) |
//! | base colour texture | `map_Kd FILE`, without options: trimesh and other readers take the rest of the line as the file name, so a clamping sampler is a warning |
//! | normal texture | `norm` and `map_Bump`, both `-bm SCALE` (and `-clamp on` for a clamping sampler) |
//! | emissive texture | `map_Ke` (`-clamp on` likewise) |
//!
//! Not held, each a warning: a second texture coordinate set (and the textures that read it),
//! `KHR_texture_transform`, metallic-roughness and occlusion textures, vertex colours' alpha,
//! an alpha cutoff.
//!
//! Cost: linear in the asset; the text is about 60 bytes per vertex and 20 per triangle.

use std::fmt::Write as _;
use std::path::Path;

use voxlod_asset::{AlphaMode, Asset, Material, TextureRef, Wrap};

use super::{blocks, linear_to_srgb, AssetFile, AssetFiles, Textures};
use crate::IoError;

/// The OBJ, its MTL and its images.
pub(crate) fn files(path: &Path, asset: &Asset) -> Result<AssetFiles, IoError> {
    let mut warnings = Vec::new();
    let m = &asset.mesh;
    let names = material_names(&asset.materials);
    let mtl_path = path.with_extension("mtl");
    let mtl_name = mtl_path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    if !m.uv[1].is_empty() {
        warnings.push("OBJ holds one texture coordinate set: set 1 was left out".to_string());
    }
    if m.colors.iter().any(|c| c.w < 1.0) {
        warnings.push("OBJ vertex colours have no alpha: it was left out".to_string());
    }
    let mut text = String::with_capacity(m.positions.len() * 60 + m.triangles.len() * 20);
    text.push_str("# written by voxlod\n");
    let _ = writeln!(text, "mtllib {mtl_name}");
    let mut written = 0usize;
    for block in blocks(asset) {
        if let Some(k) = block.material {
            let _ = writeln!(text, "usemtl {}", names[k as usize]);
        }
        for &v in &block.vertices {
            let v = v as usize;
            let p = m.positions[v];
            let _ = write!(text, "v {} {} {}", p.x, p.y, p.z);
            if let Some(c) = m.colors.get(v) {
                let s = [c.x, c.y, c.z].map(linear_to_srgb);
                let _ = write!(text, " {} {} {}", s[0], s[1], s[2]);
            }
            text.push('\n');
            if let Some(t) = m.uv[0].get(v) {
                let _ = writeln!(text, "vt {} {}", t.x, 1.0 - t.y);
            }
            if let Some(n) = m.normals.get(v) {
                let _ = writeln!(text, "vn {} {} {}", n.x, n.y, n.z);
            }
        }
        for t in &block.triangles {
            text.push('f');
            for &c in t {
                let i = written + c as usize + 1;
                match (m.uv[0].is_empty(), m.normals.is_empty()) {
                    (true, true) => write!(text, " {i}"),
                    (false, true) => write!(text, " {i}/{i}"),
                    (true, false) => write!(text, " {i}//{i}"),
                    (false, false) => write!(text, " {i}/{i}/{i}"),
                }
                .expect("writing to a String");
            }
            text.push('\n');
        }
        written += block.vertices.len();
    }
    let textures = Textures::of(&asset.images);
    let mut used = vec![false; asset.images.len()];
    let mut mtl = String::from("# written by voxlod\n");
    for (material, name) in asset.materials.iter().zip(&names) {
        let slots = Slots {
            textures: &textures,
            used: &mut used,
            warnings: &mut warnings,
            material: name,
        };
        material_text(&mut mtl, material, name, slots);
    }
    let mut carries = vec!["triangles".to_string()];
    for (present, what) in [
        (!m.normals.is_empty(), "normals"),
        (!m.uv[0].is_empty(), "texture coordinates"),
        (!m.colors.is_empty(), "vertex colours"),
        (!asset.materials.is_empty(), "materials"),
    ] {
        if present {
            carries.push(what.to_string());
        }
    }
    let mut files = vec![
        AssetFile {
            path: path.to_path_buf(),
            bytes: text.into_bytes(),
            carries,
        },
        AssetFile {
            path: mtl_path,
            bytes: mtl.into_bytes(),
            carries: vec!["materials".into()],
        },
    ];
    for (k, _) in used.iter().enumerate().filter(|(_, u)| **u) {
        files.push(textures.file(path, &asset.images, k));
    }
    Ok(AssetFiles { files, warnings })
}

/// The materials' names as MTL takes them: whitespace replaced by `_`, `material-K` for an
/// empty one, `-K` added to one an earlier material has.
fn material_names(materials: &[Material]) -> Vec<String> {
    let mut names: Vec<String> = Vec::with_capacity(materials.len());
    for (k, m) in materials.iter().enumerate() {
        let clean: String = m
            .name
            .chars()
            .map(|c| if c.is_whitespace() { '_' } else { c })
            .collect();
        let mut name = if clean.is_empty() {
            format!("material-{k}")
        } else {
            clean
        };
        if names.contains(&name) {
            name = format!("{name}-{k}");
        }
        names.push(name);
    }
    names
}

/// The base colour texture's slot, whose statement (`map_Kd`) is written without options.
const BASE: &str = "base colour texture";

/// What writing a material's texture statements needs: the images' file names, which images
/// are used (to be written), the warnings, the material's name.
struct Slots<'a> {
    textures: &'a Textures,
    used: &'a mut [bool],
    warnings: &'a mut Vec<String>,
    material: &'a str,
}

impl Slots<'_> {
    /// The arguments of a texture statement (`-clamp on`, then extra options, then the file),
    /// or `None` with a warning for a texture OBJ cannot hold.
    fn statement(&mut self, slot: &str, t: &TextureRef, options: &str) -> Option<String> {
        let set = t.transform.and_then(|x| x.tex_coord).unwrap_or(t.tex_coord);
        if set != 0 {
            self.warnings.push(format!(
                "material '{}': its {slot} reads texture coordinate set {set}, which OBJ does \
                 not hold: left out",
                self.material
            ));
            return None;
        }
        if t.transform.is_some() {
            self.warnings.push(format!(
                "material '{}': its {slot}'s texture transform was left out (MTL has no \
                 rotation, and the reader does not apply -o/-s)",
                self.material
            ));
        }
        self.used[t.image] = true;
        let clamp = t.sampler.wrap_u == Wrap::ClampToEdge && t.sampler.wrap_v == Wrap::ClampToEdge;
        let mut s = String::new();
        if clamp && options.is_empty() && slot == BASE {
            self.warnings.push(format!(
                "material '{}': its base colour texture is written without -clamp on (it \
                 repeats): trimesh and other readers take map_Kd's options as part of the \
                 file name",
                self.material
            ));
        } else if clamp {
            s.push_str("-clamp on ");
        }
        s.push_str(options);
        s.push_str(&self.textures.names[t.image]);
        Some(s)
    }
}

/// One material's MTL statements.
fn material_text(out: &mut String, m: &Material, name: &str, mut slots: Slots) {
    let [r, g, b, a] = m.base_color;
    let _ = writeln!(out, "\nnewmtl {name}");
    let _ = writeln!(out, "Kd {r} {g} {b}");
    let _ = writeln!(out, "d {a}");
    let _ = writeln!(out, "Pr {}", m.roughness);
    let _ = writeln!(out, "Pm {}", m.metallic);
    let ke = m.emissive.map(|e| e * m.emissive_strength);
    if ke.iter().any(|&e| e > 0.0) {
        let _ = writeln!(out, "Ke {} {} {}", ke[0], ke[1], ke[2]);
        if ke.iter().any(|&e| e > 1.0) {
            slots.warnings.push(format!(
                "material '{name}': its emissive factor times strength is above 1, which MTL \
                 readers clamp"
            ));
        }
    }
    if let Some(t) = &m.base_color_texture {
        if let Some(s) = slots.statement(BASE, t, "") {
            let _ = writeln!(out, "map_Kd {s}");
        }
    }
    if let Some(t) = &m.normal_texture {
        let bm = format!("-bm {} ", m.normal_scale);
        if let Some(s) = slots.statement("normal texture", t, &bm) {
            let _ = writeln!(out, "norm {s}");
            let _ = writeln!(out, "map_Bump {s}");
        }
    }
    if let Some(t) = &m.emissive_texture {
        if let Some(s) = slots.statement("emissive texture", t, "") {
            let _ = writeln!(out, "map_Ke {s}");
        }
    }
    for (slot, t) in [
        ("metallic-roughness texture", &m.metallic_roughness_texture),
        ("occlusion texture", &m.occlusion_texture),
    ] {
        if t.is_some() {
            slots.warnings.push(format!(
                "material '{name}': its {slot} was left out (MTL readers have no slot for it)"
            ));
        }
    }
    if m.alpha_mode == AlphaMode::Mask {
        slots.warnings.push(format!(
            "material '{name}': its alpha cutoff was left out (MTL has none; d is its alpha)"
        ));
    }
}
