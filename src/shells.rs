//! Multi-layer translucent shells in one call (paper §3): the source filtered into one volume,
//! the fewest layers whose piecewise constant profile is within the error bound of the
//! filter's density profile (equations 4–6), each layer an isosurface of the volume, all
//! triangles in the eight back-to-front orders. Also what is made of them: a layered `.glb`,
//! a chain of levels in one `.glb`, the triangles in one view's order, a preview picture. Cost: the filtering
//! (O(N³) samples), extraction (O(N³)) and ordering (O(T log T)).

use std::time::Instant;

use voxlod_asset::Asset;
use voxlod_core::glam::DVec3;
use voxlod_core::PolyMesh;
use voxlod_layers::{
    bake_layers, filter_solid, glb_bytes, layer_volume, layered_chain_glb, plan_layers,
    render_layered, to_poly_mesh, BakedLayers, GlbOptions, LayerPlan, Layered, LayeredLevel,
    LayersOptions, LooksOptions, Octant,
};
use voxlod_render::{Camera, Image, RenderOptions};

use crate::error::Error;
use crate::picture::{view_direction, SURFACE_COLOR};
use voxlod_pyramid::progress::{run_to_end, ProgressFn, Tracker};
use voxlod_pyramid::{InvalidOption, PyramidError, Source};

/// Layered shells and what to know about them.
#[derive(Clone, Debug)]
pub struct Layers {
    /// The plan, the layers' meshes, the eight orders, the timings.
    pub layered: Layered,
    /// A threshold at or below every sample.
    pub warnings: Vec<String>,
    /// Wall time of the whole call.
    pub seconds: f64,
}

/// The layer plan of `options` (equations 4–6), refusing options out of range: a bound that is
/// not positive or needs too many layers, a resolution below 2, a radius that is not a
/// positive number of voxels, no quadrature line. Cheap; call it to refuse bad options before
/// reading any input.
pub fn check_layers_options(options: &LayersOptions) -> Result<LayerPlan, Error> {
    let plan = plan_layers(&options.plan)
        .map_err(|e| InvalidOption::new("error", options.plan.error, e.to_string()))?;
    if options.resolution < 2 {
        let problem = "must be at least 2";
        return Err(InvalidOption::new("resolution", options.resolution, problem).into());
    }
    let r = options.radius_voxels;
    if !(r.is_finite() && r > 0.0) {
        let problem = "the filter radius must be a positive number of voxels";
        return Err(InvalidOption::new("radius_voxels", r, problem).into());
    }
    if options.lines_per_radius == 0 {
        return Err(InvalidOption::new("lines_per_radius", 0, "must be at least 1").into());
    }
    Ok(plan)
}

/// Layered shells of `source`, a solid (a mesh, a thresholded scan placed as [`crate::lod()`]
/// places its surfaces, an implicit solid), with orders for view octants in its world.
///
/// ```
/// # fn main() -> Result<(), voxlod::Error> {
/// use voxlod::sampling::{CsgSolid, Shape};
/// use voxlod::core::glam::DVec3;
/// let ball = CsgSolid::new(Shape::sphere(DVec3::ZERO, 1.0))?;
/// let options = voxlod::LayersOptions { resolution: 16, ..Default::default() };
/// let shells = voxlod::layers(&voxlod::Source::Solid(&ball), &options)?;
/// // ε = 0.025 with the hyper-cone: five layers, innermost opaque, the others translucent.
/// assert_eq!(shells.layered.mesh.layers.len(), 5);
/// assert_eq!(shells.layered.orders.len(), 8);
/// # Ok(())
/// # }
/// ```
pub fn layers(source: &Source, options: &LayersOptions) -> Result<Layers, Error> {
    layers_with(source, options, &run_to_end)
}

