//! How far a level's colours are from the input's, without rendering: the root mean square
//! difference (linear RGB, area-weighted) between what the input shows at points spread over
//! its triangles and what the level shows at the nearest point of its surface. What a point
//! shows is its vertex colour × its material's base colour factor × its base colour texture
//! ([`crate::transfer`]'s rule), so a textured level and one with the texture reduced to
//! vertex colours are measured alike. It compares two levels of one input by their looks
//! where a geometric distance cannot (a level farther from the input that keeps the texture
//! may look closer to it than a nearer one that lost it).
//!
//! Cost: O(S log L) closest-point queries on all cores for S = 4 samples per input triangle
//! and L level triangles, plus decoding each base colour texture once.

use rayon::prelude::*;
use voxlod_metrics::MeshDistance;

use crate::texture::decode_base_colours;
use crate::transfer::{colour_at, Barycentric};
use crate::{Asset, AssetError};

/// The barycentric weights of the samples on each input triangle: its centre and the middle
/// of each corner's third.
const SAMPLES: [[f32; 3]; 4] = [
    [1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0],
    [2.0 / 3.0, 1.0 / 6.0, 1.0 / 6.0],
    [1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0],
    [1.0 / 6.0, 1.0 / 6.0, 2.0 / 3.0],
];

/// The colour error of `level` against `input` (module docs), in linear RGB units (0 to √3).
/// Refuses an invalid asset or a level without triangles; images that cannot be decoded count
/// as their material's factor, as in [`crate::transfer`].
pub fn colour_error(input: &Asset, level: &Asset) -> Result<f64, AssetError> {
    input.validate()?;
    level.validate()?;
    if level.mesh.triangles.is_empty() {
        return Err(AssetError::Invalid(
            "the level has no triangles to compare colours with".into(),
        ));
    }
    let search = MeshDistance::new(&level.mesh.geometry())
        .map_err(|e| AssetError::Invalid(format!("the level cannot be searched: {e}")))?;
    let (input_textures, _) = decode_base_colours(input)?;
    let (level_textures, _) = decode_base_colours(level)?;
    let mesh = &input.mesh;
    let (sum, area) = (0..mesh.triangles.len())
        .into_par_iter()
        .map(|t| {
            let [a, b, c] = mesh.triangles[t].map(|v| mesh.positions[v as usize]);
            let area = f64::from((b - a).cross(c - a).length()) / 2.0;
            let mut squared = 0.0;
            for weights in SAMPLES {
                let at = Barycentric {
                    triangle: t,
                    weights,
                };
                let p = a * weights[0] + b * weights[1] + c * weights[2];
                let near = search.closest(p.as_dvec3());
                let there = Barycentric::on(&level.mesh, near.triangle, near.point);
                let shown = colour_at(level, &level_textures, &there);
                let d = (colour_at(input, &input_textures, &at) - shown).truncate();
                squared += f64::from(d.length_squared());
            }
            (squared * area / SAMPLES.len() as f64, area)
        })
        .reduce(|| (0.0, 0.0), |x, y| (x.0 + y.0, x.1 + y.1));
    Ok(if area > 0.0 { (sum / area).sqrt() } else { 0.0 })
}
