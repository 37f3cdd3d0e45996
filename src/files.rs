//! Reading and writing meshes and volumes in one call each, by the file's extension (the
//! formats of [`voxlod_io`]: OBJ, PLY, STL, OFF, VTK meshes; NRRD, VTK ImageData, NIfTI,
//! MetaImage and headerless raw volumes).
//!
//! The reader's details (the format, how many polygons were split, what STL welding did) are
//! in [`voxlod_io::read_mesh`]; these calls give the data. Writing goes to a temporary file that
//! replaces the target only when complete. Cost: one pass over the file.

use std::path::{Path, PathBuf};

use voxlod_core::glam::DVec3;
use voxlod_core::{TriangleMesh, Volume};
use voxlod_gltf::{GlbScene, SceneRead};
use voxlod_io::{IoError, IoErrorKind, LoadedMesh, MeshFormat, RawLayout};

use crate::error::Error;

/// Reads a triangle mesh: polygons ear-clipped, STL soups welded, nothing else changed; a glTF
/// file (`.glb`, `.gltf`) gives its scene's geometry in world space (every node and instance,
/// as [`read_scene`] reads them; its looks left out).
///
/// ```
/// # fn main() -> Result<(), voxlod::Error> {
/// let dir = std::env::temp_dir().join(format!("voxlod-doc-read-{}", std::process::id()));
/// std::fs::create_dir_all(&dir).unwrap();
/// let path = dir.join("triangle.obj");
/// std::fs::write(&path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
/// let mesh = voxlod::read_mesh(&path)?;
/// assert_eq!((mesh.vertex_count(), mesh.triangle_count()), (3, 1));
/// // A file without triangles is refused, naming the file.
/// std::fs::write(&path, "v 0 0 0\n").unwrap();
/// let e = voxlod::read_mesh(&path).unwrap_err();
/// assert!(e.to_string().contains("triangle.obj"));
/// assert_eq!(e.class(), voxlod::ErrorClass::BadInput);
/// # std::fs::remove_dir_all(&dir).unwrap();
/// # Ok(())
/// # }
/// ```
pub fn read_mesh(path: impl AsRef<Path>) -> Result<TriangleMesh, Error> {
    Ok(read_mesh_file(path)?.mesh)
}

/// [`read_mesh`] with what the reader did ([`voxlod_io::LoadedMesh`]: the format, polygons
/// split, STL welding) and, in its notes, what reading changed or left out (an unstructured
/// grid's volume cells read as their boundary; a glTF file's unknown extensions, primitives
/// that are not surfaces). Fails, naming the file, where it holds no triangle.
pub fn read_mesh_file(path: impl AsRef<Path>) -> Result<LoadedMesh, Error> {
    let path = path.as_ref();
    if !is_gltf(path) {
        return Ok(voxlod_io::read_mesh(path)?);
    }
    let read = voxlod_gltf::read_scene(path)?;
    let mut mesh = read.asset.mesh.geometry();
    if read.origin != DVec3::ZERO {
        for p in &mut mesh.positions {
            *p = (p.as_dvec3() + read.origin).as_vec3();
        }
    }
    if mesh.triangles.is_empty() {
        let problem = "the glTF scene holds no triangles";
        return Err(IoError::new(path, IoErrorKind::Malformed, problem).into());
    }
    let loaded = LoadedMesh {
        mesh,
        format: MeshFormat::Gltf,
        welded: None,
        polygons_triangulated: 0,
        notes: read.warnings,
    };
    Ok(loaded)
}

/// Writes a triangle mesh in the format of the extension (`.ply` binary with normals, `.obj`,
/// `.stl`, `.vtp`, `.vtk`).
///
/// ```
/// # fn main() -> Result<(), voxlod::Error> {
/// use voxlod::core::glam::Vec3;
/// let dir = std::env::temp_dir().join(format!("voxlod-doc-write-{}", std::process::id()));
/// std::fs::create_dir_all(&dir).unwrap();
/// let mesh = voxlod::core::TriangleMesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]]);
/// voxlod::write_mesh(dir.join("t.ply"), &mesh)?;
/// assert_eq!(voxlod::read_mesh(dir.join("t.ply"))?.triangles, mesh.triangles);
/// # std::fs::remove_dir_all(&dir).unwrap();
/// # Ok(())
/// # }
/// ```
pub fn write_mesh(path: impl AsRef<Path>, mesh: &TriangleMesh) -> Result<(), Error> {
    Ok(voxlod_io::write_mesh(path.as_ref(), mesh)?)
}

