//! How a level looks beside its input: both drawn with their looks (voxlod-render's
//! [`voxlod::render::looks`]: base colour factor × vertex colour × texture, two-sided Lambert
//! under a headlight from the vertex normals, bent by the normal map where the asset has one, as
//! three.js draws it; an asset without looks is drawn white and shaded) from the same views,
//! and compared pixel by pixel as 8-bit sRGB, the way a viewer sees them.
//!
//! **Views.** Those of the silhouette difference ([`voxlod::render::view_directions`]: the eight
//! octant diagonals, then the six axes), orthographic, each framing the input's box; 14 views of
//! 512 × 512 pixels with 2 × 2 samples per pixel by default. Background pixels count: a level
//! that covers less or more of the image than its input is charged for it.
//!
//! **PSNR** per view: `10 log10(255² / MSE)` with the MSE over the three sRGB channels of every
//! pixel; overall, the same from the MSE pooled over all views. Identical renders give
//! `f64::INFINITY` (written `null` in JSON).
//!
//! **SSIM** (Wang, Bovik, Sheikh, Simoncelli 2004, "Image quality assessment: from error
//! visibility to structural similarity", eq. 13 and §III-C): on the luma of the sRGB values
//! (`0.299 R + 0.587 G + 0.114 B`, 0..255), with the paper's 11 × 11 circular-symmetric Gaussian
//! window of standard deviation 1.5 normalised to sum 1, `C1 = (0.01 · 255)²`,
//! `C2 = (0.03 · 255)²`, the mean of the SSIM map over the positions where the window lies
//! wholly inside the image (MATLAB's `'valid'`, as the authors' reference code); no
//! downsampling. Overall: the mean over views. Written here rather than taken from a crate:
//! `image-compare` averages SSIM over non-overlapping 8 × 8 windows, not the paper's sliding
//! Gaussian one.
//!
//! Cost: two renders per view (the input's once with [`AppearanceReference`]), O(V + T +
//! samples) each, and O(pixels × 11) per view for the SSIM's separable filtering; at the
//! defaults, about 14 × 1 M samples per asset.

use glam::DVec3;
use serde::Serialize;
use voxlod::render::{
    decode_normal_maps, decode_textures, render, view_directions, AssetItem, Camera, RenderError,
    RenderOptions, Scene,
};
use voxlod_asset::Asset;

/// The views and how they are drawn.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct AppearanceOptions {
    /// Views (1 to 14): octant diagonals, then the axes.
    pub views: usize,
    /// Side of each square view in pixels.
    pub size: u32,
    /// Samples per pixel side.
    pub supersample: u32,
}

impl Default for AppearanceOptions {
    /// 14 views of 512² pixels, 2 × 2 samples each.
    fn default() -> Self {
        AppearanceOptions {
            views: 14,
            size: 512,
            supersample: 2,
        }
    }
}

/// The appearance of one view.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ViewAppearance {
    /// The direction the view looks along (unnormalised).
    pub direction: [f64; 3],
    /// Mean squared difference of the 8-bit sRGB channels.
    pub mse: f64,
    /// Peak signal-to-noise ratio in dB (infinite for identical renders).
    pub psnr: f64,
    /// Mean structural similarity of the luma, in (−1, 1], 1 for identical renders.
    pub ssim: f64,
}

/// How a level looks beside its input, over all views (see the module documentation).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AppearanceReport {
    /// PSNR in dB from the MSE pooled over all views (infinite for identical renders).
    pub psnr: f64,
    /// The mean of the views' SSIM.
    pub ssim: f64,
    /// Each view.
    pub per_view: Vec<ViewAppearance>,
    /// Images that could not be decoded (their material's factor stood in), input's then
    /// level's.
    pub warnings: Vec<String>,
}

/// One view rendered: its sRGB bytes and luma.
struct View {
    srgb: Vec<u8>,
    luma: Vec<f32>,
}

/// The input's views, rendered once, against which levels are compared.
pub struct AppearanceReference {
    cameras: Vec<Camera>,
    directions: Vec<DVec3>,
    views: Vec<View>,
    options: AppearanceOptions,
    warnings: Vec<String>,
}

impl AppearanceReference {
    /// Renders `input` from `options.views` views framing its box.
    ///
    /// # Errors
    ///
    /// The renderer's: an invalid asset or one with no geometry, a size or supersampling out
    /// of range, the memory budget's refusal.
    pub fn new(input: &Asset, options: &AppearanceOptions) -> Result<Self, RenderError> {
        if !(1..=14).contains(&options.views) {
            return Err(RenderError::Invalid(format!(
                "{} views: choose 1 to 14",
                options.views
            )));
        }
        let bounds = input.mesh.geometry().bounds();
        let directions = view_directions(options.views);
        let cameras = (directions.iter())
            .map(|&d| Camera::fit(d, &bounds, options.size, options.size, None))
            .collect::<Result<Vec<_>, _>>()?;
        let mut reference = AppearanceReference {
            cameras,
            directions,
            views: Vec::new(),
            options: *options,
            warnings: Vec::new(),
        };
        let (views, warnings) = reference.render(input)?;
        reference.views = views;
        reference.warnings = warnings;
        Ok(reference)
    }

