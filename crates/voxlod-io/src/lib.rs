//! File formats of voxlod: polygon meshes in, levels of detail out, and scanned volumes in.
//!
//! Formats are chosen by extension, without regard to case:
//!
//! | extension | kind | read | write | module |
//! |---|---|---|---|---|
//! | `.obj` | mesh | polygons (ear-clipped), normals, lines, points | triangles, normals, lines, points | `obj.rs` |
//! | `.ply` | mesh | ASCII and binary; normals, attributes, edges, points | binary little-endian, same | `ply/` |
//! | `.stl` | mesh | ASCII and binary, welded on load | binary | `stl.rs` |
//! | `.off` | mesh | OFF/COFF/NOFF, polygons | OFF/NOFF | `off.rs` |
//! | `.vtp`, `.vtk` | mesh | VTK PolyData (XML in every encoding VTK writes, legacy) | same, with attributes | `vtk/mesh.rs`, `vtk/xml.rs` |
//! | `.vtu`, `.vtk` | mesh | VTK UnstructuredGrid (XML, legacy): surface cells, volume cells as their union's boundary | — | `vtk/unstructured.rs` |
//! | `.nrrd`, `.nhdr` | volume | raw, gzip, ascii; attached or detached data | raw or gzip | `nrrd.rs` |
//! | `.vti`, `.vtk` | volume | VTK image data (XML in every encoding VTK writes, legacy) | same | `vtk/image.rs`, `vtk/xml.rs` |
//! | `.nii`, `.nii.gz` | volume | NIfTI-1 | NIfTI-1 | `nifti/` |
//! | `.mha`, `.mhd` | volume | MetaImage, zlib or not, local or detached data | same | `metaimage.rs` |
//! | `.dcm`, a folder | volume | DICOM series (one SeriesInstanceUID), in LPS | — | `dicom/mod.rs`, `dicom/geometry.rs` |
//! | `.dcm`, a folder | label map | DICOM Segmentation (BINARY, FRACTIONAL), in LPS ([`read_label_map`]) | — | `dicom/seg.rs` |
//! | any volume format above | label map | exact `u32` labels ([`read_label_map`]) | `.nrrd`, `.nii`, `.nii.gz` `uint32` ([`write_label_map`]) | `label_map.rs` |
//! | `.raw` (or any other, given a [`RawLayout`]) | volume | headerless samples | `f32` little-endian | `raw.rs` |
//! | `.zarr` (a folder) | volume | Zarr v2/v3 arrays, OME-Zarr 0.4/0.5 images; whole or by region ([`open_zarr`]) | OME-Zarr 0.5 image (Zarr v3, zstd) | `zarr/` |
//!
//! A `.vtk` file may hold either kind: [`file_kind`] looks inside to tell.
//!
//! [`read_asset`] reads a mesh with its looks as a [`voxlod_asset::Asset`] (`asset_read/`): an
//! OBJ with its MTL materials, texture coordinates, normals and images (through `tobj`), a PLY
//! or OFF with its vertex colours made linear (a PLY's texture coordinates and `TextureFile`
//! too), the other mesh formats as geometry. [`write_asset`] writes one back (`asset_write/`): an
//! OBJ with its MTL and images beside it, or a PLY with sRGB `uchar` vertex colours, texture
//! coordinates and its texture beside it.
//!
//! Every error is an [`IoError`] that prints as `path: problem` on one line, in plain words
//! (never a parser's internals), with an [`IoErrorKind`] to act on; no input, however broken,
//! makes a reader panic or hang (`tests/mutation_sweep.rs`), and every size read from a file
//! meets the memory budget before anything of that size is allocated (`budget.rs`). Readers never
//! repair: degenerate and duplicate triangles are returned as stored, for
//! `voxlod_core::repair` and `inspect` to see. Volumes come out as `f32` with the file's
//! spacing and origin, in millimetres where the file says which unit it uses.
//!
//! Every writer goes through an [`OutputSet`] (`outputs.rs`): files are written to temporaries
//! (unnamed ones on Linux) and put in place together, so a failed, interrupted or killed write
//! leaves neither a partial file nor a temporary one behind, and no output replaces an input the
//! set protects. The `write_*` functions below are sets of one file that protect nothing.
//!
//! None of this is in the voxel paper (He et al. 1995): it is the way in for the polygon models
//! and scanned volumes of its §4, and the way out for the levels §2 and §3 make. Cost: every
//! reader and writer is linear in the size of the file; memory is the decoded mesh or volume,
//! plus one copy of the data while a format's bytes are converted (each module says how much).
//!
//! A mesh and a volume, written and read back:
//!
//! ```
//! use voxlod_core::{glam::Vec3, Grid, TriangleMesh, Volume};
//! use voxlod_io::{read_mesh, read_volume, write_mesh, write_volume, IoErrorKind, MeshFormat};
//!
//! let folder = tempfile::tempdir()?;
//! // A tetrahedron, wound outwards.
//! let corners = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
//! let tetrahedron = TriangleMesh::new(corners, vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]);
//! for name in ["t.ply", "t.obj", "t.off", "t.vtp"] {
//!     write_mesh(&folder.path().join(name), &tetrahedron)?;
//!     let loaded = read_mesh(&folder.path().join(name))?;
//!     assert_eq!(loaded.mesh.triangles, tetrahedron.triangles);
//!     assert_eq!(loaded.mesh.positions, tetrahedron.positions);
//! }
//! // STL stores each triangle's own corners: reading welds the 12 back into 4.
//! write_mesh(&folder.path().join("t.stl"), &tetrahedron)?;
//! let loaded = read_mesh(&folder.path().join("t.stl"))?;
//! assert_eq!((loaded.format, loaded.mesh.vertex_count()), (MeshFormat::Stl, 4));
//! assert!((loaded.mesh.signed_volume() - 1.0 / 6.0).abs() < 1e-7);
//!
//! // A 2×3×4 volume with 0.5 mm spacing: NRRD keeps the samples, spacing and origin.
//! let grid = Grid::new([2, 3, 4], [0.5; 3], [10.0, 20.0, 30.0])?;
//! let volume = Volume::from_vec(grid, (0..24).map(|v| v as f32).collect())?;
//! let path = folder.path().join("v.nrrd");
//! write_volume(&path, &volume)?;
//! assert_eq!(read_volume(&path, None)?, volume);
//!
//! // A file cut short is an error that names the file, not a panic.
//! let bytes = std::fs::read(&path)?;
//! std::fs::write(&path, &bytes[..bytes.len() - 10])?;
//! let error = read_volume(&path, None).unwrap_err();
//! assert_eq!(error.kind, IoErrorKind::Truncated);
//! assert!(error.to_string().starts_with(&path.display().to_string()));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#![warn(missing_docs)]

