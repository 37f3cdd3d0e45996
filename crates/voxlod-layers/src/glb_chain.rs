//! Layered shells at several resolutions as one `MSFT_lod` chain (`voxlod layers --lod`): the
//! antialiased chain of paper §3 (the layers) over the pyramid of §2 (each level filtered from
//! the object with a wider filter), for viewers that switch levels.
//!
//! **Layout** (one buffer, as [`crate::glb`] lays out one layered mesh, once per level):
//! - node `k` draws mesh `k` = level `k`, finest first; node 0 carries
//!   `extensions.MSFT_lod.ids = [1, …, n−1]` and `extras.MSFT_screencoverage`; the scene holds
//!   node 0 only;
//! - mesh `k` has one primitive per layer with triangles, innermost first, each with its own
//!   blended material (alpha as in a single layered file; with looks, the layer's baked base
//!   colour texture and texture coordinates, as [`crate::glb_looks`] writes them) and extras
//!   `{"layer", "isodensity", "translucency", "alpha"}`;
//! - level `k`'s eight orders are `SCALAR` `UNSIGNED_INT` accessors named `level k order±x±y±z`,
//!   triangle lists over the level's layers' vertices concatenated in primitive order (so a
//!   vertex of layer `i` has index `its index in layer i + vertices of layers 0..i` — the
//!   positions view of the level);
//! - mesh and node extras: `{"voxlod": {"level", "radius", "grid", "orders", "triangles"}}`:
//!   the filter's support radius in the input's units, the volume grid (with its placement, as
//!   in [`crate::glb`]), the eight order
//!   accessors by octant index;
//! - scene extras: `{"voxlod": {"kind": "layered lod chain", "grid", "radius" (of the finest
//!   level), "orders", "in_cell_direction", "screen_coverage": {…, "tolerance": 0.45,
//!   "measure": "filter radius"}}}`.
//!
//! **Switching**: the layers beat the aliased single surface only while the filter radius spans
//! at most [`RADIUS_LIMIT_PIXELS`] on screen (BENCHMARKS.md). `MSFT_screencoverage` is
//! `voxlod-gltf`'s pixel-size rule applied to the radius instead of the cell size, with that
//! tolerance: level `k` is drawn from the coverage where level `k − 1`'s radius outgrows
//! 0.45 px down to where level `k + 1`'s fits, so an engine always draws the coarsest level whose
//! radius on screen is at most 0.45 px (closer than level 0 allows, level 0; `voxlod view` then
//! draws its single surface).
//!
//! Beyond the paper: the paper shows one layered level; the chain and its switching rule are
//! ours. Cost: linear in the levels' size.

use gltf::json;
use gltf::json::validation::USize64;
use serde_json::json as value;
use voxlod_gltf::CoverageOptions;

use crate::extract::LayeredMesh;
use crate::glb::{
    encode_glb, new_root, push_level, raw, GlbOptions, GridExtras, RADIUS_LIMIT_PIXELS,
};
use crate::looks::LayerLooks;
use crate::order::ORDER_NAMES;
use crate::LayersError;

/// One level of a layered chain.
#[derive(Clone, Copy, Debug)]
pub struct LayeredLevel<'a> {
    /// The layers' meshes.
    pub mesh: &'a LayeredMesh,
    /// The eight orders by [`crate::Octant::index`] (as [`crate::Layered::orders`]).
    pub orders: &'a [Vec<u32>],
    /// The filter's support radius in the input's units.
    pub radius: f64,
    /// Per layer, its baked looks ([`crate::bake_layers`] of this level, whose mesh `mesh`
    /// then is); `None`: the layers carry one colour.
    pub looks: Option<&'a [Option<LayerLooks>]>,
}

/// The viewing assumptions of a layered chain's coverages: [`RADIUS_LIMIT_PIXELS`] on a
/// 1080-pixel viewport.
pub fn layered_coverage_options() -> CoverageOptions {
    CoverageOptions {
        tolerance: RADIUS_LIMIT_PIXELS,
        ..Default::default()
    }
}

/// The bytes of the `.glb` of a layered chain, levels finest (smallest radius) first; the
/// radii must grow strictly. `options.radius` is not used (each level has its own).
pub fn layered_chain_bytes(
    levels: &[LayeredLevel],
    options: &GlbOptions,
) -> Result<Vec<u8>, LayersError> {
    let (doc, bin) = layered_chain_document(levels, options)?;
    encode_glb(&doc, bin)
}

