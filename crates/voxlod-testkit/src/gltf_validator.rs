//! The Khronos glTF validator, through the peers' kit (`shared/peers/peers.py validate-gltf`,
//! Node's `gltf-validator` in the venv `~/.cache/voxlod-peers`), for tests of `.glb` writers.
//! Absent kit: the test skips with a printed reason.

use std::path::{Path, PathBuf};
use std::process::Command;

/// What the validator said about one file.
#[derive(Clone, Debug)]
pub struct Validation {
    pub errors: u64,
    pub warnings: u64,
    /// Its whole JSON report, for assertion messages.
    pub report: String,
}

/// The kit's python and script, or `None` after printing why the test skips.
fn kit() -> Option<(PathBuf, PathBuf)> {
    let python = std::env::var_os("HOME")
        .map(|h| PathBuf::from(h).join(".cache/voxlod-peers/bin/python"))
        .filter(|p| p.is_file());
    let script = crate::data::shared_data()
        .map(|d| d.join("../peers/peers.py"))
        .filter(|p| p.is_file());
    let node = Command::new("node").arg("--version").output().is_ok();
    match (python, script, node) {
        (Some(py), Some(script), true) => Some((py, script)),
        (None, _, _) => {
            crate::skips::skip(
                "no glTF validator: ~/.cache/voxlod-peers/bin/python (the peers' kit) is missing",
            );
            None
        }
        (_, None, _) => {
            crate::skips::skip(
                "no glTF validator: ../shared/peers/peers.py is not beside the checkout",
            );
            None
        }
        (_, _, false) => {
            crate::skips::skip("no glTF validator: node is not on the PATH");
            None
        }
    }
}

/// Validates `file`, or `None` (with the reason printed) when the kit is absent. Panics when
/// the kit runs but its output is not the expected JSON.
pub fn validate_gltf(file: &Path) -> Option<Validation> {
    let (python, script) = kit()?;
    let out = Command::new(python)
        .arg(script)
        .arg("validate-gltf")
        .arg(file)
        .output()
        .expect("the validator runs");
    let report = String::from_utf8_lossy(&out.stdout).trim().to_string();
    let v: serde_json::Value = serde_json::from_str(&report)
        .unwrap_or_else(|e| panic!("validator output is not JSON ({e}): {report}"));
    let n = |k: &str| v[k].as_u64().unwrap_or(u64::MAX);
    Some(Validation {
        errors: n("errors"),
        warnings: n("warnings"),
        report,
    })
}