mod asset_read;
mod asset_write;
pub mod atomic;
mod block_read;
mod blockwise_volume;
mod budget;
mod decode_target;
mod detached;
mod dicom;
pub mod ear_clipping;
mod error;
mod guard;
mod label_map;
mod label_table;
mod metaimage;
mod mni_obj;
mod nifti;
mod nrrd;
mod obj;
mod off;
mod outputs;
mod ply;
mod raw;
mod samples;
mod stl;
mod stream_read;
mod vtk;
mod zarr;

use std::fmt;
use std::io::Read;
use std::path::Path;

use voxlod_core::validate::{find_defect, validate_mesh, Requirements};
use voxlod_core::{Attribute, PolyMesh, TriangleMesh, Volume};

pub use asset_read::{read_asset, srgb_to_linear, AssetRead};
pub use asset_write::{
    asset_files, linear_to_srgb, stage_assets, write_asset, AssetFile, AssetFiles,
};
pub use blockwise_volume::BlockwiseVolume;
pub use dicom::seg::{
    cielab_to_srgb, find_dicom_seg, is_dicom_seg, read_dicom_seg, SEGMENTATION_STORAGE,
};
pub use dicom::{list_dicom_series, read_dicom_series, DicomOptions, SeriesSummary};
pub use error::{IoError, IoErrorKind};
pub use label_map::{read_label_map, read_label_map_with, write_label_map};
pub use label_table::{read_label_table, LabelMap, LabelName};
pub use outputs::{check_image_path, OutputSet, IMAGE_EXTENSIONS};
pub use raw::{RawLayout, RawType};
pub use samples::{Endian, ParseNameError};
pub use voxlod_core::weld::WeldReport;
pub use zarr::{open_zarr, ZarrVolume};

use atomic::TempFile;
use vtk::Flavor;

// -------------------------------------------------------------------------------------------
// Formats.

/// A polygon mesh format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MeshFormat {
    /// Wavefront OBJ.
    Obj,
    /// Stanford PLY, ASCII or binary.
    Ply,
    /// STL, ASCII or binary.
    Stl,
    /// Object File Format (Geomview).
    Off,
    /// VTK XML PolyData.
    Vtp,
    /// VTK XML UnstructuredGrid, read only: its surface cells, and its volume cells as the
    /// boundary of their union.
    Vtu,
    /// Legacy VTK (PolyData).
    Vtk,
    /// glTF 2.0 (`.glb`, `.gltf`): a scene, which crate `voxlod-gltf` reads (`voxlod::read_mesh`
    /// gives its geometry); the readers and writers here refuse it, naming that reader.
    Gltf,
}

