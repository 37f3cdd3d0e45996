//! The paper's antialiasing claim, measured (§3 and Figure 7: "the effect of our antialiasing
//! algorithm is demonstrated by employing five layers of meshes on a bolt … contrasted with the
//! aliased result of applying the traditional algorithm with binary surface classification").
//!
//! One filtered volume gives both the single surface (isodensity 0.5) and the layered shells.
//! Three images are drawn with one camera: the single surface at one sample per pixel, the
//! layered shells at one sample per pixel (blended in the stored order of the view's octant), and
//! the single surface at 16×16 samples per pixel as the reference. The error of each of the first
//! two is the RMS difference from the reference over the pixels near silhouettes (within
//! `silhouette_radius` of a partly covered pixel of the reference), and over the whole image.
//!
//! What decides the outcome is the filter radius seen on screen: the layers spread the edge over
//! about the support radius R outside the surface, so they help while R is up to about half a
//! pixel and blur beyond; [`ComparisonReport::radius_pixels`] reports it.
//!
//! The object of Figure 7 is `voxlod::layers::bolt`, a CSG part: a hexagonal head, a shank, and
//! thread ridges.

use glam::DVec3;
use serde::Serialize;
use voxlod::contouring::{marching_cubes, ContourOptions};
use voxlod::core::TriangleMesh;
use voxlod::layers::{
    bolt, filter_solid, layer_volume, render_layered, Layered, LayersError, LayersOptions, Octant,
};
use voxlod::render::{
    render, rms_difference, silhouette_mask, Camera, Image, MeshItem, RenderOptions, Scene,
};
use voxlod::sampling::Solid;

/// How to compare.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct CompareOptions {
    /// Image side in pixels (square images).
    pub size: u32,
    /// View direction, eye to scene.
    #[serde(skip)]
    pub view: DVec3,
    /// The filtered volume's resolution and filter, and the layers' isodensities.
    pub layers: LayersOptions,
    /// Samples per pixel side of the reference.
    pub reference_supersample: u32,
    /// Pixels within this distance of a partly covered reference pixel are "near silhouettes".
    pub silhouette_radius: u32,
    /// Surface colour (linear RGB).
    pub color: [f32; 3],
}

impl Default for CompareOptions {
    /// 128 px, five hyper-cone layers at resolution 256 (the support radius is then about a
    /// third of a pixel), reference 16×16.
    fn default() -> Self {
        CompareOptions {
            size: 128,
            view: DVec3::new(-0.55, -0.8, -0.35),
            layers: LayersOptions {
                resolution: 256,
                ..Default::default()
            },
            reference_supersample: 16,
            silhouette_radius: 1,
            color: [0.85, 0.86, 0.9],
        }
    }
}

/// The three images and their errors.
#[derive(Clone, Debug)]
pub struct Comparison {
    /// The single surface at one sample per pixel.
    pub single: Image,
    /// The layered shells at one sample per pixel.
    pub layered: Image,
    /// The single surface supersampled: the reference.
    pub reference: Image,
    /// The figures.
    pub report: ComparisonReport,
}

/// The figures of a comparison.
#[derive(Clone, Debug, Serialize)]
pub struct ComparisonReport {
    /// Image side in pixels.
    pub size: u32,
    /// Layers of the layered shells.
    pub layers: usize,
    /// Their isodensities.
    pub isodensities: Vec<f32>,
    /// The layer plan's error, `∫₀¹ |p − d| dx` of the layers' opacity against the filtered
    /// density's profile (see `voxlod::layers`).
    pub achieved_error: f64,
    /// Triangles of the single surface.
    pub single_triangles: usize,
    /// Triangles of all the layers.
    pub layered_triangles: usize,
    /// The filter's support radius in pixels at the object's centre.
    pub radius_pixels: f64,
    /// Pixels near silhouettes, where the errors below are measured.
    pub silhouette_pixels: usize,
    /// RMS difference of the single surface from the reference over the pixels near
    /// silhouettes.
    pub rms_single: f64,
    /// The same for the layered shells.
    pub rms_layered: f64,
    /// RMS difference of the single surface from the reference over the whole image.
    pub rms_single_all: f64,
    /// The same for the layered shells.
    pub rms_layered_all: f64,
    /// The view's octant, which decides the layers' drawing order.
    pub octant: &'static str,
}

impl Comparison {
    /// The three images side by side: single, layered, reference.
    pub fn montage(&self) -> Image {
        Image::side_by_side(
            &[&self.single, &self.layered, &self.reference],
            4,
            [1.0, 1.0, 1.0],
        )
    }
}

/// One filtered volume's single surface and layered shells, to draw at several sizes.
#[derive(Clone, Debug)]
pub struct Filtered {
    /// The isosurface 0.5.
    pub single: TriangleMesh,
    /// The layers and their orders.
    pub layered: Layered,
    /// The filter's support radius in the object's units.
    pub radius: f64,
}

/// Filters `solid` with `options` and cuts its single surface and layers.
pub fn filter_for_comparison(
    solid: &dyn Solid,
    options: &LayersOptions,
) -> Result<Filtered, LayersError> {
    let (volume, _) = filter_solid(solid, options)?;
    let single = marching_cubes(&volume, &ContourOptions::at(0.5))?;
    if single.triangles.is_empty() {
        return Err(LayersError::EmptyVolume);
    }
    let layered = layer_volume(&volume, &options.plan, &options.extract)?;
    Ok(Filtered {
        single,
        radius: volume.grid.spacing[0] * options.radius_voxels,
        layered,
    })
}

