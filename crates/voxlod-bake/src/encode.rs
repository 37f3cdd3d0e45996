//! How a baked level's textures are stored: PNG (lossless) or, on request, JPEG for the
//! colour-like maps, encoded by the `image` crate.
//!
//! JPEG is what web and game pipelines expect of a proxy's colour maps (gltfpack, Simplygon
//! and InstaLOD offer it). At quality 90 it is smaller than PNG where the texels have grain
//! (a photograph-like 1024² base colour: a quarter of the PNG; Spot's painted one: 0.7) and
//! larger on flat colours with hard edges (a checker: three times the PNG); the `image`
//! crate's encoder keeps full chroma (4:4:4) and standard Huffman tables. JPEG has no alpha
//! channel, and its 8×8 block artefacts in a normal map read as shading faults, so the normal
//! map and a base colour whose alpha is used stay PNG ([`crate::output`] decides which).
//!
//! Cost: linear in the texels.

use std::io::Cursor;

use image::{ExtendedColorType, ImageEncoder};
use serde::{Deserialize, Serialize};

use crate::BakeError;

/// How the colour-like textures of a baked level (base colour, occlusion-roughness-metallic,
/// emissive) are encoded; the normal map is PNG either way.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ImageFormat {
    /// Lossless PNG.
    #[default]
    Png,
    /// Baseline JPEG (4:4:4) at this quality, 1 (smallest) to 100 (closest); a base colour
    /// whose alpha the material uses stays PNG.
    Jpeg {
        /// 1 to 100.
        quality: u8,
    },
}

impl ImageFormat {
    /// Refuses a JPEG quality outside 1..=100 ([`BakeError::Invalid`] naming the value).
    pub fn check(&self) -> Result<(), BakeError> {
        match *self {
            ImageFormat::Jpeg { quality } if !(1..=100).contains(&quality) => Err(
                BakeError::Invalid(format!("the JPEG quality {quality} is not in 1 to 100")),
            ),
            _ => Ok(()),
        }
    }

    /// The media type of images in this format.
    pub fn mime(&self) -> &'static str {
        match self {
            ImageFormat::Png => "image/png",
            ImageFormat::Jpeg { .. } => "image/jpeg",
        }
    }

    /// The file name extension of images in this format, without the dot.
    pub fn extension(&self) -> &'static str {
        match self {
            ImageFormat::Png => "png",
            ImageFormat::Jpeg { .. } => "jpg",
        }
    }
}

/// `raw` texels (`channels` bytes each, 3 or 4, row by row from the top) of a
/// `width` × `height` texture encoded in `format`. JPEG stores three channels: a fourth is
/// dropped. Refuses a JPEG quality outside 1..=100 ([`BakeError::Invalid`]); fails with
/// [`BakeError::Encode`] naming `what` when the encoder refuses the texels.
pub fn encode(
    raw: &[u8],
    width: u32,
    height: u32,
    channels: usize,
    format: ImageFormat,
    what: &'static str,
) -> Result<Vec<u8>, BakeError> {
    let colour = if channels == 4 {
        ExtendedColorType::Rgba8
    } else {
        ExtendedColorType::Rgb8
    };
    format.check()?;
    let mut bytes = Vec::new();
    let sink = Cursor::new(&mut bytes);
    let written = match format {
        ImageFormat::Png => {
            image::codecs::png::PngEncoder::new(sink).write_image(raw, width, height, colour)
        }
        ImageFormat::Jpeg { quality } => {
            image::codecs::jpeg::JpegEncoder::new_with_quality(sink, quality)
                .write_image(raw, width, height, colour)
        }
    };
    written.map_err(|e| BakeError::Encode {
        what,
        why: e.to_string(),
    })?;
    Ok(bytes)
}
