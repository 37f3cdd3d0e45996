//! `voxlod labels`: a label map (segmentation) in, one closed mesh per structure out: by default
//! every label meshed in one pass without a filter (`surfaces.rs`, `voxlod::label_surfaces`),
//! or the paper's filtered levels per label when levels or a filter are asked for
//! (`filtered.rs`, `voxlod::labels`); written as mesh files or as a neuroglancer precomputed
//! layer.

mod filtered;
mod surfaces;

use std::path::PathBuf;

use clap::{Args, ValueEnum};
use serde::Serialize;
use voxlod::core::TriangleMesh;
use voxlod::gltf::{labels_glb, LabelMesh};
use voxlod::io::{read_label_map, LabelMap, LabelName, OutputSet};
use voxlod::labels::merge_labelled;
use voxlod::sampling::Filter;
use voxlod::{EnvelopeStep, LevelEpsilon};

use super::common::{add_report, in_dir, print_json, say, CliError, MeshExtension};
use super::values::number;
use super::world::{FrameArg, FrameReport};

/// Mesh a label map: one closed, outward mesh per label (NIfTI, NRRD, MetaImage, VTK image, Zarr,
/// Slicer .seg.nrrd, DICOM Segmentation, or a neuroglancer precomputed layer; labels are whole
/// numbers up to 4294967295, 0 is background).
///
/// By default every label is meshed in one pass over the map by marching cubes of its voxels
/// (the isosurface ½ of the label's indicator, as zmesh makes it): each label closed and outward
/// on its own. With --shared the labels are meshed together by surface nets (Frisken 2022): each
/// interface between two labels is meshed once and used by both, so neighbours meet without gap
/// or overlap; the shared surface is then smoothed (--smooth, λ|μ iterations) with each vertex
/// kept within half a voxel of its corner and each label's volume kept.
///
/// With --triangles N each label's mesh is then reduced to at most about N triangles by quadric
/// edge collapse (meshoptimizer), its topology kept. With --shared the smoothed surface is
/// simplified patch by patch (the triangles between one pair of labels), the junctions where
/// three labels meet locked with the vertices next to them, so neighbours still share every
/// triangle of their interface, and no patch moved by more than a tenth of a voxel on average;
/// a label whose locked junctions hold more than N triangles stays above it, with a warning.
///
/// With --levels, --filter, --radius or --then-envelope each label's indicator is filtered and
/// contoured like a thresholded scan instead (paper §2, §4), level 0 at the map's finest spacing,
/// each further level at half the resolution, cleaned of slivers unless --no-clean.
///
/// Writes DIR/label-V.ply (label-V-NAME.ply when the file names its segments, label-V-K.ply for
/// level K of several), every label's level 0 together in DIR/labels.glb (one node per label;
/// with --format vtp or vtk also in DIR/labels.vtp, per-vertex `label`), and DIR/report.json. With --format precomputed, DIR
/// becomes a neuroglancer precomputed segmentation layer instead: the labels in raw chunks and
/// per label a multi-resolution mesh of --levels levels (Draco fragments on the octree's grid),
/// sharded above 512 labels; cloud-volume and neuroglancer read it. Its coarser levels are each
/// simplified from the finer one with the fragments' seams locked, so no crack opens between
/// levels; with --filter or --radius they are the paper's filter pyramid instead (level k the
/// label's indicator filtered at 1/2^k of the map's resolution), smoother and with fewer handles,
/// whose consecutive levels meet on a fragment's face only within about their filters' radii.
///
/// Examples:
///   voxlod labels segmentation.nii.gz -o organs
///   voxlod labels Segmentation.seg.nrrd -o models --shared --frame lps --labels 1,4,7
///   voxlod labels cells.nrrd -o cells --shared --smooth 8 --triangles 5000
///   voxlod labels aseg.mha -o aseg --levels 3 --then-envelope 1vox
///   voxlod labels cells.nrrd -o layer --format precomputed --levels 3 --unit nm
///   voxlod labels cells.nrrd -o layer --format precomputed --levels 4 --filter hypercone
///   voxlod labels SEG.dcm -o segments   # or a folder holding one DICOM SEG file
#[derive(Args, Debug)]
#[command(verbatim_doc_comment)]
pub struct LabelsArgs {
    /// The label map (.nrrd .nhdr .nii .nii.gz .mha .mhd .vti .vtk .zarr), a DICOM
    /// Segmentation (a SEG .dcm, or a folder holding one: segment numbers are labels), or a
    /// precomputed layer (a folder holding `info`; raw or compressed_segmentation chunks, in
    /// nanometres)
    pub input: PathBuf,
    /// Folder for the meshes and report.json (created if missing), or the precomputed layer
    #[arg(short, long, value_name = "DIR")]
    pub output: PathBuf,
    /// Only these labels, e.g. 1,4,7 (default: every non-zero label)
    #[arg(long, value_name = "A,B,...", value_delimiter = ',',
        value_parser = number::<u32>, allow_hyphen_values = true)]
    pub labels: Option<Vec<u32>>,
    /// Mesh every interface between two labels once, shared by both (surface nets), smoothed
    #[arg(long)]
    pub shared: bool,
    /// λ|μ smoothing iterations of the --shared surface, volumes kept (0 keeps the voxel faces)
    #[arg(long, value_name = "N", value_parser = number::<usize>, allow_hyphen_values = true)]
    pub smooth: Option<usize>,
    /// Reduce each label's mesh to at most about N triangles (at least 4; with --shared the
    /// interfaces stay shared, their junctions locked)
    #[arg(long, value_name = "N", value_parser = number::<usize>, allow_hyphen_values = true)]
    pub triangles: Option<usize>,
    /// Levels per label: the paper's filtered levels (each half the resolution of the one
    /// before), or with --format precomputed the levels of the multi-resolution mesh
    #[arg(long, value_name = "L", value_parser = number::<usize>, allow_hyphen_values = true)]
    pub levels: Option<usize>,
    /// Low-pass filter of the filtered levels: hypercone (paper eq. 3) or gaussian (σ = R/3)
    #[arg(long)]
    pub filter: Option<Filter>,
    /// Filter support radius of the filtered levels, in voxels of each level (default 1)
    #[arg(long, value_name = "VOXELS", value_parser = number::<f64>, allow_hyphen_values = true)]
    pub radius: Option<f64>,
    /// Format of the per-label meshes, or `precomputed` for a neuroglancer layer
    #[arg(long, value_enum, default_value = "ply")]
    pub format: LabelFormat,
    /// Bits per quantized coordinate of the precomputed meshes (10 or 16)
    #[arg(long, value_name = "BITS", value_parser = number::<u32>, allow_hyphen_values = true)]
    pub quantization_bits: Option<u32>,
    /// Unit of the map's spacing, for the precomputed layer's resolution in nanometres
    #[arg(long, value_enum)]
    pub unit: Option<SpacingUnit>,
    /// Then simplify each filtered level within E by simplification envelopes: a distance, a
    /// percentage of the level's diagonal (1%), or voxels of the level (1vox)
    #[arg(long, value_name = "E", value_parser = parse_level_epsilon,
        allow_hyphen_values = true)]
    pub then_envelope: Option<LevelEpsilon>,
    /// Measure each label's topology for the report (closed, manifold, consistently oriented):
    /// the filtered levels always are; for the one-pass surfaces it costs about what meshing does
    #[arg(long)]
    pub check: bool,
    /// Keep plain marching cubes for the filtered levels (no cleaning of slivers, needles and
    /// self-intersections); the default surface is plain marching cubes already
    #[arg(long)]
    pub no_clean: bool,
    #[command(flatten)]
    pub frame: FrameArg,
    /// Print the report as JSON on standard output (no progress bar)
    #[arg(long)]
    pub json: bool,
}