    /// `asset` from every view.
    fn render(&self, asset: &Asset) -> Result<(Vec<View>, Vec<String>), RenderError> {
        let (textures, mut warnings) = decode_textures(asset)?;
        let (normal_maps, noted) = decode_normal_maps(asset)?;
        warnings.extend(noted);
        let scene = Scene {
            assets: vec![AssetItem::new(asset, &textures).with_normal_maps(&normal_maps)],
            ..Default::default()
        };
        let render_options = RenderOptions {
            supersample: self.options.supersample,
            ..Default::default()
        };
        let views = (self.cameras.iter())
            .map(|camera| {
                let srgb = render(&scene, camera, &render_options)?.to_srgb8();
                let luma = luma(&srgb);
                Ok(View { srgb, luma })
            })
            .collect::<Result<Vec<_>, RenderError>>()?;
        Ok((views, warnings))
    }

    /// How many views are compared.
    pub fn views(&self) -> usize {
        self.cameras.len()
    }

    /// How `level` looks beside the input.
    ///
    /// # Errors
    ///
    /// The renderer's, as [`AppearanceReference::new`].
    pub fn compare(&self, level: &Asset) -> Result<AppearanceReport, RenderError> {
        let (views, level_warnings) = self.render(level)?;
        let side = self.options.size as usize;
        let per_view: Vec<ViewAppearance> = (self.views.iter().zip(&views))
            .zip(&self.directions)
            .map(|((a, b), d)| {
                let mse = mse(&a.srgb, &b.srgb);
                ViewAppearance {
                    direction: d.to_array(),
                    mse,
                    psnr: psnr_of_mse(mse),
                    ssim: ssim(&a.luma, &b.luma, side, side),
                }
            })
            .collect();
        let n = per_view.len().max(1) as f64;
        let pooled = per_view.iter().map(|v| v.mse).sum::<f64>() / n;
        let mut warnings = self.warnings.clone();
        warnings.extend(level_warnings);
        Ok(AppearanceReport {
            psnr: psnr_of_mse(pooled),
            ssim: per_view.iter().map(|v| v.ssim).sum::<f64>() / n,
            per_view,
            warnings,
        })
    }
}

/// How `level` looks beside `input` (see the module documentation); for several levels of one
/// input, render the input once with [`AppearanceReference`].
///
/// # Errors
///
/// The renderer's, as [`AppearanceReference::new`].
pub fn appearance(
    input: &Asset,
    level: &Asset,
    options: &AppearanceOptions,
) -> Result<AppearanceReport, RenderError> {
    AppearanceReference::new(input, options)?.compare(level)
}

/// The mean squared difference of two byte buffers of the same length (0 when empty).
pub fn mse(a: &[u8], b: &[u8]) -> f64 {
    assert_eq!(a.len(), b.len(), "images of different sizes");
    let sum: u64 = (a.iter().zip(b))
        .map(|(&x, &y)| {
            let d = x as i64 - y as i64;
            (d * d) as u64
        })
        .sum();
    sum as f64 / a.len().max(1) as f64
}

/// `10 log10(255² / mse)` in dB; infinite for 0.
pub fn psnr_of_mse(mse: f64) -> f64 {
    if mse == 0.0 {
        f64::INFINITY
    } else {
        10.0 * (255.0 * 255.0 / mse).log10()
    }
}

/// The luma `0.299 R + 0.587 G + 0.114 B` of packed 8-bit RGB, in 0..255.
pub fn luma(rgb: &[u8]) -> Vec<f32> {
    (rgb.chunks_exact(3))
        .map(|p| 0.299 * p[0] as f32 + 0.587 * p[1] as f32 + 0.114 * p[2] as f32)
        .collect()
}

/// The window's side and standard deviation (Wang et al. 2004 §III-C).
const WINDOW: usize = 11;
const SIGMA: f64 = 1.5;

/// The 11 taps of the Gaussian of standard deviation 1.5, summing to 1 (the 2-D window is their
/// outer product).
fn gaussian_taps() -> [f64; WINDOW] {
    let c = (WINDOW / 2) as f64;
    let mut taps = [0.0; WINDOW];
    for (i, t) in taps.iter_mut().enumerate() {
        let d = i as f64 - c;
        *t = (-d * d / (2.0 * SIGMA * SIGMA)).exp();
    }
    let sum: f64 = taps.iter().sum();
    taps.map(|t| t / sum)
}

