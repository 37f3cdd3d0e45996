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
