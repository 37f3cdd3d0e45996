//! `voxlod select`: which level to draw for the object-space size of a pixel.

use std::path::PathBuf;

use clap::Args;
use serde::Serialize;
use voxlod::select::{pixel_size, select_level, SelectOptions, Selection};

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
    // A level of `voxlod lod` that the filter removed has `"file": null`: it cannot be drawn.
    let with_mesh: Vec<bool> = levels
        .iter()
        .map(|l| !l.get("file").is_some_and(serde_json::Value::is_null))
        .collect();
    let options = SelectOptions::pixels(args.tolerance);
    let (selection, warnings) = select_with_mesh(&sizes, &with_mesh, pixel, &options)
        .map_err(|e| CliError::msg(format!("{}: {e}", args.report.display())))?;
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
            return Err(CliError::msg(format!("{flag} {v}: must be more than 0")));
        }
    }
    if let Some(fov) = args.fov.filter(|f| !(*f > 0.0 && *f < 180.0)) {
        return Err(CliError::usage(format!(
            "--fov {fov}: the field of view must be more than 0 and less than 180 degrees"
        )));
    }
    if args.viewport == Some(0) {
        return Err(CliError::msg(
            "--viewport 0: the viewport must be at least 1 pixel high",
        ));
    }
    Ok(())
}

/// The selection among the levels that have a mesh (`with_mesh`), and a warning when a level
/// without one would have been chosen, or when no level has one.
fn select_with_mesh(
    sizes: &[f64],
    with_mesh: &[bool],
    pixel: f64,
    options: &SelectOptions,
) -> Result<(Selection, Vec<String>), voxlod::clustering::ClusteringError> {
    let drawable: Vec<usize> = (0..sizes.len()).filter(|&i| with_mesh[i]).collect();
    let drawable_sizes: Vec<f64> = drawable.iter().map(|&i| sizes[i]).collect();
    let selection = match select_level(&drawable_sizes, pixel, options)? {
        Selection::Level(j) => Selection::Level(drawable[j]),
        Selection::Original => Selection::Original,
    };
    let mut warnings = Vec::new();
    if drawable.is_empty() && !sizes.is_empty() {
        warnings.push(
            "no level has a mesh (the filter removed the object at every level): the original \
             model is chosen"
                .to_string(),
        );
    } else if let Selection::Level(k) = select_level(sizes, pixel, options)? {
        if !with_mesh[k] {
            let instead = match selection {
                Selection::Level(i) => format!("level {i}, the coarsest with a mesh that fits,"),
                Selection::Original => "the original model".to_string(),
            };
            warnings.push(format!(
                "level {k} fits but has no mesh (the filter removed the whole object there): \
                 {instead} is chosen instead"
            ));
        }
    }
    Ok((selection, warnings))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn levels_without_a_mesh_are_passed_over() {
        // Cells of 1, 2, 4, 8; level 3 (the coarsest) has no mesh.
        let sizes = [1.0, 2.0, 4.0, 8.0];
        let options = SelectOptions::pixels(1.0);
        let with_mesh = [true, true, true, false];
        let (s, w) = select_with_mesh(&sizes, &with_mesh, 10.0, &options).unwrap();
        assert_eq!(s, Selection::Level(2));
        assert_eq!(w.len(), 1, "{w:?}");
        assert!(w[0].starts_with("level 3 fits but has no mesh"), "{w:?}");
        // A pixel of 3 fits levels 0 and 1 only: no warning.
        let (s, w) = select_with_mesh(&sizes, &with_mesh, 3.0, &options).unwrap();
        assert_eq!((s, w.len()), (Selection::Level(1), 0));
        // Nothing drawable: the original, with the reason.
        let (s, w) = select_with_mesh(&sizes, &[false; 4], 10.0, &options).unwrap();
        assert_eq!(s, Selection::Original);
        assert!(w[0].contains("no level has a mesh"), "{w:?}");
    }
}
