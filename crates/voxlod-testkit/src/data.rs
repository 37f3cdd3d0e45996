//! Where the shared real data lives, for tests, examples and benchmarks.
//!
//! The project's checkout sees the shared folder at `../shared` from the workspace root (override
//! with `VOXLOD_SHARED_DATA=/path/to/shared/data`). A user's fresh clone has no such folder:
//! callers must then skip, saying why, through [`shared_data_or_skip`], which counts the skip
//! ([`crate::skips`]).

use std::path::PathBuf;

use crate::skips::skip_as;

/// The workspace root (the folder holding the top-level `Cargo.toml`).
pub fn workspace_root() -> PathBuf {
    // This crate lives in <root>/crates/voxlod-testkit.
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .canonicalize()
        .unwrap_or_else(|_| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../.."))
}

/// The shared real-data folder (`meshes/`, `volumes/`), if present.
pub fn shared_data() -> Option<PathBuf> {
    let dir = std::env::var_os("VOXLOD_SHARED_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| workspace_root().join("../shared/data"));
    dir.is_dir().then_some(dir)
}

/// A file of the shared data folder, or `None` after recording why the caller skips
/// ([`crate::skips::skip`]; `test` names the caller where it is not a test, as in an example).
pub fn shared_data_or_skip(relative: &str, test: &str) -> Option<PathBuf> {
    match shared_data() {
        Some(dir) if dir.join(relative).is_file() => Some(dir.join(relative)),
        Some(dir) => {
            skip_as(test, format!("{} is missing", dir.join(relative).display()));
            None
        }
        None => {
            let reason = match std::env::var_os("VOXLOD_SHARED_DATA") {
                Some(dir) => format!("VOXLOD_SHARED_DATA={} is not a folder", dir.display()),
                None => "no ../shared/data beside the checkout (or VOXLOD_SHARED_DATA)".into(),
            };
            skip_as(test, reason);
            None
        }
    }
}

/// The meshes of the shared data folder (its `.obj`, `.off` and `.stl` files, sorted), or none
/// after recording why the caller skips.
pub fn shared_meshes(test: &str) -> Vec<PathBuf> {
    let Some(any) = shared_data_or_skip("meshes/fandisk.obj", test) else {
        return Vec::new();
    };
    let dir = any.parent().unwrap().to_path_buf();
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            matches!(
                p.extension().and_then(|e| e.to_str()),
                Some("obj" | "off" | "stl")
            )
        })
        .collect();
    files.sort();
    files
}
