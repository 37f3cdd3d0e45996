//! `voxlod evaluate`: every simplifier of the project on one mesh, measured against it.

use std::path::PathBuf;

use clap::Args;
use serde::Serialize;
use voxlod::asset::{Asset, Material};
use voxlod::core::{PolyMesh, TriangleMesh};
use voxlod::io::OutputSet;
use voxlod::metrics::DistanceOptions;

/// Side of each image of the preview strips, in pixels.
const PREVIEW_SIZE: u32 = 200;

use super::common::say;
use super::common::{add_report, in_dir, in_file, print_json, progress, read_mesh_input, CliError};
use super::values::{in_flags, number};
use voxlod_eval::evaluate::images::preview_strip;
use voxlod_eval::evaluate::plot::{plot_evaluation, Chart};
use voxlod_eval::evaluate::report::{markdown, ReportContext};
use voxlod_eval::evaluate::{
    evaluate, evaluate_asset, method_named, parameter_text, Budgets, EvaluateOptions, Evaluation,
    Method, PROXY,
};

/// Evaluate every simplification method on a mesh: error against triangle count.
///
/// Runs the voxel pipeline with both filters (hyper-cone and Gaussian), Rossignac–Borrel and
/// Low–Tan clustering, simplification envelopes, and the voxel pipeline followed by envelopes
/// within one voxel (the paper's proposed use, §5) at a series of triangle budgets (by default
/// half the input's triangles, then halving, eight budgets down to 100 triangles). Each
/// method's parameter (resolution, cells, or the envelope's ε in percent of the diagonal) is
/// searched until its output lands within 10 % of the budget. Each kept level is
/// measured against the input: two-sided Hausdorff, mean and RMS distance in percent of the
/// input's diagonal, components, genus, manifoldness.
///
/// Each level is also rendered beside the input from 14 views (256 × 256, orthographic) and
/// the share of silhouette pixels that differ is reported (--views 0 skips it).
///
/// An asset with looks (a glTF scene, .gltf or .glb, with materials or vertex colours; an OBJ
/// with its MTL, a PLY or OFF with colours or a texture) is evaluated on its geometry, and each
/// level's appearance is measured too: the level takes its looks from the nearest input
/// points, both are drawn with their looks from 14 views (512 × 512, orthographic), and the
/// report gives PSNR (dB, 8-bit sRGB) and SSIM (Wang et al. 2004, on luma). Such an input also
/// gets the method proxy: at every budget the level of `voxlod proxy` (the whole scene as one
/// solid, remeshed, its looks baked into one texture set of --proxy-texture² texels), measured
/// alike but drawn with its own textures. Every level and the input report their draw calls:
/// one per material the triangles use as drawn (the input's materials; 1 for each level, a
/// simplifier's with its looks as vertex colours, the proxy's with its one material).
///
/// Writes DIR/report.md, DIR/report.json, DIR/plot.png (error against triangles, log–log, one
/// curve per method) and DIR/previews/METHOD.png (the input and each level, rendered side by
/// side, the proxy's too); with --meshes, every kept level's geometry as
/// DIR/meshes/METHOD-TRIANGLES.ply (clustering levels with their dangling edges and points).
/// Nothing is written if the evaluation fails.
///
/// The envelope needs a consistently oriented manifold: an input that is not one is repaired
/// for it (the report says what changed), or left out with the reason when repair fails.
///
/// Examples:
///   voxlod evaluate bunny.obj -o bunny-eval
///   voxlod evaluate rocker-arm.obj -o rocker --budgets 8000,2000,500 --samples 200000
///   voxlod evaluate part.stl -o part-eval --methods voxel-hypercone,rossignac-borrel
///   voxlod evaluate street.glb -o street-eval --budgets 20000,5000 --methods voxel-hypercone,proxy
#[derive(Args, Debug)]
#[command(verbatim_doc_comment)]
pub struct EvaluateArgs {
    /// The mesh to simplify (.obj .ply .stl .off .vtp .vtu .vtk), or a glTF asset (.gltf .glb);
    /// a glTF, OBJ, PLY or OFF file with looks is measured for its appearance too
    pub input: PathBuf,
    /// Folder for report.md, report.json and plot.png (created if missing)
    #[arg(short, long, value_name = "DIR")]
    pub output: PathBuf,
    /// Triangle budgets, e.g. 20000,5000,1000 (default: halving from half the input's count)
    #[arg(long, value_name = "A,B,...", value_delimiter = ',',
        value_parser = number::<usize>, allow_hyphen_values = true)]
    pub budgets: Option<Vec<usize>>,
    /// Number of halving budgets when --budgets is not given
    #[arg(long, value_name = "N", default_value_t = 8, conflicts_with = "budgets",
        value_parser = number::<usize>, allow_hyphen_values = true)]
    pub count: usize,
    /// Methods to run (default: all): voxel-hypercone, voxel-gaussian, rossignac-borrel,
    /// low-tan, envelope, voxel-envelope, budget, meshopt-simplify, meshopt-sloppy, and proxy
    /// (an input with looks only)
    #[arg(long, value_name = "M,...", value_delimiter = ',', value_parser = method_named)]
    pub methods: Option<Vec<Method>>,
    /// Points sampled on each surface for each distance
    #[arg(long, value_name = "N", default_value_t = 100_000,
        value_parser = number::<usize>, allow_hyphen_values = true)]
    pub samples: usize,
    /// Accepted relative miss of a budget, e.g. 0.1 for ±10 %
    #[arg(long, value_name = "T", default_value_t = 0.1,
        value_parser = number::<f64>, allow_hyphen_values = true)]
    pub tolerance: f64,
    /// Views of the silhouette difference (0 to 14; 0 skips it and the previews)
    #[arg(long, value_name = "N", default_value_t = 14,
        value_parser = number::<usize>, allow_hyphen_values = true)]
    pub views: usize,
    /// Texels a side of the proxy's textures (16 to 16384)
    #[arg(long, value_name = "TEXELS", default_value_t = 1024,
        value_parser = number::<u32>, allow_hyphen_values = true)]
    pub proxy_texture: u32,
    /// Also write every kept level to DIR/meshes/
    #[arg(long)]
    pub meshes: bool,
    /// Print the report as JSON on standard output (no progress bar)
    #[arg(long)]
    pub json: bool,
}

