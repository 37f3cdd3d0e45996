//! Turning an input file into something the pyramid can sample: a mesh solid, a thresholded
//! volume, or a volume filtered directly. Shared by `lod` and `voxelize`.

use std::path::Path;

use clap::Args;
use serde::Serialize;
use voxlod::core::Volume;
use voxlod::sampling::{MeshPreparation, MeshSolid, ThresholdSolid};

use super::common::{check_grid_range, read_input, CliError, Input, RawArgs};
use super::values::number;
use voxlod::lod::LodSource;

/// How a scanned volume enters the pipeline.
#[derive(Args, Debug, Clone)]
pub struct VolumeRoute {
    /// Volumes: a sample of value >= T (trilinearly interpolated) is inside; the solid is then
    /// filtered and --iso stays an isodensity between 0 and 1 (paper §4, first route)
    #[arg(long, value_name = "T", conflicts_with = "direct", help_heading = "Volumes",
        value_parser = number::<f32>, allow_hyphen_values = true)]
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
            check_grid_range(&volume, path, route.raw.spacing_source())?;
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

/// A warning when `--threshold` is at or below every sample of the volume: all of it is
/// inside, and the surfaces are those of its box.
pub fn threshold_warning(loaded: &Loaded, route: &VolumeRoute) -> Option<String> {
    let (Loaded::Volume(volume), Some(t)) = (loaded, route.threshold) else {
        return None;
    };
    let (lo, hi) = volume.range()?;
    (t <= lo).then(|| {
        format!(
            "--threshold {t} is at or below every sample (the data runs from {lo} to {hi}): all \
             of the volume is inside, so the surfaces are those of its box"
        )
    })
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
                let why = if iso <= 0.0 {
                    "at or below 0 every sample is inside (the density is 0 far outside the \
                     object), so there is no surface"
                } else if iso >= 1.0 {
                    "at or above 1 only samples of full density (deep inside) could be inside, \
                     which rounding makes unreliable"
                } else {
                    return Ok(iso);
                };
                Err(CliError::usage(format!(
                    "--iso {iso}: the filtered density runs from 0 (outside) to 1 (deep inside); \
                     {why}. Choose an isodensity strictly between 0 and 1 (0.5 follows the \
                     object's surface)"
                )))
            }
        }
    }
}

/// Refuses an iso value that gives no surface, saying why. A sample is inside when its value
/// is `>= iso`, so at or below the data's minimum every sample is inside and above its maximum
/// none is; both are refused (see [`iso_without_surface`]).
pub fn check_iso(iso: f32, volume: &Volume, path: &Path) -> Result<(), CliError> {
    match iso_without_surface(iso, volume, path)? {
        Some(why) => Err(CliError::msg(why)),
        None => Ok(()),
    }
}

/// Why no sample of `volume` is on either side of `iso` (every sample inside, or none), or
/// `None` when a surface can exist. Fails when the volume has no finite sample.
pub fn iso_without_surface(
    iso: f32,
    volume: &Volume,
    path: &Path,
) -> Result<Option<String>, CliError> {
    let name = path.display();
    let (lo, hi) = volume
        .range()
        .ok_or_else(|| CliError::msg(format!("{name}: the volume has no finite samples")))?;
    let what = if iso <= lo {
        format!(
            "--iso {iso} is at or below the data's minimum: every sample is inside (a sample is \
             inside when its value is >= the iso value), so there is no surface"
        )
    } else if iso > hi {
        format!(
            "--iso {iso} is above the data's maximum: no sample reaches it, so nothing is inside \
             and there is no surface"
        )
    } else {
        return Ok(None);
    };
    Ok(Some(format!(
        "{name}: {what}. The data runs from {lo} to {hi}: choose a value above {lo} and at \
         most {hi}"
    )))
}
