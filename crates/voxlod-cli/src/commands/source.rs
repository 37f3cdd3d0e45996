//! The flags that say how a scanned volume enters the pipeline, reading the input into the
//! library's [`voxlod::Source`], and the mesh summary of reports. Shared by `lod`, `voxelize`
//! and `layers`.

use std::path::Path;

use clap::Args;
use serde::Serialize;
use voxlod::pyramid::ScanRoute;
use voxlod::sampling::MeshPreparation;

use super::common::{check_grid_range, read_input, CliError, Input, RawArgs};
use super::values::{in_flags, number};

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

impl VolumeRoute {
    /// Reads `path`, refusing a volume beyond mesh coordinates or without a route.
    pub fn read(&self, path: &Path) -> Result<Input, CliError> {
        let input = read_input(path, &self.raw)?;
        if let Input::Volume(volume) = &input {
            check_grid_range(volume, path, self.raw.spacing_source())?;
            ScanRoute::of(self.threshold, self.direct)
                .map_err(|e| in_flags(voxlod::Error::from(e).in_file(path), &[]))?;
        }
        Ok(input)
    }

    /// The library's source for what [`VolumeRoute::read`] read (which refused a volume
    /// without a route).
    pub fn source<'a>(&self, input: &'a Input) -> voxlod::Source<'a> {
        match input {
            Input::Mesh(m) => voxlod::Source::Mesh(&m.mesh),
            Input::Volume(volume) => ScanRoute::of(self.threshold, self.direct)
                .unwrap_or(ScanRoute::Direct)
                .source(volume),
        }
    }
}

/// A library warning in the command line's words: its options named as the flags.
pub fn in_flag_words(warning: &str) -> String {
    warning
        .replace("`threshold`", "--threshold")
        .replace("`resolution`", "--resolution")
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

impl MeshSummary {
    /// The summary of a mesh as read and as the library prepared it.
    pub fn of(m: &voxlod::io::LoadedMesh, preparation: MeshPreparation) -> MeshSummary {
        MeshSummary {
            format: m.format.to_string(),
            vertices: m.mesh.positions.len(),
            triangles: m.mesh.triangles.len(),
            polygons_triangulated: m.polygons_triangulated,
            preparation,
        }
    }
}
