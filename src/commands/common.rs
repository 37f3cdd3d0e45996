//! What the subcommands share: the error type, JSON reports, progress bars.

use std::time::Duration;

use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;

/// Any failure of a subcommand, shown as one line: `voxlod: error: <message>`.
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    #[error("{0}")]
    Message(String),
    #[error(transparent)]
    Core(#[from] voxlod_core::CoreError),
    #[error(transparent)]
    Io(#[from] voxlod_io::IoError),
}

impl CliError {
    pub fn msg(text: impl Into<String>) -> CliError {
        CliError::Message(text.into())
    }
}

/// Prints `report` as pretty JSON on standard output.
pub fn print_json<T: Serialize>(report: &T) -> Result<(), CliError> {
    let text = serde_json::to_string_pretty(report)
        .map_err(|e| CliError::msg(format!("cannot encode the JSON report: {e}")))?;
    println!("{text}");
    Ok(())
}

/// A progress bar on standard error for `len` steps, hidden when `quiet` (JSON mode) or when
/// standard error is not a terminal. It only draws after a second, so quick work stays silent.
pub fn progress(len: u64, message: &str, quiet: bool) -> ProgressBar {
    if quiet {
        return ProgressBar::hidden();
    }
    let bar =
        ProgressBar::with_draw_target(Some(len), indicatif::ProgressDrawTarget::stderr_with_hz(4));
    bar.set_style(
        ProgressStyle::with_template("{msg:>12} [{bar:30}] {pos}/{len} {elapsed}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    bar.set_message(message.to_string());
    bar.enable_steady_tick(Duration::from_millis(1000));
    bar
}

// -------------------------------------------------------------------------------------------
// Inputs.

use std::path::{Path, PathBuf};

use clap::Args;
use voxlod_core::{TriangleMesh, Volume};
use voxlod_io::{Endian, FileKind, LoadedMesh, RawLayout, RawType};

/// How to read a headerless raw volume. Only needed when the input has no header.
#[derive(Args, Debug, Clone, Default)]
pub struct RawArgs {
    /// Samples along x, y and z of a headerless raw volume (x varies fastest), e.g. 256,256,113
    #[arg(long, value_name = "X,Y,Z", help_heading = "Raw volumes")]
    pub dims: Option<String>,
    /// Sample type of the raw volume: u8, i16, u16, i32 or f32
    #[arg(
        long,
        value_name = "TYPE",
        default_value = "u8",
        help_heading = "Raw volumes"
    )]
    pub dtype: String,
    /// Byte order of the raw samples: little or big
    #[arg(
        long,
        value_name = "ORDER",
        default_value = "little",
        help_heading = "Raw volumes"
    )]
    pub endian: String,
    /// Distance between samples along x, y and z, in world units (millimetres for a CT)
    #[arg(
        long,
        value_name = "SX,SY,SZ",
        default_value = "1,1,1",
        help_heading = "Raw volumes"
    )]
    pub spacing: String,
    /// World position of the first sample
    #[arg(
        long,
        value_name = "X,Y,Z",
        default_value = "0,0,0",
        help_heading = "Raw volumes"
    )]
    pub origin: String,
    /// Bytes to skip at the start of the raw file
    #[arg(
        long,
        value_name = "BYTES",
        default_value_t = 0,
        help_heading = "Raw volumes"
    )]
    pub header_bytes: u64,
}

impl RawArgs {
    /// The raw layout, when `--dims` was given.
    pub fn layout(&self) -> Result<Option<RawLayout>, CliError> {
        let Some(dims) = &self.dims else {
            return Ok(None);
        };
        let dims = parse_triple::<usize>(dims, "--dims")?;
        let dtype: RawType = self
            .dtype
            .parse()
            .map_err(|e| CliError::msg(format!("--dtype: {e}")))?;
        let endian: Endian = self
            .endian
            .parse()
            .map_err(|e| CliError::msg(format!("--endian: {e}")))?;
        let mut layout = RawLayout::new(dims, dtype, endian);
        layout.spacing = parse_triple::<f64>(&self.spacing, "--spacing")?;
        layout.origin = parse_triple::<f64>(&self.origin, "--origin")?;
        layout.header_bytes = self.header_bytes;
        Ok(Some(layout))
    }
}

