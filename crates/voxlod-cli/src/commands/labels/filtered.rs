//! `voxlod labels` with levels or a filter: each label's indicator filtered and contoured as a
//! thresholded scan, level by level (paper §2, §4; `voxlod::labels`), written as mesh files or,
//! with `--format precomputed` and a filter, as the levels of detail of a neuroglancer layer.

use std::time::Instant;

use voxlod::core::TriangleMesh;
use voxlod::io::{LabelMap, LabelName, OutputSet};
use voxlod::labels::{LabelLevels, LabelOptions};
use voxlod::{Control, ThenEnvelope};

use super::{
    file_name, finish, name_of, print_label, surfaces, write_all_labels, LabelFormat, LabelReport,
    LabelsArgs, LabelsReport, LevelReport,
};
use crate::commands::common::{in_dir, progress, CliError};
use crate::commands::values::in_flags;
use crate::commands::world::{frame_report, FrameReport};
use voxlod::precomputed::write_layer_filtered;

/// The library's option names that are not the flags' names.
const FLAGS: &[(&str, &str)] = &[("radius_voxels", "--radius")];

/// Whether the flags ask for the filtered levels.
pub(super) fn asked_for(args: &LabelsArgs) -> bool {
    args.levels.is_some()
        || args.filter.is_some()
        || args.radius.is_some()
        || args.then_envelope.is_some()
}

/// Whether the flags ask for a precomputed layer's levels from the filter pyramid.
pub(super) fn pyramid_asked_for(args: &LabelsArgs) -> bool {
    args.format == LabelFormat::Precomputed && (args.filter.is_some() || args.radius.is_some())
}

/// The library's options from the flags: as many levels as the layer's levels of detail for a
/// precomputed layer.
fn label_options(args: &LabelsArgs) -> LabelOptions {
    let levels = match args.format {
        LabelFormat::Precomputed => surfaces::precomputed_options(args).lods,
        _ => args.levels.unwrap_or(1),
    };
    let mut options = LabelOptions::for_levels(levels);
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
    let count = label.levels.len();
    let file_of = |k: usize, mesh: &TriangleMesh| {
        (!mesh.is_empty()).then(|| file_name(value, name, k, count, ext.as_str()))
    };
    for level in &label.levels {
        if let Some(f) = file_of(level.plan.level, &level.mesh) {
            out.mesh(&in_dir(&args.output, &f), &level.mesh)?;
        }
    }
    let report = level_reports(&label, name, file_of);
    let first = (label.levels.into_iter())
        .find(|l| l.plan.level == 0)
        .map(|l| l.mesh);
    Ok((report, first))
}

/// One label's report, level `k`'s file named by `file_of(k, mesh)` where it was written.
fn level_reports(
    label: &LabelLevels,
    name: Option<&LabelName>,
    file_of: impl Fn(usize, &TriangleMesh) -> Option<String>,
) -> LabelReport {
    let levels = (label.levels.iter())
        .map(|level| {
            let (mesh, t) = (&level.mesh, &level.topology);
            LevelReport {
                level: level.plan.level,
                resolution: level.plan.resolution,
                voxel_size: level.plan.voxel_size,
                file: file_of(level.plan.level, mesh),
                triangles: mesh.triangles.len(),
                volume: mesh.signed_volume(),
                area: mesh.area(),
                closed_manifold: Some(t.is_closed_manifold() && t.is_consistently_oriented()),
                seconds: level.sample_seconds + level.contour_seconds,
                envelope: level.envelope.clone(),
            }
        })
        .collect();
    LabelReport {
        label: label.label.value as u32,
        name: name.map(|n| n.name.clone()),
        color: name.and_then(|n| n.color),
        voxels: label.label.voxels as u64,
        voxel_volume: label.voxel_volume,
        levels,
    }
}

