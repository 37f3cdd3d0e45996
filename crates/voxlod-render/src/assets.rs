//! Assets drawn with their looks in one call: their box, and [`render_assets`] (textures
//! decoded, the scene made, [`render`]). Cost: [`render`]'s, plus decoding each texture once.

use voxlod_asset::Asset;
use voxlod_core::Bounds;

use crate::looks::{decode_normal_maps, decode_textures, AssetItem};
use crate::{render, Camera, Image, RenderError, RenderOptions, Scene};

/// The box of the assets' triangles (empty when they have none). Cost: linear.
pub fn assets_bounds(assets: &[&Asset]) -> Bounds {
    let mut b = Bounds::EMPTY;
    for a in assets {
        for &v in a.mesh.triangles.iter().flatten() {
            if let Some(p) = a.mesh.positions.get(v as usize) {
                b.grow(p.as_dvec3());
            }
        }
    }
    b
}

/// `assets` drawn with their looks as `camera` sees them: their base colour textures and
/// normal maps decoded ([`decode_textures`], [`decode_normal_maps`]), then [`render`]; with the
/// decoding's warnings, each asset's prefixed with its index when there are several.
///
/// # Errors
///
/// As [`render`] and [`decode_textures`].
pub fn render_assets(
    assets: &[&Asset],
    camera: &Camera,
    options: &RenderOptions,
) -> Result<(Image, Vec<String>), RenderError> {
    let mut textures = Vec::with_capacity(assets.len());
    let mut warnings = Vec::new();
    for (i, a) in assets.iter().enumerate() {
        let (t, mut w) = decode_textures(a)?;
        let (maps, noted) = decode_normal_maps(a)?;
        w.extend(noted);
        let prefix = if assets.len() > 1 {
            format!("asset {i}: ")
        } else {
            String::new()
        };
        warnings.extend(w.into_iter().map(|w| format!("{prefix}{w}")));
        textures.push((t, maps));
    }
    let scene = Scene {
        assets: (assets.iter().zip(&textures))
            .map(|(a, (t, maps))| AssetItem::new(a, t).with_normal_maps(maps))
            .collect(),
        ..Default::default()
    };
    Ok((render(&scene, camera, options)?, warnings))
}
