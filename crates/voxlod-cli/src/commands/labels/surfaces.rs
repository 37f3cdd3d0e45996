//! `voxlod labels` without a filter: every label meshed in one pass over the map
//! (`voxlod::label_surfaces`, marching cubes per label or the shared surface nets), written as
//! mesh files or as a neuroglancer precomputed layer.

use std::time::Instant;

use rayon::prelude::*;
use serde::Serialize;
use voxlod::core::{mesh_topology, Grid, LabelVolume, TriangleMesh};
use voxlod::io::{LabelMap, LabelName, OutputSet};
use voxlod::precomputed::{write_layer, LayerReport, PrecomputedOptions};
use voxlod::surfaces::{
    label_surfaces_owned, BudgetReport, LabelSurface, LabelSurfaces, LabelsError, SmoothingOptions,
    Surface, SurfaceOptions,
};

use super::{
    file_name, finish_with_budget, name_of, write_all_labels, AllLabelFiles, LabelReport,
    LabelsArgs, LabelsReport, LevelReport,
};
use crate::commands::common::{in_dir, in_file, CliError};
use crate::commands::world::frame_report;

/// What the smoothing of the shared surface did, in the report.
#[derive(Serialize)]
pub(super) struct SmoothingSummary {
    /// λ|μ pairs run.
    iterations: usize,
    /// Volume-restoring rounds run.
    restore_rounds: usize,
    /// The label whose volume changed most, and by how much (relative, after restoring).
    worst_label: Option<u32>,
    worst_volume_change: Option<f64>,
    /// Vertices that ended on a face of their half-voxel box.
    constrained_vertices: usize,
}

/// What the budget of `--triangles` did, in the report (beside the report's own fields).
#[derive(Serialize)]
pub(super) struct BudgetSummary {
    /// The budget, triangles per label.
    triangles_budget: usize,
    /// Labels left above it (their locked junctions, or pieces that could not be reduced
    /// without breaking them or moving them too far, hold more).
    labels_above_budget: usize,
    /// Connected pieces kept as they were because every reduction broke their topology (or, with
    /// --shared, moved them too far).
    pieces_kept_whole: usize,
}

impl BudgetSummary {
    /// The summary of `budget`, and the warning of the labels left above it.
    fn of(budget: &BudgetReport, shared: bool) -> (BudgetSummary, Option<String>) {
        let warning = budget.above.first().map(|&(label, triangles)| {
            let why = if shared {
                "the junctions where three labels meet are locked so neighbours stay joined, and \
                 no patch moves by more than a tenth of a voxel on average"
            } else {
                "what is left cannot be reduced without breaking a piece's topology"
            };
            format!(
                "{} label(s) stay above --triangles {} ({why}); the largest, label {label}, has {triangles} triangles",
                budget.above.len(),
                budget.triangles
            )
        });
        let summary = BudgetSummary {
            triangles_budget: budget.triangles,
            labels_above_budget: budget.above.len(),
            pieces_kept_whole: budget.kept_parts,
        };
        (summary, warning)
    }
}

/// What the precomputed layer holds, in the report.
#[derive(Serialize)]
pub(super) struct LayerSummary {
    /// Levels of detail per label.
    lods: usize,
    /// How the coarser levels were made: `simplified` (each from the finer one, the seams
    /// locked) or `filtered` (the paper's filter pyramid).
    coarser_levels: &'static str,
    /// Whether the meshes are sharded.
    sharded: bool,
    /// Per level of detail: triangles over all labels.
    triangles: Vec<usize>,
    /// Per level of detail: Draco bytes over all labels.
    bytes: Vec<u64>,
    /// Octree nodes (fragments) over all labels and levels.
    fragments: usize,
    /// Bytes of the volume's chunks.
    volume_bytes: u64,
    /// The layer's resolution, nanometres per voxel.
    resolution: [f64; 3],
}

impl LayerSummary {
    pub(super) fn of(report: &LayerReport, lods: usize, coarser: &'static str) -> LayerSummary {
        let mut summary = LayerSummary {
            lods,
            coarser_levels: coarser,
            sharded: report.sharding.is_some(),
            triangles: vec![0; lods],
            bytes: vec![0; lods],
            fragments: 0,
            volume_bytes: report.volume_bytes,
            resolution: report.resolution,
        };
        for (k, lod) in report.labels.iter().flat_map(|l| l.lods.iter().enumerate()) {
            summary.triangles[k] += lod.triangles;
            summary.bytes[k] += lod.bytes;
            summary.fragments += lod.fragments;
        }
        summary
    }
}

