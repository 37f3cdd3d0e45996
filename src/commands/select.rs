//! `voxlod select`: which level to draw for the object-space size of a pixel.

use std::path::PathBuf;

use clap::Args;
use serde::Serialize;
use voxlod_baselines::{pixel_size, select_level, SelectOptions, Selection};

use super::common::{print_json, CliError};

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
    #[arg(long, value_name = "S", conflicts_with_all = ["distance", "fov", "viewport"])]
    pub pixel_size: Option<f64>,
    /// Distance from the eye to the object
    #[arg(long, value_name = "D", requires_all = ["fov", "viewport"])]
    pub distance: Option<f64>,
    /// Vertical field of view, in degrees
    #[arg(long, value_name = "DEG")]
    pub fov: Option<f64>,
    /// Viewport height, in pixels
    #[arg(long, value_name = "PIXELS")]
    pub viewport: Option<u32>,
    /// A level fits when its cell size is at most this many pixels
    #[arg(long, value_name = "PIXELS", default_value_t = 1.0)]
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
}

pub fn run(args: SelectArgs) -> Result<(), CliError> {
    let text = std::fs::read_to_string(&args.report)
        .map_err(|e| CliError::msg(format!("{}: cannot read: {e}", args.report.display())))?;
    let json: serde_json::Value = serde_json::from_str(&text)
        .map_err(|e| CliError::msg(format!("{}: not a JSON report: {e}", args.report.display())))?;
    let levels = json["levels"].as_array().ok_or_else(|| {
        CliError::msg(format!(
            "{}: no \"levels\" list: give the report of `voxlod lod` or `voxlod cluster --json`",
            args.report.display()
        ))
    })?;
    let sizes: Vec<f64> = levels
        .iter()
        .map(|l| l["cell_size"].as_f64().or_else(|| l["voxel_size"].as_f64()))
        .collect::<Option<_>>()
        .ok_or_else(|| {
            CliError::msg(format!(
                "{}: a level has neither cell_size nor voxel_size",
                args.report.display()
            ))
        })?;
    let pixel = match (args.pixel_size, args.distance, args.fov, args.viewport) {
        (Some(s), ..) => s,
        (None, Some(d), Some(fov), Some(h)) => {
            pixel_size(d, fov.to_radians(), h).map_err(|e| CliError::msg(e.to_string()))?
        }
        _ => {
            return Err(CliError::msg(
                "give --pixel-size, or --distance with --fov and --viewport",
            ))
        }
    };
    let selection = select_level(&sizes, pixel, &SelectOptions::pixels(args.tolerance))
        .map_err(|e| CliError::msg(e.to_string()))?;
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
    };
    if args.json {
        return print_json(&report);
    }
    match level {
        Some(i) => println!(
            "level {i} (cells of {:.5} for pixels of {pixel:.5}){}",
            sizes[i],
            report
                .file
                .as_deref()
                .map(|f| format!(": {f}"))
                .unwrap_or_default()
        ),
        None => println!("the original model: no level's cells fit pixels of {pixel:.5}"),
    }
    Ok(())
}
