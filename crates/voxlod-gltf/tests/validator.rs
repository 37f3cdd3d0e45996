//! The Khronos glTF validator on our chains (plain and meshopt-compressed): no errors, no
//! warnings. Runs the peers' kit (`shared/peers/peers.py validate-gltf`, Node's
//! `gltf-validator`) when present; skips with a printed reason otherwise.

mod common;

use std::path::PathBuf;
use std::process::Command;

use common::{chain_levels, sphere_chain};
use voxlod_gltf::{write_chain_glb, ChainOptions};
use voxlod_testkit::skips::skip;

/// The validator's command, or `None` after recording why the test skips.
fn validator() -> Option<(PathBuf, PathBuf)> {
    let python = std::env::var_os("HOME")
        .map(|h| PathBuf::from(h).join(".cache/voxlod-peers/bin/python"))
        .filter(|p| p.is_file());
    let peers = voxlod_testkit::data::shared_data()
        .map(|d| d.join("../peers/peers.py"))
        .filter(|p| p.is_file());
    match (python, peers) {
        (Some(py), Some(script)) => Some((py, script)),
        (None, _) => {
            skip("no glTF validator: ~/.cache/voxlod-peers/bin/python (the peers' kit) is missing");
            None
        }
        (_, None) => {
            skip("no glTF validator: ../shared/peers/peers.py is not beside the checkout");
            None
        }
    }
}

/// (errors, warnings, the validator's report).
fn validate(python: &PathBuf, script: &PathBuf, file: &std::path::Path) -> (u64, u64, String) {
    let out = Command::new(python)
        .arg(script)
        .arg("validate-gltf")
        .arg(file)
        .output()
        .expect("the validator runs");
    let text = String::from_utf8_lossy(&out.stdout).to_string();
    let report: serde_json::Value = serde_json::from_str(text.trim())
        .unwrap_or_else(|e| panic!("validator output is not JSON ({e}): {text}"));
    let n = |k: &str| report[k].as_u64().unwrap_or(u64::MAX);
    (n("errors"), n("warnings"), text)
}

#[test]
fn chains_pass_the_khronos_validator() {
    let Some((python, script)) = validator() else {
        return;
    };
    let chain = sphere_chain();
    let dir = tempfile::tempdir().unwrap();
    for (name, options) in [
        ("plain.glb", ChainOptions::default()),
        ("meshopt.glb", ChainOptions::meshopt()),
    ] {
        let path = dir.path().join(name);
        write_chain_glb(&path, &chain_levels(&chain), &options).unwrap();
        let (errors, warnings, text) = validate(&python, &script, &path);
        assert_eq!((errors, warnings), (0, 0), "{name}: {text}");
    }
}
