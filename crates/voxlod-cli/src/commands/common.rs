//! What the subcommands share: the error type, JSON reports, progress bars.

use std::time::Duration;

use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;

/// Any failure of a subcommand, shown as one line: `voxlod: error: <message>`, and ending the
/// run with the exit status of its class ([`CliError::exit_code`]).
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    /// A failure of the library: its class decides the exit status.
    #[error(transparent)]
    Library(#[from] voxlod::Error),
    /// A flag out of its range, or flags that do not go together (exit status 2).
    #[error("{0}")]
    Usage(String),
    /// Anything else the command refuses about its input (exit status 1).
    #[error("{0}")]
    Message(String),
}

impl From<voxlod::core::CoreError> for CliError {
    fn from(e: voxlod::core::CoreError) -> Self {
        CliError::Library(e.into())
    }
}

impl From<voxlod::io::IoError> for CliError {
    fn from(e: voxlod::io::IoError) -> Self {
        CliError::Library(e.into())
    }
}

/// A library failure about `path`: `path: <problem>`, keeping the failure's class.
pub fn in_file(path: &std::path::Path, e: impl Into<voxlod::Error>) -> CliError {
    CliError::Library(e.into().context(path.display().to_string()))
}

/// Exit status of a usage error (a flag out of range; also clap's).
pub const EXIT_USAGE: u8 = 2;
/// Exit status of input that cannot be processed as asked.
pub const EXIT_BAD_INPUT: u8 = 1;
/// Exit status of work that would not fit in the memory budget (`VOXLOD_MAX_MEMORY`).
pub const EXIT_TOO_LARGE: u8 = 3;
/// Exit status of a file that cannot be opened, read, written or renamed.
pub const EXIT_IO: u8 = 4;
/// Exit status of a run stopped by SIGINT (128 + 2; SIGTERM gives 143).
pub const EXIT_INTERRUPTED: u8 = 130;

impl CliError {
    /// An error described in words (bad input, exit status 1).
    pub fn msg(text: impl Into<String>) -> CliError {
        CliError::Message(text.into())
    }

    /// A flag out of its range (exit status 2).
    pub fn usage(text: impl Into<String>) -> CliError {
        CliError::Usage(text.into())
    }

    /// The exit status of this error's class: usage 2, bad input 1, too large for memory 3,
    /// I/O 4, cancelled 130.
    pub fn exit_code(&self) -> u8 {
        use voxlod::ErrorClass;
        match self {
            CliError::Usage(_) => EXIT_USAGE,
            CliError::Message(_) => EXIT_BAD_INPUT,
            CliError::Library(e) => match e.class() {
                ErrorClass::Usage => EXIT_USAGE,
                ErrorClass::BadInput => EXIT_BAD_INPUT,
                ErrorClass::TooLarge => EXIT_TOO_LARGE,
                ErrorClass::Io => EXIT_IO,
                ErrorClass::Cancelled => EXIT_INTERRUPTED,
            },
        }
    }
}

/// Exit status of a run whose standard output was closed by its reader (`voxlod … | head`):
/// 128 + SIGPIPE's number, as for a program that SIGPIPE ends.
pub const EXIT_CLOSED_OUTPUT: u8 = 141;

/// Writes `text` and a newline on standard output: the one way the subcommands print.
///
/// A reader that closes the pipe early (`voxlod lod … --json | head -c 10`) ends the run
/// quietly, with [`EXIT_CLOSED_OUTPUT`] and nothing on standard error, where `println!` would
/// panic; any other failure to write is one error line and [`EXIT_IO`]. Either way the files
/// not yet committed are removed first (outputs are committed before their report is printed,
/// so a committed set stays whole).
pub fn say(text: impl std::fmt::Display) {
    use std::io::Write;
    let mut stdout = std::io::stdout().lock();
    let written = writeln!(stdout, "{text}").and_then(|()| stdout.flush());
    if let Err(e) = written {
        voxlod::io::atomic::remove_temporaries_for_exit();
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            std::process::exit(i32::from(EXIT_CLOSED_OUTPUT));
        }
        eprintln!("voxlod: error: cannot write to standard output: {e}");
        std::process::exit(i32::from(EXIT_IO));
    }
}

/// Prints `report` as pretty JSON on standard output.
pub fn print_json<T: Serialize>(report: &T) -> Result<(), CliError> {
    let text = serde_json::to_string_pretty(report)
        .map_err(|e| CliError::msg(format!("cannot encode the JSON report: {e}")))?;
    say(text);
    Ok(())
}

