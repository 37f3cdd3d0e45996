//! `voxlod render`: meshes and layered `.glb` files to a PNG with the software rasterizer.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use glam::DVec3;
use serde::Serialize;
use voxlod::core::{Bounds, PolyMesh, TriangleMesh};
use voxlod::layers::{recover_cells, scene_order, CellTriangles, Octant, View};
use voxlod::render::{render, Camera, LineItem, MeshItem, PointItem, RenderOptions, Scene};
use voxlod_gltf::{read_glb, GlbScene};

use super::camera::{view_direction, CameraArgs, SURFACE_COLOR};
use super::common::say;
use super::common::{is_glb, print_json, thousands, CliError};
use super::values::{number, numbers, ImageSize};

/// The vertical field of view of `--perspective`, in degrees, when `--fov` is not given.
const DEFAULT_FOV: f64 = 35.0;

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

/// Dangling edges of one look, drawn as one line item.
struct LineGroup {
    input: usize,
    lines: Vec<[u32; 2]>,
    color: [f32; 3],
    width: f32,
}

const WIRE: [f32; 3] = [0.95, 0.55, 0.2];

/// The dangling edges of `m` grouped by pixel width (quarter pixels) and shade (1/32): per-line
/// widths from the `width` attribute and shades from the dynamic normal (Low–Tan) when the
/// file has them, else one group of `default_width` pixels, unshaded.
fn line_groups(
    input: usize,
    m: &PolyMesh,
    camera: &Camera,
    options: &RenderOptions,
    default_width: f32,
) -> Result<Vec<LineGroup>, CliError> {
    use voxlod::clustering::thick_edges::{dynamic_normal, NORMAL, WIDTH};
    let attr = |name: &str| m.line_attributes.iter().find(|a| a.name == name);
    let Some(widths) = attr(WIDTH) else {
        return Ok(vec![LineGroup {
            input,
            lines: m.lines.clone(),
            color: WIRE,
            width: default_width,
        }]);
    };
    let normals = match NORMAL.map(attr) {
        [Some(x), Some(y), Some(z)] => Some((x, y, z)),
        _ => None,
    };
    let light = options
        .light_direction(camera)
        .map_err(|e| CliError::msg(e.to_string()))?
        .as_vec3();
    let mut groups: std::collections::BTreeMap<(u32, u32), Vec<[u32; 2]>> = Default::default();
    for (i, &[a, b]) in m.lines.iter().enumerate() {
        let (pa, pb) = (m.mesh.positions[a as usize], m.mesh.positions[b as usize]);
        let mid = ((pa + pb) * 0.5).as_dvec3();
        let px = (widths.values[i] as f64 / camera.pixel_size_at(mid)).max(1.0);
        let shade = match normals {
            Some((x, y, z)) => {
                let stored = glam::Vec3::new(x.values[i], y.values[i], z.values[i]);
                let towards = if camera.is_perspective() {
                    (camera.eye - mid).as_vec3()
                } else {
                    -camera.forward.as_vec3()
                };
                options.shade(dynamic_normal(pa, pb, stored, towards), light)
            }
            None => 1.0,
        };
        let key = ((px * 4.0).round() as u32, (shade * 32.0).round() as u32);
        groups.entry(key).or_default().push([a, b]);
    }
    Ok(groups
        .into_iter()
        .map(|((w, s), lines)| LineGroup {
            input,
            lines,
            color: WIRE.map(|c| c * s as f32 / 32.0),
            width: w as f32 / 4.0,
        })
        .collect())
}

/// One input, read.
enum Loaded {
    Plain(PolyMesh),
    Layered(GlbScene, PathBuf),
}

/// Reads every input: plain meshes, and layered or plain `.glb` files.
fn read_inputs(paths: &[PathBuf]) -> Result<Vec<Loaded>, CliError> {
    let mut inputs = Vec::new();
    for path in paths {
        if is_glb(path) {
            let scene = read_glb(path).map_err(|e| CliError::msg(e.to_string()))?;
            if scene.is_layered() {
                inputs.push(Loaded::Layered(scene, path.clone()));
            } else {
                inputs.push(Loaded::Plain(PolyMesh::from(scene.mesh)));
            }
        } else {
            inputs.push(Loaded::Plain(voxlod::io::read_poly_mesh(path)?));
        }
    }
    Ok(inputs)
}

