//! The peers' Python (`~/.cache/voxlod-peers/bin/python`, with nibabel, pydicom, SimpleITK and
//! zmesh), for tests that check a reader against an independent one. Absent, the caller skips
//! with the recorded reason.

use std::ffi::OsStr;
use std::path::PathBuf;
use std::process::Command;

use crate::skips::skip;

/// The interpreter, if the peers' environment is installed.
pub fn python() -> Option<PathBuf> {
    let python = PathBuf::from(std::env::var_os("HOME")?).join(".cache/voxlod-peers/bin/python");
    python.is_file().then_some(python)
}

/// Runs `script` (with `args` as `sys.argv[1..]`) in the peers' Python and returns its standard
/// output; `None`, after recording why, when the interpreter or a module it imports is missing,
/// or the script fails.
pub fn run_python(script: &str, args: &[&OsStr]) -> Option<String> {
    let Some(python) = python() else {
        skip("no peers' Python at ~/.cache/voxlod-peers/bin/python (nibabel, pydicom, SimpleITK)");
        return None;
    };
    let out = Command::new(python)
        .arg("-c")
        .arg(script)
        .args(args)
        .output()
        .ok()?;
    if !out.status.success() {
        let err = String::from_utf8_lossy(&out.stderr);
        skip(format!(
            "the peers' Python failed: {}",
            err.lines().last().unwrap_or("")
        ));
        return None;
    }
    Some(String::from_utf8_lossy(&out.stdout).into_owned())
}
