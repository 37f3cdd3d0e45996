//! `voxlod labels`: a label map (segmentation) in, one closed mesh per structure out, each with
//! its levels of detail (`voxlod::labels`).

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use serde::Serialize;
use voxlod::core::TriangleMesh;
use voxlod::gltf::{labels_glb, LabelMesh};
use voxlod::io::{read_label_map, LabelName, OutputSet};
use voxlod::labels::{merge_labelled, LabelLevels, LabelOptions};
use voxlod::sampling::Filter;
use voxlod::{Control, EnvelopeStep, LevelEpsilon, ThenEnvelope};

use super::common::say;
use super::common::{add_report, in_dir, print_json, progress, CliError, MeshExtension};
use super::values::{in_flags, number};
use super::world::{frame_report, FrameArg, FrameReport};

/// The library's option names that are not the flags' names.
const FLAGS: &[(&str, &str)] = &[("radius_voxels", "--radius")];

/// Mesh a label map: one closed, outward mesh per label (NIfTI, NRRD, MetaImage, Slicer .seg.nrrd,
/// DICOM Segmentation).
///
/// Each label's inside function (its voxels, trilinearly thresholded at ½) is filtered and
/// contoured like a thresholded scan (paper §2, §4), so --levels, --filter, --radius and
/// --then-envelope mean what they mean for `voxlod lod`; level 0 samples at the map's finest
/// spacing. Levels are cleaned of slivers, needles and self-intersections as `voxlod lod` cleans
/// them (--no-clean keeps plain marching cubes). Labels are meshed in parallel, largest first. Writes DIR/label-V.ply (or label-V-NAME.ply when the file names its segments,
/// label-V-K.ply for level K of several), every label's level 0 together in DIR/labels.vtp
/// (per-vertex `label`) and DIR/labels.glb (one node per label, per-vertex `_LABEL`), and
/// DIR/report.json (per label: voxels, voxel volume, and per level triangles, mesh volume and
/// area).
///
/// Examples:
///   voxlod labels segmentation.nii.gz -o organs
///   voxlod labels Segmentation.seg.nrrd -o models --frame lps --labels 1,4,7
///   voxlod labels aseg.mha -o aseg --levels 3 --then-envelope 1vox
///   voxlod labels SEG.dcm -o segments   # or a folder holding one DICOM SEG file
#[derive(Args, Debug)]
#[command(verbatim_doc_comment)]
pub struct LabelsArgs {
    /// The label map: integer samples, 0 is background (.nrrd .nhdr .nii .nii.gz .mha .mhd .vti),
    /// or a DICOM Segmentation (a SEG .dcm, or a folder holding one): segment numbers are labels
    pub input: PathBuf,
    /// Folder for the meshes and report.json (created if missing)
    #[arg(short, long, value_name = "DIR")]
    pub output: PathBuf,
    /// Only these labels, e.g. 1,4,7 (default: every non-zero label)
    #[arg(long, value_name = "A,B,...", value_delimiter = ',',
        value_parser = number::<i64>, allow_hyphen_values = true)]
    pub labels: Option<Vec<i64>>,
    /// Levels per label, each half the resolution of the one before
    #[arg(long, value_name = "L", default_value_t = 1,
        value_parser = number::<usize>, allow_hyphen_values = true)]
    pub levels: usize,
    /// Low-pass filter: hypercone (paper eq. 3) or gaussian (σ = R/3)
    #[arg(long, default_value = "hypercone")]
    pub filter: Filter,
    /// Filter support radius, in voxels of each level
    #[arg(long, value_name = "VOXELS", default_value_t = 1.0,
        value_parser = number::<f64>, allow_hyphen_values = true)]
    pub radius: f64,
    /// Format of the per-label meshes
    #[arg(long, value_enum, default_value = "ply")]
    pub format: MeshExtension,
    /// Then simplify each level within E by simplification envelopes: a distance, a percentage
    /// of the level's diagonal (1%), or voxels of the level (1vox)
    #[arg(long, value_name = "E", value_parser = parse_level_epsilon,
        allow_hyphen_values = true)]
    pub then_envelope: Option<LevelEpsilon>,
    /// Keep plain marching cubes (no cleaning of slivers, needles and self-intersections)
    #[arg(long)]
    pub no_clean: bool,
    #[command(flatten)]
    pub frame: FrameArg,
    /// Print the report as JSON on standard output (no progress bar)
    #[arg(long)]
    pub json: bool,
}

