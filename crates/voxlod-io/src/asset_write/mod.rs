//! Assets with their looks written as files other tools read: [`asset_files`] gives the bytes of
//! every file an asset takes, [`write_asset`] writes them all or none (an [`OutputSet`]).
//!
//! - `.obj` ([`obj`]): the OBJ, its MTL library beside it (`NAME.mtl`) and the images the
//!   materials use, as files beside them (their bytes as read: PNG, JPEG, …).
//! - `.ply` ([`ply`]): one binary little-endian PLY with normals, vertex colours as `uchar`
//!   sRGB and texture coordinates as `texture_u`/`texture_v`, the base colour texture named by
//!   a `comment TextureFile` line and written beside it.
//!
//! Both split the mesh into one block of vertices per material (a vertex that triangles of two
//! materials share is written once for each), as OBJ readers make one part per `usemtl`
//! anyway; read back with [`crate::read_asset`], the triangles are the same, in material
//! order, and the vertices those blocks. What a format cannot hold is a warning in
//! [`AssetFiles::warnings`], never dropped in silence; each file says what it carries
//! ([`AssetFile::carries`]).
//!
//! Colours: the asset's are linear; files get sRGB values ([`linear_to_srgb`]), the inverse of
//! what the reader does.
//!
//! Cost: linear in the asset, plus its images' bytes copied once.

mod obj;
mod ply;

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use voxlod_asset::{Asset, Image};

use crate::{extension, IoError, OutputSet};

/// One file of an asset: where it goes, its bytes, and what it carries, in words.
#[derive(Clone, Debug, PartialEq)]
pub struct AssetFile {
    /// Its path: the path asked for, or a file beside it.
    pub path: PathBuf,
    /// Its content.
    pub bytes: Vec<u8>,
    /// What it holds: `"triangles"`, `"normals"`, `"texture coordinates"`, `"vertex colours"`,
    /// `"materials"`, `"texture"`, …
    pub carries: Vec<String>,
}

/// Every file of an asset, the main one first, and what could not be kept.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AssetFiles {
    /// The files, the OBJ or PLY first.
    pub files: Vec<AssetFile>,
    /// What the format could not hold (a second texture coordinate set, a texture transform,
    /// a second texture in a PLY, …), one sentence each.
    pub warnings: Vec<String>,
}

/// The files of `asset` written at `path` (`.obj` or `.ply`, by extension). Refuses another
/// extension, or an asset that breaks [`Asset::validate`] or has no triangles.
pub fn asset_files(path: &Path, asset: &Asset) -> Result<AssetFiles, IoError> {
    asset
        .validate()
        .map_err(|e| IoError::unsupported(path, format!("cannot write the asset: {e}")))?;
    if asset.mesh.triangles.is_empty() {
        return Err(IoError::unsupported(path, "the asset has no triangles"));
    }
    match extension(path).as_str() {
        "obj" => obj::files(path, asset),
        "ply" => ply::files(path, asset),
        other => Err(IoError::unsupported(
            path,
            format!("an asset is written as .obj (with its MTL) or .ply, not '.{other}'"),
        )),
    }
}

/// Writes `asset` at `path` with the files beside it, all of them or none (see
/// [`asset_files`]); returns what was written and the warnings.
///
/// ```
/// use voxlod_asset::{Asset, AssetMesh, Material};
/// use voxlod_core::glam::{Vec3, Vec4};
///
/// let folder = tempfile::tempdir()?;
/// let asset = Asset {
///     mesh: AssetMesh {
///         positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
///         triangles: vec![[0, 1, 2]],
///         colors: vec![Vec4::new(1.0, 0.0, 0.0, 1.0); 3],
///         material: vec![0],
///         ..AssetMesh::default()
///     },
///     materials: vec![Material::default()],
///     ..Asset::default()
/// };
/// let path = folder.path().join("red.ply");
/// voxlod_io::write_asset(&path, &asset)?;
/// let back = voxlod_io::read_asset(&path)?.asset;
/// assert_eq!(back.mesh.colors[0], Vec4::new(1.0, 0.0, 0.0, 1.0));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn write_asset(path: &Path, asset: &Asset) -> Result<AssetFiles, IoError> {
    let files = asset_files(path, asset)?;
    let mut out = OutputSet::new();
    stage_assets(&mut out, &[&files])?;
    out.commit()?;
    Ok(files)
}

