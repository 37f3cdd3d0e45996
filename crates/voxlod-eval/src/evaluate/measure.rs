//! The measuring: the input's figures once, then for each kept level its two-sided surface
//! distance to the input ([`mesh_distance`]: Hausdorff, mean and RMS over area-uniform samples
//! of both surfaces, as fractions of the input's diagonal too), its topology, and when asked its
//! silhouette difference from the input ([`super::images`]).
//!
//! Only triangles are measured: the dangling edges and isolated points that clustering leaves
//! are counted but have no area to sample, and the vertices only they use are dropped first.
//!
//! Cost per level: two BVH builds and `2 × samples` closest-point queries, plus one render per
//! view when silhouettes are measured.

use std::time::Instant;

use voxlod::core::{mesh_topology, TriangleMesh};
use voxlod::metrics::{mesh_distance, welded_mesh_report, DistanceOptions, MetricsError};

use voxlod::render::RenderError;
use voxlod_asset::Asset;

use super::error::EvaluateError;
use super::images::SilhouetteReference;
use super::results::{CurvePoint, InputSummary, LevelAppearance};
use super::trial::Trial;
use crate::appearance::AppearanceReference;
use crate::methods::Method;

/// The input's figures, after welding coincident vertices. Fails on a mesh that cannot be
/// measured: broken indices or coordinates, or no area.
pub(super) fn summarise_input(mesh: &TriangleMesh) -> Result<InputSummary, EvaluateError> {
    let health = welded_mesh_report(mesh)?;
    if health.area <= 0.0 {
        return Err(EvaluateError::Input(MetricsError::NoArea {
            triangles: mesh.triangles.len(),
        }));
    }
    Ok(InputSummary {
        vertices: mesh.positions.len(),
        triangles: mesh.triangles.len(),
        area: health.area,
        diagonal: health.diagonal,
        components: health.topology.components,
        boundary_loops: health.topology.boundary_loops,
        genus: health.topology.genus,
        closed_manifold: health.closed_manifold,
    })
}

/// What every level is measured against.
pub(super) struct Measurer<'a> {
    /// The input mesh.
    pub mesh: &'a TriangleMesh,
    /// Its figures (the diagonal is the unit of every fraction).
    pub input: &'a InputSummary,
    /// Its silhouettes, when images are measured.
    pub silhouettes: Option<&'a SilhouetteReference>,
    /// Samples per surface.
    pub distance: &'a DistanceOptions,
    /// The input asset and its renders, when it has looks.
    pub looks: Option<(&'a Asset, &'a AppearanceReference)>,
}

impl Measurer<'_> {
    /// Distances, silhouettes and topology of `trial`'s level, kept for `budget`.
    pub fn measure(
        &self,
        method: Method,
        trial: &Trial,
        budget: usize,
    ) -> Result<CurvePoint, EvaluateError> {
        let start = Instant::now();
        // Vertices that only dangling edges or points use do not belong to the surface.
        let mut surface = trial.level.mesh.clone();
        surface.remove_unreferenced_vertices();
        let distance = mesh_distance(self.mesh, &surface, self.distance).map_err(|source| {
            EvaluateError::Distance {
                method,
                parameter: method.parameter_name(),
                value: trial.parameter,
                source,
            }
        })?;
        let distance_seconds = start.elapsed().as_secs_f64();
        let start = Instant::now();
        let image_difference = match self.silhouettes {
            Some(reference) => Some(reference.difference(&trial.level).map_err(|source| {
                EvaluateError::Render {
                    method,
                    parameter: method.parameter_name(),
                    value: trial.parameter,
                    source,
                }
            })?),
            None => None,
        };
        let image_seconds = start.elapsed().as_secs_f64();
        let appearance = match self.looks {
            Some((asset, reference)) => {
                let render_error = |source| EvaluateError::Render {
                    method,
                    parameter: method.parameter_name(),
                    value: trial.parameter,
                    source,
                };
                Some(level_appearance(asset, reference, &surface).map_err(render_error)?)
            }
            None => None,
        };
        let topology = mesh_topology(&surface);
        let fraction = |x: f64| x / self.input.diagonal;
        Ok(CurvePoint {
            budget,
            parameter: trial.parameter,
            triangles: trial.triangles(),
            vertices: trial.level.mesh.positions.len(),
            dangling_edges: trial.level.lines.len(),
            isolated_points: trial.level.points.len(),
            hausdorff: distance.hausdorff,
            mean: distance.mean,
            rms: distance.rms,
            hausdorff_fraction: fraction(distance.hausdorff),
            mean_fraction: fraction(distance.mean),
            rms_fraction: fraction(distance.rms),
            input_to_level_fraction: fraction(distance.first_to_second.max),
            level_to_input_fraction: fraction(distance.second_to_first.max),
            components: topology.components,
            boundary_loops: topology.boundary_loops,
            non_manifold_edges: topology.non_manifold_edges,
            genus: topology.genus,
            closed_manifold: topology.is_closed_manifold() && topology.is_consistently_oriented(),
            image_difference,
            simplify_seconds: trial.seconds,
            distance_seconds,
            image_seconds,
            appearance,
            level: trial.level.clone(),
        })
    }
}

/// The level with looks from the nearest points of `asset`, measured against its renders.
fn level_appearance(
    asset: &Asset,
    reference: &AppearanceReference,
    level: &TriangleMesh,
) -> Result<LevelAppearance, RenderError> {
    let start = Instant::now();
    let transferred = voxlod_asset::transfer(asset, level).map_err(|e| match e {
        voxlod_asset::AssetError::Core(c) => RenderError::Core(c),
        other => RenderError::Invalid(format!("taking looks onto the level: {other}")),
    })?;
    let report = reference.compare(&transferred.asset)?;
    Ok(LevelAppearance {
        psnr: report.psnr,
        ssim: report.ssim,
        seconds: start.elapsed().as_secs_f64(),
    })
}
