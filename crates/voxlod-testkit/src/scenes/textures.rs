//! Generated textures for the scenes, encoded as PNG: patterns with sharp, position-specific
//! detail (checks, stripes, bricks, rows of glyphs, noise), so that a texel taken from the
//! wrong place shows in a render. Every pattern is a pure function of the texel and a seed.
//!
//! Cost: linear in the texels, plus the PNG encoding.

use std::io::Cursor;

/// An sRGB colour with alpha, 8 bits a channel.
pub type Rgba = [u8; 4];

/// A 32-bit integer hash of a texel and a seed (the finaliser of MurmurHash3 over a mix of the
/// three), uniform enough for value noise and glyph bits.
pub fn hash(x: u32, y: u32, seed: u32) -> u32 {
    let mut h = x
        .wrapping_mul(0x8da6_b343)
        .wrapping_add(y.wrapping_mul(0xd816_3841))
        .wrapping_add(seed.wrapping_mul(0xcb1a_b31f));
    h ^= h >> 16;
    h = h.wrapping_mul(0x85eb_ca6b);
    h ^= h >> 13;
    h = h.wrapping_mul(0xc2b2_ae35);
    h ^ (h >> 16)
}

/// [`hash`] as a number in 0..1.
pub fn unit(x: u32, y: u32, seed: u32) -> f32 {
    (hash(x, y, seed) >> 8) as f32 / (1u32 << 24) as f32
}

/// A `width × height` RGBA PNG of `texel(x, y)`.
pub fn png(width: u32, height: u32, texel: impl Fn(u32, u32) -> Rgba) -> Vec<u8> {
    let img = image::RgbaImage::from_fn(width, height, |x, y| image::Rgba(texel(x, y)));
    let mut bytes = Vec::new();
    img.write_to(&mut Cursor::new(&mut bytes), image::ImageFormat::Png)
        .expect("a PNG encodes in memory");
    bytes
}

/// `a` and `b` mixed, `t` = 0 giving `a`.
pub fn mix(a: Rgba, b: Rgba, t: f32) -> Rgba {
    let t = t.clamp(0.0, 1.0);
    std::array::from_fn(|k| (a[k] as f32 + (b[k] as f32 - a[k] as f32) * t).round() as u8)
}

/// Smooth value noise in 0..1 at texel (x, y): `octaves` of lattice values (cells of `cell`
/// texels, halving each octave) blended with smoothstep, tiling over `size` texels.
pub fn value_noise(x: u32, y: u32, size: u32, cell: u32, octaves: u32, seed: u32) -> f32 {
    let (mut sum, mut weight, mut amplitude, mut cell) = (0.0, 0.0, 1.0, cell.max(1));
    for octave in 0..octaves {
        let cells = (size / cell).max(1);
        let (fx, fy) = (x as f32 / cell as f32, y as f32 / cell as f32);
        let (ix, iy) = (fx.floor() as u32, fy.floor() as u32);
        let (tx, ty) = (smooth(fx.fract()), smooth(fy.fract()));
        let at = |i: u32, j: u32| unit(i % cells, j % cells, seed.wrapping_add(octave));
        let top = at(ix, iy) + (at(ix + 1, iy) - at(ix, iy)) * tx;
        let bottom = at(ix, iy + 1) + (at(ix + 1, iy + 1) - at(ix, iy + 1)) * tx;
        sum += amplitude * (top + (bottom - top) * ty);
        weight += amplitude;
        amplitude *= 0.5;
        cell = (cell / 2).max(1);
    }
    sum / weight
}

fn smooth(t: f32) -> f32 {
    t * t * (3.0 - 2.0 * t)
}

/// Squares of `cell` texels alternating between `a` and `b`.
pub fn checks(size: u32, cell: u32, a: Rgba, b: Rgba) -> Vec<u8> {
    png(size, size, |x, y| {
        if (x / cell + y / cell).is_multiple_of(2) {
            a
        } else {
            b
        }
    })
}