/// `values` (`width × height`, row by row) filtered by the window where it fits wholly: an
/// image of `(width − 10) × (height − 10)`.
fn filter_valid(values: &[f64], width: usize, height: usize, taps: &[f64; WINDOW]) -> Vec<f64> {
    let (ow, oh) = (width + 1 - WINDOW, height + 1 - WINDOW);
    let mut rows = vec![0.0; ow * height];
    for y in 0..height {
        let line = &values[y * width..(y + 1) * width];
        for x in 0..ow {
            rows[y * ow + x] = (0..WINDOW).map(|k| taps[k] * line[x + k]).sum();
        }
    }
    let mut out = vec![0.0; ow * oh];
    for y in 0..oh {
        for x in 0..ow {
            out[y * ow + x] = (0..WINDOW).map(|k| taps[k] * rows[(y + k) * ow + x]).sum();
        }
    }
    out
}

/// The mean SSIM of two luma images of `width × height` values in 0..255 (see the module
/// documentation); 1 for identical images. Images smaller than the window are compared as one
/// window of uniform weights.
pub fn ssim(a: &[f32], b: &[f32], width: usize, height: usize) -> f64 {
    assert_eq!(a.len(), width * height);
    assert_eq!(b.len(), width * height);
    let (c1, c2) = ((0.01f64 * 255.0).powi(2), (0.03f64 * 255.0).powi(2));
    let index = |mx: f64, my: f64, xx: f64, yy: f64, xy: f64| {
        let (vx, vy, cov) = (xx - mx * mx, yy - my * my, xy - mx * my);
        ((2.0 * mx * my + c1) * (2.0 * cov + c2)) / ((mx * mx + my * my + c1) * (vx + vy + c2))
    };
    let x: Vec<f64> = a.iter().map(|&v| v as f64).collect();
    let y: Vec<f64> = b.iter().map(|&v| v as f64).collect();
    if width < WINDOW || height < WINDOW {
        let n = x.len().max(1) as f64;
        let mean = |v: &mut dyn Iterator<Item = f64>| v.sum::<f64>() / n;
        return index(
            mean(&mut x.iter().copied()),
            mean(&mut y.iter().copied()),
            mean(&mut x.iter().map(|v| v * v)),
            mean(&mut y.iter().map(|v| v * v)),
            mean(&mut x.iter().zip(&y).map(|(p, q)| p * q)),
        );
    }
    let taps = gaussian_taps();
    let f = |v: &[f64]| filter_valid(v, width, height, &taps);
    let square = |v: &[f64]| v.iter().map(|t| t * t).collect::<Vec<_>>();
    let (mx, my) = (f(&x), f(&y));
    let (xx, yy) = (f(&square(&x)), f(&square(&y)));
    let xy = f(&x.iter().zip(&y).map(|(p, q)| p * q).collect::<Vec<_>>());
    let sum: f64 = (0..mx.len())
        .map(|i| index(mx[i], my[i], xx[i], yy[i], xy[i]))
        .sum();
    sum / mx.len() as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn psnr_of_a_uniform_difference_is_exact() {
        let a = vec![100u8; 30];
        let b = vec![104u8; 30];
        assert_eq!(mse(&a, &b), 16.0);
        assert!((psnr_of_mse(16.0) - 20.0 * (255.0f64 / 4.0).log10()).abs() < 1e-12);
        assert_eq!(psnr_of_mse(mse(&a, &a)), f64::INFINITY);
    }

    #[test]
    fn ssim_is_one_for_identical_images_and_falls_with_noise_and_contrast() {
        let (w, h) = (40, 30);
        let mut state = 12345u32;
        let a: Vec<f32> = (0..w * h)
            .map(|_| {
                state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                (state >> 24) as f32
            })
            .collect();
        assert_eq!(ssim(&a, &a, w, h), 1.0);
        // Halved contrast about the mean: luminance kept, contrast term below 1.
        let mean = a.iter().sum::<f32>() / a.len() as f32;
        let flat: Vec<f32> = a.iter().map(|v| mean + 0.5 * (v - mean)).collect();
        let s = ssim(&a, &flat, w, h);
        assert!(s < 0.95 && s > 0.5, "{s}");
        // A constant image against a textured one: structure lost.
        let grey = vec![mean; a.len()];
        assert!(ssim(&a, &grey, w, h) < 0.1);
        // The window sums to 1.
        assert!((gaussian_taps().iter().sum::<f64>() - 1.0).abs() < 1e-15);
    }
}
