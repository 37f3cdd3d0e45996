//! A material's base colour texture decoded for sampling: PNG and JPEG through the `image`
//! crate, sRGB converted to linear (a normal map's stored values kept as data,
//! [`decode_normal_maps`], and bent into a shading normal by [`bend_normal`]), read bilinearly (or nearest, as the sampler says) with the
//! sampler's wrap modes and the slot's `KHR_texture_transform`. Other encodings (KTX2, WebP)
//! are not decoded; [`decode_base_colours`] names them in its warnings and the material's factor
//! stands in.
//!
//! Cost: decoding is linear in the image; the image's size meets the memory limit before it
//! is decoded. A sample costs four texel reads.

use std::io::Cursor;

use image::{ImageFormat, ImageReader};
use voxlod_core::glam::{Vec2, Vec3, Vec4};
use voxlod_core::memory::check_allocation;

use crate::{Asset, AssetError, Image, Sampler, TextureRef, Wrap};

/// A decoded image: linear RGBA texels, row by row from the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Texels {
    /// Width in texels.
    pub width: usize,
    /// Height in texels.
    pub height: usize,
    /// Linear RGBA, `width × height` of them.
    pub rgba: Vec<Vec4>,
}

/// Decodes a PNG or JPEG image (colour channels sRGB, converted to linear; alpha kept).
/// Fails on another encoding or corrupt bytes, naming the image.
pub fn decode(image: &Image) -> Result<Texels, AssetError> {
    decode_named(image, "an image")
}

/// [`decode`] of the asset's image `k`; errors name it by its name, or by `image k` when it has
/// none.
pub fn decode_at(asset: &Asset, k: usize) -> Result<Texels, AssetError> {
    decode_named(&asset.images[k], &format!("image {k}"))
}

/// The width and height of a PNG or JPEG image, read from its header without decoding it;
/// `None` for another encoding or a header that does not read. Cost: the header only.
pub fn dimensions(image: &Image) -> Option<(u32, u32)> {
    let format = decoded_format(&image.mime)?;
    let reader = ImageReader::with_format(Cursor::new(image.bytes.as_slice()), format);
    reader.into_dimensions().ok()
}

/// The formats this module decodes.
fn decoded_format(mime: &str) -> Option<ImageFormat> {
    match mime {
        "image/png" => Some(ImageFormat::Png),
        "image/jpeg" => Some(ImageFormat::Jpeg),
        _ => None,
    }
}

/// [`decode`], errors naming the image by its name, or `unnamed` when it has none.
fn decode_named(image: &Image, unnamed: &str) -> Result<Texels, AssetError> {
    decode_as(image, unnamed, true)
}

/// A PNG or JPEG image decoded as `srgb` colour (converted to linear) or as data (the stored
/// values over 255, as normal maps hold them), errors naming the image.
fn decode_as(image: &Image, unnamed: &str, srgb: bool) -> Result<Texels, AssetError> {
    let name = if image.name.is_empty() {
        unnamed
    } else {
        &image.name
    };
    let bad = |why: String| AssetError::Invalid(format!("{name} ({}): {why}", image.mime));
    let Some(format) = decoded_format(&image.mime) else {
        return Err(bad(format!("{} images are not decoded", image.mime)));
    };
    let reader = || ImageReader::with_format(Cursor::new(image.bytes.as_slice()), format);
    let (w, h) = reader().into_dimensions().map_err(|e| bad(e.to_string()))?;
    let count = (w as u64) * (h as u64);
    check_allocation(&format!("the {w}×{h} texture {name}"), count * 20)?;
    let rgba = reader()
        .decode()
        .map_err(|e| bad(e.to_string()))?
        .into_rgba8();
    let texels = rgba
        .pixels()
        .map(|p| {
            let c = |v: u8| match srgb {
                true => srgb_to_linear(v as f32 / 255.0),
                false => v as f32 / 255.0,
            };
            Vec4::new(c(p[0]), c(p[1]), c(p[2]), p[3] as f32 / 255.0)
        })
        .collect();
    Ok(Texels {
        width: w as usize,
        height: h as usize,
        rgba: texels,
    })
}

