//! `voxlod labels` with levels or a filter: each label's indicator filtered and contoured as a
//! thresholded scan, level by level (paper §2, §4; `voxlod::labels`).

use std::time::Instant;

use voxlod::core::TriangleMesh;
use voxlod::io::{LabelMap, LabelName, OutputSet};
use voxlod::labels::{LabelLevels, LabelOptions};
use voxlod::{Control, ThenEnvelope};

use super::{
    file_name, finish, name_of, print_label, write_all_labels, LabelReport, LabelsArgs,
    LabelsReport, LevelReport,
};
use crate::commands::common::{in_dir, in_file, progress, CliError};
use crate::commands::values::in_flags;
use crate::commands::world::frame_report;

/// The library's option names that are not the flags' names.
const FLAGS: &[(&str, &str)] = &[("radius_voxels", "--radius")];

/// Whether the flags ask for the filtered levels.
pub(super) fn asked_for(args: &LabelsArgs) -> bool {
    args.levels.is_some()
        || args.filter.is_some()
        || args.radius.is_some()
        || args.then_envelope.is_some()
}

/// The library's options from the flags.
fn label_options(args: &LabelsArgs) -> LabelOptions {
    let mut options = LabelOptions::for_levels(args.levels.unwrap_or(1));
    options.labels = args
        .labels
        .as_ref()
        .map(|l| l.iter().map(|&v| i64::from(v)).collect());
    if let Some(filter) = args.filter {
        options.lod.pyramid.filter = filter;
    }
    if let Some(radius) = args.radius {
        options.lod.pyramid.radius_voxels = radius;
    }
    options.lod.clean = options.lod.clean.filter(|_| !args.no_clean);
    options.frame = args.frame.target();
    options.then_envelope = args.then_envelope.map(ThenEnvelope::new);
    options
}

/// One label's levels (made by `voxlod::labels`), staged for writing: its report and its
/// level 0.
fn write_label(
    args: &LabelsArgs,
    label: LabelLevels,
    name: Option<&LabelName>,
    out: &mut OutputSet,
) -> Result<(LabelReport, Option<TriangleMesh>), CliError> {
    let value = label.label.value as u32;
    let ext = args
        .format
        .mesh()
        .expect("filtered levels are written as mesh files");
    let mut reports = Vec::new();
    let mut first = None;
    let count = label.levels.len();
    for level in label.levels {
        let start = Instant::now();
        let mesh = level.mesh;
        let k = level.plan.level;
        let file = (!mesh.is_empty()).then(|| file_name(value, name, k, count, ext.as_str()));
        if let Some(f) = &file {
            out.mesh(&in_dir(&args.output, f), &mesh)?;
        }
        let t = level.topology;
        reports.push(LevelReport {
            level: k,
            resolution: level.plan.resolution,
            voxel_size: level.plan.voxel_size,
            file,
            triangles: mesh.triangles.len(),
            volume: mesh.signed_volume(),
            area: mesh.area(),
            closed_manifold: Some(t.is_closed_manifold() && t.is_consistently_oriented()),
            seconds: level.sample_seconds + level.contour_seconds + start.elapsed().as_secs_f64(),
            envelope: level.envelope,
        });
        if k == 0 {
            first = Some(mesh);
        }
    }
    let report = LabelReport {
        label: value,
        name: name.map(|n| n.name.clone()),
        color: name.and_then(|n| n.color),
        voxels: label.label.voxels as u64,
        voxel_volume: label.voxel_volume,
        levels: reports,
    };
    Ok((report, first))
}

/// The filtered levels of every label, written with the report.
pub(super) fn run(args: &LabelsArgs, read: LabelMap) -> Result<(), CliError> {
    let start = Instant::now();
    let map = read
        .labels
        .to_volume()
        .map_err(|e| in_file(&args.input, e))?;
    let (table, mut warnings) = (read.table, read.warnings);
    let mut out = OutputSet::protecting([&args.input]);
    out.create_dir(&args.output)?;
    let bar = progress(0, "labels", args.json);
    let meshed = voxlod::labels(&map, &label_options(args), &|p| {
        bar.set_length(p.total as u64);
        bar.set_position(p.done as u64);
        Control::Continue
    })
    .map_err(|e| in_flags(e.in_file(&args.input), FLAGS))?;
    bar.finish_and_clear();
    let mut reports = Vec::new();
    let mut firsts: Vec<(u32, TriangleMesh)> = Vec::new();
    for label in meshed.labels {
        let value = label.label.value as u32;
        let (report, first) = write_label(args, label, name_of(&table, value), &mut out)?;
        if !args.json {
            print_label(&report);
        }
        reports.push(report);
        if let Some(mesh) = first.filter(|m| !m.is_empty()) {
            firsts.push((value, mesh));
        }
    }
    let (all_labels, all_labels_gltf) = write_all_labels(
        &args.output,
        args.format,
        &firsts,
        &table,
        (&mut out, &mut warnings),
    )?;
    let report = LabelsReport {
        input: args.input.display().to_string(),
        surface: "filtered",
        frame: frame_report(map.world(), args.frame.target()),
        all_labels,
        all_labels_gltf,
        labels: reports,
        smoothing: None,
        precomputed: None,
        warnings,
        total_seconds: start.elapsed().as_secs_f64(),
    };
    finish(args, report, out, false)
}
