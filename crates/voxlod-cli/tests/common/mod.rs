//! Helpers for the command-line tests: running the binary, making input files.

#![allow(dead_code, unused_imports)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use voxlod::core::TriangleMesh;

pub use voxlod_testkit::files::files_in;
pub use voxlod_testkit::shapes::holed_block;

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

/// Writes `mesh` into `dir/name` and returns the path.
pub fn write_mesh(dir: &Path, name: &str, mesh: &TriangleMesh) -> PathBuf {
    let path = dir.join(name);
    voxlod::io::write_mesh(&path, mesh).unwrap();
    path
}

pub fn arg(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The volume-weighted centroid and the enclosed volume of a closed mesh.
pub fn centroid_and_volume(mesh: &TriangleMesh) -> (voxlod::core::glam::DVec3, f64) {
    let (mut c, mut v) = (voxlod::core::glam::DVec3::ZERO, 0.0);
    for t in &mesh.triangles {
        let [a, b, d] = t.map(|i| mesh.positions[i as usize].as_dvec3());
        let w = a.dot(b.cross(d)) / 6.0;
        v += w;
        c += (a + b + d) / 4.0 * w;
    }
    (c / v, v)
}