/// The camera along `view` that frames everything.
fn frame(args: &RenderArgs, view: DVec3, inputs: &[Loaded]) -> Result<Camera, CliError> {
    let mut bounds = Bounds::EMPTY;
    for input in inputs {
        bounds = bounds.union(&match input {
            Loaded::Plain(m) => poly_bounds(m),
            Loaded::Layered(g, _) => g.mesh.bounds(),
        });
    }
    if bounds.is_empty() {
        return Err(CliError::msg(
            "nothing to draw: the inputs hold no geometry",
        ));
    }
    Camera::fit(
        view,
        &bounds,
        args.camera.size.width,
        args.camera.size.height,
        args.perspective.then_some(args.fov.unwrap_or(DEFAULT_FOV)),
    )
    .map_err(|e| CliError::msg(e.to_string()))
}

/// The report before drawing: the image, the camera and the warnings; no counts yet.
fn empty_report(args: &RenderArgs, octant: Octant, warnings: Vec<String>) -> RenderReport {
    RenderReport {
        output: args.output.display().to_string(),
        width: args.camera.size.width,
        height: args.camera.size.height,
        supersample: args.supersample,
        perspective: args.perspective,
        view: args.camera.view,
        octant: octant.name(),
        opaque_triangles: 0,
        layered_triangles: 0,
        lines: 0,
        points: 0,
        layered_order: None,
        seconds: 0.0,
        warnings,
    }
}

/// The plain inputs' opaque meshes, points and line groups in the scene, counted in the report.
fn add_plain<'a>(
    args: &RenderArgs,
    inputs: &'a [Loaded],
    groups: &'a [LineGroup],
    scene: &mut Scene<'a>,
    report: &mut RenderReport,
) {
    for input in inputs {
        if let Loaded::Plain(m) = input {
            report.opaque_triangles += m.mesh.triangles.len();
            report.lines += m.lines.len();
            report.points += m.points.len();
            if !m.mesh.triangles.is_empty() {
                scene.meshes.push(MeshItem::opaque(&m.mesh, SURFACE_COLOR));
            }
            if !m.points.is_empty() {
                scene.points.push(PointItem {
                    positions: &m.mesh.positions,
                    points: &m.points,
                    color: [0.3, 0.7, 0.95],
                    size: args.point_size,
                });
            }
        }
    }
    for g in groups {
        let Loaded::Plain(m) = &inputs[g.input] else {
            unreachable!("line groups come from plain meshes")
        };
        scene.lines.push(LineItem {
            positions: &m.mesh.positions,
            lines: &g.lines,
            color: g.color,
            width: g.width,
        });
    }
}

/// The layered inputs in one blended mesh in back-to-front order (none without them).
fn blend_inputs(
    args: &RenderArgs,
    inputs: &[Loaded],
    octant: Octant,
    camera: &Camera,
    report: &mut RenderReport,
) -> Result<Option<Blended>, CliError> {
    let layered: Vec<(&GlbScene, &PathBuf)> = inputs
        .iter()
        .filter_map(|i| match i {
            Loaded::Layered(g, p) => Some((g, p)),
            Loaded::Plain(_) => None,
        })
        .collect();
    if layered.is_empty() {
        return Ok(None);
    }
    let (b, how) = blend_layers(&layered, octant, camera, args.perspective)?;
    report.layered_order = Some(how);
    report.layered_triangles = b.mesh.triangles.len();
    Ok(Some(b))
}