/// The sRGB transfer function undone (IEC 61966-2-1).
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// The base colour texture of every material decoded, one entry per material (`None` where it
/// has none or it could not be decoded), with a warning for each image that could not be.
pub fn decode_base_colours(
    asset: &Asset,
) -> Result<(Vec<Option<Texels>>, Vec<String>), AssetError> {
    let mut decoded: Vec<Option<Option<Texels>>> = vec![None; asset.images.len()];
    let mut warnings = Vec::new();
    let mut out = Vec::with_capacity(asset.materials.len());
    for material in &asset.materials {
        let Some(slot) = &material.base_color_texture else {
            out.push(None);
            continue;
        };
        if decoded[slot.image].is_none() {
            decoded[slot.image] = Some(match decode_at(asset, slot.image) {
                Ok(t) => Some(t),
                Err(AssetError::Core(e)) => return Err(e.into()),
                Err(e) => {
                    warnings.push(format!("{e}: its material's base colour factor stands in"));
                    None
                }
            });
        }
        out.push(decoded[slot.image].clone().flatten());
    }
    Ok((out, warnings))
}

/// The normal texture of every material decoded as data (the stored values over 255), one
/// entry per material (`None` where it has none or it could not be decoded), with a warning
/// for each image that could not be.
pub fn decode_normal_maps(asset: &Asset) -> Result<(Vec<Option<Texels>>, Vec<String>), AssetError> {
    let mut out = Vec::with_capacity(asset.materials.len());
    let mut warnings = Vec::new();
    for material in &asset.materials {
        let Some(slot) = &material.normal_texture else {
            out.push(None);
            continue;
        };
        match decode_as(
            &asset.images[slot.image],
            &format!("image {}", slot.image),
            false,
        ) {
            Ok(t) => out.push(Some(t)),
            Err(AssetError::Core(e)) => return Err(e.into()),
            Err(e) => {
                warnings.push(format!("{e}: its material's normal map is not drawn"));
                out.push(None);
            }
        }
    }
    Ok((out, warnings))
}

/// The unit normal `n` bent by the normal-map sample `m` (stored values, 0..1) in the tangent
/// frame of `tangent` (xyz, w the bitangent's sign), its xy scaled by `scale` (glTF 2.0
/// §3.9.3); `n` where the tangent is parallel to it.
pub fn bend_normal(n: Vec3, tangent: Vec4, m: Vec4, scale: f32) -> Vec3 {
    let t = (tangent.truncate() - n * n.dot(tangent.truncate())).try_normalize();
    let Some(t) = t else { return n };
    let b = n.cross(t) * if tangent.w < 0.0 { -1.0 } else { 1.0 };
    let x = (2.0 * m.x - 1.0) * scale;
    let y = (2.0 * m.y - 1.0) * scale;
    let z = 2.0 * m.z - 1.0;
    (t * x + b * y + n * z).try_normalize().unwrap_or(n)
}

impl Texels {
    /// The texture at the vertex coordinates `uv` of the slot's set (transform applied), read
    /// as the slot's sampler says.
    pub fn sample(&self, slot: &TextureRef, uv: Vec2) -> Vec4 {
        let uv = slot.transform.map_or(uv, |t| t.apply(uv));
        self.sample_at(uv, &slot.sampler)
    }

    /// The texture at texture coordinates `uv` (0..1 across the image, v down).
    pub fn sample_at(&self, uv: Vec2, sampler: &Sampler) -> Vec4 {
        let x = uv.x * self.width as f32 - 0.5;
        let y = uv.y * self.height as f32 - 0.5;
        if !sampler.linear {
            let i = wrap(x.round() as i64, self.width, sampler.wrap_u);
            let j = wrap(y.round() as i64, self.height, sampler.wrap_v);
            return self.rgba[j * self.width + i];
        }
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let texel = |dx: i64, dy: i64| {
            let i = wrap(x0 as i64 + dx, self.width, sampler.wrap_u);
            let j = wrap(y0 as i64 + dy, self.height, sampler.wrap_v);
            self.rgba[j * self.width + i]
        };
        let top = texel(0, 0).lerp(texel(1, 0), fx);
        let bottom = texel(0, 1).lerp(texel(1, 1), fx);
        top.lerp(bottom, fy)
    }
}

/// Texel index `i` wrapped into `0..n`.
fn wrap(i: i64, n: usize, mode: Wrap) -> usize {
    let n = n as i64;
    match mode {
        Wrap::Repeat => i.rem_euclid(n) as usize,
        Wrap::ClampToEdge => i.clamp(0, n - 1) as usize,
        Wrap::MirroredRepeat => {
            let m = i.rem_euclid(2 * n);
            (if m < n { m } else { 2 * n - 1 - m }) as usize
        }
    }
}
