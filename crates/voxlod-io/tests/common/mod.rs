//! Helpers of the readers' and writers' tests; the general ones come from voxlod-testkit.
#![allow(dead_code, unused_imports)]

use std::path::Path;

use voxlod_core::TriangleMesh;
use voxlod_io::{IoError, IoErrorKind};

pub use voxlod_testkit::files::{entries, gzip, write, zlib};
pub use voxlod_testkit::volumes::small_volume;

/// A file VTK wrote (`scripts/vtk-fixtures.py`, under `tests/data/vtk`).
pub fn vtk_data(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/vtk")
        .join(name)
}

/// The XML writer modes of `scripts/vtk-fixtures.py` (file name suffixes).
pub const VTK_MODES: [&str; 13] = [
    "default",
    "raw-zlib",
    "raw-plain",
    "raw-zlib-u64",
    "raw-plain-u64",
    "raw-zlib-blocks",
    "raw-lz4",
    "raw-lzma",
    "raw-zlib-big",
    "base64-plain-u64",
    "inline-zlib",
    "inline-plain",
    "ascii",
];

/// A unit cube, 8 vertices and 12 outward triangles, with outward corner normals.
pub fn cube() -> TriangleMesh {
    let mut mesh = voxlod_testkit::shapes::unit_cube_ringwise();
    mesh.compute_vertex_normals();
    mesh
}

/// Asserts that `result` failed with `kind` and a message naming the file.
pub fn assert_error<T: std::fmt::Debug>(
    result: Result<T, IoError>,
    kind: IoErrorKind,
    path: &Path,
) -> IoError {
    let err = result.expect_err("expected an error");
    let text = err.to_string();
    assert_eq!(err.kind, kind, "{text}");
    let name = path.file_name().unwrap().to_string_lossy();
    assert!(
        text.contains(&*name),
        "message does not name {name}: {text}"
    );
    assert!(!text.contains('\n'), "message spans lines: {text}");
    err
}

/// A NIfTI-1 header (348 bytes and 4 of extension flags) with the given dim and datatype.
pub fn nifti(dim: [i16; 8], datatype: i16, bitpix: i16) -> Vec<u8> {
    let mut h = vec![0u8; 352];
    h[0..4].copy_from_slice(&348i32.to_le_bytes());
    for (i, d) in dim.iter().enumerate() {
        h[40 + 2 * i..42 + 2 * i].copy_from_slice(&d.to_le_bytes());
    }
    h[70..72].copy_from_slice(&datatype.to_le_bytes());
    h[72..74].copy_from_slice(&bitpix.to_le_bytes());
    for i in 0..8 {
        h[76 + 4 * i..80 + 4 * i].copy_from_slice(&1f32.to_le_bytes());
    }
    h[108..112].copy_from_slice(&352f32.to_le_bytes());
    h[344..348].copy_from_slice(b"n+1\0");
    h
}

/// Reads `path` as its extension says: a mesh (a `.vtk` whose name starts with `mesh` or `cube`
/// too; an OBJ, PLY or OFF also with its looks, `read_asset`), a volume, or for `.raw` 2x2x2 big-endian `u16` samples.
pub fn read_by_extension(path: &Path) -> Result<(), IoError> {
    let name = path
        .file_name()
        .unwrap()
        .to_string_lossy()
        .to_ascii_lowercase();
    let mesh = [".obj", ".ply", ".stl", ".off", ".vtp", ".vtu"]
        .iter()
        .any(|e| name.ends_with(e))
        || (name.ends_with(".vtk") && ["mesh", "cube", "grid"].iter().any(|p| name.starts_with(p)));
    let looks = [".obj", ".ply", ".off"].iter().any(|e| name.ends_with(e));
    if mesh {
        voxlod_io::read_poly_mesh(path)?;
        if looks {
            voxlod_io::read_asset(path)?;
        }
        Ok(())
    } else if name.ends_with(".seg.dcm") {
        voxlod_io::read_label_map(path).map(|_| ())
    } else if name.ends_with(".seg.nrrd") {
        voxlod_io::read_label_table(path)?;
        voxlod_io::read_volume(path, None).map(|_| ())
    } else if name.ends_with(".raw") {
        let layout =
            voxlod_io::RawLayout::new([2, 2, 2], voxlod_io::RawType::U16, voxlod_io::Endian::Big);
        voxlod_io::read_volume(path, Some(&layout)).map(|_| ())
    } else {
        voxlod_io::read_volume(path, None).map(|_| ())
    }
}