/// What report.json holds: the evaluation and the files written beside it.
#[derive(Serialize)]
struct EvaluateReport<'a> {
    input: String,
    #[serde(flatten)]
    evaluation: &'a Evaluation,
    plot: Option<String>,
    plot_font: Option<String>,
    previews: Vec<String>,
    meshes: Vec<String>,
    /// Every warning printed without --json.
    warnings: Vec<String>,
}

/// The evaluation's options from the flags.
fn evaluate_options(args: &EvaluateArgs) -> Result<EvaluateOptions, CliError> {
    if args.samples == 0 {
        return Err(CliError::usage("--samples must be at least 1"));
    }
    if !(args.tolerance > 0.0 && args.tolerance < 1.0) {
        return Err(CliError::usage(format!(
            "--tolerance must lie strictly between 0 and 1, got {}",
            args.tolerance
        )));
    }
    let mut options = EvaluateOptions::standard();
    options.budgets = budgets(args)?;
    if let Some(methods) = &args.methods {
        let mut unique: Vec<Method> = Vec::new();
        for &m in methods {
            if !unique.contains(&m) {
                unique.push(m);
            }
        }
        options.methods = unique;
    }
    options.distance = DistanceOptions::for_samples(args.samples);
    options.tolerance = args.tolerance;
    if args.views > 14 {
        return Err(CliError::usage(format!(
            "--views {}: at most 14 (the octant diagonals and the axes)",
            args.views
        )));
    }
    options.images.views = args.views;
    if !(16..=16384).contains(&args.proxy_texture) {
        return Err(CliError::usage(format!(
            "--proxy-texture {}: a side of 16 to 16384 texels",
            args.proxy_texture
        )));
    }
    options.proxy_texture = args.proxy_texture;
    Ok(options)
}

/// The triangle budgets: --budgets, or --count halvings down to 100 triangles.
fn budgets(args: &EvaluateArgs) -> Result<Budgets, CliError> {
    match &args.budgets {
        Some(list) => {
            if let Some(zero) = list.iter().position(|&b| b == 0) {
                return Err(CliError::usage(format!(
                    "--budgets: budget {} is 0; budgets are triangle counts of at least 1",
                    zero + 1
                )));
            }
            Ok(Budgets::Explicit(list.clone()))
        }
        None if args.count == 0 => Err(CliError::usage("--count must be at least 1")),
        None => Ok(Budgets::Halving {
            count: args.count,
            smallest: 100,
        }),
    }
}

