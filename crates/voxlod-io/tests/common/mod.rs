//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use voxlod_core::glam::Vec3;
use voxlod_core::{Grid, TriangleMesh, Volume};
use voxlod_io::{IoError, IoErrorKind};

/// A unit cube, 8 vertices and 12 outward triangles, with outward corner normals.
pub fn cube() -> TriangleMesh {
    let p = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
    let positions = vec![
        p(0., 0., 0.),
        p(1., 0., 0.),
        p(1., 1., 0.),
        p(0., 1., 0.),
        p(0., 0., 1.),
        p(1., 0., 1.),
        p(1., 1., 1.),
        p(0., 1., 1.),
    ];
    let triangles = vec![
        [0, 2, 1],
        [0, 3, 2],
        [4, 5, 6],
        [4, 6, 7],
        [0, 1, 5],
        [0, 5, 4],
        [1, 2, 6],
        [1, 6, 5],
        [2, 3, 7],
        [2, 7, 6],
        [3, 0, 4],
        [3, 4, 7],
    ];
    let mut mesh = TriangleMesh::new(positions, triangles);
    mesh.compute_vertex_normals();
    mesh
}

/// A 5×4×3 volume with distinct values, uneven spacing and an offset origin.
pub fn small_volume() -> Volume {
    let grid = Grid::new([5, 4, 3], [0.5, 1.40625, 2.5], [-90.0, 12.25, 3.5]).unwrap();
    let values = (0..60).map(|i| i as f32 * 1.5 - 7.0).collect();
    Volume::from_vec(grid, values).unwrap()
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

/// The names in a directory, sorted.
pub fn entries(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

pub fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

pub fn gzip(bytes: &[u8]) -> Vec<u8> {
    use std::io::Write;
    let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    enc.write_all(bytes).unwrap();
    enc.finish().unwrap()
}

pub fn zlib(bytes: &[u8]) -> Vec<u8> {
    use std::io::Write;
    let mut enc = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
    enc.write_all(bytes).unwrap();
    enc.finish().unwrap()
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
/// too), a volume, or for `.raw` 2x2x2 big-endian `u16` samples.
pub fn read_by_extension(path: &Path) -> Result<(), IoError> {
    let name = path
        .file_name()
        .unwrap()
        .to_string_lossy()
        .to_ascii_lowercase();
    let mesh = [".obj", ".ply", ".stl", ".off", ".vtp"]
        .iter()
        .any(|e| name.ends_with(e))
        || (name.ends_with(".vtk") && (name.starts_with("mesh") || name.starts_with("cube")));
    if mesh {
        voxlod_io::read_poly_mesh(path).map(|_| ())
    } else if name.ends_with(".raw") {
        let layout =
            voxlod_io::RawLayout::new([2, 2, 2], voxlod_io::RawType::U16, voxlod_io::Endian::Big);
        voxlod_io::read_volume(path, Some(&layout)).map(|_| ())
    } else {
        voxlod_io::read_volume(path, None).map(|_| ())
    }
}
