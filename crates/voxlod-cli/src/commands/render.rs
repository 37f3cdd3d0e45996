//! `voxlod render`: meshes, glTF assets with their looks and layered `.glb` files to a PNG with
//! the software rasterizer.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use glam::DVec3;
use serde::Serialize;
use voxlod::core::PolyMesh;
use voxlod::layers::Octant;
use voxlod::render::{assets_bounds, render_assets, Camera, Image, RenderOptions};
use voxlod::{DrawOptions, Drawable, Drawing};

use super::camera::CameraArgs;
use super::common::say;
use super::common::{in_file, print_json, thousands, CliError};
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
/// the antialiasing comparison's reference). glTF assets (.gltf, or a .glb that is not layered)
/// with materials or vertex colours are drawn with their looks: base colour factor × vertex
/// colour × base colour texture, alpha masks honoured, Lambert-shaded; mixed with other inputs,
/// they are drawn as plain meshes, with a warning.
///
/// Examples:
///   voxlod render helmet.glb -o helmet.png --supersample 4
///   voxlod render bunny.glb -o bunny.png --view -1,-0.5,-1
///   voxlod render level-0.ply level-3.ply -o levels.png --size 1200x800 --supersample 4
///   voxlod render part.glb -o near.png --perspective --fov 30
#[derive(Args, Debug)]
#[command(verbatim_doc_comment)]
pub struct RenderArgs {
    /// Meshes (.obj .ply .stl .off .vtp .vtu .vtk), glTF assets (.gltf .glb) and layered .glb files
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
    /// Whether the inputs were drawn with their looks (glTF assets' materials, colours and
    /// textures).
    looks: bool,
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
    let (inputs, assets) = read_inputs(&args.meshes, &mut warnings)?;
    let looks = assets.is_some();
    let drawing = match assets {
        Some(assets) => draw_assets(&assets, &options, &mut warnings)?,
        None => voxlod::draw(&inputs, &options).map_err(|e| in_flags(e, &[]))?,
    };
    let png = drawing.image.to_png().map_err(voxlod::Error::from)?;
    out.png(&args.output, &png)?;
    out.commit()?;
    let report = render_report(
        &args,
        &drawing,
        start.elapsed().as_secs_f64(),
        warnings,
        looks,
    );
    if args.json {
        return print_json(&report);
    }
    print_report(&args, &report);
    Ok(())
}

/// The inputs as plain or layered drawables, and as assets with their looks when every input
/// is a glTF asset that has looks (materials or vertex colours); a warning when only some are.
fn read_inputs(
    paths: &[PathBuf],
    warnings: &mut Vec<String>,
) -> Result<(Vec<Drawable>, Option<Vec<voxlod::gltf::SceneRead>>), CliError> {
    let (mut drawables, mut assets) = (Vec::new(), Vec::new());
    for path in paths {
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
        let gltf = ext.eq_ignore_ascii_case("gltf");
        let drawable = if gltf {
            None
        } else {
            Some(voxlod::read_drawable(path)?)
        };
        let plain = matches!(drawable, None | Some(Drawable::Plain(_)));
        if plain && (gltf || ext.eq_ignore_ascii_case("glb")) {
            let read = voxlod::gltf::read_scene(path).map_err(|e| in_file(path, e))?;
            let drawable = drawable
                .unwrap_or_else(|| Drawable::Plain(PolyMesh::from(read.asset.mesh.geometry())));
            drawables.push(drawable);
            let looks = !read.asset.materials.is_empty() || !read.asset.mesh.colors.is_empty();
            if looks {
                assets.push((path, read));
            }
            continue;
        }
        drawables.extend(drawable);
    }
    if assets.is_empty() {
        return Ok((drawables, None));
    }
    if assets.len() < paths.len() {
        let names: Vec<String> = assets
            .iter()
            .map(|(p, _)| p.display().to_string())
            .collect();
        warnings.push(format!(
            "{} drawn without their looks: assets are drawn with them only when every input is one",
            names.join(", ")
        ));
        return Ok((drawables, None));
    }
    let reads = assets.into_iter().map(|(_, read)| read).collect();
    Ok((drawables, Some(reads)))
}

/// Glb assets drawn with their looks, framed as [`voxlod::draw`] frames meshes.
fn draw_assets(
    reads: &[voxlod::gltf::SceneRead],
    options: &DrawOptions,
    warnings: &mut Vec<String>,
) -> Result<Drawing, CliError> {
    let view = voxlod::view_direction(options.view).map_err(|e| in_flags(e, &[]))?;
    let assets: Vec<_> = reads.iter().map(|r| &r.asset).collect();
    for r in reads {
        warnings.extend(r.warnings.iter().cloned());
    }
    let fov = options.perspective.then_some(options.fov);
    let render_error = |e| CliError::from(voxlod::Error::from(e));
    let bounds = assets_bounds(&assets);
    let camera =
        Camera::fit(view, &bounds, options.width, options.height, fov).map_err(render_error)?;
    let render_options = RenderOptions {
        supersample: options.supersample,
        background: options.background,
        ..Default::default()
    };
    let (image, decode_warnings): (Image, _) =
        render_assets(&assets, &camera, &render_options).map_err(render_error)?;
    warnings.extend(decode_warnings);
    Ok(Drawing {
        image,
        octant: Octant::of(view).map_err(|e| CliError::from(voxlod::Error::from(e)))?,
        opaque_triangles: assets.iter().map(|a| a.mesh.triangles.len()).sum(),
        layered_triangles: 0,
        lines: 0,
        points: 0,
        layered_order: None,
    })
}

/// The report of a drawing.
fn render_report(
    args: &RenderArgs,
    drawing: &Drawing,
    seconds: f64,
    warnings: Vec<String>,
    looks: bool,
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
        looks,
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
