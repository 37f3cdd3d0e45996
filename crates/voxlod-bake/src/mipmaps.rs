//! A source texture seen from afar: a texel of the bake covers a patch of the source surface,
//! and where that patch spans many of the source texture's texels (a brick wall's tiled
//! texture baked into a whole building's atlas), sampling the texture at one point aliases
//! into moiré that no later filter can undo. The texture is therefore kept as a mipmap pyramid
//! (each level the one below averaged over 2 × 2 texels, as a GPU builds it) and sampled
//! trilinearly at the level whose texels are as large as the patch (the footprint), as a
//! renderer does for a minified texture (OpenGL 4.6 §8.14).
//!
//! Cost: building, 4/3 of the image's texels; a sample, two bilinear samples.

use voxlod_asset::texture::Texels;
use voxlod_asset::TextureRef;
use voxlod_core::glam::{Vec2, Vec3, Vec4};

/// A texture and its mipmap levels (level 0 the image itself, the last 1 × 1).
#[derive(Clone, Debug)]
pub struct Mipmaps {
    levels: Vec<Texels>,
}

impl Mipmaps {
    /// The pyramid of `image`: each level half the one below (rounded down, at least 1) a
    /// side, each texel the mean of the 2 × 2 texels below it (an odd last row or column of
    /// the level below is left out, as a box filter does).
    pub fn new(image: Texels) -> Mipmaps {
        let mut levels = vec![image];
        loop {
            let below = levels.last().expect("level 0 is there");
            if below.width <= 1 && below.height <= 1 {
                break;
            }
            let next = halved(below);
            levels.push(next);
        }
        Mipmaps { levels }
    }

    /// Levels in the pyramid.
    pub fn level_count(&self) -> usize {
        self.levels.len()
    }

    /// The image's texels a side (level 0).
    pub fn size(&self) -> (usize, usize) {
        (self.levels[0].width, self.levels[0].height)
    }

    /// The texture at `uv` (as [`Texels::sample`]: the slot's transform and sampler) for a
    /// footprint of `texels` of level 0 across: bilinear at level 0 up to one texel, then
    /// between the two levels around `log2(texels)`, linearly.
    pub fn sample(&self, slot: &TextureRef, uv: Vec2, texels: f32) -> Vec4 {
        let lod = texels.max(1.0).log2().min((self.levels.len() - 1) as f32);
        let below = lod.floor() as usize;
        let fine = self.levels[below].sample(slot, uv);
        if below + 1 >= self.levels.len() || lod == below as f32 {
            return fine;
        }
        let coarse = self.levels[below + 1].sample(slot, uv);
        fine.lerp(coarse, lod - below as f32)
    }
}

/// Texels per world unit along a triangle with corners `world` and, in texels, `texels`: the
/// square root of its area in texels over its area in the world (0 where it has no world
/// area).
pub fn texels_per_unit(world: [Vec3; 3], texels: [Vec2; 3]) -> f32 {
    let [a, b, c] = world;
    let [p, q, r] = texels;
    let in_texels = 0.5 * (q - p).perp_dot(r - p).abs();
    let in_world = 0.5 * (b - a).cross(c - a).length();
    if in_world > 0.0 {
        (in_texels / in_world).sqrt()
    } else {
        0.0
    }
}

/// `level` averaged over 2 × 2 texels.
fn halved(level: &Texels) -> Texels {
    let (w, h) = ((level.width / 2).max(1), (level.height / 2).max(1));
    let mut rgba = Vec::with_capacity(w * h);
    for j in 0..h {
        let rows = (2 * j)..(2 * j + 2).min(level.height);
        for i in 0..w {
            let columns = (2 * i)..(2 * i + 2).min(level.width);
            let (mut sum, mut n) = (Vec4::ZERO, 0.0);
            for y in rows.clone() {
                for x in columns.clone() {
                    sum += level.rgba[y * level.width + x];
                    n += 1.0;
                }
            }
            rgba.push(sum / n);
        }
    }
    Texels {
        width: w,
        height: h,
        rgba,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A checker of single texels, black and white, `n` a side.
    fn fine_checker(n: usize) -> Texels {
        let rgba = (0..n * n)
            .map(|k| match (k % n + k / n) % 2 {
                0 => Vec4::ZERO,
                _ => Vec4::ONE,
            })
            .collect();
        Texels {
            width: n,
            height: n,
            rgba,
        }
    }

    #[test]
    fn a_64_texel_image_has_seven_levels_down_to_one_texel() {
        let m = Mipmaps::new(fine_checker(64));
        assert_eq!(m.level_count(), 7);
        assert_eq!((m.levels[6].width, m.levels[6].height), (1, 1));
        // Every level of a texel checker is its mean, 0.5, from level 1 on.
        assert!(m.levels[1..]
            .iter()
            .all(|l| l.rgba.iter().all(|&t| t == Vec4::splat(0.5))));
    }

    #[test]
    fn a_footprint_of_many_texels_sees_the_mean_and_one_texel_sees_the_texel() {
        let m = Mipmaps::new(fine_checker(64));
        let slot = TextureRef {
            image: 0,
            tex_coord: 0,
            transform: None,
            sampler: Default::default(),
        };
        // The centre of texel (10, 20): black, as (10 + 20) is even.
        let uv = Vec2::new(10.5 / 64.0, 20.5 / 64.0);
        assert_eq!(m.sample(&slot, uv, 1.0), Vec4::ZERO);
        assert_eq!(m.sample(&slot, uv, 8.0), Vec4::splat(0.5));
        // Halfway between levels 0 and 1 in log2: half the way to the mean.
        let half = m.sample(&slot, uv, std::f32::consts::SQRT_2);
        assert!(
            (half - Vec4::splat(0.25)).abs().max_element() < 1e-6,
            "{half}"
        );
    }

    #[test]
    fn odd_sides_average_what_they_cover() {
        let image = Texels {
            width: 3,
            height: 1,
            rgba: vec![Vec4::ZERO, Vec4::ONE, Vec4::splat(0.25)],
        };
        let m = Mipmaps::new(image);
        assert_eq!(m.level_count(), 2);
        assert_eq!((m.levels[1].width, m.levels[1].height), (1, 1));
        assert_eq!(m.levels[1].rgba[0], Vec4::splat(0.5));
    }
}
