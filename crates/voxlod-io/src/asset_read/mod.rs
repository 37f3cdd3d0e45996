//! Meshes with their looks: [`read_asset`] reads a file into a [`voxlod_asset::Asset`], the
//! mesh that carries texture coordinates, normals, colours and a material per triangle.
//!
//! - `.obj` with its MTL libraries ([`obj`], through `tobj`): per-corner texture coordinates
//!   and normals, vertices split where the corners of one position differ, a material per
//!   triangle from `usemtl`, and the materials' images read beside their MTL file ([`mtl`]).
//! - `.ply` with vertex colours (`red`, `green`, `blue`, optionally `alpha`; `uchar`, `ushort`
//!   or `float`), normals, and per-vertex texture coordinates (`u`/`v`, `s`/`t`, ...) with the
//!   texture a `comment TextureFile` line names, read by the geometry reader (`ply/`), which
//!   names the colour and texture properties it met ([`crate::ply`]'s `PlyColors`, `PlyLooks`).
//!   Per-corner texture coordinates of faces (MeshLab's `texcoord` lists) are not read.
//! - `.off`, COFF vertex colours included (`off.rs`).
//! - `.stl`, `.vtp`, `.vtk`: the geometry (and normals) only, as [`crate::read_mesh`] reads it.
//!
//! Vertex colours in files are sRGB by convention (they are 8-bit display values, as MeshLab,
//! CloudCompare and scanners write them); the asset's colours are linear, so each channel but
//! alpha goes through the sRGB transfer function ([`srgb_to_linear`]). A mesh that comes with
//! no material of its own (PLY, OFF, STL, VTK, and OBJ faces without a known `usemtl`) gets one
//! added last, named `default`: white, not metallic, fully rough, so that vertex colours show
//! as a scan's diffuse colour rather than as glTF's default (fully metallic) material.
//!
//! Errors are [`IoError`]s naming the file; problems that leave the asset usable (a missing
//! MTL file or texture, normals or texture coordinates given for some faces only) are warnings
//! in [`AssetRead::warnings`] and the asset is read without what was missing.
//!
//! Cost: linear in the file (and its MTL files and images); memory the asset, plus `tobj`'s
//! copy of an OBJ's data while it is converted. Every size meets the memory budget first.

pub(crate) mod mtl;
pub(crate) mod obj;

use std::path::Path;

use voxlod_asset::{Asset, AssetMesh, Material, Part, Sampler, TextureRef};
use voxlod_core::glam::{Vec2, Vec4};
use voxlod_core::PolyMesh;

use crate::{check_finite, check_readable, mesh_format_of, off, ply, IoError, MeshFormat};

/// An asset read from a mesh file, and what was left out of it.
#[derive(Clone, Debug, PartialEq)]
pub struct AssetRead {
    /// The asset; [`Asset::validate`] holds.
    pub asset: Asset,
    /// What the reader left out or could not find, in words, one problem each.
    pub warnings: Vec<String>,
}

/// Reads a mesh file with its looks, by extension (see the module documentation for what each
/// format gives). A file without triangles, or whose asset breaks [`Asset::validate`], is
/// [`IoErrorKind::Malformed`](crate::IoErrorKind::Malformed); non-finite coordinates are
/// [`IoErrorKind::NonFinite`](crate::IoErrorKind::NonFinite). Cost: linear in the file.
///
/// ```
/// use voxlod_io::read_asset;
///
/// let folder = tempfile::tempdir()?;
/// let path = folder.path().join("red.ply");
/// let header = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
///               property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n\
///               element face 1\nproperty list uchar int vertex_indices\nend_header\n";
/// std::fs::write(&path, format!("{header}0 0 0 255 0 0\n1 0 0 255 0 0\n0 1 0 255 0 0\n3 0 1 2\n"))?;
/// let read = read_asset(&path)?;
/// assert_eq!(read.asset.mesh.colors[0].to_array(), [1.0, 0.0, 0.0, 1.0]);
/// assert_eq!(read.asset.materials[0].name, "default");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn read_asset(path: &Path) -> Result<AssetRead, IoError> {
    let format = mesh_format_of(path)?;
    check_readable(path)?;
    let mut warnings = Vec::new();
    let asset = match format {
        MeshFormat::Obj if !crate::mni_obj::is_mni_file(path)? => obj::read(path, &mut warnings)?,
        MeshFormat::Ply => ply_asset(path, &mut warnings)?,
        MeshFormat::Off => {
            let content = off::read(path)?;
            let colors = content.colors.iter().map(|&c| srgba_to_linear(c)).collect();
            geometry_asset(path, PolyMesh::from(content.mesh), colors, &mut warnings)?
        }
        // An MNI polygon file has its geometry only.
        MeshFormat::Obj | MeshFormat::Stl | MeshFormat::Vtp | MeshFormat::Vtu | MeshFormat::Vtk => {
            let loaded = crate::read_mesh(path)?;
            warnings.extend(loaded.notes);
            geometry_asset(path, PolyMesh::from(loaded.mesh), Vec::new(), &mut warnings)?
        }
        MeshFormat::Gltf => return Err(crate::gltf_elsewhere(path)),
    };
    if asset.mesh.triangles.is_empty() {
        return Err(IoError::malformed(path, "no triangles"));
    }
    asset
        .validate()
        .map_err(|e| IoError::malformed(path, e.to_string()))?;
    Ok(AssetRead { asset, warnings })
}

