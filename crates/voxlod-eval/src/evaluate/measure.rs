//! The measuring: the input's figures once, then for each kept level its two-sided surface
//! distance to the input ([`mesh_distance`]: Hausdorff, mean and RMS over area-uniform samples
//! of both surfaces, as fractions of the input's diagonal too), its topology, and when asked its
//! silhouette difference from the input ([`super::images`]).
//!
//! Only triangles are measured: the dangling edges and isolated points that clustering leaves
//! are counted but have no area to sample, and the vertices only they use are dropped first.
//!
//! The appearance of a level beside an input asset: a level without looks of its own takes
//! them from the nearest input points ([`voxlod_asset::transfer`]); a level with its own (the
//! proxy's baked textures, [`Measurer::measure_asset`]) is drawn as it is.
//!
//! Cost per level: two BVH builds and `2 × samples` closest-point queries, plus one render per
//! view when silhouettes are measured.

use std::time::Instant;

use voxlod::core::{mesh_topology, TriangleMesh};
use voxlod::metrics::{mesh_distance, welded_mesh_report, DistanceOptions, MetricsError};

use voxlod::render::RenderError;
use voxlod_asset::Asset;

use super::draw_calls::draw_calls;
use super::error::EvaluateError;
use super::images::SilhouetteReference;
use super::results::{CurvePoint, InputSummary, LevelAppearance};
use super::trial::Trial;
use crate::appearance::AppearanceReference;
use crate::methods::Method;

/// The input's figures, after welding coincident vertices. Fails on a mesh that cannot be
/// measured: broken indices or coordinates, or no area.
/// `draw_calls` is the input's as given ([`super::draw_calls`]).
pub(super) fn summarise_input(
    mesh: &TriangleMesh,
    draw_calls: usize,
) -> Result<InputSummary, EvaluateError> {
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
        draw_calls,
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
    /// Distances, silhouettes and topology of `trial`'s level, kept for `budget`; beside an
    /// input asset, its appearance with looks taken from the nearest input points.
    pub fn measure(
        &self,
        method: Method,
        trial: &Trial,
        budget: usize,
    ) -> Result<CurvePoint, EvaluateError> {
        self.measure_with(method, trial, budget, None)
    }

    /// [`Measurer::measure`] of a level that has looks of its own, `level` (whose geometry is
    /// `trial`'s): its appearance is measured as `level` is drawn, and its draw calls are
    /// `level`'s ([`super::draw_calls`]).
    pub fn measure_asset(
        &self,
        method: Method,
        trial: &Trial,
        budget: usize,
        level: &Asset,
    ) -> Result<CurvePoint, EvaluateError> {
        self.measure_with(method, trial, budget, Some(level))
    }

    fn measure_with(
        &self,
        method: Method,
        trial: &Trial,
        budget: usize,
        own_looks: Option<&Asset>,
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
        let render_error = |source| EvaluateError::Render {
            method,
            parameter: method.parameter_name(),
            value: trial.parameter,
            source,
        };
        let start = Instant::now();
        let image_difference = match self.silhouettes {
            Some(reference) => Some(reference.difference(&trial.level).map_err(render_error)?),
            None => None,
        };
        let image_seconds = start.elapsed().as_secs_f64();
        let appearance = match self.looks {
            Some((asset, reference)) => {
                let looks = match own_looks {
                    Some(level) => Looks::Own(level),
                    None => Looks::Taken(asset, &surface),
                };
                Some(level_appearance(reference, looks).map_err(render_error)?)
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
            draw_calls: own_looks.map_or(1, draw_calls),
            level: trial.level.clone(),
        })
    }
}

/// Where a level's looks come from for its appearance.
enum Looks<'a> {
    /// From the nearest points of the input asset, onto the level's geometry.
    Taken(&'a Asset, &'a TriangleMesh),
    /// The level's own.
    Own(&'a Asset),
}

/// The level with its looks, measured against the input's renders.
fn level_appearance(
    reference: &AppearanceReference,
    looks: Looks,
) -> Result<LevelAppearance, RenderError> {
    let start = Instant::now();
    let report = match looks {
        Looks::Own(level) => reference.compare(level)?,
        Looks::Taken(asset, level) => {
            let transferred = voxlod_asset::transfer(asset, level).map_err(|e| match e {
                voxlod_asset::AssetError::Core(c) => RenderError::Core(c),
                other => RenderError::Invalid(format!("taking looks onto the level: {other}")),
            })?;
            reference.compare(&transferred.asset)?
        }
    };
    Ok(LevelAppearance {
        psnr: report.psnr,
        ssim: report.ssim,
        seconds: start.elapsed().as_secs_f64(),
    })
}
