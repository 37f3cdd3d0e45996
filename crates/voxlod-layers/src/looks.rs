//! The layered shells of an asset with looks take its base colour: each layer gets a UV atlas
//! and a base colour texture baked from the asset by `voxlod-bake` (a ray from each texel's
//! point of the layer finds the asset's surface, whose colour the texel takes), and its
//! material becomes that texture times a factor of white with the layer's blend alpha.
//!
//! Beyond the paper: He et al.'s layers (§3) carry one colour each, with only their
//! translucency differing; baking the asset's looks onto every layer is ours, the same bake
//! that scene proxies get.
//!
//! **The orders stay true.** The atlas splits a layer's vertices at chart seams, so the
//! vertex count of each layer changes, but its triangles stay the same triangles in the same
//! order (the bake's atlas keeps the level's triangle order, and [`in_level_order`] checks
//! that, matching the triangles by their corners where it would not hold). The eight orders,
//! lists of triangles of the layers concatenated ([`crate::Layered::orders`]), therefore hold
//! for the baked layers as they are; written to a `.glb` ([`crate::glb_looks`]) they name the
//! new vertices.
//!
//! **Slivers.** The bake is told the layers' voxel, so its atlas is made with the ends of the
//! layer's edges shorter than [`voxlod_bake::slivers::SNAP_VOXELS`] of a voxel snapped together
//! (xatlas mis-scales charts holding marching cubes' slivers); the layer keeps its positions.
//!
//! Cost: per layer with triangles, one bake (`voxlod_bake::bake`: the atlas, the layers'
//! atlases side by side, then a ray cast per covered texel, O(texels × log N) for N asset
//! triangles); the textures other than base colour that the bake encodes are dropped.

use std::collections::HashMap;

use glam::Vec2;
use voxlod_asset::{Asset, Image};
use voxlod_bake::{Atlas, BakeError, BakeOptions, BakeReport};
use voxlod_core::TriangleMesh;

use crate::extract::{Layer, LayeredMesh};
use crate::LayersError;

/// The side of each layer's base colour texture unless asked otherwise, in texels.
pub const DEFAULT_TEXTURE: u32 = 512;

/// How the layers' looks are baked.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LooksOptions {
    /// Texels a side of each layer's (square) base colour texture; 8 to 16384.
    pub texture: u32,
    /// The filter's support radius in voxels of the layers' grid: every layer lies within it
    /// of the asset's surface, so the bake's rays look that far plus one voxel.
    pub radius_voxels: f64,
}

impl Default for LooksOptions {
    /// [`DEFAULT_TEXTURE`] texels a side, a filter radius of one voxel.
    fn default() -> Self {
        LooksOptions {
            texture: DEFAULT_TEXTURE,
            radius_voxels: 1.0,
        }
    }
}

/// One layer's baked looks.
#[derive(Clone, Debug, PartialEq)]
pub struct LayerLooks {
    /// Texture coordinates of each vertex of the baked layer's mesh, in [0, 1], v down the
    /// image (as glTF has it).
    pub uv: Vec<Vec2>,
    /// The base colour texture as the bake encoded it (PNG; RGBA where the asset has alpha).
    pub base_color: Image,
    /// What the bake did (its `width` and `height` are the texture's).
    pub report: BakeReport,
}

/// Layered shells with the asset's looks baked on.
#[derive(Clone, Debug, PartialEq)]
pub struct BakedLayers {
    /// The layers with their vertices split at chart seams (positions, and the bake's normals
    /// where the layers have normals): the same layers with the same triangles in the same
    /// order, cells and alphas unchanged, so the orders of the unbaked layers hold.
    pub mesh: LayeredMesh,
    /// Per layer, its looks; `None` for a layer without triangles.
    pub looks: Vec<Option<LayerLooks>>,
    /// What the bakes warned of, each prefixed by its layer.
    pub warnings: Vec<String>,
}

impl From<BakeError> for LayersError {
    /// A memory refusal stays a core error; the rest is the bake's.
    fn from(e: BakeError) -> Self {
        match e {
            BakeError::Core(e) => LayersError::Core(e),
            other => LayersError::Bake(other),
        }
    }
}

/// Whether baking `asset` would give more than one flat white: it has vertex colours, or a
/// material with a base colour texture or a base colour factor other than opaque white.
/// Cost: linear in the materials.
pub fn has_base_colour(asset: &Asset) -> bool {
    !asset.mesh.colors.is_empty()
        || asset
            .materials
            .iter()
            .any(|m| m.base_color_texture.is_some() || m.base_color != [1.0; 4])
}