/// [`layers`], reporting progress after the filtering and after the extraction and ordering,
/// and stopping with [`Error::Cancelled`] when asked.
pub fn layers_with(
    source: &Source,
    options: &LayersOptions,
    progress: &ProgressFn,
) -> Result<Layers, Error> {
    let start = Instant::now();
    check_layers_options(options)?;
    let prepared = source.prepare()?;
    let solid = prepared.solid().ok_or(PyramidError::NeedsSolid)?;
    let mut tracker = Tracker::start(progress, 2)?;
    let (volume, density) = filter_solid(solid, options)?;
    let sample_seconds = start.elapsed().as_secs_f64();
    tracker.step(0, "filtered")?;
    let mut layered = layer_volume(&volume, &options.plan, &options.extract)?;
    layered.density = Some(density);
    layered.timings.sample_seconds = sample_seconds;
    tracker.step(0, "extracted")?;
    Ok(Layers {
        layered,
        warnings: prepared.warnings().to_vec(),
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// Layered shells at each of `resolutions` (finest first, strictly decreasing), each filtered
/// from the source with `options`' radius in voxels of its own grid: the levels of a layered
/// `MSFT_lod` chain (`voxlod_layers::layered_chain_bytes`; [`layers_radius`] gives each level's
/// radius). The source is prepared once. Cost: the sum of the levels', the finest dominating.
pub fn layers_levels(
    source: &Source,
    options: &LayersOptions,
    resolutions: &[usize],
) -> Result<Vec<Layers>, Error> {
    check_layers_levels(options, resolutions)?;
    let prepared = source.prepare()?;
    let solid = prepared.solid().ok_or(PyramidError::NeedsSolid)?;
    let mut out = Vec::with_capacity(resolutions.len());
    for &r in resolutions {
        let start = Instant::now();
        let level_options = LayersOptions {
            resolution: r,
            ..*options
        };
        let (volume, density) = filter_solid(solid, &level_options)?;
        let sample_seconds = start.elapsed().as_secs_f64();
        let mut layered = layer_volume(&volume, &options.plan, &options.extract)?;
        layered.density = Some(density);
        layered.timings.sample_seconds = sample_seconds;
        out.push(Layers {
            layered,
            warnings: prepared.warnings().to_vec(),
            seconds: start.elapsed().as_secs_f64(),
        });
    }
    Ok(out)
}

/// [`check_layers_options`] for the levels of [`layers_levels`]: also refuses resolutions that
/// do not decrease strictly from the finest. Cheap; call it before reading any input.
pub fn check_layers_levels(options: &LayersOptions, resolutions: &[usize]) -> Result<(), Error> {
    if resolutions.is_empty() || resolutions.windows(2).any(|w| w[1] >= w[0]) {
        let list = format!("{resolutions:?}");
        let problem = "the levels' resolutions must decrease strictly from the finest";
        return Err(InvalidOption::new("resolutions", list, problem).into());
    }
    for &resolution in resolutions {
        check_layers_options(&LayersOptions {
            resolution,
            ..*options
        })?;
    }
    Ok(())
}

/// Layered shells at several resolutions and the bytes of their `MSFT_lod` chain.
#[derive(Clone, Debug)]
pub struct LayersChain {
    /// One per resolution, finest first.
    pub levels: Vec<Layers>,
    /// Each level's filter support radius in the input's units ([`layers_radius`]).
    pub radii: Vec<f64>,
    /// Each level's `MSFT_screencoverage`: the coverage down to which it is drawn.
    pub screen_coverage: Vec<f64>,
    /// The `.glb` file.
    pub bytes: Vec<u8>,
    /// Per level, its layers with the asset's looks baked, where looks were given.
    pub baked: Vec<Option<BakedLayers>>,
}

/// The layered shells of [`layers_levels`] as one binary glTF `MSFT_lod` chain
/// (`voxlod_layers::glb_chain`): a mesh per level with a primitive per layer and the level's
/// eight orders, switched where each level's filter radius spans at most
/// [`voxlod_layers::RADIUS_LIMIT_PIXELS`] on screen. With `looks`, every level's layers take
/// the asset's base colour (`voxlod_layers::bake_layers`, one bake per layer). Cost: the
/// levels', the bakes', then linear in their size.
pub fn layers_chain(
    source: &Source,
    options: &LayersOptions,
    resolutions: &[usize],
    looks: Option<(&Asset, &LooksOptions)>,
) -> Result<LayersChain, Error> {
    let levels = layers_levels(source, options, resolutions)?;
    let radii: Vec<f64> = levels
        .iter()
        .map(|l| layers_radius(&l.layered, options.radius_voxels))
        .collect();
    let baked: Vec<Option<BakedLayers>> = match looks {
        Some((asset, o)) => (levels.iter())
            .map(|l| bake_layers(asset, &l.layered.mesh, o).map(Some))
            .collect::<Result<_, _>>()?,
        None => vec![None; levels.len()],
    };
    let chain: Vec<LayeredLevel> = (levels.iter().zip(&radii).zip(&baked))
        .map(|((l, &radius), b)| LayeredLevel {
            mesh: b.as_ref().map_or(&l.layered.mesh, |b| &b.mesh),
            orders: &l.layered.orders,
            radius,
            looks: b.as_ref().map(|b| &b.looks[..]),
        })
        .collect();
    let (bytes, screen_coverage) = layered_chain_glb(&chain)?;
    Ok(LayersChain {
        levels,
        radii,
        screen_coverage,
        bytes,
        baked,
    })
}

/// The bytes of a layered `.glb` of one level: a mesh per layer (innermost first) with its
/// blended material, the eight orders as index accessors, the volume grid (and placement) and
/// the filter radius of `radius_voxels` voxels in the scene's extras.
pub fn layered_glb(layered: &Layered, radius_voxels: f64) -> Result<Vec<u8>, Error> {
    let options = GlbOptions {
        radius: Some(layers_radius(layered, radius_voxels)),
        ..Default::default()
    };
    Ok(glb_bytes(&layered.mesh, &layered.orders, &options)?)
}

/// The filter's support radius of layered shells in the input's units: `radius_voxels` voxels
/// of their grid (its largest spacing).
pub fn layers_radius(layered: &Layered, radius_voxels: f64) -> f64 {
    radius_voxels
        * layered
            .mesh
            .grid
            .spacing
            .iter()
            .copied()
            .fold(0.0, f64::max)
}

/// The octant of a view direction, naming the option `view` when it has none.
fn octant(view: DVec3) -> Result<Octant, Error> {
    Ok(Octant::of(view_direction(view)?)?)
}

/// All layers in one mesh with per-vertex `opacity` and `layer`, triangles back to front for
/// views along `view` (its octant's order): what a PLY or VTK file of layers holds.
pub fn layered_poly_mesh(layered: &Layered, view: DVec3) -> Result<PolyMesh, Error> {
    let order = &layered.orders[octant(view)?.index()];
    Ok(to_poly_mesh(&layered.mesh, Some(order))?)
}

/// The layered shells drawn along `view` at `width` × `height` pixels, one sample per pixel,
/// blended in the stored order of the view's octant.
pub fn layered_preview(
    layered: &Layered,
    view: DVec3,
    width: u32,
    height: u32,
) -> Result<Image, Error> {
    let cat = layered.mesh.concatenated();
    let octant = octant(view)?;
    let camera = Camera::fit(
        view_direction(view)?,
        &cat.mesh.bounds(),
        width,
        height,
        None,
    )?;
    let alphas: Vec<f32> = layered.mesh.layers.iter().map(|l| l.alpha).collect();
    Ok(render_layered(
        &cat.mesh,
        &cat.triangle_layer,
        &alphas,
        &layered.orders[octant.index()],
        SURFACE_COLOR,
        &camera,
        &RenderOptions::default(),
    )?)
}
