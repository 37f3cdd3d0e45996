//! `voxlod render`: meshes and layered `.glb` files to a PNG with the software rasterizer.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use glam::DVec3;
use serde::Serialize;
use voxlod::{DrawOptions, Drawing};

use super::camera::CameraArgs;
use super::common::say;
use super::common::{print_json, thousands, CliError};
use super::values::{in_flags, number, numbers};

/// Draw meshes and layered shells to a PNG (software rasterizer, Lambert shading).
///
/// Plain meshes are drawn opaque through a z-buffer, with their dangling edges as lines and
/// isolated points as squares. Edges that carry a `width` attribute (the thick edges of
/// `voxlod cluster`, in world units) are drawn that wide, shaded with the patent's dynamic
/// normal when they carry `normal_x/y/z`; others are --line-width pixels wide. A layered .glb (from `voxlod
/// layers`) is alpha-blended in the back-to-front order it stores for the octant of --view. With
/// --perspective, or with several layered files, the order is computed afresh from the volume
/// grid the file records: split at the eye's cell, objects ordered by their buffers' boxes and
/// interleaved where the buffers overlap. --supersample N draws N×N samples per pixel (16 gives
/// the antialiasing comparison's reference).
///
/// Examples:
///   voxlod render bunny.glb -o bunny.png --view -1,-0.5,-1
///   voxlod render level-0.ply level-3.ply -o levels.png --size 1200x800 --supersample 4
///   voxlod render part.glb -o near.png --perspective --fov 30
#[derive(Args, Debug)]
#[command(verbatim_doc_comment)]
pub struct RenderArgs {
    /// Meshes (.obj .ply .stl .off .vtp .vtk) and layered or plain .glb files
    #[arg(required = true, value_name = "MESH")]
    pub meshes: Vec<PathBuf>,
    /// The PNG to write
    #[arg(short, long, value_name = "PNG")]
    pub output: PathBuf,
    #[command(flatten)]
    pub camera: CameraArgs,
    /// N×N samples per pixel (1 to 32)
    #[arg(long, value_name = "N", default_value_t = 1,
        value_parser = number::<u32>, allow_hyphen_values = true)]
    pub supersample: u32,
    /// A perspective camera instead of an orthographic one
    #[arg(long)]
    pub perspective: bool,
    /// Vertical field of view of the perspective camera, in degrees (more than 0, less than
    /// 180; 35 when not given)
    #[arg(long, value_name = "DEG", value_parser = number::<f64>, allow_hyphen_values = true)]
    pub fov: Option<f64>,
    /// Width of dangling edges, in pixels
    #[arg(long, value_name = "PX", default_value_t = 2.0,
        value_parser = number::<f32>, allow_hyphen_values = true)]
    pub line_width: f32,
    /// Side of isolated points, in pixels
    #[arg(long, value_name = "PX", default_value_t = 4.0,
        value_parser = number::<f32>, allow_hyphen_values = true)]
    pub point_size: f32,
    /// Background colour, linear RGB in [0, 1]
    #[arg(long, value_name = "R,G,B", default_value = "0.05,0.06,0.08",
        value_parser = numbers::<f32, 3>, allow_hyphen_values = true)]
    pub background: [f32; 3],
    /// Print a JSON report on standard output
    #[arg(long)]
    pub json: bool,
}

#[derive(Serialize)]
struct RenderReport {
    output: String,
    width: u32,
    height: u32,
    supersample: u32,
    perspective: bool,
    view: [f64; 3],
    octant: &'static str,
    opaque_triangles: usize,
    layered_triangles: usize,
    lines: usize,
    points: usize,
    /// "stored" (the file's order for the octant) or "computed" (from the volume grids).
    layered_order: Option<&'static str>,
    seconds: f64,
    warnings: Vec<String>,
}

pub fn run(args: RenderArgs) -> Result<(), CliError> {
    let start = Instant::now();
    voxlod::io::check_image_path(&args.output)?;
    let mut out = voxlod::io::OutputSet::protecting(&args.meshes);
    out.check(&args.output)?;
    let options = DrawOptions {
        view: DVec3::from(args.camera.view),
        width: args.camera.size.width,
        height: args.camera.size.height,
        supersample: args.supersample,
        perspective: args.perspective,
        fov: args.fov.unwrap_or(DrawOptions::default().fov),
        line_width: args.line_width,
        point_size: args.point_size,
        background: args.background,
    };
    voxlod::check_draw_options(&options).map_err(|e| in_flags(e, &[]))?;
    let mut warnings = Vec::new();
    if let (Some(fov), false) = (args.fov, args.perspective) {
        warnings.push(format!(
            "--fov {fov} has no effect without --perspective (the camera is orthographic)"
        ));
    }
    let inputs = args
        .meshes
        .iter()
        .map(voxlod::read_drawable)
        .collect::<Result<Vec<_>, _>>()?;
    let drawing = voxlod::draw(&inputs, &options).map_err(|e| in_flags(e, &[]))?;
    let png = drawing.image.to_png().map_err(voxlod::Error::from)?;
    out.png(&args.output, &png)?;
    out.commit()?;
    let report = render_report(&args, &drawing, start.elapsed().as_secs_f64(), warnings);
    if args.json {
        return print_json(&report);
    }
    print_report(&args, &report);
    Ok(())
}

/// The report of a drawing.
fn render_report(
    args: &RenderArgs,
    drawing: &Drawing,
    seconds: f64,
    warnings: Vec<String>,
) -> RenderReport {
    RenderReport {
        output: args.output.display().to_string(),
        width: args.camera.size.width,
        height: args.camera.size.height,
        supersample: args.supersample,
        perspective: args.perspective,
        view: args.camera.view,
        octant: drawing.octant.name(),
        opaque_triangles: drawing.opaque_triangles,
        layered_triangles: drawing.layered_triangles,
        lines: drawing.lines,
        points: drawing.points,
        layered_order: drawing.layered_order,
        seconds,
        warnings,
    }
}

/// The warnings on standard error and one line on standard output.
fn print_report(args: &RenderArgs, report: &RenderReport) {
    for w in &report.warnings {
        eprintln!("warning: {w}");
    }
    say(format_args!(
        "{} opaque and {} layered triangles at {}x{} ({}x{} samples per pixel) in {:.2} s -> {}",
        thousands(report.opaque_triangles),
        thousands(report.layered_triangles),
        report.width,
        report.height,
        args.supersample,
        args.supersample,
        report.seconds,
        args.output.display()
    ));
}