/// The warning for a layer's labels whose coarser levels hold a finer level's surface, because
/// the level had none (thinner than its filter, or smaller than its simplification's error).
pub(super) fn carried_warning(report: &LayerReport) -> Option<String> {
    let carried = (report.labels.iter())
        .filter(|l| l.lods.iter().any(|lod| lod.carried))
        .count();
    (carried > 0).then(|| format!(
        "{carried} label(s) have no surface at some coarser levels of detail (thinner than those levels' filter, or smaller than their simplification's error): each such level holds the finer level's surface"
    ))
}

/// The precomputed layer's options from the flags.
pub(super) fn precomputed_options(args: &LabelsArgs) -> PrecomputedOptions {
    let mut options = PrecomputedOptions::default();
    options.lods = args.levels.unwrap_or(options.lods);
    if let Some(bits) = args.quantization_bits {
        options.quantization_bits = bits;
    }
    if let Some(unit) = args.unit {
        options.nanometres_per_unit = unit.nanometres();
    }
    options
}

/// The library's options from the flags (a precomputed layer stays in the map's frame).
fn surface_options(args: &LabelsArgs) -> SurfaceOptions {
    let surface = if args.shared {
        let mut smoothing = SmoothingOptions::default();
        if let Some(n) = args.smooth {
            smoothing.iterations = n;
        }
        Surface::Shared(smoothing)
    } else {
        Surface::MarchingCubes
    };
    SurfaceOptions {
        surface,
        labels: args.labels.clone(),
        frame: args.frame.target(),
        triangles: args.triangles,
        ..SurfaceOptions::default()
    }
}

/// One label's report, its level 0 the surface at the map's resolution.
fn label_report(
    grid: &Grid,
    l: &LabelSurface,
    name: Option<&LabelName>,
    file: Option<String>,
    check: bool,
) -> LabelReport {
    let closed_manifold = check.then(|| {
        let t = mesh_topology(&l.mesh);
        t.is_closed_manifold() && t.is_consistently_oriented()
    });
    let finest = grid.spacing.iter().cloned().fold(f64::INFINITY, f64::min);
    LabelReport {
        label: l.label.value,
        name: name.map(|n| n.name.clone()),
        color: name.and_then(|n| n.color),
        voxels: l.label.voxels,
        voxel_volume: l.voxel_volume,
        levels: vec![LevelReport {
            level: 0,
            resolution: grid.dims.into_iter().max().unwrap_or(0),
            voxel_size: finest,
            file,
            triangles: l.mesh.triangles.len(),
            volume: l.mesh.signed_volume(),
            area: l.mesh.area(),
            closed_manifold,
            seconds: 0.0,
            envelope: None,
        }],
    }
}

fn smoothing_summary(surfaces: &LabelSurfaces) -> Option<SmoothingSummary> {
    surfaces.smoothing.as_ref().map(|s| SmoothingSummary {
        iterations: s.iterations,
        restore_rounds: s.restore_rounds,
        worst_label: s.worst.map(|w| w.label),
        worst_volume_change: s.worst.map(|w| w.relative()),
        constrained_vertices: s.constrained_vertices,
    })
}

/// Every label's mesh written as a file, with the all-labels files; the labels' reports.
fn write_files(
    args: &LabelsArgs,
    grid: &Grid,
    surfaces: Vec<LabelSurface>,
    table: &[LabelName],
    (out, warnings): (&mut OutputSet, &mut Vec<String>),
) -> Result<(Vec<LabelReport>, AllLabelFiles), CliError> {
    let ext = args.format.mesh().expect("mesh files");
    let reports: Vec<LabelReport> = surfaces
        .par_iter()
        .map(|l| {
            let name = name_of(table, l.label.value);
            let file = file_name(l.label.value, name, 0, 1, ext.as_str());
            label_report(grid, l, name, Some(file), args.check)
        })
        .collect();
    for (l, report) in surfaces.iter().zip(&reports) {
        let file = report.levels[0].file.as_deref().expect("named above");
        out.mesh(&in_dir(&args.output, file), &l.mesh)?;
    }
    let firsts: Vec<(u32, TriangleMesh)> = surfaces
        .into_iter()
        .map(|l| (l.label.value, l.mesh))
        .collect();
    Ok((
        reports,
        write_all_labels(&args.output, args.format, &firsts, table, (out, warnings))?,
    ))
}