/// A volume format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum VolumeFormat {
    /// NRRD with attached data.
    Nrrd,
    /// NRRD header with a detached data file.
    Nhdr,
    /// VTK XML image data.
    Vti,
    /// Legacy VTK (structured points).
    Vtk,
    /// NIfTI-1, `.nii` or `.nii.gz`.
    Nifti,
    /// MetaImage with local data.
    Mha,
    /// MetaImage header with a detached data file.
    Mhd,
    /// Headerless samples.
    Raw,
    /// A DICOM series: a folder of slices, or one `.dcm` file (read-only).
    Dicom,
    /// A Zarr array or OME-Zarr image (a folder).
    Zarr,
}

/// What a file holds, as [`file_kind`] tells.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FileKind {
    /// A polygon mesh, in this format.
    Mesh(MeshFormat),
    /// A sampled volume, in this format.
    Volume(VolumeFormat),
}

impl fmt::Display for MeshFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            MeshFormat::Obj => "OBJ",
            MeshFormat::Ply => "PLY",
            MeshFormat::Stl => "STL",
            MeshFormat::Off => "OFF",
            MeshFormat::Vtp => "VTK XML PolyData",
            MeshFormat::Vtu => "VTK XML UnstructuredGrid",
            MeshFormat::Vtk => "legacy VTK PolyData",
            MeshFormat::Gltf => "glTF",
        })
    }
}

impl fmt::Display for VolumeFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            VolumeFormat::Nrrd => "NRRD",
            VolumeFormat::Nhdr => "NRRD (detached header)",
            VolumeFormat::Vti => "VTK XML image data",
            VolumeFormat::Vtk => "legacy VTK structured points",
            VolumeFormat::Nifti => "NIfTI-1",
            VolumeFormat::Mha => "MetaImage",
            VolumeFormat::Mhd => "MetaImage (detached header)",
            VolumeFormat::Raw => "headerless raw",
            VolumeFormat::Dicom => "DICOM series",
            VolumeFormat::Zarr => "Zarr",
        })
    }
}

/// The mesh extensions the readers take, for messages.
pub const MESH_EXTENSIONS: &str = ".obj, .ply, .stl, .off, .vtp, .vtu, .vtk, .glb, .gltf";
const VOLUME_EXTENSIONS: &str =
    ".nrrd, .nhdr, .vti, .vtk, .nii, .nii.gz, .mha, .mhd, .raw, .zarr, .dcm or a DICOM folder";

/// The lower-case file name, for extension tests.
fn lower_name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default()
}

fn extension(path: &Path) -> String {
    path.extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default()
}

/// The mesh format of a path, by extension (case-insensitive).
pub fn mesh_format_of(path: &Path) -> Result<MeshFormat, IoError> {
    Ok(match extension(path).as_str() {
        "obj" => MeshFormat::Obj,
        "ply" => MeshFormat::Ply,
        "stl" => MeshFormat::Stl,
        "off" => MeshFormat::Off,
        "vtp" => MeshFormat::Vtp,
        "vtu" => MeshFormat::Vtu,
        "vtk" => MeshFormat::Vtk,
        "glb" | "gltf" => MeshFormat::Gltf,
        other => {
            return Err(IoError::unsupported(
                path,
                format!(
                    "'{}' is not a mesh extension (expected one of {MESH_EXTENSIONS})",
                    if other.is_empty() {
                        "no extension"
                    } else {
                        other
                    }
                ),
            ))
        }
    })
}