/// The image side at which the filter radius of `filtered` spans `radius_pixels` on screen,
/// viewed along `view` (the camera fits the layers' box, as [`compare_filtered`]'s).
pub fn size_for_radius(
    filtered: &Filtered,
    view: DVec3,
    radius_pixels: f64,
) -> Result<u32, LayersError> {
    const PROBE: u32 = 1000;
    let bounds = filtered.layered.mesh.concatenated().mesh.bounds();
    let camera = Camera::fit(view, &bounds, PROBE, PROBE, None)?;
    let at_probe = filtered.radius / camera.pixel_size_at(bounds.center());
    Ok((PROBE as f64 * radius_pixels / at_probe).round().max(8.0) as u32)
}

/// Filters `solid`, builds its single surface and layers, renders and measures (see the module
/// documentation).
pub fn compare_antialiasing(
    solid: &dyn Solid,
    options: &CompareOptions,
) -> Result<Comparison, LayersError> {
    compare_filtered(&filter_for_comparison(solid, &options.layers)?, options)
}

/// Renders and measures a filtered object (`options.layers` is not used: it was filtered).
pub fn compare_filtered(
    filtered: &Filtered,
    options: &CompareOptions,
) -> Result<Comparison, LayersError> {
    let octant = Octant::of(options.view)?;
    let Filtered {
        single,
        layered,
        radius,
    } = filtered;
    let cat = layered.mesh.concatenated();
    let bounds = cat.mesh.bounds();
    let camera = Camera::fit(options.view, &bounds, options.size, options.size, None)?;
    let base = RenderOptions::default();
    let draw_single = |supersample: u32| -> Result<Image, LayersError> {
        Ok(render(
            &Scene {
                meshes: vec![MeshItem::opaque(single, options.color)],
                ..Default::default()
            },
            &camera,
            &RenderOptions {
                supersample,
                ..base
            },
        )?)
    };
    let single_image = draw_single(1)?;
    let reference = draw_single(options.reference_supersample)?;
    let layered_image = render_layered(
        &cat.mesh,
        &cat.triangle_layer,
        &layered
            .mesh
            .layers
            .iter()
            .map(|l| l.alpha)
            .collect::<Vec<_>>(),
        &layered.orders[octant.index()],
        options.color,
        &camera,
        &base,
    )?;
    let mask = silhouette_mask(&reference, options.silhouette_radius);
    let rms = |img: &Image, m: Option<&[bool]>| rms_difference(img, &reference, m).unwrap_or(0.0);
    let report = ComparisonReport {
        size: options.size,
        layers: layered.plan.len(),
        isodensities: layered.plan.isodensities(),
        achieved_error: layered.plan.achieved_error,
        single_triangles: single.triangles.len(),
        layered_triangles: cat.mesh.triangles.len(),
        radius_pixels: radius / camera.pixel_size_at(layered.mesh.grid.bounds().center()),
        silhouette_pixels: mask.iter().filter(|&&m| m).count(),
        rms_single: rms(&single_image, Some(&mask)),
        rms_layered: rms(&layered_image, Some(&mask)),
        rms_single_all: rms(&single_image, None),
        rms_layered_all: rms(&layered_image, None),
        octant: octant.name(),
    };
    Ok(Comparison {
        single: single_image,
        layered: layered_image,
        reference,
        report,
    })
}

/// The comparison on the [`bolt`] with the default options, staged in `out` into `dir`:
/// `antialias.png` (single surface, layered shells and reference side by side),
/// `antialias-single.png`, `antialias-layered.png`, `antialias-reference.png` and
/// `antialias.json` (the figures). Returns a one-line summary. Used by `voxlod demo`, which
/// commits `out`.
pub fn demo_comparison(
    out: &mut voxlod::io::OutputSet,
    dir: &std::path::Path,
) -> Result<String, LayersError> {
    let solid = voxlod::sampling::CsgSolid::new(bolt())?;
    let c = compare_antialiasing(&solid, &CompareOptions::default())?;
    for (name, image) in [
        ("antialias.png", &c.montage()),
        ("antialias-single.png", &c.single),
        ("antialias-layered.png", &c.layered),
        ("antialias-reference.png", &c.reference),
    ] {
        out.png(&dir.join(name), &image.to_png()?)?;
    }
    let json = serde_json::to_string_pretty(&c.report)
        .map_err(|e| LayersError::Invalid(format!("cannot encode the report: {e}")))?;
    out.text(&dir.join("antialias.json"), &json)?;
    let r = &c.report;
    Ok(format!(
        "Antialiasing (paper §3, Figure 7): the bolt at {0}x{0} px, RMS near silhouettes against \
         the 16x16-sample reference: single surface {1:.4}, {2} layers {3:.4} ({4:+.0}%). \
         Images in {5}/antialias*.png.",
        r.size,
        r.rms_single,
        r.layers,
        r.rms_layered,
        100.0 * (r.rms_layered / r.rms_single - 1.0),
        dir.display()
    ))
}
