//! Evaluation of every simplifier of the project on one mesh: for each method and each triangle
//! budget, the level closest to the budget, how far its surface lies from the input, and what it
//! did to the topology. The result is the error-against-triangles curve of each method, which
//! [`plot`] draws and [`report`] writes up.
//!
//! The pieces, one file each:
//!
//! - the methods ([`crate::methods`]): each behind the [`Simplifier`](crate::methods::Simplifier)
//!   trait, controlled by a parameter, not by a triangle count (the voxel pipeline by its
//!   resolution, [`voxlod::lod`]; the clustering baselines by their cells across the longest
//!   side; simplification envelopes by ε);
//! - the budget search (`search.rs`): for each budget, the parameter whose output is nearest
//!   it, searched in log–log space until a trial lands within [`EvaluateOptions::tolerance`] of
//!   it or [`EvaluateOptions::max_trials`] runs were spent; typically one to three runs per
//!   budget;
//! - the measuring (`measure.rs`): the two-sided surface distance of each kept level to the
//!   input ([`voxlod::metrics::mesh_distance`]: Hausdorff, mean and RMS over area-uniform
//!   samples of both surfaces), given absolutely and as a fraction of the **input's**
//!   bounding-box diagonal (the same unit for every level and method, unlike `voxlod compare`,
//!   whose unit is the box of both meshes), its topology, and when [`EvaluateOptions::images`]
//!   asks for it the share of differing silhouette pixels over a set of views ([`images`]);
//! - the scene proxy (`proxy.rs`, [`PROXY`]): on an asset with looks, [`voxlod::proxy`]'s
//!   level at each budget, measured alike and drawn with its own baked textures;
//! - draw calls (`draw_calls.rs`, [`draw_calls`]): of the input as given and of every level;
//! - [`plot`] and [`report`]: the chart and the Markdown write-up.
//!
//! Simplification envelopes need a consistently oriented manifold; an input that is not one is
//! cut into one first ([`voxlod::envelope::repair_for_envelope`]), and [`Curve::notes`] says
//! what that changed. An input that cannot be made one is listed in [`Evaluation::omitted`] and
//! the other methods go on.
//!
//! Cost: the voxel trials dominate (a filtered density at the trial's resolution, then marching
//! cubes; about 0.2 s at resolution 64 on the bunny), then the envelope trials; clustering
//! trials take milliseconds. Then one distance measurement per kept level (two BVH builds,
//! `2 × samples` queries). The measured levels are kept in memory for the caller to write.
//!
//! # Example
//!
//! Two methods on a small torus, one budget:
//!
//! ```
//! use voxlod::metrics::DistanceOptions;
//! use voxlod_eval::evaluate::{evaluate, Budgets, EvaluateOptions, ImageOptions, Method};
//!
//! # let mesh = voxlod_testkit::shapes::torus(48, 24, 2.0, 0.7);
//! // `mesh`: a torus of 2304 triangles (or any mesh, say from `voxlod::io::read_mesh`).
//! let options = EvaluateOptions {
//!     methods: vec!["voxel-hypercone".parse()?, "rossignac-borrel".parse()?],
//!     budgets: Budgets::Explicit(vec![400]),
//!     distance: DistanceOptions::for_samples(2_000),
//!     images: ImageOptions::off(),
//!     ..EvaluateOptions::quick()
//! };
//! let evaluation = evaluate(&mesh, &options, |_, _| {})?;
//! for curve in &evaluation.curves {
//!     let point = &curve.points[0];
//!     // Within the quick options' 20 % of the budget, and close to the input.
//!     assert!(point.triangles.abs_diff(400) <= 80, "{}: {}", curve.method, point.triangles);
//!     assert!(point.hausdorff_fraction < 0.1);
//! }
//! // The voxel level of a torus is a closed manifold of genus 1.
//! assert_eq!(evaluation.curves[0].method, Method::ALL[0]);
//! assert_eq!(evaluation.curves[0].points[0].genus, Some(1));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod draw_calls;
mod error;
mod measure;
mod options;
mod proxy;
mod results;
mod search;
mod trial;

pub mod images;
pub mod plot;
pub mod report;

pub use crate::methods::{Method, RunFailure};
pub use draw_calls::draw_calls;
pub use error::{parameter_text, EvaluateError};
pub use images::{ImageDifference, ImageOptions, SilhouetteReference};
pub use options::{Budgets, EvaluateOptions};
pub use proxy::{method_named, PROXY};
pub use results::{Curve, CurvePoint, Evaluation, InputSummary, LevelAppearance, Omission};

use std::time::Instant;

use voxlod::core::weld::weld_vertices;
use voxlod::core::TriangleMesh;
use voxlod_asset::Asset;

use crate::appearance::{AppearanceOptions, AppearanceReference};

use crate::methods::{MethodInput, Needs};
use measure::{summarise_input, Measurer};
use proxy::proxy_curve;
use search::{method_curve, CurveJob};