/// Every method at every budget, a line per kept level on standard error (without --json).
fn measure(
    args: &EvaluateArgs,
    mesh: &TriangleMesh,
    looks: Option<&Asset>,
    options: &EvaluateOptions,
) -> Result<Evaluation, CliError> {
    let run = |m: &&Method| **m != PROXY || looks.is_some();
    let methods = options.methods.iter().filter(run).count();
    let steps = methods * options.budgets.resolve(mesh.triangles.len()).len();
    let bar = progress(steps as u64, "levels", args.json);
    let on_point = |method: Method, point: &voxlod_eval::evaluate::CurvePoint| {
        bar.inc(1);
        if !args.json {
            let appearance = point.appearance.map_or(String::new(), |a| {
                format!(", PSNR {:.2} dB, SSIM {:.4}", a.psnr, a.ssim)
            });
            bar.suspend(|| {
                eprintln!(
                    "{method:>16} {:>15} {:>6}: {:>8} triangles, Hausdorff {:.3} %, mean {:.4} %{appearance}",
                    method.parameter_name(),
                    parameter_text(point.parameter),
                    point.triangles,
                    100.0 * point.hausdorff_fraction,
                    100.0 * point.mean_fraction
                )
            });
        }
    };
    let evaluation = match looks {
        Some(asset) => evaluate_asset(asset, options, on_point),
        None => evaluate(mesh, options, on_point),
    }
    .map_err(|e| in_flags(voxlod::Error::from(e).in_file(&args.input), &[]))?;
    bar.finish_and_clear();
    Ok(evaluation)
}

/// The input's geometry, and the input as an asset when it has looks, with its reader's
/// warnings: a glTF scene with materials or vertex colours; an OBJ, PLY or OFF file with
/// colours or materials other than the plain white one the asset reader adds
/// ([`voxlod::io::read_asset`]). Any other input is read as a mesh.
fn read_input(
    path: &std::path::Path,
    warnings: &mut Vec<String>,
) -> Result<(TriangleMesh, Option<Asset>), CliError> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    let is = |names: &[&str]| names.iter().any(|n| ext.eq_ignore_ascii_case(n));
    if is(&["gltf", "glb"]) {
        let read = voxlod::gltf::read_scene(path).map_err(|e| in_file(path, e))?;
        warnings.extend(read.warnings);
        let asset = read.asset;
        let looks = !asset.materials.is_empty() || !asset.mesh.colors.is_empty();
        return Ok((asset.mesh.geometry(), looks.then_some(asset)));
    }
    if is(&["obj", "ply", "off"]) {
        let read = voxlod::io::read_asset(path)?;
        let plain = |m: &Material| m.textures().count() == 0 && m.base_color == [1.0; 4];
        let a = &read.asset;
        if !a.mesh.colors.is_empty() || a.materials.len() > 1 || !a.materials.iter().all(plain) {
            warnings.extend(read.warnings);
            return Ok((read.asset.mesh.geometry(), Some(read.asset)));
        }
    }
    Ok((read_mesh_input(path)?.mesh, None))
}

/// The plot of error against triangles, or a warning (printed at once without --json).
fn chart(
    args: &EvaluateArgs,
    evaluation: &Evaluation,
    warnings: &mut Vec<String>,
) -> Option<Chart> {
    let name = args.input.display().to_string();
    let title = args
        .input
        .file_name()
        .map_or(name, |f| f.to_string_lossy().into_owned());
    match plot_evaluation(evaluation, &title) {
        Ok(chart) => Some(chart),
        Err(e) => {
            warnings.push(format!("no chart: {e}"));
            if !args.json {
                eprintln!("warning: no chart: {e}");
            }
            None
        }
    }
}

/// One preview strip per method with levels: (method, file in DIR, PNG bytes).
type Strip = (Method, String, Vec<u8>);

/// The input and each method's levels rendered side by side (none with --views 0).
fn preview_strips(
    args: &EvaluateArgs,
    mesh: &TriangleMesh,
    evaluation: &Evaluation,
) -> Result<Vec<Strip>, CliError> {
    let mut strips = Vec::new();
    if args.views == 0 {
        return Ok(strips);
    }
    for curve in evaluation.curves.iter().filter(|c| !c.points.is_empty()) {
        let levels: Vec<&PolyMesh> = curve.points.iter().map(|p| &p.level).collect();
        let strip = preview_strip(mesh, &levels, PREVIEW_SIZE)
            .and_then(|image| image.to_png())
            .map_err(|e| {
                let e = voxlod::Error::from(e).context(format!("preview of {}", curve.method));
                e.context(args.input.display().to_string())
            })?;
        strips.push((
            curve.method,
            format!("previews/{}.png", curve.method),
            strip,
        ));
    }
    Ok(strips)
}