/// The precomputed layer of the map and its labels' meshes; the labels' reports.
fn write_precomputed(
    args: &LabelsArgs,
    map: &LabelVolume,
    surfaces: Vec<LabelSurface>,
    table: &[LabelName],
) -> Result<(Vec<LabelReport>, LayerSummary, Option<String>), CliError> {
    let options = precomputed_options(args);
    let reports: Vec<LabelReport> = surfaces
        .par_iter()
        .map(|l| {
            label_report(
                &map.grid,
                l,
                name_of(table, l.label.value),
                None,
                args.check,
            )
        })
        .collect();
    let meshes: Vec<(u32, TriangleMesh)> = surfaces
        .into_iter()
        .map(|l| (l.label.value, l.mesh))
        .collect();
    let layer = write_layer(&args.output, map, &meshes, &options)
        .map_err(|e| CliError::Library(voxlod::Error::from(e)))?;
    let summary = LayerSummary::of(&layer, options.lods, "simplified");
    Ok((reports, summary, carried_warning(&layer)))
}

/// The library's call, its `--labels` error named by the flag.
fn meshed(args: &LabelsArgs, map: MapHeld) -> Result<LabelSurfaces, CliError> {
    let options = surface_options(args);
    let surfaces = match map {
        MapHeld::Borrowed(map) => voxlod::label_surfaces(map, &options),
        MapHeld::Owned(map) => label_surfaces_owned(map, &options).map_err(voxlod::Error::from),
    };
    surfaces.map_err(|e| match e {
        voxlod::Error::Labels(LabelsError::Missing(label, _)) => {
            CliError::usage(format!("--labels {label}: {e}"))
        }
        e => in_file(&args.input, e),
    })
}

/// The map, kept for the precomputed layer's chunks or given away to be dropped once meshed.
enum MapHeld<'a> {
    Borrowed(&'a LabelVolume),
    Owned(LabelVolume),
}

/// Every label meshed without a filter, written with the report.
pub(super) fn run(args: &LabelsArgs, read: LabelMap) -> Result<(), CliError> {
    let start = Instant::now();
    let (map, table, mut warnings) = (read.labels, read.table, read.warnings);
    let frame = frame_report(map.world(), args.frame.target());
    let surface = if args.shared {
        "surface_nets"
    } else {
        "marching_cubes"
    };
    let mut budget = None;
    let (reports, all_labels, all_labels_gltf, precomputed, smoothing, out) = match args
        .format
        .mesh()
    {
        Some(_) => {
            let grid = map.grid;
            let surfaces = meshed(args, MapHeld::Owned(map))?;
            let smoothing = smoothing_summary(&surfaces);
            if let Some(b) = &surfaces.budget {
                let (summary, warning) = BudgetSummary::of(b, args.shared);
                budget = Some(summary);
                warnings.extend(warning);
            }
            let mut out = OutputSet::protecting([&args.input]);
            out.create_dir(&args.output)?;
            let files = (&mut out, &mut warnings);
            let (reports, (all, gltf)) = write_files(args, &grid, surfaces.labels, &table, files)?;
            (reports, all, gltf, None, smoothing, out)
        }
        None => {
            let surfaces = meshed(args, MapHeld::Borrowed(&map))?;
            let smoothing = smoothing_summary(&surfaces);
            let (reports, layer, carried) = write_precomputed(args, &map, surfaces.labels, &table)?;
            warnings.extend(carried);
            let out = OutputSet::protecting([&args.input]);
            (reports, None, None, Some(layer), smoothing, out)
        }
    };
    let report = LabelsReport {
        input: args.input.display().to_string(),
        surface,
        frame,
        all_labels,
        all_labels_gltf,
        labels: reports,
        smoothing,
        precomputed,
        warnings,
        total_seconds: start.elapsed().as_secs_f64(),
    };
    finish_with_budget(args, report, budget, out, true)
}
