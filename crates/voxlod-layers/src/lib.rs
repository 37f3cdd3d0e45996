//! Multi-layer translucent shells (He, Hong, Kaufman, Varshney, Wang 1995, §3): object-space
//! antialiasing by several isosurfaces of one filtered volume, each more translucent than the one
//! inside it, composited back to front.
//!
//! - [`plan`]: how many layers and which isodensities, optimally for an error bound
//!   (equations 4–6).
//! - [`extract`]: every layer from one volume, in one pass over it, with each triangle's cell,
//!   placed where the volume's index-to-world transform puts it (an oblique or flipped scan's
//!   world, as `voxlod::lod` places its surfaces).
//! - [`order`]: back to front by slice-by-slice traversal of the cells; the eight orthographic
//!   orders; perspective orders split at the eye's cell. [`scene`]: several objects, by their
//!   buffers' boxes, interleaved exactly where the buffers overlap. [`verify`]: checking an order.
//! - [`glb`]: binary glTF with the eight orders stored; [`glb_chain`]: layered levels as one
//!   `MSFT_lod` chain, switched by the filter radius on screen; [`export`]: PLY and VTK with
//!   per-vertex `opacity` and `layer`.
//! - [`looks`]: an asset's base colour baked onto every layer (`voxlod-bake`; the paper's
//!   layers carry one colour), on atlases made with the slivers snapped shut (`voxlod_bake::slivers`),
//!   written by [`glb_looks`].
//! - [`pipeline`]: solid → volume → plan → layers → orders in one call.
//! - [`preview`]: drawing the layered shells in a stored order.
//! - [`bolt()`]: the bolt of Figure 7, a CSG part.
//!
//! The paper's antialiasing claim, measured, is in `voxlod-eval` (`antialias`).
//!
//! Cost: filtering the solid dominates (see `voxlod-sampling`); planning takes milliseconds,
//! extraction one read of the volume, and the eight orders O(T) plus a few pair tests per
//! occupied cell.
//!
//! # Example
//!
//! The bolt of Figure 7 at 24 samples across: the default plan (hyper-cone, ε = 0.025) gives
//! five shells, innermost opaque, and each stored order draws every triangle once with none
//! before a triangle behind it (checked along the octant's diagonal).
//!
//! ```
//! use voxlod_layers::{bolt, check_order, layer_solid, LayersOptions, Octant, View};
//! use voxlod_sampling::CsgSolid;
//!
//! let solid = CsgSolid::new(bolt())?;
//! let layered = layer_solid(&solid, &LayersOptions { resolution: 24, ..Default::default() })?;
//! assert_eq!(layered.plan.len(), 5);
//! assert_eq!(layered.mesh.layers[0].alpha, 1.0);
//! assert!(layered.mesh.layers.iter().all(|l| l.alpha > 0.0 && l.alpha <= 1.0));
//!
//! let all = layered.mesh.concatenated();
//! let octant = Octant::from_index(0);
//! let order = &layered.orders[octant.index()];
//! let mut sorted = order.clone();
//! sorted.sort_unstable();
//! assert!(sorted.iter().copied().eq(0..all.mesh.triangles.len() as u32));
//! let view = View::Orthographic { direction: octant.diagonal() };
//! let check = check_order(&all.mesh.positions, &all.mesh.triangles, order, &view)?;
//! assert!(check.overlapping_pairs > 0);
//! assert_eq!(check.violations, 0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#![warn(missing_docs)]

mod bolt;
pub mod error;
pub mod export;
pub mod extract;
pub mod geometry;
pub mod glb;
pub mod glb_chain;
pub mod glb_looks;
mod glb_parts;
pub mod looks;
pub mod order;
pub mod pipeline;
pub mod plan;
pub mod preview;
pub mod scene;
pub mod verify;

pub use bolt::bolt;
pub use error::LayersError;
pub use export::{to_poly_mesh, write_layered_mesh};
pub use extract::{extract_layers, Concatenated, ExtractOptions, Layer, LayeredMesh};
pub use glb::{
    baked_glb_bytes, glb_bytes, write_baked_glb, write_glb, GlbOptions, RADIUS_LIMIT_PIXELS,
};
pub use glb_chain::{
    layered_chain_bytes, layered_chain_document, layered_chain_glb, layered_coverage_options,
    LayeredLevel,
};
pub use looks::{
    bake_layers, has_base_colour, in_level_order, BakedLayers, LayerLooks, LooksOptions,
    DEFAULT_TEXTURE,
};
pub use order::{
    index_cells, octant_order, octant_orders, recover_cells, view_order, CellIndex, CellTriangles,
    Octant, View, ORDER_NAMES,
};
pub use pipeline::{
    filter_solid, layer_solid, layer_volume, orders_of, Layered, LayersOptions, Timings,
};
pub use plan::{
    blend_alphas, optimal_plan, plan_layers, Blending, LayerPlan, PlanOptions, PlannedLayer,
    MAX_LAYERS,
};
pub use preview::render_layered;
pub use scene::{scene_order, SceneOrder};
pub use verify::{check_order, OrderCheck};