/// Adds the previews, the level meshes (with --meshes) and the plot to the output set:
/// the level meshes' files and the report's notes.
fn write_files(
    args: &EvaluateArgs,
    out: &mut OutputSet,
    evaluation: &Evaluation,
    strips: &[Strip],
    chart: Option<&Chart>,
) -> Result<(Vec<String>, Vec<String>), CliError> {
    let mut notes = Vec::new();
    if !strips.is_empty() {
        out.create_dir(&in_dir(&args.output, "previews"))?;
        for (_, file, png) in strips {
            out.png(&in_dir(&args.output, file), png)?;
        }
    }
    let mut meshes = Vec::new();
    if args.meshes {
        let dir = in_dir(&args.output, "meshes");
        out.create_dir(&dir)?;
        for curve in &evaluation.curves {
            for point in &curve.points {
                let file = format!("{}-{}.ply", curve.method, point.triangles);
                out.poly_mesh(&dir.join(&file), &point.level)?;
                meshes.push(format!("meshes/{file}"));
            }
        }
        notes.push(format!("{} level meshes in `meshes/`.", meshes.len()));
    }
    if let Some(chart) = chart {
        out.png(&in_dir(&args.output, "plot.png"), &chart.png)?;
    }
    if let Some(font) = chart.and_then(|c| c.font.as_ref()) {
        notes.push(format!("Chart text in {}.", font.display()));
    }
    Ok((meshes, notes))
}

pub fn run(args: EvaluateArgs) -> Result<(), CliError> {
    let options = evaluate_options(&args)?;
    let mut out = OutputSet::protecting([&args.input]);
    for file in ["report.json", "report.md", "plot.png"] {
        out.check(&in_dir(&args.output, file))?;
    }
    let mut warnings = Vec::new();
    let (mesh, looks) = read_input(&args.input, &mut warnings)?;
    if looks.is_none() && options.methods.contains(&PROXY) && args.methods.is_some() {
        warnings.push(
            "proxy: the input has no looks (materials or colours) to bake; it is not evaluated"
                .into(),
        );
    }
    if !args.json {
        warnings.iter().for_each(|w| eprintln!("warning: {w}"));
    }
    let name = args.input.display().to_string();
    let evaluation = measure(&args, &mesh, looks.as_ref(), &options)?;
    let chart = chart(&args, &evaluation, &mut warnings);
    let strips = preview_strips(&args, &mesh, &evaluation)?;
    // Everything is computed: now write, as one set that appears at the end.
    out.create_dir(&args.output)?;
    let (meshes, notes) = write_files(&args, &mut out, &evaluation, &strips, chart.as_ref())?;
    let plot = chart.as_ref().map(|_| "plot.png".to_string());
    let report = EvaluateReport {
        input: name.clone(),
        evaluation: &evaluation,
        plot: plot.clone(),
        plot_font: chart
            .as_ref()
            .and_then(|c| c.font.as_ref())
            .map(|f| f.display().to_string()),
        previews: strips.iter().map(|(_, f, _)| f.clone()).collect(),
        meshes,
        warnings,
    };
    add_report(&mut out, &args.output, &report)?;
    let context = ReportContext {
        input: name,
        plot_file: plot,
        plot_unlabelled: chart.as_ref().is_some_and(|c| !c.labelled),
        previews: strips.iter().map(|(m, f, _)| (*m, f.clone())).collect(),
        notes,
    };
    out.text(
        &in_dir(&args.output, "report.md"),
        &markdown(&evaluation, &context),
    )?;
    out.commit()?;
    if args.json {
        return print_json(&report);
    }
    print_summary(&args, &evaluation);
    Ok(())
}

/// What was left out, and one line of totals, on standard output.
fn print_summary(args: &EvaluateArgs, evaluation: &Evaluation) {
    for o in &evaluation.omitted {
        say(format_args!("not evaluated: {}: {}", o.what, o.reason));
    }
    say(format_args!(
        "{} methods, {} levels in {:.1} s; report in {}",
        evaluation.curves.len(),
        evaluation
            .curves
            .iter()
            .map(|c| c.points.len())
            .sum::<usize>(),
        evaluation.seconds,
        in_dir(&args.output, "report.md").display()
    ));
}
