//! The headless browser of the browser tests: Debian's `chromium` (installed by `.ci/run`), or
//! the binary `VOXLOD_CHROMIUM` names.

use std::path::PathBuf;

use crate::skips::skip;

/// The browser's path, or `None` after printing why the test skips.
pub fn chromium() -> Option<PathBuf> {
    let path = std::env::var_os("VOXLOD_CHROMIUM")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("/usr/bin/chromium"));
    if path.is_file() {
        Some(path)
    } else {
        skip(format!(
            "no browser: {} is missing (apt-get install chromium, as .ci/run does)",
            path.display()
        ));
        None
    }
}
