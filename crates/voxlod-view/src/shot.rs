//! A screenshot of a page by a headless Chromium (WebGL2 through SwiftShader, no GPU), for the
//! tests and scripts that check what the page draws: the camera goes in the page's address
//! (`#camera=DISTANCE,DX,DY,DZ&model=I`), the PNG is what the browser showed once its virtual
//! time budget ran out (images decoded and drawn again by then).
//!
//! Cost: one browser start (about a second) per screenshot.

use std::path::{Path, PathBuf};
use std::process::Command;

use voxlod_io::{IoError, IoErrorKind};

use crate::ViewError;

/// How to take a screenshot.
#[derive(Clone, Debug, PartialEq)]
pub struct ShotOptions {
    /// The window's width and height in pixels.
    pub size: u32,
    /// Distance from the model's centre to the eye, in the model's units.
    pub distance: f64,
    /// Direction from the model's centre to the eye (any length).
    pub direction: [f64; 3],
    /// Which model of the page (0 for the first).
    pub model: usize,
    /// The browser's virtual time budget in milliseconds: how long the page may run before the
    /// screenshot.
    pub budget_ms: u32,
}

impl Default for ShotOptions {
    fn default() -> Self {
        ShotOptions {
            size: 400,
            distance: 3.0,
            direction: [0.0, 0.0, 1.0],
            model: 0,
            budget_ms: 5000,
        }
    }
}

/// Runs `browser` (a Chromium binary) on `page` and writes its screenshot to `png`. An error
/// names the page when the browser cannot start or leaves no PNG (with the browser's output).
pub fn screenshot(
    browser: &Path,
    page: &Path,
    options: &ShotOptions,
    png: &Path,
) -> Result<(), ViewError> {
    let fail = |m: String| IoError::new(page, IoErrorKind::Access, m);
    let profile = profile_dir(png);
    let [dx, dy, dz] = options.direction;
    let url = format!(
        "file://{}#camera={},{dx},{dy},{dz}&model={}",
        page.display(),
        options.distance,
        options.model
    );
    let _ = std::fs::remove_file(png);
    let out = Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--use-gl=swiftshader",
            "--enable-unsafe-swiftshader",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--no-first-run",
            "--hide-scrollbars",
        ])
        .arg(format!("--virtual-time-budget={}", options.budget_ms))
        .arg(format!("--user-data-dir={}", profile.display()))
        .arg(format!("--window-size={0},{0}", options.size))
        .arg(format!("--screenshot={}", png.display()))
        .arg(url)
        .output();
    let _ = std::fs::remove_dir_all(&profile);
    let out = out.map_err(|e| fail(format!("cannot run {}: {e}", browser.display())))?;
    if !png.is_file() {
        return Err(fail(format!(
            "{} left no screenshot: {}",
            browser.display(),
            String::from_utf8_lossy(&out.stderr).trim()
        ))
        .into());
    }
    Ok(())
}

/// The browser's own profile folder beside the screenshot, removed after the run.
fn profile_dir(png: &Path) -> PathBuf {
    let mut name = png.file_name().unwrap_or_default().to_os_string();
    name.push(".profile");
    png.with_file_name(name)
}