/// The volume format of a path, by extension (case-insensitive). Only `.raw` maps to
/// [`VolumeFormat::Raw`] here; [`read_volume`] also reads other extensions as raw when given a
/// [`RawLayout`].
pub fn volume_format_of(path: &Path) -> Result<VolumeFormat, IoError> {
    if lower_name(path).ends_with(".nii.gz") {
        return Ok(VolumeFormat::Nifti);
    }
    // Both are folders: a Zarr store by its extension or its metadata files, else DICOM slices.
    let zarr_metadata = ["zarr.json", ".zarray", ".zgroup"];
    if extension(path) == "zarr" || zarr_metadata.iter().any(|m| path.join(m).is_file()) {
        return Ok(VolumeFormat::Zarr);
    }
    if path.is_dir() {
        return Ok(VolumeFormat::Dicom);
    }
    Ok(match extension(path).as_str() {
        "nrrd" => VolumeFormat::Nrrd,
        "nhdr" => VolumeFormat::Nhdr,
        "vti" => VolumeFormat::Vti,
        "vtk" => VolumeFormat::Vtk,
        "nii" => VolumeFormat::Nifti,
        "mha" => VolumeFormat::Mha,
        "mhd" => VolumeFormat::Mhd,
        "raw" => VolumeFormat::Raw,
        "dcm" | "dicom" => VolumeFormat::Dicom,
        _ if dicom::looks_like_dicom(path) => VolumeFormat::Dicom,
        "zarr" => VolumeFormat::Zarr,
        other => {
            return Err(IoError::unsupported(
                path,
                format!(
                    "'{}' is not a volume extension (expected one of {VOLUME_EXTENSIONS}; headerless raw data of any name can be read by giving its layout)",
                    if other.is_empty() { "no extension" } else { other }
                ),
            ))
        }
    })
}

/// Whether a file is a mesh or a volume: by extension, and for `.vtk` (which may be either) by
/// the `DATASET` line of the file, which must then exist.
pub fn file_kind(path: &Path) -> Result<FileKind, IoError> {
    if extension(path) == "vtk" {
        let file =
            std::fs::File::open(path).map_err(|e| IoError::access(path, "cannot open", &e))?;
        let mut head = Vec::with_capacity(1024);
        file.take(1024)
            .read_to_end(&mut head)
            .map_err(|e| IoError::access(path, "cannot read", &e))?;
        let head = String::from_utf8_lossy(&head).to_ascii_uppercase();
        return if head.contains("STRUCTURED_POINTS") {
            Ok(FileKind::Volume(VolumeFormat::Vtk))
        } else if head.contains("POLYDATA") || head.contains("UNSTRUCTURED_GRID") {
            Ok(FileKind::Mesh(MeshFormat::Vtk))
        } else {
            Err(IoError::unsupported(
                path,
                "the legacy VTK file holds neither POLYDATA, UNSTRUCTURED_GRID nor STRUCTURED_POINTS",
            ))
        };
    }
    if let Ok(format) = mesh_format_of(path) {
        return Ok(FileKind::Mesh(format));
    }
    if let Ok(format) = volume_format_of(path) {
        return Ok(FileKind::Volume(format));
    }
    Err(IoError::unsupported(
        path,
        format!("unknown extension: meshes are {MESH_EXTENSIONS}; volumes are {VOLUME_EXTENSIONS}"),
    ))
}

// -------------------------------------------------------------------------------------------
// Meshes.

/// A mesh as read, with what the reader did to it.
#[derive(Clone, Debug)]
pub struct LoadedMesh {
    /// The mesh, triangulated.
    pub mesh: TriangleMesh,
    /// The format it was read as.
    pub format: MeshFormat,
    /// For STL: how welding the triangle soup merged its corners. `None` for indexed formats.
    pub welded: Option<WeldReport>,
    /// Faces with more than three corners that were split by ear clipping.
    pub polygons_triangulated: usize,
    /// What reading changed or left out, in words: an unstructured grid's volume cells read as
    /// their boundary, its cell data left out (and, from `voxlod::read_mesh_file`, what a glTF
    /// scene's reader left out).
    pub notes: Vec<String>,
}

/// Borrowed parts of a [`PolyMesh`], so that a plain [`TriangleMesh`] is written without a copy.
#[derive(Clone, Copy)]
pub(crate) struct PolyView<'a> {
    pub mesh: &'a TriangleMesh,
    pub lines: &'a [[u32; 2]],
    pub points: &'a [u32],
    pub vertex_attributes: &'a [Attribute],
    pub line_attributes: &'a [Attribute],
}

impl<'a> From<&'a TriangleMesh> for PolyView<'a> {
    fn from(mesh: &'a TriangleMesh) -> Self {
        PolyView {
            mesh,
            lines: &[],
            points: &[],
            vertex_attributes: &[],
            line_attributes: &[],
        }
    }
}

impl<'a> From<&'a PolyMesh> for PolyView<'a> {
    fn from(m: &'a PolyMesh) -> Self {
        PolyView {
            mesh: &m.mesh,
            lines: &m.lines,
            points: &m.points,
            vertex_attributes: &m.vertex_attributes,
            line_attributes: &m.line_attributes,
        }
    }
}