/// Bakes `source`'s base colour onto every layer of `layered` (see the module
/// documentation). Refuses a texture side outside 8..=16384, a radius that is not a positive
/// number, and whatever the bake refuses (an invalid asset, a texture the memory limit cannot
/// hold). Cost: the source prepared once, then one bake per layer with triangles.
pub fn bake_layers(
    source: &Asset,
    layered: &LayeredMesh,
    options: &LooksOptions,
) -> Result<BakedLayers, LayersError> {
    layered.validate()?;
    if !(options.radius_voxels.is_finite() && options.radius_voxels > 0.0) {
        return Err(LayersError::Invalid(format!(
            "the filter radius {} is not a positive number of voxels",
            options.radius_voxels
        )));
    }
    let texture = options.texture;
    if !(8..=voxlod_bake::atlas::MAX_TEXTURE).contains(&texture) {
        return Err(LayersError::Invalid(format!(
            "a {texture}² texture: the side must be 8 to {} texels",
            voxlod_bake::atlas::MAX_TEXTURE
        )));
    }
    let voxel = layered.grid.spacing.iter().copied().fold(0.0, f64::max) as f32;
    // A layer's translucency already stands for how much of its cell the filtered solid
    // covers (§3): its texels take the source's alpha where the bake ray finds it, not an
    // opacity measured by view rays, which would count the same gaps twice.
    let bake_options = BakeOptions {
        voxel_size: Some(voxel),
        cage_voxels: (options.radius_voxels + 1.0) as f32,
        opacity_rays: 0,
        ..BakeOptions::for_texture(texture)
    };
    let mut out = BakedLayers {
        mesh: LayeredMesh {
            grid: layered.grid,
            placement: layered.placement,
            layers: Vec::with_capacity(layered.layers.len()),
        },
        looks: Vec::with_capacity(layered.layers.len()),
        warnings: Vec::new(),
    };
    let each: Vec<_> = (layered.layers.iter())
        .map(|l| (!l.mesh.triangles.is_empty()).then_some((&l.mesh, &bake_options)))
        .collect();
    let prepared = voxlod_bake::BakeSource::new(source)?;
    let atlases = voxlod_bake::atlases(&each);
    for (i, (layer, atlas)) in layered.layers.iter().zip(atlases).enumerate() {
        let Some(atlas) = atlas else {
            out.mesh.layers.push(layer.clone());
            out.looks.push(None);
            continue;
        };
        let (baked, looks) = bake_layer(&prepared, layer, atlas?, &bake_options)?;
        let noted = looks.report.warnings.iter();
        out.warnings
            .extend(noted.map(|w| format!("layer {i}: {w}")));
        out.mesh.layers.push(baked);
        out.looks.push(Some(looks));
    }
    Ok(out)
}

/// One layer with triangles baked: the layer on the atlas's vertices (its triangles in its
/// own order, its own positions) and its looks.
fn bake_layer(
    source: &voxlod_bake::BakeSource,
    layer: &Layer,
    atlas: Atlas,
    options: &BakeOptions,
) -> Result<(Layer, LayerLooks), LayersError> {
    let baked = voxlod_bake::bake_from(source, &layer.mesh, atlas, options)?;
    let atlas = &baked.atlas;
    let triangles = in_level_order(&layer.mesh.triangles, &atlas.triangles, &atlas.level_vertex)?;
    let positions = atlas.positions.clone();
    let mut asset = baked.asset;
    let base_color = asset
        .materials
        .first()
        .and_then(|m| m.base_color_texture.as_ref())
        .map(|t| asset.images.swap_remove(t.image))
        .ok_or_else(|| LayersError::Invalid("the bake made no base colour texture".into()))?;
    let normals = if layer.mesh.normals.is_empty() {
        Vec::new()
    } else {
        std::mem::take(&mut asset.mesh.normals)
    };
    let mesh = TriangleMesh {
        positions,
        normals,
        triangles,
    };
    let uv = std::mem::take(&mut asset.mesh.uv[0]);
    let layer = Layer {
        isodensity: layer.isodensity,
        translucency: layer.translucency,
        alpha: layer.alpha,
        mesh,
        cells: layer.cells.clone(),
    };
    let looks = LayerLooks {
        uv,
        base_color,
        report: baked.report,
    };
    Ok((layer, looks))
}