/// What `--format` writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum LabelFormat {
    Ply,
    Obj,
    Stl,
    Vtp,
    Vtk,
    /// A neuroglancer precomputed segmentation layer with multi-resolution meshes
    Precomputed,
}

impl LabelFormat {
    /// The mesh files' format, `None` for a precomputed layer.
    fn mesh(self) -> Option<MeshExtension> {
        match self {
            LabelFormat::Ply => Some(MeshExtension::Ply),
            LabelFormat::Obj => Some(MeshExtension::Obj),
            LabelFormat::Stl => Some(MeshExtension::Stl),
            LabelFormat::Vtp => Some(MeshExtension::Vtp),
            LabelFormat::Vtk => Some(MeshExtension::Vtk),
            LabelFormat::Precomputed => None,
        }
    }
}

/// The unit of a map's spacing.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum SpacingUnit {
    /// Nanometres (connectomics maps)
    Nm,
    /// Micrometres (micro-CT, light microscopy)
    Um,
    /// Millimetres (medical maps)
    Mm,
}

impl SpacingUnit {
    fn nanometres(self) -> f64 {
        match self {
            SpacingUnit::Nm => 1.0,
            SpacingUnit::Um => 1e3,
            SpacingUnit::Mm => 1e6,
        }
    }
}

