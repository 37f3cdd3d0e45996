//! Comparing images: RMS difference, over all pixels or over the pixels near silhouettes.
//!
//! The silhouette mask is taken from a reference image's coverage: a pixel is near a silhouette
//! when some pixel within `radius` (a square neighbourhood) is partly covered, i.e. its coverage
//! lies strictly between 0 and 1 (by more than 1/512), or when the neighbourhood holds both
//! uncovered and fully covered pixels. With a supersampled reference, partial coverage marks
//! exactly the pixels that edges cross. Cost: O(pixels × radius²).

use crate::Image;

/// Pixels within `radius` of a silhouette of `reference` (see the module documentation).
pub fn silhouette_mask(reference: &Image, radius: u32) -> Vec<bool> {
    let (w, h) = (reference.width as i64, reference.height as i64);
    let eps = 1.0 / 512.0;
    let class = |c: f32| -> u8 {
        if c <= eps {
            1
        } else if c >= 1.0 - eps {
            2
        } else {
            4
        }
    };
    let classes: Vec<u8> = reference.coverage.iter().map(|&c| class(c)).collect();
    let r = radius as i64;
    let mut mask = vec![false; classes.len()];
    for y in 0..h {
        for x in 0..w {
            let mut seen = 0u8;
            for yy in (y - r).max(0)..=(y + r).min(h - 1) {
                for xx in (x - r).max(0)..=(x + r).min(w - 1) {
                    seen |= classes[(yy * w + xx) as usize];
                }
            }
            mask[(y * w + x) as usize] = seen & 4 != 0 || seen == 3;
        }
    }
    mask
}

/// RMS of the per-channel difference of linear RGB, over the pixels where `mask` is true (all
/// pixels when `None`). `None` when the images differ in size or no pixel is selected.
pub fn rms_difference(a: &Image, b: &Image, mask: Option<&[bool]>) -> Option<f64> {
    if a.width != b.width || a.height != b.height {
        return None;
    }
    let mut sum = 0.0f64;
    let mut n = 0usize;
    for i in 0..a.rgb.len() {
        if mask.is_some_and(|m| !m[i]) {
            continue;
        }
        for c in 0..3 {
            let d = (a.rgb[i][c] - b.rgb[i][c]) as f64;
            sum += d * d;
        }
        n += 3;
    }
    (n > 0).then(|| (sum / n as f64).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mask_follows_edges_and_rms_is_exact() {
        let mut img = Image::new(8, 8, [0.0; 3]);
        for y in 0..8 {
            for x in 0..4 {
                let i = img.index(x, y);
                img.coverage[i] = 1.0;
                img.rgb[i] = [1.0; 3];
            }
        }
        let mask = silhouette_mask(&img, 1);
        for y in 0..8 {
            for x in 0..8u32 {
                assert_eq!(mask[img.index(x, y)], (3..=4).contains(&x), "{x},{y}");
            }
        }
        let mut other = img.clone();
        let i = other.index(3, 0);
        other.rgb[i] = [0.5; 3];
        let all = rms_difference(&img, &other, None).unwrap();
        assert!((all - (0.25f64 / 64.0).sqrt()).abs() < 1e-9);
        let near = rms_difference(&img, &other, Some(&mask)).unwrap();
        assert!((near - (0.25f64 / 16.0).sqrt()).abs() < 1e-9);
    }
}
