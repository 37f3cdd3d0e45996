//! MTL materials as glTF metallic-roughness materials, and their images read beside the MTL
//! file.
//!
//! | MTL | [`Material`] |
//! |---|---|
//! | `Kd` | base colour factor, as linear (what glTF converters do: MTL colours carry no transfer function, and renderers of OBJ use them as linear reflectance) |
//! | `map_Kd` | base colour texture; the factor stays `Kd`, which MTL multiplies the texture by, as glTF does |
//! | `d`, or `1 - Tr` | base colour alpha; below 1 the material blends |
//! | `Ns` | roughness `(2 / (Ns + 2))^(1/4)`: the Phong exponent's equivalent Beckmann width `α = sqrt(2 / (Ns + 2))` (Walter et al. 2007), and glTF's `α = roughness²`; no `Ns` is roughness 1 |
//! | `Pr`, `Pm` (the PBR extension of MTL) | roughness and metalness, in place of the above |
//! | `Ke`, `map_Ke` | emissive factor and texture |
//! | `map_Bump`, `bump`, `norm` (`-bm s`: the scale) | normal texture |
//!
//! Metalness is 0 without `Pm`: MTL describes dielectrics. `Ka`, `Ks`, `Ni`, `illum` and the
//! other maps have no metallic-roughness counterpart and are ignored. Texture statements may
//! carry options (`-s 1 1 1`, `-clamp on`, ...) before the file name: `-clamp on` gives a
//! clamping sampler, `-bm` the normal scale, the others are skipped. A texture file that is
//! missing or unreadable is a warning and the slot stays empty.
//!
//! Images are kept as their files' bytes (no decoding); their media type comes from the bytes'
//! signature, else from the extension. An image used by several materials is read once.
//!
//! Cost: linear in the MTL data and the image files.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use voxlod_asset::{AlphaMode, Image, Material, Sampler, TextureRef, Wrap};

use crate::{budget, IoError};

/// What one texture statement of an MTL file says: the file and its options that matter.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct TextureStatement {
    /// The file name, relative to the MTL file (backslashes turned into slashes).
    pub file: String,
    /// `-clamp on`.
    pub clamp: bool,
    /// `-bm`, the bump multiplier.
    pub bump_scale: Option<f32>,
}

/// How many values follow each texture option.
fn option_arity(option: &str) -> usize {
    match option {
        "-o" | "-s" | "-t" => 3,
        "-mm" => 2,
        _ => 1,
    }
}

/// Parses a texture statement's arguments (`[-option values...] file name`); `None` when no
/// file name is left. Options with fewer values than usual (`-s 2 2`) are read up to the first
/// token that is not a number.
pub(crate) fn texture_statement(arguments: &str) -> Option<TextureStatement> {
    let mut tokens: Vec<&str> = arguments.split_whitespace().collect();
    let mut statement = TextureStatement {
        file: String::new(),
        clamp: false,
        bump_scale: None,
    };
    let mut k = 0;
    while k < tokens.len() && tokens[k].starts_with('-') && tokens[k].len() > 1 {
        let option = tokens[k];
        k += 1;
        let mut taken = 0;
        while taken < option_arity(option) && k < tokens.len() {
            let value = tokens[k];
            let numeric = value.parse::<f32>().is_ok();
            let word = matches!(value, "on" | "off") || option == "-imfchan" || option == "-type";
            if !(numeric || word) {
                break;
            }
            match option {
                "-clamp" => statement.clamp = value == "on",
                "-bm" => statement.bump_scale = value.parse().ok(),
                _ => {}
            }
            k += 1;
            taken += 1;
        }
    }
    tokens.drain(..k);
    statement.file = tokens.join(" ").replace('\\', "/");
    (!statement.file.is_empty()).then_some(statement)
}

/// The images of an asset being read, each file read once.
#[derive(Default)]
pub(crate) struct Images {
    pub images: Vec<Image>,
    by_path: HashMap<PathBuf, Option<usize>>,
}