/// The value parser of `--then-envelope` (the error without the flag's name).
fn parse_level_epsilon(text: &str) -> Result<LevelEpsilon, String> {
    text.parse()
}

/// One level of a label in the report.
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
    /// Closed, manifold and consistently oriented (`null` where not measured: see `--check`).
    closed_manifold: Option<bool>,
    seconds: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    envelope: Option<EnvelopeStep>,
}

/// One label in the report.
#[derive(Serialize)]
struct LabelReport {
    label: u32,
    name: Option<String>,
    color: Option<[f32; 3]>,
    voxels: u64,
    /// Voxel count times the voxel's volume.
    voxel_volume: f64,
    levels: Vec<LevelReport>,
}

/// The whole report (report.json, `--json`).
#[derive(Serialize)]
struct LabelsReport {
    input: String,
    /// `marching_cubes`, `surface_nets` or `filtered`.
    surface: &'static str,
    #[serde(flatten)]
    frame: FrameReport,
    all_labels: Option<String>,
    /// The glTF with every label's level 0 (`_LABEL` per vertex).
    all_labels_gltf: Option<String>,
    labels: Vec<LabelReport>,
    #[serde(skip_serializing_if = "Option::is_none")]
    smoothing: Option<surfaces::SmoothingSummary>,
    #[serde(skip_serializing_if = "Option::is_none")]
    precomputed: Option<surfaces::LayerSummary>,
    /// What reading the map warned of (overlapping DICOM segments).
    warnings: Vec<String>,
    total_seconds: f64,
}

/// Refuses flags that do not go together, naming them.
fn check_flags(args: &LabelsArgs) -> Result<(), CliError> {
    let filtered = filtered::asked_for(args);
    let precomputed = args.format == LabelFormat::Precomputed;
    let refuse = |text: &str| Err(CliError::usage(text.to_string()));
    if args.levels == Some(0) {
        return refuse("--levels must be at least 1");
    }
    if args.smooth.is_some() && !args.shared {
        return refuse("--smooth smooths the --shared surface: add --shared");
    }
    if args
        .triangles
        .is_some_and(|n| n < voxlod::surfaces::budget::MIN_TRIANGLES)
    {
        return refuse("--triangles must be at least 4 (a closed surface needs four triangles)");
    }
    if precomputed && args.triangles.is_some() {
        return refuse("--triangles does not apply to --format precomputed: the layer makes its coarser levels itself (--levels)");
    }
    if filtered && args.triangles.is_some() {
        return refuse("--triangles reduces the one-pass surfaces (marching cubes or --shared): it does not go with --levels, --filter, --radius or --then-envelope");
    }
    if precomputed && args.shared && filtered::pyramid_asked_for(args) {
        return refuse("--shared meshes the labels together without a filter: it does not go with --filter or --radius, which make --format precomputed's levels from the filter pyramid");
    }
    if precomputed && args.then_envelope.is_some() {
        return refuse("--then-envelope does not apply to --format precomputed");
    }
    if filtered && args.shared && !precomputed {
        return refuse("--shared meshes the labels together without a filter: it does not go with --levels, --filter, --radius or --then-envelope");
    }
    if precomputed && args.frame.target().is_some() {
        return refuse(
            "--frame does not apply to --format precomputed: a layer keeps the map's own axes",
        );
    }
    if !precomputed && (args.quantization_bits.is_some() || args.unit.is_some()) {
        return refuse("--quantization-bits and --unit apply to --format precomputed only");
    }
    Ok(())
}

pub fn run(args: LabelsArgs) -> Result<(), CliError> {
    check_flags(&args)?;
    let read = read_map(&args.input)?;
    args.frame
        .check(read.labels.orientation.frame, &args.input)?;
    let precomputed = args.format == LabelFormat::Precomputed;
    if filtered::asked_for(&args) && (!precomputed || filtered::pyramid_asked_for(&args)) {
        filtered::run(&args, read)
    } else {
        surfaces::run(&args, read)
    }
}

/// The label map of `input`: a neuroglancer precomputed layer (a folder holding `info`; its
/// labels in nanometres), or any file `read_label_map` reads.
fn read_map(input: &std::path::Path) -> Result<LabelMap, CliError> {
    if !input.join("info").is_file() {
        return Ok(read_label_map(input)?);
    }
    let labels = voxlod::precomputed::read_labels(input)
        .map_err(|e| CliError::Library(voxlod::Error::from(e)))?;
    Ok(LabelMap {
        labels,
        table: Vec::new(),
        warnings: Vec::new(),
    })
}

