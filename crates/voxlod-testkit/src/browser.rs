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

/// The flags every browser test starts Chromium with: headless, WebGL2 through SwiftShader (no
/// GPU), and none of the background connections this machine's closed network refuses.
pub const HEADLESS: &[&str] = &[
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--use-gl=swiftshader",
    "--enable-unsafe-swiftshader",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
];

/// How to take a screenshot of a page of `voxlod view`.
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
    /// screenshot (images decoded and drawn again by then).
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

/// Runs `browser` on the page `page` of `voxlod view` with the camera in its address
/// (`#camera=DISTANCE,DX,DY,DZ&model=I`) and writes its screenshot to `png`. Panics, naming
/// the page and with the browser's output, when the browser cannot start or leaves no PNG.
/// Cost: one browser start (about a second).
pub fn screenshot(
    browser: &std::path::Path,
    page: &std::path::Path,
    options: &ShotOptions,
    png: &std::path::Path,
) {
    let mut name = png.file_name().unwrap_or_default().to_os_string();
    name.push(".profile");
    let profile = png.with_file_name(name);
    let [dx, dy, dz] = options.direction;
    let url = format!(
        "file://{}#camera={},{dx},{dy},{dz}&model={}",
        page.display(),
        options.distance,
        options.model
    );
    let _ = std::fs::remove_file(png);
    let out = std::process::Command::new(browser)
        .args(HEADLESS)
        .arg("--hide-scrollbars")
        .arg(format!("--virtual-time-budget={}", options.budget_ms))
        .arg(format!("--user-data-dir={}", profile.display()))
        .arg(format!("--window-size={0},{0}", options.size))
        .arg(format!("--screenshot={}", png.display()))
        .arg(url)
        .output();
    let _ = std::fs::remove_dir_all(&profile);
    let out = out.unwrap_or_else(|e| panic!("cannot run {}: {e}", browser.display()));
    assert!(
        png.is_file(),
        "{} left no screenshot of {}: {}",
        browser.display(),
        page.display(),
        String::from_utf8_lossy(&out.stderr).trim()
    );
}
