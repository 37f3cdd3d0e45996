//! The whole job as one call: a solid filtered into a volume (paper §2), the layers planned for
//! the filter (§3, equations 4–6), cut from the volume in one pass, and put in the eight
//! back-to-front orders. Each stage is timed for reports.
//!
//! Cost: the filtering dominates (O(N³) samples, each a quadrature over the filter's support,
//! see voxlod-sampling); the rest is [`crate::extract`]'s one read of the volume and
//! [`crate::order`]'s O(T).

use std::time::Instant;

use serde::Serialize;
use voxlod_core::{Volume, WorldTransform};
use voxlod_sampling::{filtered_density, level_grid, DensityOptions, DensityReport, Solid};

use crate::extract::{extract_layers, ExtractOptions, LayeredMesh};
use crate::order::{octant_orders, CellTriangles};
use crate::plan::{plan_layers, LayerPlan, PlanOptions};
use crate::LayersError;

/// How to build layered shells from a solid.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct LayersOptions {
    /// Samples across the longest side of the object's box.
    pub resolution: usize,
    /// Filter support radius in voxels.
    pub radius_voxels: f64,
    /// Filter and error bound.
    pub plan: PlanOptions,
    /// Quadrature lines per support radius (see [`DensityOptions`]).
    pub lines_per_radius: usize,
    /// Normals, and one pass or one per layer.
    pub extract: ExtractOptions,
}

impl Default for LayersOptions {
    /// 128 samples, hyper-cone of one voxel, ε = 0.025 (five layers).
    fn default() -> Self {
        LayersOptions {
            resolution: 128,
            radius_voxels: 1.0,
            plan: PlanOptions::default(),
            lines_per_radius: DensityOptions::DEFAULT_LINES_PER_RADIUS,
            extract: ExtractOptions::default(),
        }
    }
}

impl LayersOptions {
    /// The paper's bolt (Figure 7): five layers, here of the Gaussian, at `resolution`.
    pub fn five_gaussian_layers(resolution: usize) -> Self {
        LayersOptions {
            resolution,
            plan: PlanOptions::new(voxlod_sampling::Filter::GAUSSIAN, 0.02),
            ..Default::default()
        }
    }
}

/// Seconds spent per stage.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Timings {
    /// Filtering the solid into the volume (0 when given a volume).
    pub sample_seconds: f64,
    /// Planning the layers.
    pub plan_seconds: f64,
    /// Cutting the layers from the volume.
    pub extract_seconds: f64,
    /// The eight back-to-front orders.
    pub order_seconds: f64,
}

/// Planned, extracted and ordered layers.
#[derive(Clone, Debug)]
pub struct Layered {
    /// How many layers, at which isodensities, with which alphas.
    pub plan: LayerPlan,
    /// The layers' meshes, innermost first.
    pub mesh: LayeredMesh,
    /// The eight orders by [`crate::Octant::index`], as global triangle indices into
    /// [`LayeredMesh::concatenated`].
    pub orders: Vec<Vec<u32>>,
    /// How the solid was filtered (`None` when given a volume).
    pub density: Option<DensityReport>,
    /// Seconds per stage.
    pub timings: Timings,
}

/// Filters `solid` on the grid `options` asks for (its box at `resolution` samples across,
/// padded, radius `radius_voxels`): the volume the layers are cut from. A solid made from an
/// oriented scan ([`Solid::world`]) is sampled in its axis-aligned grid space and the volume
/// placed in the scan's world (its direction and frame, its first sample where the scan's
/// transform puts it), so the layers cut from it land where `voxlod::lod` puts the scan's
/// surfaces.
pub fn filter_solid(
    solid: &dyn Solid,
    options: &LayersOptions,
) -> Result<(Volume, DensityReport), LayersError> {
    let bounds = solid.bounds();
    let voxel = bounds.longest_extent() / options.resolution.max(1) as f64;
    let radius = options.radius_voxels * voxel;
    let grid = level_grid(&bounds, options.resolution, radius)?;
    let density_options = DensityOptions {
        filter: options.plan.filter,
        radius,
        lines_per_radius: options.lines_per_radius,
    };
    let (volume, report) = filtered_density(solid, &grid, &density_options)?;
    Ok((in_world(volume, solid.world())?, report))
}

/// A volume sampled in a scan's axis-aligned grid space, placed in the scan's `world`
/// (unchanged without one; [`WorldTransform::place`]).
fn in_world(volume: Volume, world: Option<WorldTransform>) -> Result<Volume, LayersError> {
    Ok(match world {
        Some(world) => world.place(volume)?,
        None => volume,
    })
}

/// Filters `solid` and builds its layers (see the module documentation).
pub fn layer_solid(solid: &dyn Solid, options: &LayersOptions) -> Result<Layered, LayersError> {
    let start = Instant::now();
    let (volume, report) = filter_solid(solid, options)?;
    let sample_seconds = start.elapsed().as_secs_f64();
    let mut out = layer_volume(&volume, &options.plan, &options.extract)?;
    out.density = Some(report);
    out.timings.sample_seconds = sample_seconds;
    Ok(out)
}

/// Builds the layers of an already filtered volume (density 1 inside, 0 outside).
pub fn layer_volume(
    volume: &Volume,
    plan: &PlanOptions,
    extract: &ExtractOptions,
) -> Result<Layered, LayersError> {
    let start = Instant::now();
    let plan = plan_layers(plan)?;
    let plan_seconds = start.elapsed().as_secs_f64();
    if volume.range().is_none() {
        return Err(LayersError::EmptyVolume);
    }
    let start = Instant::now();
    let mesh = extract_layers(volume, &plan, extract)?;
    let extract_seconds = start.elapsed().as_secs_f64();
    let start = Instant::now();
    let orders = orders_of(&mesh)?;
    let order_seconds = start.elapsed().as_secs_f64();
    Ok(Layered {
        plan,
        mesh,
        orders,
        density: None,
        timings: Timings {
            sample_seconds: 0.0,
            plan_seconds,
            extract_seconds,
            order_seconds,
        },
    })
}

/// The eight octant orders of a layered mesh, for view octants in the space of its vertices
/// (the world of a placed volume; [`octant_orders`]).
pub fn orders_of(mesh: &LayeredMesh) -> Result<Vec<Vec<u32>>, LayersError> {
    let cat = mesh.concatenated();
    octant_orders(&CellTriangles {
        grid: mesh.grid,
        placement: mesh.placement,
        positions: &cat.mesh.positions,
        triangles: &cat.mesh.triangles,
        cells: &cat.cells,
    })
}