pub fn run(args: RenderArgs) -> Result<(), CliError> {
    let start = Instant::now();
    voxlod::io::check_image_path(&args.output)?;
    let mut out = voxlod::io::OutputSet::protecting(&args.meshes);
    out.check(&args.output)?;
    let view = view_direction(args.camera.view)?;
    let warnings = check_render_args(&args)?;
    let octant = Octant::of(view).map_err(|e| CliError::msg(format!("--view: {e}")))?;
    let inputs = read_inputs(&args.meshes)?;
    let camera = frame(&args, view, &inputs)?;
    let options = RenderOptions {
        supersample: args.supersample,
        background: args.background,
        ..Default::default()
    };
    let mut report = empty_report(&args, octant, warnings);
    // Opaque meshes, lines, points.
    let mut groups = Vec::new();
    for (i, input) in inputs.iter().enumerate() {
        if let Loaded::Plain(m) = input {
            if !m.lines.is_empty() {
                groups.extend(line_groups(i, m, &camera, &options, args.line_width)?);
            }
        }
    }
    let mut scene = Scene::default();
    add_plain(&args, &inputs, &groups, &mut scene, &mut report);
    // Layered files: one blended mesh in back-to-front order.
    let blended = blend_inputs(&args, &inputs, octant, &camera, &mut report)?;
    if let Some(b) = &blended {
        scene.meshes.push(MeshItem::blended(
            &b.mesh,
            b.palette.clone(),
            &b.triangle_palette,
            &b.order,
        ));
    }
    let image = render(&scene, &camera, &options).map_err(|e| CliError::msg(e.to_string()))?;
    let png = image.to_png().map_err(|e| CliError::msg(e.to_string()))?;
    out.png(&args.output, &png)?;
    out.commit()?;
    report.seconds = start.elapsed().as_secs_f64();
    if args.json {
        return print_json(&report);
    }
    print_report(&args, &report);
    Ok(())
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

/// Refuses flags out of their range; returns warnings for flags that have no effect.
fn check_render_args(args: &RenderArgs) -> Result<Vec<String>, CliError> {
    if !(1..=32).contains(&args.supersample) {
        return Err(CliError::usage(format!(
            "--supersample {}: choose 1 to 32 samples per pixel side",
            args.supersample
        )));
    }
    let fov = args.fov.unwrap_or(DEFAULT_FOV);
    if !(fov > 0.0 && fov < 180.0) {
        return Err(CliError::usage(format!(
            "--fov {fov}: the field of view must be more than 0 and less than 180 degrees"
        )));
    }
    let widest = ImageSize::MAX_SIDE as f32;
    for (flag, px) in [
        ("--line-width", args.line_width),
        ("--point-size", args.point_size),
    ] {
        if !(px > 0.0 && px <= widest) {
            return Err(CliError::msg(format!(
                "{flag} {px}: choose more than 0 and at most {widest} pixels"
            )));
        }
    }
    if let Some(c) = args.background.iter().find(|c| !(0.0..=1.0).contains(*c)) {
        let [r, g, b] = args.background;
        return Err(CliError::usage(format!(
            "--background {r},{g},{b}: each component is linear RGB from 0 to 1, not {c}"
        )));
    }
    let mut warnings = Vec::new();
    if args.fov.is_some() && !args.perspective {
        warnings.push(format!(
            "--fov {fov} has no effect without --perspective (the camera is orthographic)"
        ));
    }
    Ok(warnings)
}

fn poly_bounds(m: &PolyMesh) -> Bounds {
    let mut b = m.mesh.bounds();
    for &v in m.lines.iter().flatten().chain(&m.points) {
        b.grow(m.mesh.positions[v as usize].as_dvec3());
    }
    b
}

/// Every layered input in one blended mesh.
struct Blended {
    mesh: TriangleMesh,
    palette: Vec<[f32; 4]>,
    triangle_palette: Vec<u16>,
    order: Vec<u32>,
}

fn blend_layers(
    layered: &[(&GlbScene, &PathBuf)],
    octant: Octant,
    camera: &Camera,
    perspective: bool,
) -> Result<(Blended, &'static str), CliError> {
    let mut out = Blended {
        mesh: TriangleMesh::default(),
        palette: Vec::new(),
        triangle_palette: Vec::new(),
        order: Vec::new(),
    };
    let mut first_triangle = Vec::new();
    for (g, _) in layered {
        let base = out.mesh.positions.len() as u32;
        first_triangle.push(out.mesh.triangles.len() as u32);
        let palette_base = out.palette.len();
        if palette_base + g.parts.len() > u16::MAX as usize {
            return Err(CliError::msg("too many layers to draw at once"));
        }
        out.palette.extend(g.parts.iter().map(|p| p.color));
        out.triangle_palette
            .extend(g.triangle_parts().iter().map(|&p| p + palette_base as u16));
        out.mesh.positions.extend_from_slice(&g.mesh.positions);
        out.mesh
            .triangles
            .extend(g.mesh.triangles.iter().map(|t| t.map(|v| v + base)));
    }
    let with_normals = layered.iter().all(|(g, _)| !g.mesh.normals.is_empty());
    if with_normals {
        for (g, _) in layered {
            out.mesh.normals.extend_from_slice(&g.mesh.normals);
        }
    }
    if let ([(g, path)], false) = (layered, perspective) {
        // The stored order: triangles of global vertex indices; find each one's index.
        let stored = g.orders[octant.index()].as_ref().ok_or_else(|| {
            CliError::msg(format!("{}: no {} order", path.display(), octant.name()))
        })?;
        let mut by_corners = std::collections::HashMap::with_capacity(g.mesh.triangles.len());
        for (i, t) in g.mesh.triangles.iter().enumerate() {
            by_corners.insert(*t, i as u32);
        }
        out.order = stored
            .iter()
            .map(|t| {
                by_corners.get(t).copied().ok_or_else(|| {
                    CliError::msg(format!(
                        "{}: the {} order names a triangle no layer has",
                        path.display(),
                        octant.name()
                    ))
                })
            })
            .collect::<Result<_, _>>()?;
        return Ok((out, "stored"));
    }
    // Computed afresh from the grids.
    let mut cells = Vec::new();
    for (g, path) in layered {
        let grid = g.grid.ok_or_else(|| {
            CliError::msg(format!(
                "{}: the file records no volume grid, which --perspective and several layered \
                 files need (write it with `voxlod layers`)",
                path.display()
            ))
        })?;
        cells.push(recover_cells(&grid, &g.mesh.positions, &g.mesh.triangles));
    }
    let objects: Vec<CellTriangles> = layered
        .iter()
        .zip(&cells)
        .map(|((g, _), c)| CellTriangles {
            grid: g.grid.expect("checked"),
            positions: &g.mesh.positions,
            triangles: &g.mesh.triangles,
            cells: c,
        })
        .collect();
    let view = if perspective {
        View::Perspective { eye: camera.eye }
    } else {
        View::Orthographic {
            direction: camera.forward,
        }
    };
    let order = scene_order(&objects, &view).map_err(|e| CliError::msg(e.to_string()))?;
    out.order = order
        .order
        .iter()
        .map(|&(o, t)| first_triangle[o as usize] + t)
        .collect();
    Ok((out, "computed"))
}

#[cfg(test)]
mod tests {
    use glam::{DVec3, Vec3};
    use voxlod::core::{Attribute, Bounds, PolyMesh, TriangleMesh};
    use voxlod::render::{Camera, RenderOptions};

    use super::line_groups;

    #[test]
    fn thick_edges_keep_their_world_width_and_face_the_viewer() {
        // Two edges along x, 0.1 and 0.3 wide, seen from -z over a 2-unit-tall view of 200 px
        // (0.01 per pixel): 10 and 30 pixels.
        let positions = vec![
            Vec3::new(-0.5, 0.2, 0.0),
            Vec3::new(0.5, 0.2, 0.0),
            Vec3::new(-0.5, -0.2, 0.0),
            Vec3::new(0.5, -0.2, 0.0),
        ];
        let mut m = PolyMesh::from(TriangleMesh::new(positions, Vec::new()));
        m.lines = vec![[0, 1], [2, 3]];
        let attr = |name: &str, values: Vec<f32>| Attribute {
            name: name.into(),
            values,
        };
        m.line_attributes = vec![attr("width", vec![0.1, 0.3])];
        let mut cam = Camera::fit(
            DVec3::new(0.0, 0.0, 1.0),
            &Bounds::new(DVec3::splat(-1.0), DVec3::splat(1.0)),
            200,
            200,
            None,
        )
        .unwrap();
        cam.projection = voxlod::render::Projection::Orthographic { half_height: 1.0 };
        let options = RenderOptions::default();
        let groups = line_groups(0, &m, &cam, &options, 2.0).unwrap();
        let mut widths: Vec<f32> = groups.iter().map(|g| g.width).collect();
        widths.sort_by(f32::total_cmp);
        assert_eq!(widths, vec![10.0, 30.0]);
        // Normals across the edges: the dynamic normal turns them to the viewer, so both edges
        // are shaded alike whatever the stored normal.
        m.line_attributes.extend([
            attr("normal_x", vec![0.0, 0.0]),
            attr("normal_y", vec![1.0, 0.0]),
            attr("normal_z", vec![0.0, 1.0]),
        ]);
        let groups = line_groups(0, &m, &cam, &options, 2.0).unwrap();
        assert_eq!(groups.len(), 2);
        assert_eq!(groups[0].color, groups[1].color);
        // Without widths: one group of the default width.
        m.line_attributes.clear();
        let groups = line_groups(0, &m, &cam, &options, 2.0).unwrap();
        assert_eq!((groups.len(), groups[0].width), (1, 2.0));
    }
}
