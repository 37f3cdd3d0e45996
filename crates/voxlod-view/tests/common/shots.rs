//! Screenshots for the browser tests: a 400-pixel square window, the page's 45° field of view,
//! and the pixels the tests read (the level patch, what is drawn, colours around a point).

#![allow(dead_code)] // not every test file uses every helper

use std::path::{Path, PathBuf};

use image::RgbImage;
use voxlod_testkit::browser::ShotOptions;

pub const SIZE: u32 = 400;
pub const FOV: f64 = std::f64::consts::PI / 4.0;

/// A screenshot of `page` with the camera at `distance` along `dir` (centre to eye).
pub fn screenshot(
    browser: &Path,
    page: &Path,
    distance: f64,
    dir: [f64; 3],
    png: &Path,
) -> RgbImage {
    let options = ShotOptions {
        size: SIZE,
        distance,
        direction: dir,
        ..ShotOptions::default()
    };
    voxlod_testkit::browser::screenshot(browser, page, &options, png);
    image::open(png).unwrap().to_rgb8()
}

/// The colour of the level (or octant) patch at the top left.
pub fn patch(img: &RgbImage) -> [u8; 3] {
    img.get_pixel(8, 8).0
}

/// Pixels away from white, outside the top strip (patch and overlay).
pub fn drawn_pixels(img: &RgbImage) -> usize {
    img.enumerate_pixels()
        .filter(|(_, y, p)| *y >= 30 && p.0.iter().any(|&c| c < 235))
        .count()
}

/// The mean colour of the 5 × 5 pixels around `(x, y)`.
pub fn mean_around(img: &RgbImage, x: u32, y: u32) -> [f64; 3] {
    let mut sum = [0.0; 3];
    for (dx, dy) in (0..5).flat_map(|i| (0..5).map(move |j| (i, j))) {
        let p = img.get_pixel(x + dx - 2, y + dy - 2).0;
        for c in 0..3 {
            sum[c] += p[c] as f64 / 25.0;
        }
    }
    sum
}

/// Where screenshots go: `VOXLOD_VIEW_SHOTS` to keep them, else a temporary folder.
pub fn shots() -> (Option<tempfile::TempDir>, PathBuf) {
    match std::env::var_os("VOXLOD_VIEW_SHOTS") {
        Some(dir) => {
            std::fs::create_dir_all(&dir).unwrap();
            (None, PathBuf::from(dir))
        }
        None => {
            let t = tempfile::tempdir().unwrap();
            let p = t.path().to_path_buf();
            (Some(t), p)
        }
    }
}