/// The filtered levels of every label, written with the report.
pub(super) fn run(args: &LabelsArgs, read: LabelMap) -> Result<(), CliError> {
    let start = Instant::now();
    // The map as read: its u32 labels exact, however large.
    let map = &read.labels;
    let bar = progress(0, "labels", args.json);
    let meshed = voxlod::labels(map, &label_options(args), &|p| {
        bar.set_length(p.total as u64);
        bar.set_position(p.done as u64);
        Control::Continue
    })
    .map_err(|e| in_flags(e.in_file(&args.input), FLAGS))?;
    bar.finish_and_clear();
    let frame = frame_report(map.world(), args.frame.target());
    let precomputed = args.format == LabelFormat::Precomputed;
    let vanished = vanished(&meshed.labels, precomputed, &args.input)?;
    if precomputed {
        return write_precomputed(args, read, meshed.labels, (frame, start, vanished));
    }
    let (table, mut warnings) = (read.table, read.warnings);
    warnings.extend(vanished);
    let mut out = OutputSet::protecting([&args.input]);
    out.create_dir(&args.output)?;
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
        frame,
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

/// Labels listed by value in a warning at most.
const LISTED: usize = 10;

/// The warning for labels with levels the filter emptied (thinner than those levels' filter):
/// for mesh files, any level (it gets no file); for a precomputed layer, level 0 (the label
/// gets no mesh; its coarser levels are carried, `write_layer_filtered`). Fails, writing
/// nothing, when no label has a level with a surface to write.
fn vanished(
    labels: &[LabelLevels],
    precomputed: bool,
    input: &std::path::Path,
) -> Result<Option<String>, CliError> {
    let empty = |l: &&LabelLevels| match precomputed {
        true => l.levels.first().is_none_or(|level| level.mesh.is_empty()),
        false => l.levels.iter().any(|level| level.mesh.is_empty()),
    };
    let values: Vec<String> = (labels.iter().filter(empty))
        .map(|l| l.label.value.to_string())
        .collect();
    let written = |l: &LabelLevels| match precomputed {
        true => !l.levels[0].mesh.is_empty(),
        false => l.levels.iter().any(|level| !level.mesh.is_empty()),
    };
    if !labels.iter().any(written) {
        return Err(CliError::msg(format!(
            "{}: no label has a surface at any level: the filter removed every one of the {} labels, each thinner than the filter at every level",
            input.display(),
            labels.len()
        )));
    }
    if values.is_empty() {
        return Ok(None);
    }
    let listed = values
        .iter()
        .take(LISTED)
        .cloned()
        .collect::<Vec<_>>()
        .join(", ");
    let more = if values.len() > LISTED { ", …" } else { "" };
    let what = match precomputed {
        true => "no surface even at level 0 (thinner than the finest filter): the layer has no mesh for them",
        false => "no surface at some levels (thinner than those levels' filter): those levels have no file",
    };
    Ok(Some(format!(
        "{} label(s) have {what} (labels {listed}{more})",
        values.len()
    )))
}

/// The precomputed layer of the map whose levels of detail are the labels' filtered levels
/// (`voxlod::precomputed::write_layer_filtered`), written with the report.
fn write_precomputed(
    args: &LabelsArgs,
    read: LabelMap,
    labels: Vec<LabelLevels>,
    (frame, start, vanished): (FrameReport, Instant, Option<String>),
) -> Result<(), CliError> {
    let options = surfaces::precomputed_options(args);
    let (table, mut warnings) = (read.table, read.warnings);
    warnings.extend(vanished);
    let reports: Vec<LabelReport> = (labels.iter())
        .map(|l| level_reports(l, name_of(&table, l.label.value as u32), |_, _| None))
        .collect();
    let levels: Vec<(u32, Vec<TriangleMesh>)> = (labels.into_iter())
        .map(|l| {
            let meshes = l.levels.into_iter().map(|level| level.mesh).collect();
            (l.label.value as u32, meshes)
        })
        .collect();
    let layer = write_layer_filtered(&args.output, &read.labels, &levels, &options)
        .map_err(|e| CliError::Library(voxlod::Error::from(e)))?;
    warnings.extend(surfaces::carried_warning(&layer));
    let report = LabelsReport {
        input: args.input.display().to_string(),
        surface: "filtered",
        frame,
        all_labels: None,
        all_labels_gltf: None,
        labels: reports,
        smoothing: None,
        precomputed: Some(surfaces::LayerSummary::of(&layer, options.lods, "filtered")),
        warnings,
        total_seconds: start.elapsed().as_secs_f64(),
    };
    finish(args, report, OutputSet::protecting([&args.input]), true)
}
