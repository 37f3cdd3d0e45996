//! The rendered image: linear RGB and coverage per pixel, PNG encoding, side-by-side montage.
//!
//! Cost: O(pixels) for each conversion; 16 bytes a pixel.

use image::ImageEncoder;

use crate::RenderError;

/// Linear RGB in [0, 1] and coverage (alpha: the fraction of the pixel the scene covers).
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Pixels per row.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// Linear RGB of each pixel, row by row from the top left.
    pub rgb: Vec<[f32; 3]>,
    /// The fraction of each pixel the scene covers, row by row (0 for background only).
    pub coverage: Vec<f32>,
}

impl Image {
    /// An image of `width × height` pixels of `background`, nothing covered.
    pub fn new(width: u32, height: u32, background: [f32; 3]) -> Image {
        let n = width as usize * height as usize;
        Image {
            width,
            height,
            rgb: vec![background; n],
            coverage: vec![0.0; n],
        }
    }

    /// The index of pixel (x, y) in [`Image::rgb`] and [`Image::coverage`] (y down).
    #[inline]
    pub fn index(&self, x: u32, y: u32) -> usize {
        y as usize * self.width as usize + x as usize
    }

    /// 8-bit sRGB bytes, row by row.
    pub fn to_srgb8(&self) -> Vec<u8> {
        let encode = |c: f32| {
            let c = c.clamp(0.0, 1.0);
            let s = if c <= 0.003_130_8 {
                12.92 * c
            } else {
                1.055 * c.powf(1.0 / 2.4) - 0.055
            };
            (s * 255.0 + 0.5) as u8
        };
        self.rgb.iter().flat_map(|p| p.map(encode)).collect()
    }

    /// The image as PNG bytes (8-bit sRGB).
    pub fn to_png(&self) -> Result<Vec<u8>, RenderError> {
        let mut out = Vec::new();
        image::codecs::png::PngEncoder::new(&mut out)
            .write_image(
                &self.to_srgb8(),
                self.width,
                self.height,
                image::ExtendedColorType::Rgb8,
            )
            .map_err(|e| RenderError::Png(e.to_string()))?;
        Ok(out)
    }

    /// Images next to each other, `gap` pixels of `background` apart, top-aligned.
    pub fn side_by_side(images: &[&Image], gap: u32, background: [f32; 3]) -> Image {
        let width = images.iter().map(|i| i.width).sum::<u32>()
            + gap * images.len().saturating_sub(1) as u32;
        let height = images.iter().map(|i| i.height).max().unwrap_or(0);
        let mut out = Image::new(width.max(1), height.max(1), background);
        let mut x0 = 0;
        for img in images {
            for y in 0..img.height {
                for x in 0..img.width {
                    let (s, d) = (img.index(x, y), out.index(x0 + x, y));
                    out.rgb[d] = img.rgb[s];
                    out.coverage[d] = img.coverage[s];
                }
            }
            x0 += img.width + gap;
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn png_round_trips_through_the_decoder() {
        let mut img = Image::new(3, 2, [0.0, 0.0, 0.0]);
        let i = img.index(2, 1);
        img.rgb[i] = [1.0, 0.5, 0.0];
        let png = img.to_png().unwrap();
        let back = image::load_from_memory(&png).unwrap().to_rgb8();
        assert_eq!(back.dimensions(), (3, 2));
        assert_eq!(back.get_pixel(2, 1).0, [255, 188, 0]);
        assert_eq!(back.get_pixel(0, 0).0, [0, 0, 0]);
        let both = Image::side_by_side(&[&img, &img], 1, [1.0; 3]);
        assert_eq!((both.width, both.height), (7, 2));
        assert_eq!(both.rgb[both.index(3, 0)], [1.0; 3]);
    }
}
