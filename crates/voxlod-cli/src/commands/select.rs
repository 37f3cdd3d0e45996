//! `voxlod select`: which level to draw for the object-space size of a pixel.

use std::path::{Path, PathBuf};

use clap::Args;
use serde::Serialize;
use voxlod::io::{IoError, IoErrorKind};
use voxlod::select::{pixel_size, SelectOptions, Selection};

use super::common::say;
use super::common::{print_json, CliError};
use super::values::number;

/// Pick the level of detail whose cell size fits the object-space size of a pixel.
///
/// Reads the report.json of `voxlod lod` (levels' voxel_size) or the JSON of `voxlod cluster
/// --json` (levels' cell_size), and chooses the coarsest level whose cells are no larger than
/// TOLERANCE pixels (Low–Tan's model selection; Rossignac–Borrel §5.4). A pixel's object-space
/// size is given directly (--pixel-size), or from the viewing distance, the vertical field of
/// view and the viewport's height in pixels. When no level fits, the original model is chosen.
///
/// Examples:
///   voxlod select bunny-lods/report.json --pixel-size 0.002
///   voxlod select bunny-lods/report.json --distance 0.5 --fov 60 --viewport 1080 --json
#[derive(Args, Debug)]
#[command(verbatim_doc_comment)]
pub struct SelectArgs {
    /// A report of levels: report.json of `voxlod lod`, or the JSON of `voxlod cluster --json`
    pub report: PathBuf,
    /// Object-space size of one pixel, in the model's units
    #[arg(long, value_name = "S", conflicts_with_all = ["distance", "fov", "viewport"],
        value_parser = number::<f64>, allow_hyphen_values = true)]
    pub pixel_size: Option<f64>,
    /// Distance from the eye to the object
    #[arg(long, value_name = "D", requires_all = ["fov", "viewport"],
        value_parser = number::<f64>, allow_hyphen_values = true)]
    pub distance: Option<f64>,
    /// Vertical field of view, in degrees (more than 0, less than 180)
    #[arg(long, value_name = "DEG", value_parser = number::<f64>, allow_hyphen_values = true)]
    pub fov: Option<f64>,
    /// Viewport height, in pixels
    #[arg(long, value_name = "PIXELS", value_parser = number::<u32>, allow_hyphen_values = true)]
    pub viewport: Option<u32>,
    /// A level fits when its cell size is at most this many pixels
    #[arg(long, value_name = "PIXELS", default_value_t = 1.0,
        value_parser = number::<f64>, allow_hyphen_values = true)]
    pub tolerance: f64,
    /// Print the choice as JSON on standard output
    #[arg(long)]
    pub json: bool,
}

#[derive(Serialize)]
struct SelectReport {
    pixel_size: f64,
    tolerance: f64,
    selection: Selection,
    level: Option<usize>,
    cell_size: Option<f64>,
    file: Option<String>,
    /// Every warning printed without --json (levels passed over because they have no mesh).
    warnings: Vec<String>,
}

pub fn run(args: SelectArgs) -> Result<(), CliError> {
    check_select_args(&args)?;
    let levels = read_levels(&args.report)?;
    let sizes: Vec<f64> = levels
        .iter()
        .map(|l| l["cell_size"].as_f64().or_else(|| l["voxel_size"].as_f64()))
        .collect::<Option<_>>()
        .ok_or_else(|| malformed(&args.report, "a level has neither cell_size nor voxel_size"))?;
    let pixel = match (args.pixel_size, args.distance, args.fov, args.viewport) {
        (Some(s), ..) => s,
        (None, Some(d), Some(fov), Some(h)) => pixel_size(d, fov.to_radians(), h)?,
        _ => {
            return Err(CliError::usage(
                "give --pixel-size, or --distance with --fov and --viewport",
            ))
        }
    };
    // A level of `voxlod lod` that the filter removed has `"file": null`: it cannot be drawn.
    let with_mesh: Vec<bool> = levels
        .iter()
        .map(|l| !l.get("file").is_some_and(serde_json::Value::is_null))
        .collect();
    let options = SelectOptions::pixels(args.tolerance);
    let chosen = voxlod::select_drawn(&sizes, &with_mesh, pixel, &options)
        .map_err(|e| e.in_file(&args.report))?;
    let (selection, warnings) = (chosen.selection, chosen.warnings);
    let level = match selection {
        Selection::Level(i) => Some(i),
        Selection::Original => None,
    };
    let report = SelectReport {
        pixel_size: pixel,
        tolerance: args.tolerance,
        selection,
        level,
        cell_size: level.map(|i| sizes[i]),
        // lod's report names files relative to its folder; cluster's names them fully.
        file: level.and_then(|i| levels[i]["file"].as_str()).map(|f| {
            let dir = args.report.parent().unwrap_or(std::path::Path::new(""));
            dir.join(f).display().to_string()
        }),
        warnings,
    };
    if args.json {
        return print_json(&report);
    }
    for w in &report.warnings {
        eprintln!("warning: {w}");
    }
    match level {
        Some(i) => say(format_args!(
            "level {i} (cells of {:.5} for pixels of {pixel:.5}){}",
            sizes[i],
            report
                .file
                .as_deref()
                .map(|f| format!(": {f}"))
                .unwrap_or_default()
        )),
        None => say(format_args!(
            "the original model: no level's cells fit pixels of {pixel:.5}"
        )),
    }
    Ok(())
}

/// Refuses flags out of their range, naming them (the selection's own errors would speak of
/// radians and parameters).
fn check_select_args(args: &SelectArgs) -> Result<(), CliError> {
    let positive = [
        ("--pixel-size", args.pixel_size),
        ("--distance", args.distance),
        ("--tolerance", Some(args.tolerance)),
    ];
    for (flag, value) in positive {
        if let Some(v) = value.filter(|v| *v <= 0.0) {
            return Err(CliError::usage(format!("{flag} {v}: must be more than 0")));
        }
    }
    if let Some(fov) = args.fov.filter(|f| !(*f > 0.0 && *f < 180.0)) {
        return Err(CliError::usage(format!(
            "--fov {fov}: the field of view must be more than 0 and less than 180 degrees"
        )));
    }
    if args.viewport == Some(0) {
        return Err(CliError::usage(
            "--viewport 0: the viewport must be at least 1 pixel high",
        ));
    }
    Ok(())
}

/// The levels of a report: the `levels` list of `voxlod lod`'s report.json or of `voxlod
/// cluster --json`.
fn read_levels(path: &Path) -> Result<Vec<serde_json::Value>, CliError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| IoError::new(path, IoErrorKind::Access, format!("cannot read: {e}")))?;
    let mut json: serde_json::Value = serde_json::from_str(&text)
        .map_err(|e| malformed(path, format!("not a JSON report: {e}")))?;
    match json.get_mut("levels").map(serde_json::Value::take) {
        Some(serde_json::Value::Array(levels)) => Ok(levels),
        _ => Err(malformed(
            path,
            "no \"levels\" list: give the report of `voxlod lod` or `voxlod cluster --json`",
        )),
    }
}

/// A report that is not what `select` reads.
fn malformed(path: &Path, problem: impl Into<String>) -> CliError {
    IoError::new(path, IoErrorKind::Malformed, problem).into()
}