/// The report written beside the meshes (or into the layer), then printed: as JSON, or the
/// warnings, each label's line when `per_label` (the filtered route prints them as it goes) and
/// a summary.
fn finish(
    args: &LabelsArgs,
    report: LabelsReport,
    out: OutputSet,
    per_label: bool,
) -> Result<(), CliError> {
    finish_with_budget(args, report, None, out, per_label)
}

/// The report with what the budget did (`--triangles`), its fields beside the report's own.
#[derive(Serialize)]
struct Written<'a> {
    #[serde(flatten)]
    report: &'a LabelsReport,
    #[serde(flatten)]
    budget: Option<&'a surfaces::BudgetSummary>,
}

/// [`finish`], the budget's summary added to the report when there is one.
fn finish_with_budget(
    args: &LabelsArgs,
    report: LabelsReport,
    budget: Option<surfaces::BudgetSummary>,
    mut out: OutputSet,
    per_label: bool,
) -> Result<(), CliError> {
    let written = Written {
        report: &report,
        budget: budget.as_ref(),
    };
    add_report(&mut out, &args.output, &written)?;
    out.commit()?;
    if args.json {
        return print_json(&written);
    }
    for w in &report.warnings {
        eprintln!("warning: {w}");
    }
    for label in report.labels.iter().filter(|_| per_label) {
        print_label(label);
    }
    say(format_args!(
        "{} labels written to {} in {:.2} s",
        report.labels.len(),
        args.output.display(),
        report.total_seconds
    ));
    Ok(())
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

/// The file of level `level` of `levels` of a label.
fn file_name(
    label: u32,
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

/// The entry of the map's label table for `value`.
fn name_of(table: &[LabelName], value: u32) -> Option<&LabelName> {
    table.iter().find(|n| n.value == i64::from(value))
}

/// The names of the `.vtp` and the `.glb` of every label's level 0 (`None` when not written).
type AllLabelFiles = (Option<String>, Option<String>);

/// The most triangles the files of all labels together hold: beyond, a viewer would not open
/// them, and they would double the output; each label's own file is written all the same.
const ALL_LABELS_MAX_TRIANGLES: usize = 4_000_000;

/// Every label's level 0 (those with a surface) in one `.glb`, and in one `.vtp` when the
/// per-label files are VTK's (`vtp`, `vtk`); their file names. Not written, with a warning, when
/// the labels hold more than [`ALL_LABELS_MAX_TRIANGLES`] together.
fn write_all_labels(
    output: &std::path::Path,
    format: LabelFormat,
    firsts: &[(u32, TriangleMesh)],
    table: &[LabelName],
    (out, warnings): (&mut OutputSet, &mut Vec<String>),
) -> Result<AllLabelFiles, CliError> {
    let triangles: usize = firsts.iter().map(|(_, m)| m.triangles.len()).sum();
    if triangles > ALL_LABELS_MAX_TRIANGLES {
        warnings.push(format!(
            "labels.glb not written: the labels hold {triangles} triangles together, more than \
             {ALL_LABELS_MAX_TRIANGLES}; each label has its own file (or see --format precomputed)"
        ));
        return Ok((None, None));
    }
    if firsts.is_empty() {
        return Ok((None, None));
    }
    let vtp = matches!(format, LabelFormat::Vtp | LabelFormat::Vtk);
    if vtp {
        let refs: Vec<(i64, &TriangleMesh)> =
            firsts.iter().map(|(v, m)| (i64::from(*v), m)).collect();
        out.poly_mesh(&in_dir(output, "labels.vtp"), &merge_labelled(&refs))?;
    }
    let gltf: Vec<LabelMesh> = firsts
        .iter()
        .map(|(value, mesh)| {
            let name = name_of(table, *value);
            LabelMesh {
                value: i64::from(*value),
                name: name.map(|n| n.name.as_str()),
                color: name.and_then(|n| n.color),
                mesh,
            }
        })
        .collect();
    let glb = labels_glb(&gltf).map_err(voxlod::Error::from)?;
    out.bytes(&in_dir(output, "labels.glb"), &glb)?;
    Ok((vtp.then(|| "labels.vtp".into()), Some("labels.glb".into())))
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
