//! Turning an input file into something the pyramid can sample: a mesh solid, a thresholded
//! volume, or a volume filtered directly. Shared by `lod` and `voxelize`.

use std::path::Path;

use clap::Args;
use serde::Serialize;
use voxlod_core::Volume;
use voxlod_sampling::{MeshPreparation, MeshSolid, ThresholdSolid};

use super::common::{read_input, CliError, Input, RawArgs};
use crate::lod::LodSource;

/// How a scanned volume enters the pipeline.
#[derive(Args, Debug, Clone, Default)]
pub struct VolumeRoute {
    /// Volumes: a sample of value >= T (trilinearly interpolated) is inside; the solid is then
    /// filtered and --iso stays an isodensity between 0 and 1 (paper §4, first route)
    #[arg(
        long,
        value_name = "T",
        conflicts_with = "direct",
        help_heading = "Volumes"
    )]
    pub threshold: Option<f32>,
    /// Volumes: filter the data itself; --iso is then in the data's own units (paper §4,
    /// second route)
    #[arg(long, help_heading = "Volumes")]
    pub direct: bool,
    #[command(flatten)]
    pub raw: RawArgs,
}

/// What was read, kept alive for the borrowing [`LodSource`].
pub enum Loaded {
    Mesh(Box<MeshSolid>, MeshSummary),
    Volume(Volume),
}

/// What the mesh reader and the mesh preparation did, for reports.
#[derive(Clone, Debug, Serialize)]
pub struct MeshSummary {
    pub format: String,
    pub vertices: usize,
    pub triangles: usize,
    pub polygons_triangulated: usize,
    pub preparation: MeshPreparation,
}

/// Reads `path`.
pub fn load(path: &Path, route: &VolumeRoute) -> Result<Loaded, CliError> {
    match read_input(path, &route.raw)? {
        Input::Mesh(loaded) => {
            let solid = MeshSolid::new(&loaded.mesh)
                .map_err(|e| CliError::msg(format!("{}: {e}", path.display())))?;
            let summary = MeshSummary {
                format: loaded.format.to_string(),
                vertices: loaded.mesh.positions.len(),
                triangles: loaded.mesh.triangles.len(),
                polygons_triangulated: loaded.polygons_triangulated,
                preparation: solid.preparation,
            };
            Ok(Loaded::Mesh(Box::new(solid), summary))
        }
        Input::Volume(volume) => {
            if route.threshold.is_none() && !route.direct {
                return Err(CliError::msg(format!(
                    "{}: a volume needs --threshold T (inside where the data is >= T) or --direct \
                     (filter the data itself, with --iso in its units)",
                    path.display()
                )));
            }
            Ok(Loaded::Volume(volume))
        }
    }
}

/// A thresholded volume must outlive the source that borrows it.
pub enum Prepared<'a> {
    Mesh(&'a MeshSolid),
    Threshold(ThresholdSolid<'a>),
    Direct(&'a Volume),
}

impl<'a> Prepared<'a> {
    pub fn new(
        loaded: &'a Loaded,
        route: &VolumeRoute,
        path: &Path,
    ) -> Result<Prepared<'a>, CliError> {
        Ok(match loaded {
            Loaded::Mesh(solid, _) => Prepared::Mesh(solid),
            Loaded::Volume(volume) => match route.threshold {
                Some(t) => Prepared::Threshold(
                    ThresholdSolid::new(volume, t)
                        .map_err(|e| CliError::msg(format!("{}: {e}", path.display())))?,
                ),
                None => Prepared::Direct(volume),
            },
        })
    }

    pub fn source(&self) -> LodSource<'_> {
        match self {
            Prepared::Mesh(s) => LodSource::Solid(*s),
            Prepared::Threshold(s) => LodSource::Solid(s),
            Prepared::Direct(v) => LodSource::Direct(v),
        }
    }

    /// The default isodensity, or the check of a given one against the density's range.
    pub fn iso(&self, given: Option<f32>, path: &Path) -> Result<f32, CliError> {
        match self {
            Prepared::Direct(volume) => {
                let iso = given.ok_or_else(|| {
                    CliError::msg(format!(
                        "{}: --direct needs --iso V in the data's units",
                        path.display()
                    ))
                })?;
                check_iso(iso, volume, path)?;
                Ok(iso)
            }
            _ => {
                let iso = given.unwrap_or(0.5);
                if !(iso > 0.0 && iso < 1.0) {
                    return Err(CliError::msg(format!(
                        "--iso {iso} is outside the filtered density's range: choose an \
                         isodensity strictly between 0 and 1"
                    )));
                }
                Ok(iso)
            }
        }
    }
}

/// Refuses an iso value that no surface can have: outside `(min, max]` of the data.
pub fn check_iso(iso: f32, volume: &Volume, path: &Path) -> Result<(), CliError> {
    let (lo, hi) = volume.range().ok_or_else(|| {
        CliError::msg(format!(
            "{}: the volume has no finite samples",
            path.display()
        ))
    })?;
    if !iso.is_finite() || iso <= lo || iso > hi {
        return Err(CliError::msg(format!(
            "{}: --iso {iso} is outside the data's range ({lo} to {hi}); no surface lies there",
            path.display()
        )));
    }
    Ok(())
}