/// Parses `A,B,C`.
pub fn parse_triple<T: std::str::FromStr>(text: &str, flag: &str) -> Result<[T; 3], CliError> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    if parts.len() != 3 {
        return Err(CliError::msg(format!(
            "{flag} takes three comma-separated values, got '{text}'"
        )));
    }
    let parse = |s: &str| {
        s.parse::<T>()
            .map_err(|_| CliError::msg(format!("{flag}: '{s}' is not a valid number")))
    };
    Ok([parse(parts[0])?, parse(parts[1])?, parse(parts[2])?])
}

/// A file given on the command line: a mesh or a volume.
pub enum Input {
    Mesh(LoadedMesh),
    Volume(Volume),
}

/// Reads `path` as a mesh or a volume, by its extension (or as raw when `--dims` is given).
pub fn read_input(path: &Path, raw: &RawArgs) -> Result<Input, CliError> {
    if let Some(layout) = raw.layout()? {
        return Ok(Input::Volume(voxlod_io::read_volume(path, Some(&layout))?));
    }
    match voxlod_io::file_kind(path)? {
        FileKind::Mesh(_) => Ok(Input::Mesh(voxlod_io::read_mesh(path)?)),
        FileKind::Volume(voxlod_io::VolumeFormat::Raw) => Err(CliError::msg(format!(
            "{}: a headerless raw volume needs --dims X,Y,Z (and --dtype, --endian, --spacing)",
            path.display()
        ))),
        FileKind::Volume(_) => Ok(Input::Volume(voxlod_io::read_volume(path, None)?)),
    }
}

/// Reads a mesh, refusing volumes.
pub fn read_mesh_input(path: &Path) -> Result<LoadedMesh, CliError> {
    match voxlod_io::file_kind(path)? {
        FileKind::Mesh(_) => Ok(voxlod_io::read_mesh(path)?),
        FileKind::Volume(_) => Err(CliError::msg(format!(
            "{}: this is a volume; this command takes a mesh",
            path.display()
        ))),
    }
}

/// Output mesh formats.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshExtension {
    Ply,
    Obj,
    Stl,
    Vtp,
    Vtk,
}

impl MeshExtension {
    pub fn as_str(self) -> &'static str {
        match self {
            MeshExtension::Ply => "ply",
            MeshExtension::Obj => "obj",
            MeshExtension::Stl => "stl",
            MeshExtension::Vtp => "vtp",
            MeshExtension::Vtk => "vtk",
        }
    }
}

/// `out.ply` for one level, `out-K.ply` for level K of several.
pub fn level_path(output: &Path, level: usize, levels: usize) -> PathBuf {
    if levels <= 1 {
        return output.to_path_buf();
    }
    let stem = output
        .file_stem()
        .map(|s| s.to_string_lossy())
        .unwrap_or_default();
    match output.extension() {
        Some(ext) => output.with_file_name(format!("{stem}-{level}.{}", ext.to_string_lossy())),
        None => output.with_file_name(format!("{stem}-{level}")),
    }
}

/// `dir/name`.
pub fn in_dir(dir: &Path, name: &str) -> PathBuf {
    dir.join(name)
}

/// Counts of a mesh for human output, e.g. `12,345 triangles`.
pub fn thousands(n: usize) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// A mesh's vertex and triangle counts in words.
pub fn describe_mesh(mesh: &TriangleMesh) -> String {
    format!(
        "{} vertices, {} triangles",
        thousands(mesh.positions.len()),
        thousands(mesh.triangles.len())
    )
}