/// A PLY file as an asset: its vertex colours made linear, and its per-vertex texture
/// coordinates (v flipped) with the texture its `comment TextureFile` names, read beside it,
/// as the default material's base colour texture.
fn ply_asset(path: &Path, warnings: &mut Vec<String>) -> Result<Asset, IoError> {
    let content = ply::read(path)?;
    let attributes = &content.mesh.vertex_attributes;
    let n = content.mesh.mesh.positions.len();
    let colors = content.colors.map_or_else(Vec::new, |c| {
        let channel = |k: usize, i: usize| {
            c.channels[k].map_or(1.0, |(a, scale)| attributes[a].values[i] * scale)
        };
        (0..n)
            .map(|i| srgba_to_linear([0, 1, 2, 3].map(|k| channel(k, i))))
            .collect()
    });
    let looks = &content.looks;
    let uv: Vec<Vec2> = looks.uv.map_or_else(Vec::new, |[u, v]| {
        let (u, v) = (&attributes[u].values, &attributes[v].values);
        (0..n).map(|i| Vec2::new(u[i], 1.0 - v[i])).collect()
    });
    let mut images = mtl::Images::default();
    let mut texture = None;
    if let Some(file) = &looks.texture_file {
        if uv.is_empty() {
            warnings.push(format!(
                "the texture {file} is left out: the vertices have no texture coordinates{}",
                if looks.face_texcoords {
                    " (per-corner texcoord lists of faces are not read)"
                } else {
                    ""
                }
            ));
        } else {
            let dir = path.parent().unwrap_or(Path::new(""));
            let file = mtl::texture_statement(file).map_or_else(|| file.clone(), |s| s.file);
            texture = images.get(&dir.join(file), "default", warnings)?;
        }
    }
    let mut asset = geometry_asset(path, content.mesh, colors, warnings)?;
    asset.mesh.uv[0] = uv;
    if let Some(image) = texture {
        asset.materials[0].base_color_texture = Some(TextureRef {
            image,
            tex_coord: 0,
            transform: None,
            sampler: Sampler::default(),
        });
        asset.images = images.images;
    }
    Ok(asset)
}

/// The asset of a mesh that has geometry, normals and colours but no materials: one `default`
/// material, one part. Lines and points are left out with a warning. The mesh is checked as
/// [`crate::read_mesh`] checks it (finite, indices in range).
fn geometry_asset(
    path: &Path,
    poly: PolyMesh,
    colors: Vec<Vec4>,
    warnings: &mut Vec<String>,
) -> Result<Asset, IoError> {
    check_finite(path, &poly.mesh)?;
    poly.validate()
        .map_err(|e| IoError::malformed(path, e.to_string()))?;
    if !poly.lines.is_empty() || !poly.points.is_empty() {
        warnings.push(format!(
            "{} lines and {} points left out: an asset holds triangles only",
            poly.lines.len(),
            poly.points.len()
        ));
    }
    let mesh = poly.mesh;
    let triangle_count = mesh.triangles.len();
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    Ok(Asset {
        mesh: AssetMesh {
            material: vec![0; triangle_count],
            positions: mesh.positions,
            triangles: mesh.triangles,
            normals: mesh.normals,
            colors,
            ..AssetMesh::default()
        },
        materials: vec![default_material()],
        images: Vec::new(),
        parts: vec![Part {
            name,
            first_triangle: 0,
            triangle_count: triangle_count as u32,
        }],
    })
}

/// The material of a mesh that names none: white, dielectric, fully rough, opaque.
pub(crate) fn default_material() -> Material {
    Material {
        name: "default".into(),
        metallic: 0.0,
        roughness: 1.0,
        ..Material::default()
    }
}

/// One sRGB-encoded channel value in 0..=1 as linear light (IEC 61966-2-1's transfer function:
/// `c / 12.92` up to 0.04045, `((c + 0.055) / 1.055)^2.4` above). Values outside 0..=1 are
/// clamped first.
pub fn srgb_to_linear(c: f32) -> f32 {
    let c = c.clamp(0.0, 1.0);
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// An sRGB colour with linear alpha, as a linear RGBA colour.
pub(crate) fn srgba_to_linear(c: [f32; 4]) -> Vec4 {
    Vec4::new(
        srgb_to_linear(c[0]),
        srgb_to_linear(c[1]),
        srgb_to_linear(c[2]),
        c[3].clamp(0.0, 1.0),
    )
}