#[derive(Serialize)]
struct LevelReport {
    level: usize,
    resolution: usize,
    voxel_size: f64,
    file: Option<String>,
    triangles: usize,
    /// Enclosed volume of the mesh, in world units cubed.
    volume: f64,
    area: f64,
    closed_manifold: bool,
    seconds: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    envelope: Option<EnvelopeStep>,
}

#[derive(Serialize)]
struct LabelReport {
    label: i64,
    name: Option<String>,
    color: Option<[f32; 3]>,
    voxels: usize,
    /// Voxel count times the voxel's volume.
    voxel_volume: f64,
    levels: Vec<LevelReport>,
}

#[derive(Serialize)]
struct LabelsReport {
    input: String,
    #[serde(flatten)]
    frame: FrameReport,
    all_labels: Option<String>,
    /// The glTF with every label's level 0 (`_LABEL` per vertex).
    all_labels_gltf: Option<String>,
    labels: Vec<LabelReport>,
    /// What reading the map warned of (overlapping DICOM segments).
    warnings: Vec<String>,
    total_seconds: f64,
}

/// `liver` → `liver`, `Left Kidney` → `left-kidney`: a name safe in a file name.
fn slug(name: &str) -> String {
    let mut out = String::new();
    for c in name.chars() {
        if c.is_ascii_alphanumeric() {
            out.push(c.to_ascii_lowercase());
        } else if !out.ends_with('-') {
            out.push('-');
        }
    }
    out.trim_matches('-').chars().take(60).collect()
}

fn file_name(
    label: i64,
    name: Option<&LabelName>,
    level: usize,
    levels: usize,
    ext: &str,
) -> String {
    let mut stem = format!("label-{label}");
    if let Some(n) = name.map(|n| slug(&n.name)).filter(|s| !s.is_empty()) {
        stem.push('-');
        stem.push_str(&n);
    }
    if levels > 1 {
        stem.push_str(&format!("-{level}"));
    }
    format!("{stem}.{ext}")
}

/// The value parser of `--then-envelope` (the error without the flag's name).
fn parse_level_epsilon(text: &str) -> Result<LevelEpsilon, String> {
    text.parse()
}

/// One label's levels (made by `voxlod::labels`), staged for writing: its report and its
/// level 0.
fn write_label(
    args: &LabelsArgs,
    label: LabelLevels,
    name: Option<&LabelName>,
    out: &mut OutputSet,
) -> Result<(LabelReport, Option<TriangleMesh>), CliError> {
    let value = label.label.value;
    let mut reports = Vec::new();
    let mut first = None;
    let count = label.levels.len();
    for level in label.levels {
        let start = Instant::now();
        let mesh = level.mesh;
        let k = level.plan.level;
        let file =
            (!mesh.is_empty()).then(|| file_name(value, name, k, count, args.format.as_str()));
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
            closed_manifold: t.is_closed_manifold() && t.is_consistently_oriented(),
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
        voxels: label.label.voxels,
        voxel_volume: label.voxel_volume,
        levels: reports,
    };
    Ok((report, first))
}

/// The library's options from the flags.
fn label_options(args: &LabelsArgs) -> LabelOptions {
    let mut options = LabelOptions::for_levels(args.levels);
    options.labels = args.labels.clone();
    options.lod.pyramid.filter = args.filter;
    options.lod.pyramid.radius_voxels = args.radius;
    options.lod.clean = options.lod.clean.filter(|_| !args.no_clean);
    options.frame = args.frame.target();
    options.then_envelope = args.then_envelope.map(ThenEnvelope::new);
    options
}