/// Fails unless `path` is a readable, non-empty file.
pub(crate) fn check_readable(path: &Path) -> Result<(), IoError> {
    let meta = std::fs::metadata(path).map_err(|e| IoError::access(path, "cannot open", &e))?;
    if meta.is_dir() {
        return Err(IoError::new(
            path,
            IoErrorKind::Access,
            "is a directory, not a file",
        ));
    }
    if meta.len() == 0 {
        return Err(IoError::new(path, IoErrorKind::Empty, "the file is empty"));
    }
    Ok(())
}

/// The whole file in memory, after checking that it fits (so that a huge file is a
/// [`IoErrorKind::TooLarge`] error rather than an abort).
pub(crate) fn read_file(path: &Path) -> Result<Vec<u8>, IoError> {
    let len = std::fs::metadata(path)
        .map_err(|e| IoError::access(path, "cannot open", &e))?
        .len();
    budget::check_bytes(path, "reading the file", len)?;
    std::fs::read(path).map_err(|e| IoError::access(path, "cannot read", &e))
}

/// Coordinates and normals must be finite; the message names the first bad vertex. (Other
/// defects are the `validate` that follows: a malformed file, or a mesh that cannot be written.)
fn check_finite(path: &Path, mesh: &TriangleMesh) -> Result<(), IoError> {
    match find_defect(mesh, &Requirements::files()) {
        Some(defect) if defect.is_non_finite() => Err(IoError::new(
            path,
            IoErrorKind::NonFinite,
            defect.to_string(),
        )),
        _ => Ok(()),
    }
}

/// What [`read_any`] read, and what the reader did.
struct ReadAny {
    mesh: PolyMesh,
    format: MeshFormat,
    welded: Option<WeldReport>,
    polygons_triangulated: usize,
    notes: Vec<String>,
}

/// Reads any supported format into a [`PolyMesh`], with what the reader did.
fn read_any(path: &Path) -> Result<ReadAny, IoError> {
    let format = mesh_format_of(path)?;
    check_readable(path)?;
    let mut notes = Vec::new();
    let (mesh, welded, polygons_triangulated) = match format {
        MeshFormat::Obj => {
            let c = obj::read(path)?;
            (c.mesh, None, c.polygons_triangulated)
        }
        MeshFormat::Ply => {
            let c = ply::read(path)?;
            (c.mesh, None, c.polygons_triangulated)
        }
        MeshFormat::Stl => {
            let (mesh, report) = stl::read(path)?;
            (PolyMesh::from(mesh), Some(report), 0)
        }
        MeshFormat::Off => {
            let c = off::read(path)?;
            (PolyMesh::from(c.mesh), None, c.polygons_triangulated)
        }
        MeshFormat::Vtp | MeshFormat::Vtu | MeshFormat::Vtk => {
            let flavor = if format == MeshFormat::Vtk {
                Flavor::Legacy
            } else {
                Flavor::Xml
            };
            let c = vtk::mesh::read(path, flavor)?;
            notes = c.notes;
            (c.mesh, None, c.polygons_triangulated)
        }
        MeshFormat::Gltf => return Err(gltf_elsewhere(path)),
    };
    check_finite(path, &mesh.mesh)?;
    mesh.validate()
        .map_err(|e| IoError::malformed(path, e.to_string()))?;
    Ok(ReadAny {
        mesh,
        format,
        welded,
        polygons_triangulated,
        notes,
    })
}

/// Reads a triangle mesh (see the table in the crate documentation). Polygons are
/// ear-clipped, STL soups welded; nothing else is changed. A file without triangles is
/// [`IoErrorKind::Malformed`].
pub fn read_mesh(path: &Path) -> Result<LoadedMesh, IoError> {
    let read = read_any(path)?;
    if let Err(e) = validate_mesh(&read.mesh.mesh, &Requirements::default()) {
        return Err(IoError::malformed(path, e.to_string()));
    }
    Ok(LoadedMesh {
        mesh: read.mesh.mesh,
        format: read.format,
        welded: read.welded,
        polygons_triangulated: read.polygons_triangulated,
        notes: read.notes,
    })
}

/// Reads a mesh with its lines, points and attributes. PLY and VTK files carry all of them,
/// OBJ lines and points; other formats give triangles only. The file must hold at least one
/// triangle, line or point.
pub fn read_poly_mesh(path: &Path) -> Result<PolyMesh, IoError> {
    let poly = read_any(path)?.mesh;
    if poly.mesh.triangles.is_empty() && poly.lines.is_empty() && poly.points.is_empty() {
        return Err(IoError::malformed(path, "no triangles, lines or points"));
    }
    Ok(poly)
}