/// Adds `DIR/report.json`, the pretty-printed report, to a command's output set.
pub fn add_report<T: Serialize>(
    out: &mut voxlod::io::OutputSet,
    dir: &Path,
    report: &T,
) -> Result<(), CliError> {
    let text = serde_json::to_string_pretty(report)
        .map_err(|e| CliError::msg(format!("cannot encode the report: {e}")))?;
    Ok(out.text(&in_dir(dir, "report.json"), &text)?)
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

use std::str::FromStr;

use clap::Args;
use voxlod::core::{TriangleMesh, Volume};
use voxlod::io::{Endian, FileKind, LoadedMesh, RawLayout, RawType};

use super::values::{number, numbers};

/// How to read a headerless raw volume. Only needed when the input has no header.
#[derive(Args, Debug, Clone)]
pub struct RawArgs {
    /// Samples along x, y and z of a headerless raw volume (x varies fastest), e.g. 256,256,113
    #[arg(long, value_name = "X,Y,Z", help_heading = "Raw volumes",
        value_parser = numbers::<usize, 3>, allow_hyphen_values = true)]
    pub dims: Option<[usize; 3]>,
    /// Sample type of the raw volume: u8, i16, u16, i32 or f32
    #[arg(long, value_name = "TYPE", default_value = "u8", help_heading = "Raw volumes",
        value_parser = RawType::from_str)]
    pub dtype: RawType,
    /// Byte order of the raw samples: little or big
    #[arg(long, value_name = "ORDER", default_value = "little", help_heading = "Raw volumes",
        value_parser = Endian::from_str)]
    pub endian: Endian,
    /// Distance between samples along x, y and z, in world units (millimetres for a CT)
    #[arg(long, value_name = "SX,SY,SZ", default_value = "1,1,1", help_heading = "Raw volumes",
        value_parser = numbers::<f64, 3>, allow_hyphen_values = true)]
    pub spacing: [f64; 3],
    /// World position of the first sample
    #[arg(long, value_name = "X,Y,Z", default_value = "0,0,0", help_heading = "Raw volumes",
        value_parser = numbers::<f64, 3>, allow_hyphen_values = true)]
    pub origin: [f64; 3],
    /// Bytes to skip at the start of the raw file
    #[arg(long, value_name = "BYTES", default_value_t = 0, help_heading = "Raw volumes",
        value_parser = number::<u64>, allow_hyphen_values = true)]
    pub header_bytes: u64,
    /// DICOM: the SeriesInstanceUID to read from a folder holding several series (without it,
    /// such a folder is refused with the list of its series)
    #[arg(long, value_name = "UID", help_heading = "DICOM", value_parser = series_uid,
        allow_hyphen_values = true)]
    pub series: Option<String>,
}

/// A DICOM UID as `--series` takes it: digits and dots, at most 64 characters (PS3.5 §9.1).
fn series_uid(text: &str) -> Result<String, String> {
    let digits_and_dots = text.chars().all(|c| c.is_ascii_digit() || c == '.');
    if text.is_empty() || text.len() > 64 || !digits_and_dots {
        return Err("a SeriesInstanceUID is digits and dots, at most 64 characters".into());
    }
    Ok(text.to_string())
}

impl RawArgs {
    /// The raw layout, when `--dims` was given.
    pub fn layout(&self) -> Result<Option<RawLayout>, CliError> {
        let Some(dims) = self.dims else {
            return Ok(None);
        };
        let list = |v: [String; 3]| v.join(",");
        if dims.contains(&0) {
            return Err(CliError::usage(format!(
                "--dims {}: each dimension must be at least 1 sample",
                list(dims.map(|d| d.to_string()))
            )));
        }
        if self.spacing.iter().any(|&s| s <= 0.0) {
            return Err(CliError::usage(format!(
                "--spacing {}: the distance between samples must be more than 0 along every axis",
                list(self.spacing.map(|s| s.to_string()))
            )));
        }
        let mut layout = RawLayout::new(dims, self.dtype, self.endian);
        layout.spacing = self.spacing;
        layout.origin = self.origin;
        layout.header_bytes = self.header_bytes;
        Ok(Some(layout))
    }

    /// Where a volume's spacing and origin come from, for errors about them.
    pub fn spacing_source(&self) -> &'static str {
        if self.dims.is_some() {
            "--spacing and --origin"
        } else {
            "the spacing and origin in the file's header"
        }
    }
}