/// Runs every method of `options` on `mesh` at every budget and measures each level against
/// `mesh`. `on_point` hears of each measured level as soon as it is made (for progress). The
/// scene proxy ([`PROXY`]) bakes an asset's looks and is passed over here, without an entry in
/// [`Evaluation::omitted`] ([`evaluate_asset`] runs it).
///
/// Fails on a mesh that cannot be measured (empty, no area, broken indices or coordinates), a
/// mesh the voxel methods cannot sample, or a run that fails; the error names the method and
/// parameter. A method whose needs the input cannot meet (a manifold for the envelope) is left
/// out and listed in [`Evaluation::omitted`].
pub fn evaluate(
    mesh: &TriangleMesh,
    options: &EvaluateOptions,
    on_point: impl FnMut(Method, &CurvePoint),
) -> Result<Evaluation, EvaluateError> {
    run(mesh, None, options, on_point)
}

/// [`evaluate`] on an asset's geometry welded by position (texture seams and split normals
/// part vertices that its surface shares; the simplifiers take the surface, as the proxy does),
/// each level also measured for its appearance
/// ([`CurvePoint::appearance`]): it takes its looks from the nearest points of the asset
/// ([`voxlod_asset::transfer`]), and both are rendered from the 14 views of
/// [`AppearanceOptions::default`] ([`crate::appearance`]). With [`PROXY`] among the methods,
/// the asset's proxy levels too, drawn with their own baked textures (module `proxy.rs`).
/// Cost: [`evaluate`]'s, plus the transfer and 14 renders per level, plus the proxy's.
///
/// # Errors
///
/// [`evaluate`]'s; an asset that cannot be rendered is [`EvaluateError::InputRender`]; a proxy
/// that fails other than by missing a budget is [`EvaluateError::Proxy`].
pub fn evaluate_asset(
    asset: &Asset,
    options: &EvaluateOptions,
    on_point: impl FnMut(Method, &CurvePoint),
) -> Result<Evaluation, EvaluateError> {
    let reference = AppearanceReference::new(asset, &AppearanceOptions::default())
        .map_err(EvaluateError::InputRender)?;
    let mut mesh = asset.mesh.geometry();
    weld_vertices(&mut mesh);
    run(&mesh, Some((asset, &reference)), options, on_point)
}

/// [`evaluate`], with the appearance measured against `looks` when given.
fn run(
    mesh: &TriangleMesh,
    looks: Option<(&Asset, &AppearanceReference)>,
    options: &EvaluateOptions,
    mut on_point: impl FnMut(Method, &CurvePoint),
) -> Result<Evaluation, EvaluateError> {
    let start = Instant::now();
    let input = summarise_input(mesh, looks.map_or(1, |(asset, _)| draw_calls(asset)))?;
    if options.methods.is_empty() {
        return Err(EvaluateError::NoMethods);
    }
    let budgets = options.budgets.resolve(mesh.triangles.len());
    if budgets.is_empty() {
        return Err(EvaluateError::NoBudgets {
            triangles: mesh.triangles.len(),
        });
    }
    let prepared =
        MethodInput::prepare(mesh, Needs::of(&options.methods), options.lines_per_radius)
            .map_err(EvaluateError::Solid)?;
    let silhouettes = if options.images.views > 0 {
        Some(
            images::silhouette_reference(mesh, &options.images)
                .map_err(EvaluateError::InputRender)?,
        )
    } else {
        None
    };
    let measurer = Measurer {
        mesh,
        input: &input,
        silhouettes: silhouettes.as_ref(),
        distance: &options.distance,
        looks,
    };
    let job = CurveJob {
        measurer: &measurer,
        budgets: &budgets,
        options,
    };
    let mut omitted: Vec<Omission> = Vec::new();
    let mut curves = Vec::new();
    for &method in &options.methods {
        if method == PROXY {
            // A proxy bakes the input's looks: a mesh without them has none.
            if let Some((asset, _)) = looks {
                let curve = proxy_curve(asset, &job, &mut on_point)?;
                curves.push(curve);
            }
            continue;
        }
        let needs = method.simplifier().needs();
        if let Some(reason) = prepared.unmet(needs) {
            let what = method.simplifier().description();
            if !omitted.iter().any(|o| o.what == what) {
                omitted.push(Omission {
                    what: what.into(),
                    reason,
                });
            }
            continue;
        }
        let mut curve = method_curve(method, &prepared, &job, &mut on_point)?;
        if needs.manifold {
            curve.notes = prepared.manifold_notes().to_vec();
        }
        curves.push(curve);
    }
    Ok(Evaluation {
        input,
        budgets,
        samples_per_side: options.distance.samples_per_side,
        tolerance: options.tolerance,
        image_views: options.images.views.min(14),
        image_size: options.images.size,
        appearance_views: looks.map_or(0, |(_, r)| r.views()),
        curves,
        omitted,
        seconds: start.elapsed().as_secs_f64(),
    })
}