/// Checks a mesh before writing it, so that a bad mesh fails before any file is touched.
pub(crate) fn check_for_writing(path: &Path, mesh: &PolyMesh) -> Result<(), IoError> {
    check_finite(path, &mesh.mesh)?;
    mesh.validate()
        .map_err(|e| IoError::malformed(path, format!("cannot write: {e}")))
}

/// The refusal of a glTF file by this crate's single-mesh readers and writers.
pub(crate) fn gltf_elsewhere(path: &Path) -> IoError {
    IoError::unsupported(
        path,
        "a glTF scene is read by the glTF reader (voxlod::read_mesh, voxlod::read_scene) and \
         written by the glTF writers (voxlod lod --format glb), not by the mesh readers",
    )
}

/// [`check_for_writing`] for a plain triangle mesh.
pub(crate) fn check_triangles_for_writing(path: &Path, mesh: &TriangleMesh) -> Result<(), IoError> {
    check_finite(path, mesh)?;
    mesh.validate()
        .map_err(|e| IoError::malformed(path, format!("cannot write: {e}")))
}

/// The temporary file of a mesh, in the format of its extension.
pub(crate) fn stage_view(path: &Path, view: PolyView<'_>) -> Result<TempFile, IoError> {
    let plain = view.lines.is_empty()
        && view.points.is_empty()
        && view.vertex_attributes.is_empty()
        && view.line_attributes.is_empty();
    match mesh_format_of(path)? {
        MeshFormat::Ply => ply::write(path, view),
        MeshFormat::Obj => obj::write(path, view),
        MeshFormat::Vtp => vtk::mesh::write(path, view, Flavor::Xml),
        MeshFormat::Vtk => vtk::mesh::write(path, view, Flavor::Legacy),
        MeshFormat::Vtu => Err(IoError::unsupported(
            path,
            "an unstructured grid (.vtu) is read, not written: write the surface as .vtp or .vtk",
        )),
        format @ (MeshFormat::Stl | MeshFormat::Off) => {
            if !plain {
                return Err(IoError::unsupported(
                    path,
                    format!("{format} holds triangles only, not lines, points or attributes; write .ply, .vtp or .vtk"),
                ));
            }
            if format == MeshFormat::Stl {
                stl::write(path, view.mesh)
            } else {
                off::write(path, view.mesh)
            }
        }
        MeshFormat::Gltf => Err(gltf_elsewhere(path)),
    }
}

/// Writes a triangle mesh, by extension: `.ply` (binary little-endian, with normals when
/// present), `.obj`, `.stl` (binary), `.off`, `.vtp` and `.vtk` (VTK PolyData).
pub fn write_mesh(path: &Path, mesh: &TriangleMesh) -> Result<(), IoError> {
    let mut set = OutputSet::new();
    set.mesh(path, mesh)?;
    set.commit()
}

/// Writes a mesh with its lines, points and attributes: `.ply` (an `edge` element with one
/// float property per line attribute, a `point` element, vertex attributes as extra vertex
/// properties), `.vtp`/`.vtk` (verts, lines and polys; attributes as point and cell data),
/// `.obj` (lines and points, no attributes). STL and OFF hold triangles only: a mesh with
/// anything more is refused rather than silently reduced.
pub fn write_poly_mesh(path: &Path, mesh: &PolyMesh) -> Result<(), IoError> {
    let mut set = OutputSet::new();
    set.poly_mesh(path, mesh)?;
    set.commit()
}

// -------------------------------------------------------------------------------------------
// Volumes.

/// How volumes are written.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct VolumeWriteOptions {
    /// Compress the samples: gzip for NRRD, zlib for VTK XML (`.vti`) and MetaImage. Legacy
    /// VTK and raw files are never compressed; NIfTI is gzipped when its name ends in `.gz`,
    /// whatever this says. Off by default: compressing a large volume
    /// costs far more time than writing it (vtkio's compressor is the slowest, several seconds
    /// for a 256³ volume; NRRD with gzip is the quick way to a small file).
    pub compress: bool,
}