/// Adds the files of several assets (the levels of one chain) to `out`. A file that two of
/// them give with the same bytes (a texture the levels share) is added once; two different
/// files at one path are refused, naming it.
pub fn stage_assets(out: &mut OutputSet, assets: &[&AssetFiles]) -> Result<(), IoError> {
    let mut staged: HashMap<&Path, &[u8]> = HashMap::new();
    for f in assets.iter().flat_map(|a| &a.files) {
        match staged.get(f.path.as_path()) {
            Some(bytes) if *bytes == &f.bytes[..] => continue,
            Some(_) => {
                return Err(IoError::new(
                    &f.path,
                    crate::IoErrorKind::Conflict,
                    "two different files of the assets written would take this name",
                ))
            }
            None => {}
        }
        out.bytes(&f.path, &f.bytes)?;
        staged.insert(&f.path, &f.bytes);
    }
    Ok(())
}

/// One block of the mesh: the triangles of one material, with the vertices they use.
pub(crate) struct Block {
    /// The material, an index into the asset's materials (`None`: the asset has none).
    pub material: Option<u32>,
    /// The asset's vertex of each of the block's vertices, in order of first use.
    pub vertices: Vec<u32>,
    /// The triangles, as indices into `vertices`.
    pub triangles: Vec<[u32; 3]>,
}

/// The mesh split into one block per material, in order of the material's first triangle.
pub(crate) fn blocks(asset: &Asset) -> Vec<Block> {
    let m = &asset.mesh;
    let mut out: Vec<Block> = Vec::new();
    let mut slot: HashMap<Option<u32>, usize> = HashMap::new();
    let mut local: Vec<HashMap<u32, u32>> = Vec::new();
    for (t, tri) in m.triangles.iter().enumerate() {
        let material = m.material.get(t).copied();
        let b = *slot.entry(material).or_insert_with(|| {
            out.push(Block {
                material,
                vertices: Vec::new(),
                triangles: Vec::new(),
            });
            local.push(HashMap::new());
            out.len() - 1
        });
        let (block, map) = (&mut out[b], &mut local[b]);
        let corner = tri.map(|v| {
            *map.entry(v).or_insert_with(|| {
                block.vertices.push(v);
                (block.vertices.len() - 1) as u32
            })
        });
        block.triangles.push(corner);
    }
    out
}

/// The images an asset's materials use, as files beside `path`: each named by its own name
/// (its file name part, characters other than letters, digits, `.`, `-`, `_` replaced by `_`)
/// with the extension of its media type, or `texture-K` when it has none; a name two images
/// would share gets `-K` added.
pub(crate) struct Textures {
    /// File name of each image of the asset (those no material uses too).
    pub names: Vec<String>,
}

impl Textures {
    pub(crate) fn of(images: &[Image]) -> Textures {
        let mut names: Vec<String> = Vec::with_capacity(images.len());
        for (k, image) in images.iter().enumerate() {
            let stem = Path::new(&image.name)
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default();
            let stem: String = stem
                .chars()
                .map(|c| {
                    if c.is_ascii_alphanumeric() || "._-".contains(c) {
                        c
                    } else {
                        '_'
                    }
                })
                .collect();
            let stem = if stem.trim_matches(['.', '_']).is_empty() {
                format!("texture-{k}")
            } else {
                stem
            };
            let ext = image_extension(image);
            let mut name = format!("{stem}.{ext}");
            if names.contains(&name) {
                name = format!("{stem}-{k}.{ext}");
            }
            names.push(name);
        }
        Textures { names }
    }

    /// The file of image `k` beside `path`, with what it carries.
    pub(crate) fn file(&self, path: &Path, images: &[Image], k: usize) -> AssetFile {
        AssetFile {
            path: path.with_file_name(&self.names[k]),
            bytes: images[k].bytes.to_vec(),
            carries: vec!["texture".into()],
        }
    }
}

/// The file extension of an image's media type (`bin` for an unknown one).
fn image_extension(image: &Image) -> &'static str {
    match image.mime.as_str() {
        "image/png" => "png",
        "image/jpeg" => "jpg",
        "image/ktx2" => "ktx2",
        "image/webp" => "webp",
        "image/bmp" => "bmp",
        "image/x-tga" => "tga",
        _ => "bin",
    }
}

/// One linear channel value as sRGB-encoded, in 0..=1 (IEC 61966-2-1: `12.92 c` up to
/// 0.0031308, `1.055 c^(1/2.4) − 0.055` above); the inverse of [`crate::srgb_to_linear`].
/// Values outside 0..=1 are clamped first.
pub fn linear_to_srgb(c: f32) -> f32 {
    let c = c.clamp(0.0, 1.0);
    if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_round_trips() {
        for k in 0..=255 {
            let s = k as f32 / 255.0;
            let back = linear_to_srgb(crate::srgb_to_linear(s));
            assert!((back - s).abs() < 1e-5, "{s} came back as {back}");
        }
    }
}
