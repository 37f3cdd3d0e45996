//! Reading and writing meshes and volumes in one call each, by the file's extension (the
//! formats of [`voxlod_io`]: OBJ, PLY, STL, OFF, VTK meshes; NRRD, VTK ImageData, NIfTI,
//! MetaImage and headerless raw volumes).
//!
//! The reader's details (the format, how many polygons were split, what STL welding did) are
//! in [`voxlod_io::read_mesh`]; these calls give the data. Writing goes to a temporary file that
//! replaces the target only when complete. Cost: one pass over the file.

use std::path::Path;

use voxlod_core::{TriangleMesh, Volume};
use voxlod_gltf::GlbScene;
use voxlod_io::RawLayout;

use crate::error::Error;

/// Reads a triangle mesh: polygons ear-clipped, STL soups welded, nothing else changed.
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
    Ok(voxlod_io::read_mesh(path.as_ref())?.mesh)
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

/// Whether `path` names a binary glTF file (extension `.glb`, any case).
pub(crate) fn is_glb(path: impl AsRef<Path>) -> bool {
    path.as_ref()
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("glb"))
}