/// A file given on the command line: a mesh or a volume.
pub enum Input {
    Mesh(LoadedMesh),
    Volume(Volume),
}

/// Reads `path` as a mesh or a volume, by its extension (or as raw when `--dims` is given).
pub fn read_input(path: &Path, raw: &RawArgs) -> Result<Input, CliError> {
    if let Some(layout) = raw.layout()? {
        return Ok(Input::Volume(voxlod::io::read_volume(path, Some(&layout))?));
    }
    let kind = voxlod::io::file_kind(path)?;
    if let Some(uid) = &raw.series {
        if kind != FileKind::Volume(voxlod::io::VolumeFormat::Dicom) {
            return Err(CliError::usage(format!(
                "--series {uid}: {} is not a DICOM folder or file",
                path.display()
            )));
        }
        let options = voxlod::io::DicomOptions::series(uid);
        let volume = voxlod::io::read_dicom_series(&[path.to_path_buf()], &options)?;
        return Ok(Input::Volume(volume));
    }
    match kind {
        FileKind::Mesh(_) => Ok(Input::Mesh(read_mesh_file(path)?)),
        FileKind::Volume(voxlod::io::VolumeFormat::Raw) => Err(CliError::usage(format!(
            "{}: a headerless raw volume needs --dims X,Y,Z (and --dtype, --endian, --spacing)",
            path.display()
        ))),
        FileKind::Volume(_) => Ok(Input::Volume(voxlod::io::read_volume(path, None)?)),
    }
}

/// Whether `path` is a binary glTF file (`.glb`), which the layers crate reads.
pub fn is_glb(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("glb"))
}

/// A mesh file as [`voxlod::read_mesh_file`] reads it (a glTF file as its scene's geometry),
/// the reader's notes printed on standard error.
fn read_mesh_file(path: &Path) -> Result<LoadedMesh, CliError> {
    let loaded = voxlod::read_mesh_file(path).map_err(CliError::Library)?;
    for w in &loaded.notes {
        eprintln!("warning: {}: {w}", path.display());
    }
    Ok(loaded)
}

/// Reads a mesh, refusing volumes.
pub fn read_mesh_input(path: &Path) -> Result<LoadedMesh, CliError> {
    match voxlod::io::file_kind(path)? {
        FileKind::Mesh(_) => read_mesh_file(path),
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

/// Refuses a volume whose samples lie beyond the 32-bit range of mesh coordinates, before any
/// work (`voxlod::pyramid::source::check_grid_range`): its surfaces would have infinite
/// vertices. `source` says where the spacing and origin came from ("the file's header",
/// "--spacing and --origin").
pub fn check_grid_range(volume: &Volume, path: &Path, source: &str) -> Result<(), CliError> {
    check_grid_reach(&volume.grid, path, source)
}

/// [`check_grid_range`] for a volume known by its grid only (a scan read blockwise).
pub fn check_grid_reach(g: &voxlod::core::Grid, path: &Path, source: &str) -> Result<(), CliError> {
    voxlod::pyramid::source::check_grid_reach(g).map_err(|e| {
        let e = voxlod::Error::from(e).in_file(path);
        CliError::msg(format!("{e}; check {source}"))
    })
}

/// Refuses a computed mesh with a non-finite vertex or normal, as what it is: the computation
/// left the range of 32-bit floats (`what` names the input and step, `cause` what led there),
/// rather than letting the writer blame the output file.
pub fn check_computed_mesh(mesh: &TriangleMesh, what: &str, cause: &str) -> Result<(), CliError> {
    if let Some(i) = mesh.positions.iter().position(|p| !p.is_finite()) {
        let p = mesh.positions[i];
        return Err(CliError::msg(format!(
            "{what}: the computed surface has a vertex at ({}, {}, {}), beyond the range of \
             32-bit coordinates; {cause}",
            p.x, p.y, p.z
        )));
    }
    if mesh.normals.iter().any(|n| !n.is_finite()) {
        return Err(CliError::msg(format!(
            "{what}: the computed surface has a non-finite normal; {cause}"
        )));
    }
    Ok(())
}

/// `n thing` or `n things`: "1 level", "5 levels", "0 vertices" (give both forms).
pub fn count(n: usize, one: &str, many: &str) -> String {
    format!("{} {}", thousands(n), if n == 1 { one } else { many })
}
