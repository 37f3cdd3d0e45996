//! Multi-layer translucent shells (He, Hong, Kaufman, Varshney, Wang 1995, §3): object-space
//! antialiasing by several isosurfaces of one filtered volume, each more translucent than the one
//! inside it, composited back to front.
//!
//! - [`plan`]: how many layers and which isodensities, optimally for an error bound
//!   (equations 4–6).
//! - [`extract`]: every layer from one volume, in one pass over it, with each triangle's cell.
//! - [`order`]: back to front by slice-by-slice traversal of the cells; the eight orthographic
//!   orders; perspective orders split at the eye's cell. [`scene`]: several objects, by their
//!   buffers' boxes, interleaved exactly where the buffers overlap. [`verify`]: checking an order.
//! - [`glb`]: binary glTF with the eight orders stored; [`export`]: PLY and VTK with per-vertex
//!   `opacity` and `layer`.
//! - [`pipeline`]: solid → volume → plan → layers → orders in one call.
//! - [`preview`]: drawing the layered shells in a stored order.
//! - [`bolt()`]: the bolt of Figure 7, a CSG part.
//!
//! The paper's antialiasing claim, measured, is in `voxlod-eval` (`antialias`).

mod bolt;
pub mod error;
pub mod export;
pub mod extract;
pub mod geometry;
pub mod glb;
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
pub use glb::{glb_bytes, parse_glb, read_glb, write_glb, GlbOptions, GlbScene};
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