/// The bytes of the `.glb` of a layered chain ([`layered_chain_bytes`] with the default
/// options) and each level's `MSFT_screencoverage`, the coverage down to which it is drawn.
pub fn layered_chain_glb(levels: &[LayeredLevel]) -> Result<(Vec<u8>, Vec<f64>), LayersError> {
    let (doc, bin) = layered_chain_document(levels, &GlbOptions::default())?;
    let coverage = doc["nodes"][0]["extras"]["MSFT_screencoverage"]
        .as_array()
        .map(|c| c.iter().filter_map(|v| v.as_f64()).collect())
        .unwrap_or_default();
    Ok((encode_glb(&doc, bin)?, coverage))
}

/// The JSON value and binary chunk of a layered chain (see the module documentation).
pub fn layered_chain_document(
    levels: &[LayeredLevel],
    options: &GlbOptions,
) -> Result<(serde_json::Value, Vec<u8>), LayersError> {
    let Some(finest) = levels.first() else {
        return Err(LayersError::Invalid("a layered chain needs a level".into()));
    };
    let radii: Vec<f64> = levels.iter().map(|l| l.radius).collect();
    let (lo, hi) = bounds(levels);
    let diameter = (hi - lo).length();
    let coverages = voxlod_gltf::screen_coverages(&radii, diameter, &layered_coverage_options())
        .map_err(|e| LayersError::Invalid(e.to_string()))?;
    let mut root = new_root();
    let mut bin = Vec::new();
    for (k, level) in levels.iter().enumerate() {
        push_chain_level(&mut root, &mut bin, k, level, options)?;
    }
    root.buffers[0].byte_length = USize64(bin.len() as u64);
    if levels.len() >= 2 {
        root.extensions_used = vec!["MSFT_lod".into()];
    }
    let centre = (lo + hi) * 0.5;
    let c = layered_coverage_options();
    let scene = root.push(json::Scene {
        extensions: None,
        extras: raw(value!({"voxlod": {
            "kind": "layered lod chain",
            "grid": GridExtras::of(finest.mesh),
            "radius": finest.radius,
            "orders": ORDER_NAMES,
            "in_cell_direction": "octant diagonal",
            "screen_coverage": {
                "definition": "bounding-sphere diameter / viewport height (2 d tan(fov/2))",
                "measure": "filter radius",
                "viewport_height": c.viewport_height,
                "tolerance": c.tolerance,
                "diameter": diameter,
                "center": [centre.x, centre.y, centre.z],
            }
        }})),
        name: Some(options.name.clone()),
        nodes: vec![json::Index::new(0)],
    });
    root.scene = Some(scene);
    let mut doc = serde_json::to_value(&root)
        .map_err(|e| LayersError::Gltf(format!("cannot encode the JSON chunk: {e}")))?;
    voxlod_gltf::declare_lod(&mut doc, levels.len(), &coverages);
    Ok((doc, bin))
}

/// Level `k` as its buffer views, accessors, materials, one mesh and one node.
fn push_chain_level(
    root: &mut json::Root,
    bin: &mut Vec<u8>,
    k: usize,
    level: &LayeredLevel,
    options: &GlbOptions,
) -> Result<(), LayersError> {
    let prefix = format!("level {k} ");
    let layers = (level.mesh, level.looks);
    let parts = push_level(root, bin, layers, level.orders, options.color, &prefix)?;
    if parts.primitives.is_empty() {
        return Err(LayersError::Invalid(format!(
            "level {k} of the chain has no triangle"
        )));
    }
    let extras = value!({"voxlod": {
        "level": k,
        "radius": level.radius,
        "grid": GridExtras::of(level.mesh),
        "orders": parts.orders.iter().map(|a| a.value()).collect::<Vec<_>>(),
        "triangles": level.mesh.triangle_count(),
    }});
    let mesh = root.push(json::Mesh {
        extensions: None,
        extras: raw(extras.clone()),
        name: Some(format!("level {k}")),
        primitives: parts.primitives.into_iter().map(|(_, p)| p).collect(),
        weights: None,
    });
    root.push(json::Node {
        mesh: Some(mesh),
        name: Some(format!("level {k}")),
        extras: raw(extras),
        ..Default::default()
    });
    Ok(())
}

/// The box of every level's vertices.
fn bounds(levels: &[LayeredLevel]) -> (glam::DVec3, glam::DVec3) {
    let mut lo = glam::DVec3::INFINITY;
    let mut hi = glam::DVec3::NEG_INFINITY;
    for l in levels {
        for layer in &l.mesh.layers {
            for p in &layer.mesh.positions {
                lo = lo.min(p.as_dvec3());
                hi = hi.max(p.as_dvec3());
            }
        }
    }
    (lo, hi)
}