/// Reads a volume by its extension; a headerless raw file needs its `raw_layout` (dimensions,
/// sample type, byte order, spacing, origin), which other formats ignore.
///
/// ```
/// # fn main() -> Result<(), voxlod::Error> {
/// use voxlod::io::{Endian, RawLayout, RawType};
/// let dir = std::env::temp_dir().join(format!("voxlod-doc-volume-{}", std::process::id()));
/// std::fs::create_dir_all(&dir).unwrap();
/// let path = dir.join("v.raw");
/// std::fs::write(&path, (0u8..8).collect::<Vec<u8>>()).unwrap();
/// let layout = RawLayout::new([2, 2, 2], RawType::U8, Endian::Little);
/// let volume = voxlod::read_volume(&path, Some(&layout))?;
/// assert_eq!((volume.grid.dims, volume.get(1, 1, 1)), ([2, 2, 2], 7.0));
/// # std::fs::remove_dir_all(&dir).unwrap();
/// # Ok(())
/// # }
/// ```
pub fn read_volume(
    path: impl AsRef<Path>,
    raw_layout: Option<&RawLayout>,
) -> Result<Volume, Error> {
    Ok(voxlod_io::read_volume(path.as_ref(), raw_layout)?)
}

/// Writes a volume in the format of the extension (`.nrrd`, `.nhdr`, `.vti`, `.vtk`, `.mha`,
/// `.mhd`, `.raw`), uncompressed; [`voxlod_io::write_volume_with`] compresses.
///
/// ```
/// # fn main() -> Result<(), voxlod::Error> {
/// use voxlod::core::{Grid, Volume};
/// let dir = std::env::temp_dir().join(format!("voxlod-doc-wvol-{}", std::process::id()));
/// std::fs::create_dir_all(&dir).unwrap();
/// let grid = Grid::new([3, 3, 3], [0.5; 3], [0.0; 3])?;
/// let volume = Volume::filled(grid, 2.0, "the doc volume")?;
/// voxlod::write_volume(dir.join("v.nrrd"), &volume)?;
/// let back = voxlod::read_volume(dir.join("v.nrrd"), None)?;
/// assert_eq!((back.grid.spacing, back.get(2, 2, 2)), ([0.5; 3], 2.0));
/// # std::fs::remove_dir_all(&dir).unwrap();
/// # Ok(())
/// # }
/// ```
pub fn write_volume(path: impl AsRef<Path>, volume: &Volume) -> Result<(), Error> {
    Ok(voxlod_io::write_volume(path.as_ref(), volume)?)
}

/// Reads a binary glTF file (`.glb`): the layered shells of [`crate::layers()`] as stored
/// (every layer's triangles in one mesh, each layer's range and material as a part, the
/// volume grid and the eight back-to-front orders); any other file as its scene
/// ([`voxlod_gltf::read_scene`]: every node's primitives in world space, compressed, quantized
/// and instanced files included), a part per primitive and instance. Errors name the file.
pub fn read_glb(path: impl AsRef<Path>) -> Result<GlbScene, Error> {
    Ok(voxlod_gltf::read_any_glb(path.as_ref())?)
}

/// Whether `path` names a glTF file (extension `.glb` or `.gltf`, any case).
pub(crate) fn is_gltf(path: impl AsRef<Path>) -> bool {
    voxlod_io::mesh_format_of(path.as_ref()).ok() == Some(MeshFormat::Gltf)
}

/// Whether `path` names a binary glTF file (extension `.glb`, any case).
pub(crate) fn is_glb(path: impl AsRef<Path>) -> bool {
    path.as_ref()
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("glb"))
}