/// Every label's level 0 (those with a surface) in one `.vtp` and one `.glb`; their file names.
fn write_all_labels(
    args: &LabelsArgs,
    firsts: &[(i64, TriangleMesh)],
    table: &[LabelName],
    out: &mut OutputSet,
) -> Result<(Option<String>, Option<String>), CliError> {
    if firsts.is_empty() {
        return Ok((None, None));
    }
    let refs: Vec<(i64, &TriangleMesh)> = firsts.iter().map(|(v, m)| (*v, m)).collect();
    out.poly_mesh(&in_dir(&args.output, "labels.vtp"), &merge_labelled(&refs))?;
    let gltf: Vec<LabelMesh> = firsts
        .iter()
        .map(|(value, mesh)| {
            let name = table.iter().find(|n| n.value == *value);
            LabelMesh {
                value: *value,
                name: name.map(|n| n.name.as_str()),
                color: name.and_then(|n| n.color),
                mesh,
            }
        })
        .collect();
    let glb = labels_glb(&gltf).map_err(voxlod::Error::from)?;
    out.bytes(&in_dir(&args.output, "labels.glb"), &glb)?;
    Ok((Some("labels.vtp".into()), Some("labels.glb".into())))
}

/// The one line a label gets on the terminal.
fn print_label(report: &LabelReport) {
    let l0 = &report.levels[0];
    say(format_args!(
        "label {}{}: {} voxels, {} triangles, volume {:.1} (voxels: {:.1}), area {:.1}",
        report.label,
        report
            .name
            .as_deref()
            .map(|n| format!(" ({n})"))
            .unwrap_or_default(),
        report.voxels,
        l0.triangles,
        l0.volume,
        report.voxel_volume,
        l0.area
    ));
}

pub fn run(args: LabelsArgs) -> Result<(), CliError> {
    let start = Instant::now();
    if args.levels == 0 {
        return Err(CliError::usage("--levels must be at least 1"));
    }
    let read = read_label_map(&args.input)?;
    let map = (read.labels.to_volume()).map_err(|e| super::common::in_file(&args.input, e))?;
    let table = read.table;
    if !args.json {
        for w in &read.warnings {
            eprintln!("warning: {w}");
        }
    }
    args.frame.check(&map, &args.input)?;
    let mut out = OutputSet::protecting([&args.input]);
    out.create_dir(&args.output)?;
    let bar = progress(0, "labels", args.json);
    let meshed = voxlod::labels(&map, &label_options(&args), &|p| {
        bar.set_length(p.total as u64);
        bar.set_position(p.done as u64);
        Control::Continue
    })
    .map_err(|e| in_flags(e.in_file(&args.input), FLAGS))?;
    bar.finish_and_clear();
    let mut reports = Vec::new();
    let mut firsts: Vec<(i64, TriangleMesh)> = Vec::new();
    for label in meshed.labels {
        let value = label.label.value;
        let name = table.iter().find(|n| n.value == value);
        let (report, first) = write_label(&args, label, name, &mut out)?;
        if !args.json {
            print_label(&report);
        }
        reports.push(report);
        if let Some(mesh) = first.filter(|m| !m.is_empty()) {
            firsts.push((value, mesh));
        }
    }
    let (all_labels, all_labels_gltf) = write_all_labels(&args, &firsts, &table, &mut out)?;
    let frame = frame_report(&map, args.frame.target());
    let report = LabelsReport {
        input: args.input.display().to_string(),
        frame,
        all_labels,
        all_labels_gltf,
        labels: reports,
        warnings: read.warnings,
        total_seconds: start.elapsed().as_secs_f64(),
    };
    add_report(&mut out, &args.output, &report)?;
    out.commit()?;
    if args.json {
        print_json(&report)?;
    } else {
        say(format_args!(
            "{} labels written to {} in {:.2} s",
            report.labels.len(),
            args.output.display(),
            report.total_seconds
        ));
    }
    Ok(())
}