/// Vertical stripes cycling through `colours`, each `width` texels wide, with a thin dark
/// line every fourth stripe so that the cycle's phase shows.
pub fn stripes(size: u32, width: u32, colours: &[Rgba]) -> Vec<u8> {
    png(size, size, |x, _| {
        let k = (x / width) as usize;
        if k.is_multiple_of(4) && x % width < 2 {
            [20, 20, 20, 255]
        } else {
            colours[k % colours.len()]
        }
    })
}

/// Noise between `dark` and `light`, stretched along x by `stretch` (grain for wood, bark).
pub fn grain(size: u32, stretch: u32, dark: Rgba, light: Rgba, seed: u32) -> Vec<u8> {
    png(size, size, |x, y| {
        let n = value_noise(x / stretch.max(1), y, size, 16, 4, seed);
        let rings = (n * 12.0).fract();
        mix(dark, light, 0.35 * n + 0.65 * rings)
    })
}

/// Bricks of 64 × 24 texels in half-bond with 4-texel mortar, each brick's colour varied by
/// its own hash.
pub fn bricks(size: u32, brick: Rgba, mortar: Rgba, seed: u32) -> Vec<u8> {
    png(size, size, |x, y| {
        let row = y / 24;
        let shifted = x + if row % 2 == 1 { 32 } else { 0 };
        let (column, bx, by) = (shifted / 64, shifted % 64, y % 24);
        if bx < 4 || by < 4 {
            return mortar;
        }
        let tint = unit(column % (size / 64).max(1), row, seed);
        mix(brick, [40, 20, 10, 255], 0.35 * tint)
    })
}

/// Rows of text-like glyphs on paper: cells of 8 × 12 texels, each a random 5 × 7 bitmap of
/// `ink` (a blank cell between words), lines 16 texels apart.
pub fn glyphs(size: u32, paper: Rgba, ink: Rgba, seed: u32) -> Vec<u8> {
    png(size, size, |x, y| {
        let (line, within_line) = (y / 16, y % 16);
        let (cell, within_cell) = (x / 8, x % 8);
        let (gx, gy) = (within_cell.wrapping_sub(1), within_line.wrapping_sub(2));
        if gx >= 5 || gy >= 7 || hash(cell, line, seed ^ 0x5bd1).is_multiple_of(6) {
            return paper;
        }
        let bits = hash(cell, line, seed);
        if (bits >> ((gy * 5 + gx) % 32)) & 1 == 1 {
            ink
        } else {
            paper
        }
    })
}

/// A leaf card's texture: four leaves (ellipses with a midrib and side veins) on a transparent
/// background, alpha 0 between the leaves and 255 on them.
pub fn leaves(size: u32, seed: u32) -> Vec<u8> {
    let s = size as f32;
    png(size, size, |x, y| {
        let (px, py) = (x as f32 / s, y as f32 / s);
        let (qx, qy) = (
            (px * 2.0).fract() * 2.0 - 1.0,
            (py * 2.0).fract() * 2.0 - 1.0,
        );
        let leaf = (px * 2.0) as u32 + 2 * (py * 2.0) as u32;
        // The leaf's axis runs along y: an ellipse narrowing to a tip.
        let width = 0.55 * (1.0 - qy * qy).max(0.0).sqrt() * (1.0 - 0.3 * qy);
        if qx.abs() > width || qy.abs() > 0.95 {
            return [0, 0, 0, 0];
        }
        let vein = qx.abs() < 0.04 || ((qy + qx.abs() * 0.8) * 6.0).fract() < 0.08;
        let tint = unit(leaf, 0, seed);
        let green = mix([40, 110, 30, 255], [120, 170, 40, 255], tint);
        if vein {
            mix(green, [200, 220, 120, 255], 0.6)
        } else {
            green
        }
    })
}

/// Noise between `a` and `b` at a fine scale with scratches along x (worn metal, concrete).
pub fn speckle(size: u32, a: Rgba, b: Rgba, seed: u32) -> Vec<u8> {
    png(size, size, |x, y| {
        let n = value_noise(x, y, size, 32, 5, seed);
        let scratch = hash(y, x / 32, seed ^ 0x77).is_multiple_of(29);
        mix(a, b, if scratch { 1.0 } else { n })
    })
}