/// The triangles of an atlas in the order of the level it was made from: entry `t` is the
/// atlas triangle whose corners copy level triangle `t`'s corners (`level_vertex` maps an
/// atlas vertex to the level vertex it copies), in `t`'s corner order. Where the atlas keeps
/// the level's order (checked first, O(T)) that is the atlas's own list; otherwise the
/// triangles are matched by their corners (O(T) expected, hashing). Fails when a level
/// triangle has no copy left in the atlas or the counts differ.
pub fn in_level_order(
    level: &[[u32; 3]],
    atlas: &[[u32; 3]],
    level_vertex: &[u32],
) -> Result<Vec<[u32; 3]>, LayersError> {
    let corners = |t: &[u32; 3]| t.map(|v| level_vertex.get(v as usize).copied());
    let lost = |what: String| LayersError::Invalid(format!("the atlas {what}"));
    if atlas.len() != level.len() {
        return Err(lost(format!(
            "has {} triangles for the layer's {}",
            atlas.len(),
            level.len()
        )));
    }
    let same = |(a, l): (&[u32; 3], &[u32; 3])| corners(a) == l.map(Some);
    if atlas.iter().zip(level).all(same) {
        return Ok(atlas.to_vec());
    }
    // By corners, each key rotated to start at its smallest corner (the winding kept).
    let mut by_key: HashMap<[u32; 3], Vec<u32>> = HashMap::with_capacity(atlas.len());
    for (i, a) in atlas.iter().enumerate() {
        let c = corners(a);
        let Some(c) = c[0].zip(c[1]).zip(c[2]).map(|((x, y), z)| [x, y, z]) else {
            return Err(lost(format!(
                "triangle {i} names a vertex it does not have"
            )));
        };
        by_key.entry(rotated(c).0).or_default().push(i as u32);
    }
    let mut out = Vec::with_capacity(level.len());
    for (t, l) in level.iter().enumerate() {
        let (key, turn) = rotated(*l);
        let Some(a) = by_key.get_mut(&key).and_then(|v| v.pop()) else {
            return Err(lost(format!("lost triangle {t} of the layer")));
        };
        let a = atlas[a as usize];
        let at = rotated(a.map(|v| level_vertex[v as usize])).1;
        // Corner k of the level triangle is corner k - turn of the key, which is corner
        // k - turn + at of the atlas triangle.
        out.push(std::array::from_fn(|k| a[(k + at + 3 - turn) % 3]));
    }
    Ok(out)
}

/// `t` rotated to start at its smallest corner, and by how many places it was turned
/// (corner `k` of the result is corner `(k + turn) % 3` of `t`).
fn rotated(t: [u32; 3]) -> ([u32; 3], usize) {
    let turn = (0..3).min_by_key(|&k| t[k]).unwrap_or(0);
    (std::array::from_fn(|k| t[(k + turn) % 3]), turn)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A level of three triangles on five vertices, and an atlas that copies vertex 1 twice
    /// (a seam) and lists the triangles in another order with their corners turned.
    #[test]
    fn shuffled_atlas_triangles_come_back_in_the_level_order() {
        let level = [[0, 1, 2], [1, 3, 2], [2, 3, 4]];
        // Atlas vertices 0..6 copy level vertices 0, 1, 2, 3, 4, 1.
        let level_vertex = [0, 1, 2, 3, 4, 1];
        let atlas = [[3, 4, 2], [2, 5, 3], [1, 2, 0]];
        let out = in_level_order(&level, &atlas, &level_vertex).unwrap();
        assert_eq!(out, vec![[0, 1, 2], [5, 3, 2], [2, 3, 4]]);
        for (o, l) in out.iter().zip(&level) {
            assert_eq!(o.map(|v| level_vertex[v as usize]), *l);
        }
        // In order already: the atlas's own list.
        let kept = [[0, 1, 2], [5, 3, 2], [2, 3, 4]];
        assert_eq!(in_level_order(&level, &kept, &level_vertex).unwrap(), kept);
    }

    #[test]
    fn a_lost_or_reversed_triangle_is_an_error() {
        let level = [[0, 1, 2], [1, 3, 2]];
        let level_vertex = [0, 1, 2, 3];
        let reversed = [[0, 2, 1], [1, 3, 2]];
        let e = in_level_order(&level, &reversed, &level_vertex).unwrap_err();
        assert!(e.to_string().contains("lost triangle 0"), "{e}");
        let short = [[0, 1, 2]];
        let e = in_level_order(&level, &short, &level_vertex).unwrap_err();
        assert!(
            e.to_string().contains("1 triangles for the layer's 2"),
            "{e}"
        );
    }
}