/// Reads a volume by extension. Headerless raw files (`.raw`, or any extension that is not a
/// self-describing format) need `raw`, the layout the file does not carry; for the other
/// formats `raw` is ignored.
///
/// ```
/// use voxlod_io::{read_volume, Endian, IoErrorKind, RawLayout, RawType};
///
/// let folder = tempfile::tempdir()?;
/// let path = folder.path().join("scan.raw");
/// // Two by two by one big-endian u16 samples: 1, 2, 256, 65535.
/// std::fs::write(&path, [0u8, 1, 0, 2, 1, 0, 255, 255])?;
/// let mut layout = RawLayout::new([2, 2, 1], RawType::U16, Endian::Big);
/// layout.spacing = [0.5, 0.5, 2.0];
/// let volume = read_volume(&path, Some(&layout))?;
/// assert_eq!(volume.as_slice(), &[1.0, 2.0, 256.0, 65535.0]);
/// assert_eq!(volume.grid.spacing, [0.5, 0.5, 2.0]);
///
/// // A layout that does not match the file's size is refused, with the sizes in the message.
/// layout.dims = [2, 2, 2];
/// let error = read_volume(&path, Some(&layout)).unwrap_err();
/// assert_eq!(error.kind, IoErrorKind::SizeMismatch);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn read_volume(path: &Path, raw: Option<&RawLayout>) -> Result<Volume, IoError> {
    let format = match volume_format_of(path) {
        Ok(format) => format,
        Err(_) if raw.is_some() => VolumeFormat::Raw,
        Err(e) => return Err(e),
    };
    if !matches!(format, VolumeFormat::Dicom | VolumeFormat::Zarr) {
        check_readable(path)?;
    }
    match format {
        VolumeFormat::Dicom => read_dicom_series(&[path.to_path_buf()], &DicomOptions::default()),
        VolumeFormat::Zarr => open_zarr(path)?.read_all(),
        VolumeFormat::Nrrd | VolumeFormat::Nhdr => nrrd::read(path),
        VolumeFormat::Vti => vtk::image::read(path, Flavor::Xml),
        VolumeFormat::Vtk => vtk::image::read(path, Flavor::Legacy),
        VolumeFormat::Nifti => crate::nifti::read(path),
        VolumeFormat::Mha | VolumeFormat::Mhd => metaimage::read(path),
        VolumeFormat::Raw => match raw {
            Some(layout) => raw::read(path, layout),
            None => Err(IoError::unsupported(
                path,
                "a headerless raw volume needs its layout (dimensions, sample type, byte order)",
            )),
        },
    }
}

/// Opens a volume for reading window by window ([`BlockwiseVolume::read_window`]) instead of whole:
/// a headerless raw file with `raw` (as [`read_volume`] reads it), a NRRD (`.nrrd`, `.nhdr`) with
/// raw encoding, or a MetaImage (`.mha`, `.mhd`) with uncompressed data. The header is parsed and
/// the file's size checked; no sample is read. `Ok(None)` for any other file: compressed or ascii
/// data (no random access: read it whole with [`read_volume`]), other volume formats, and files
/// that are not volumes.
///
/// ```
/// use voxlod_io::{open_volume_blockwise, Endian, RawLayout, RawType};
///
/// let folder = tempfile::tempdir()?;
/// let path = folder.path().join("ramp.raw");
/// std::fs::write(&path, (0u8..24).collect::<Vec<u8>>())?;
/// let layout = RawLayout::new([4, 3, 2], RawType::U8, Endian::Little);
/// let scan = open_volume_blockwise(&path, Some(&layout))?.expect("raw files are read in windows");
/// // Samples x 1..3, y 2, z 0..2: indices 9, 10 and 21, 22.
/// let window = scan.read_window([1, 2, 0], [2, 1, 2])?;
/// assert_eq!(window.as_slice(), &[9.0, 10.0, 21.0, 22.0]);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn open_volume_blockwise(
    path: &Path,
    raw: Option<&RawLayout>,
) -> Result<Option<BlockwiseVolume>, IoError> {
    let format = match volume_format_of(path) {
        Ok(format) => format,
        Err(_) if raw.is_some() => VolumeFormat::Raw,
        Err(_) => return Ok(None),
    };
    match (format, raw) {
        (VolumeFormat::Nrrd | VolumeFormat::Nhdr, _) => nrrd::open_blockwise(path),
        (VolumeFormat::Mha | VolumeFormat::Mhd, _) => metaimage::open_blockwise(path),
        (VolumeFormat::Raw, Some(layout)) => raw::open_blockwise(path, layout).map(Some),
        _ => Ok(None),
    }
}

/// Writes a volume with default options (uncompressed). See [`write_volume_with`].
pub fn write_volume(path: &Path, volume: &Volume) -> Result<(), IoError> {
    write_volume_with(path, volume, &VolumeWriteOptions::default())
}

