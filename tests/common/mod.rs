//! Helpers for the command-line tests: running the binary, making input files.

#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use voxlod::core::glam::Vec3;
use voxlod::core::TriangleMesh;

/// Runs `voxlod` with `args`.
pub fn voxlod(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_voxlod"))
        .args(args)
        .output()
        .expect("the voxlod binary runs")
}

pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Asserts a clean failure: non-zero exit, one `voxlod: error:` line naming `what`, no panic.
pub fn assert_clean_failure(o: &Output, what: &str) {
    let err = stderr(o);
    assert!(
        !o.status.success(),
        "expected failure, got success; stderr: {err}"
    );
    assert!(!err.contains("panicked"), "panic: {err}");
    assert!(err.contains("voxlod: error:"), "no error line: {err}");
    assert!(err.contains(what), "error does not mention '{what}': {err}");
}

/// Parses the JSON printed by a `--json` run.
pub fn json(o: &Output) -> serde_json::Value {
    assert!(o.status.success(), "failed: {}", stderr(o));
    serde_json::from_str(&stdout(o)).unwrap_or_else(|e| panic!("bad JSON ({e}): {}", stdout(o)))
}

/// A box with a through-hole along z (genus 1), as a closed triangle mesh: the outer box
/// [-1, 1]² × [-0.5, 0.5] minus the square hole [-0.4, 0.4]².
pub fn holed_block() -> TriangleMesh {
    let (o, i, h) = (1.0f32, 0.4f32, 0.5f32);
    let mut positions = Vec::new();
    // Rings: outer and inner squares at bottom (z = -h) and top (z = +h).
    for &z in &[-h, h] {
        for &s in &[o, i] {
            positions.extend([
                Vec3::new(-s, -s, z),
                Vec3::new(s, -s, z),
                Vec3::new(s, s, z),
                Vec3::new(-s, s, z),
            ]);
        }
    }
    // Indices: bottom outer 0..4, bottom inner 4..8, top outer 8..12, top inner 12..16.
    let mut triangles = Vec::new();
    for k in 0..4u32 {
        let n = (k + 1) % 4;
        // Top face ring (normal +z) and bottom face ring (normal -z).
        triangles.push([8 + k, 8 + n, 12 + n]);
        triangles.push([8 + k, 12 + n, 12 + k]);
        triangles.push([k, 4 + n, n]);
        triangles.push([k, 4 + k, 4 + n]);
        // Outer walls (normal outwards) and inner walls (normal into the hole).
        triangles.push([k, n, 8 + n]);
        triangles.push([k, 8 + n, 8 + k]);
        triangles.push([4 + k, 12 + n, 4 + n]);
        triangles.push([4 + k, 12 + k, 12 + n]);
    }
    TriangleMesh::new(positions, triangles)
}

/// Writes `mesh` into `dir/name` and returns the path.
pub fn write_mesh(dir: &Path, name: &str, mesh: &TriangleMesh) -> PathBuf {
    let path = dir.join(name);
    voxlod::io::write_mesh(&path, mesh).unwrap();
    path
}

/// Every file below `dir`.
pub fn files_in(dir: &Path) -> Vec<PathBuf> {
    match std::fs::read_dir(dir) {
        Ok(entries) => entries.map(|e| e.unwrap().path()).collect(),
        Err(_) => Vec::new(),
    }
}

pub fn arg(p: &Path) -> &str {
    p.to_str().unwrap()
}