/// Reads a scene as one asset in world space, with the readers' warnings and the world point
/// its positions are relative to: a glTF file (`.glb`, `.gltf`: every node, instance and
/// material, [`voxlod_gltf::read_scene`]), a folder of meshes and glTF files (each read with its
/// looks and joined, [`voxlod_asset::join`], in the order of their names; textures and
/// material libraries beside them are read through the files that name them), or one mesh
/// with its looks (OBJ with MTL, coloured PLY or OFF, STL, VTK: [`voxlod_io::read_asset`]).
/// Errors name the file, or the folder where it holds no mesh. Cost: one pass over each file.
///
/// ```
/// # fn main() -> Result<(), voxlod::Error> {
/// let dir = std::env::temp_dir().join(format!("voxlod-doc-scene-{}", std::process::id()));
/// std::fs::create_dir_all(&dir).unwrap();
/// std::fs::write(dir.join("a.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
/// std::fs::write(dir.join("b.off"), "OFF\n3 1 0\n5 0 0\n6 0 0\n5 1 0\n3 0 1 2\n").unwrap();
/// let scene = voxlod::read_scene(&dir)?;
/// assert_eq!(scene.asset.mesh.triangles.len(), 2);
/// assert_eq!(scene.asset.parts.len(), 2);
/// # std::fs::remove_dir_all(&dir).unwrap();
/// # Ok(())
/// # }
/// ```
pub fn read_scene(path: impl AsRef<Path>) -> Result<SceneRead, Error> {
    let path = path.as_ref();
    if path.is_dir() {
        return read_scene_folder(path);
    }
    if is_gltf(path) {
        return Ok(voxlod_gltf::read_scene(path)?);
    }
    let read = voxlod_io::read_asset(path)?;
    Ok(SceneRead {
        asset: read.asset,
        warnings: read.warnings,
        origin: DVec3::ZERO,
    })
}

/// Files a folder scene reads past without a word: what its meshes and glTF files name.
const COMPANIONS: [&str; 7] = ["mtl", "png", "jpg", "jpeg", "bin", "ktx2", "webp"];

/// [`read_scene`] of a folder: its mesh and glTF files, in the order of their names, joined;
/// the first glTF file's origin is the scene's, the others' positions moved to it.
fn read_scene_folder(folder: &Path) -> Result<SceneRead, Error> {
    let access = |e: std::io::Error| {
        IoError::new(
            folder,
            IoErrorKind::Access,
            format!("cannot list the folder: {e}"),
        )
    };
    let mut entries: Vec<PathBuf> = (std::fs::read_dir(folder).map_err(access)?)
        .map(|e| e.map(|e| e.path()).map_err(access))
        .collect::<Result<_, _>>()?;
    entries.sort();
    let (mut assets, mut warnings, mut origin) = (Vec::new(), Vec::new(), None);
    let mut left_out = Vec::new();
    for path in entries {
        let name = path
            .file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into());
        let extension = (path.extension().and_then(|e| e.to_str()))
            .map_or_else(String::new, str::to_ascii_lowercase);
        let is_mesh = voxlod_io::mesh_format_of(&path).is_ok() || is_gltf(&path);
        if path.is_dir() || !is_mesh {
            if path.is_dir() || !COMPANIONS.contains(&extension.as_str()) {
                left_out.push(name);
            }
            continue;
        }
        let mut read = read_scene(&path)?;
        let common = *origin.get_or_insert(read.origin);
        let shift = (read.origin - common).as_vec3();
        read.asset
            .mesh
            .positions
            .iter_mut()
            .for_each(|p| *p += shift);
        warnings.extend(read.warnings.into_iter().map(|w| format!("{name}: {w}")));
        let stem = path
            .file_stem()
            .map_or(name.clone(), |s| s.to_string_lossy().into());
        assets.push((stem, read.asset));
    }
    if assets.is_empty() {
        return Err(IoError::new(
            folder,
            IoErrorKind::Empty,
            format!(
                "the folder holds no mesh or glTF file ({}, .glb, .gltf)",
                voxlod_io::MESH_EXTENSIONS
            ),
        )
        .into());
    }
    if !left_out.is_empty() {
        warnings.push(format!(
            "{} entries of the folder are neither meshes nor glTF files and were left out \
             (subfolders are not read): {}",
            left_out.len(),
            left_out.join(", ")
        ));
    }
    let asset = voxlod_asset::join(assets)
        .map_err(|e| IoError::new(folder, IoErrorKind::TooLarge, e.to_string()))?;
    Ok(SceneRead {
        asset,
        warnings,
        origin: origin.unwrap_or(DVec3::ZERO),
    })
}