impl Images {
    /// The index of the image at `path`, read on first use; `None` (with a warning, once) when
    /// it cannot be read. An image too large for the memory budget is an error.
    pub(crate) fn get(
        &mut self,
        path: &Path,
        material: &str,
        warnings: &mut Vec<String>,
    ) -> Result<Option<usize>, IoError> {
        if let Some(&known) = self.by_path.get(path) {
            return Ok(known);
        }
        let index = match std::fs::metadata(path) {
            Ok(meta) if meta.is_file() => {
                budget::check_bytes(path, "reading the texture", meta.len())?;
                match std::fs::read(path) {
                    Ok(bytes) => {
                        let mime = mime_of(path, &bytes);
                        if mime != "image/png" && mime != "image/jpeg" {
                            warnings.push(format!(
                                "material '{material}': texture {} is {}, which glTF viewers may not show (PNG and JPEG are core glTF)",
                                path.display(),
                                if mime.is_empty() { "of an unknown type" } else { &mime }
                            ));
                        }
                        let name = path
                            .file_name()
                            .map(|n| n.to_string_lossy().into_owned())
                            .unwrap_or_default();
                        self.images.push(Image {
                            name,
                            mime,
                            bytes: Arc::new(bytes),
                        });
                        Some(self.images.len() - 1)
                    }
                    Err(e) => {
                        warnings.push(format!(
                            "material '{material}': texture {} cannot be read ({e}): left out",
                            path.display()
                        ));
                        None
                    }
                }
            }
            _ => {
                warnings.push(format!(
                    "material '{material}': texture {} not found: left out",
                    path.display()
                ));
                None
            }
        };
        self.by_path.insert(path.to_path_buf(), index);
        Ok(index)
    }
}

/// The media type of an image file: by signature, else by extension; empty when neither says.
fn mime_of(path: &Path, bytes: &[u8]) -> String {
    let by_signature = if bytes.starts_with(b"\x89PNG\r\n\x1a\n") {
        Some("image/png")
    } else if bytes.starts_with(&[0xFF, 0xD8, 0xFF]) {
        Some("image/jpeg")
    } else if bytes.starts_with(b"\xABKTX 20\xBB") {
        Some("image/ktx2")
    } else if bytes.len() >= 12 && &bytes[..4] == b"RIFF" && &bytes[8..12] == b"WEBP" {
        Some("image/webp")
    } else if bytes.starts_with(b"BM") {
        Some("image/bmp")
    } else {
        None
    };
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let by_extension = match extension.as_str() {
        "png" => "image/png",
        "jpg" | "jpeg" => "image/jpeg",
        "ktx2" => "image/ktx2",
        "webp" => "image/webp",
        "bmp" => "image/bmp",
        "tga" => "image/x-tga",
        _ => "",
    };
    by_signature.unwrap_or(by_extension).to_string()
}

/// The roughness of a Phong exponent (see the module's table).
pub(crate) fn roughness_of_shininess(ns: f32) -> f32 {
    if !(ns.is_finite() && ns >= 0.0) {
        return 1.0;
    }
    (2.0 / (ns + 2.0)).powf(0.25).clamp(0.0, 1.0)
}

/// A number among a material's statements tobj does not know (`Tr`, `Pr`, `Pm`).
fn unknown_number(material: &tobj::Material, key: &str) -> Option<f32> {
    material
        .unknown_param
        .get(key)
        .and_then(|v| v.split_whitespace().next()?.parse::<f32>().ok())
        .filter(|v| v.is_finite())
}