/// Writes a volume by extension, samples as `f32`: `.nrrd`, `.nhdr` (+ `<name>.raw` beside
/// it), `.vti`, `.vtk` (legacy), `.mha`, `.mhd` (+ `<name>.raw`), `.raw` (headerless,
/// little-endian; spacing and origin are not stored), `.nii` and `.nii.gz` (NIfTI-1, gzip by
/// the name alone; sform and qform, `nifti/write.rs`). Every format with a header keeps the
/// index-to-world transform: NRRD and MetaImage in full (frame included), NIfTI in RAS, VTK XML
/// as its `Direction` (VTK has no anatomical frame); legacy VTK refuses an oblique volume. DICOM
/// is read-only. The data file of a
/// `.nhdr` or `.mhd` never replaces another file: when `<name>.raw` exists (and is not the data
/// file of the header being replaced) it gets a free name that the header records; an
/// [`OutputSet`] says which.
pub fn write_volume_with(
    path: &Path,
    volume: &Volume,
    options: &VolumeWriteOptions,
) -> Result<(), IoError> {
    let mut set = OutputSet::new();
    set.volume(path, volume, options)?;
    set.commit()
}

/// The format of `path`, once `volume` is known to be writable there.
pub(crate) fn check_volume_for_writing(
    path: &Path,
    volume: &Volume,
) -> Result<VolumeFormat, IoError> {
    let format = volume_format_of(path)?;
    if format == VolumeFormat::Dicom {
        return Err(IoError::unsupported(
            path,
            format!("writing {format} is not supported; write .nrrd, .nii, .vti, .mha or .vtk"),
        ));
    }
    let g = &volume.grid;
    if volume.values.len() != g.len() || volume.values.as_slice().is_none() {
        return Err(IoError::malformed(
            path,
            format!(
                "cannot write: {} samples for a {}x{}x{} grid",
                volume.values.len(),
                g.dims[0],
                g.dims[1],
                g.dims[2]
            ),
        ));
    }
    voxlod_core::Grid::new(g.dims, g.spacing, g.origin)
        .map_err(|e| IoError::malformed(path, format!("cannot write: {e}")))?;
    if format == VolumeFormat::Vtk && !volume.orientation.is_axis_aligned() {
        return Err(IoError::unsupported(
            path,
            "the volume is oblique (its index axes are not the world axes) and legacy VTK structured points cannot hold a direction; write .vti, .nrrd, .nii or .mha to keep it",
        ));
    }
    Ok(format)
}

/// The extension of the data file beside a volume header (`.nhdr`, `.mhd`); `None` for formats
/// with the data inside.
pub(crate) fn detached_data_extension(
    format: VolumeFormat,
    options: &VolumeWriteOptions,
) -> Option<&'static str> {
    match (format, options.compress) {
        (VolumeFormat::Nhdr | VolumeFormat::Mhd, false) => Some("raw"),
        (VolumeFormat::Nhdr, true) => Some("raw.gz"),
        (VolumeFormat::Mhd, true) => Some("zraw"),
        _ => None,
    }
}

/// The temporary files of a volume in `format` (checked by [`check_volume_for_writing`]): the
/// data file's first when `data` names one (for the formats of [`detached_data_extension`]).
pub(crate) fn stage_volume(
    path: &Path,
    format: VolumeFormat,
    volume: &Volume,
    options: &VolumeWriteOptions,
    data: Option<&Path>,
) -> Result<Vec<TempFile>, IoError> {
    let compress = options.compress;
    let detached = || {
        data.ok_or_else(|| IoError::unsupported(path, "a detached header needs a data file name"))
    };
    Ok(match format {
        VolumeFormat::Nrrd => vec![nrrd::write(path, volume, compress)?],
        VolumeFormat::Nhdr => nrrd::write_detached(path, detached()?, volume, compress)?.into(),
        VolumeFormat::Vti => vec![vtk::image::write(path, volume, Flavor::Xml, compress)?],
        VolumeFormat::Vtk => vec![vtk::image::write(path, volume, Flavor::Legacy, false)?],
        VolumeFormat::Mha => vec![metaimage::write(path, volume, compress)?],
        VolumeFormat::Mhd => metaimage::write_detached(path, detached()?, volume, compress)?.into(),
        VolumeFormat::Raw => vec![raw::write(path, volume)?],
        VolumeFormat::Nifti => {
            let gzip = lower_name(path).ends_with(".gz");
            vec![nifti::write::write(path, volume, gzip)?]
        }
        VolumeFormat::Dicom => {
            return Err(IoError::unsupported(
                path,
                format!("writing {format} is not supported"),
            ))
        }
        VolumeFormat::Zarr => {
            return Err(IoError::unsupported(
                path,
                "a Zarr store is a folder: write it through an OutputSet",
            ))
        }
    })
}