/// A material of an MTL file (`dir` is the file's folder) as a glTF material, its images added
/// to `images`. Cost: the images' sizes, on first use.
pub(crate) fn material(
    m: &tobj::Material,
    dir: &Path,
    images: &mut Images,
    warnings: &mut Vec<String>,
) -> Result<Material, IoError> {
    let finite = |c: [f32; 3]| c.map(|x| if x.is_finite() { x.max(0.0) } else { 0.0 });
    let mut out = super::default_material();
    out.name = m.name.clone();
    let kd = finite(m.diffuse.unwrap_or([1.0; 3]));
    let alpha = m
        .dissolve
        .filter(|d| d.is_finite())
        .or_else(|| unknown_number(m, "Tr").map(|tr| 1.0 - tr))
        .unwrap_or(1.0)
        .clamp(0.0, 1.0);
    out.base_color = [kd[0].min(1.0), kd[1].min(1.0), kd[2].min(1.0), alpha];
    if alpha < 1.0 {
        out.alpha_mode = AlphaMode::Blend;
    }
    out.roughness = unknown_number(m, "Pr")
        .map(|r| r.clamp(0.0, 1.0))
        .unwrap_or_else(|| m.shininess.map_or(1.0, roughness_of_shininess));
    out.metallic = unknown_number(m, "Pm").map_or(0.0, |v| v.clamp(0.0, 1.0));
    if let Some(ke) = m.emissive {
        out.emissive = finite(ke).map(|x| x.min(1.0));
    }

    let mut texture =
        |arguments: Option<&str>| -> Result<Option<(TextureRef, TextureStatement)>, IoError> {
            let Some(statement) = arguments.and_then(texture_statement) else {
                return Ok(None);
            };
            let path = dir.join(&statement.file);
            let Some(image) = images.get(&path, &m.name, warnings)? else {
                return Ok(None);
            };
            let wrap = if statement.clamp {
                Wrap::ClampToEdge
            } else {
                Wrap::Repeat
            };
            let sampler = Sampler {
                wrap_u: wrap,
                wrap_v: wrap,
                ..Sampler::default()
            };
            let reference = TextureRef {
                image,
                tex_coord: 0,
                transform: None,
                sampler,
            };
            Ok(Some((reference, statement)))
        };
    out.base_color_texture = texture(m.diffuse_texture.as_deref())?.map(|(t, _)| t);
    out.emissive_texture =
        texture(m.unknown_param.get("map_Ke").map(String::as_str))?.map(|(t, _)| t);
    let normal = m
        .normal_texture
        .as_deref()
        .or_else(|| m.unknown_param.get("norm").map(String::as_str))
        .or_else(|| m.unknown_param.get("map_norm").map(String::as_str));
    if let Some((t, statement)) = texture(normal)? {
        out.normal_texture = Some(t);
        out.normal_scale = statement
            .bump_scale
            .filter(|s| s.is_finite())
            .unwrap_or(1.0);
    }
    if m.dissolve_texture.is_some() {
        warnings.push(format!(
            "material '{}': its alpha map (map_d) is left out: glTF takes alpha from the base colour texture",
            m.name
        ));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texture_statements_skip_options() {
        let s = texture_statement("-s 1 1 1 -clamp on tex.png").unwrap();
        assert_eq!((s.file.as_str(), s.clamp), ("tex.png", true));
        let s = texture_statement("-bm 0.5 maps\\normal map.png").unwrap();
        assert_eq!(s.file, "maps/normal map.png");
        assert_eq!(s.bump_scale, Some(0.5));
        let s = texture_statement("-o 0.5 0.5 a.jpg").unwrap();
        assert_eq!(s.file, "a.jpg");
        assert!(texture_statement("-clamp on").is_none());
        assert!(texture_statement("   ").is_none());
    }

    #[test]
    fn shininess_maps_to_roughness() {
        assert_eq!(roughness_of_shininess(0.0), 1.0);
        assert!((roughness_of_shininess(1000.0) - (2.0f32 / 1002.0).powf(0.25)).abs() < 1e-7);
        assert!(roughness_of_shininess(10.0) > roughness_of_shininess(100.0));
        assert_eq!(roughness_of_shininess(f32::NAN), 1.0);
    }
}
