//! `voxlod render`: meshes and layered `.glb` files to a PNG with the software rasterizer.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use serde::Serialize;
use voxlod_core::{Bounds, PolyMesh, TriangleMesh};
use voxlod_layers::{read_glb, recover_cells, scene_order, CellTriangles, GlbScene, Octant, View};
use voxlod_render::{render, Camera, LineItem, MeshItem, PointItem, RenderOptions, Scene};

use super::common::{parse_triple, print_json, CliError};
use super::layers::{parse_size, parse_view};

/// The colour of surfaces (linear RGB): a light steel grey.
pub const SURFACE_COLOR: [f32; 3] = [0.85, 0.86, 0.9];

/// Draw meshes and layered shells to a PNG (software rasterizer, Lambert shading).
///
/// Plain meshes are drawn opaque through a z-buffer, with their dangling edges as lines
/// --line-width pixels wide and isolated points as squares. A layered .glb (from `voxlod
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
    /// Direction the camera looks along (eye to scene)
    #[arg(
        long,
        value_name = "X,Y,Z",
        default_value = "-1,-1,-1",
        allow_hyphen_values = true
    )]
    pub view: String,
    /// Image size in pixels
    #[arg(long, value_name = "WxH", default_value = "800x800")]
    pub size: String,
    /// N×N samples per pixel (1 to 32)
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub supersample: u32,
    /// A perspective camera instead of an orthographic one
    #[arg(long)]
    pub perspective: bool,
    /// Vertical field of view of the perspective camera, in degrees
    #[arg(long, value_name = "DEG", default_value_t = 35.0)]
    pub fov: f64,
    /// Width of dangling edges, in pixels
    #[arg(long, value_name = "PX", default_value_t = 2.0)]
    pub line_width: f32,
    /// Side of isolated points, in pixels
    #[arg(long, value_name = "PX", default_value_t = 4.0)]
    pub point_size: f32,
    /// Background colour, linear RGB in [0, 1]
    #[arg(long, value_name = "R,G,B", default_value = "0.05,0.06,0.08")]
    pub background: String,
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
}

/// One input, read.
enum Loaded {
    Plain(PolyMesh),
    Layered(GlbScene, PathBuf),
}

pub fn run(args: RenderArgs) -> Result<(), CliError> {
    let start = Instant::now();
    let view = parse_view(&args.view)?;
    let (width, height) = parse_size(&args.size)?;
    if !(1..=32).contains(&args.supersample) {
        return Err(CliError::msg(format!(
            "--supersample {}: choose 1 to 32",
            args.supersample
        )));
    }
    let background = parse_triple::<f32>(&args.background, "--background")?;
    let octant = Octant::of(view).map_err(|e| CliError::msg(format!("--view: {e}")))?;
    let mut inputs = Vec::new();
    for path in &args.meshes {
        let is_glb = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("glb"));
        if is_glb {
            let scene = read_glb(path).map_err(|e| CliError::msg(e.to_string()))?;
            if scene.is_layered() {
                inputs.push(Loaded::Layered(scene, path.clone()));
            } else {
                inputs.push(Loaded::Plain(PolyMesh::from(scene.mesh)));
            }
        } else {
            inputs.push(Loaded::Plain(voxlod_io::read_poly_mesh(path)?));
        }
    }
    // Opaque meshes, lines, points.
    let mut scene = Scene::default();
    let mut bounds = Bounds::EMPTY;
    let mut report = RenderReport {
        output: args.output.display().to_string(),
        width,
        height,
        supersample: args.supersample,
        perspective: args.perspective,
        view: view.to_array(),
        octant: octant.name(),
        opaque_triangles: 0,
        layered_triangles: 0,
        lines: 0,
        points: 0,
        layered_order: None,
        seconds: 0.0,
    };
    for input in &inputs {
        match input {
            Loaded::Plain(m) => {
                bounds = bounds.union(&poly_bounds(m));
                report.opaque_triangles += m.mesh.triangles.len();
                report.lines += m.lines.len();
                report.points += m.points.len();
                if !m.mesh.triangles.is_empty() {
                    scene.meshes.push(MeshItem::opaque(&m.mesh, SURFACE_COLOR));
                }
                if !m.lines.is_empty() {
                    scene.lines.push(LineItem {
                        positions: &m.mesh.positions,
                        lines: &m.lines,
                        color: [0.95, 0.55, 0.2],
                        width: args.line_width,
                    });
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
            Loaded::Layered(g, _) => bounds = bounds.union(&g.mesh.bounds()),
        }
    }
    if bounds.is_empty() {
        return Err(CliError::msg(
            "nothing to draw: the inputs hold no geometry",
        ));
    }
    let camera = Camera::fit(
        view,
        &bounds,
        width,
        height,
        args.perspective.then_some(args.fov),
    )
    .map_err(|e| CliError::msg(e.to_string()))?;
    // Layered files: one blended mesh in back-to-front order.
    let layered: Vec<(&GlbScene, &PathBuf)> = inputs
        .iter()
        .filter_map(|i| match i {
            Loaded::Layered(g, p) => Some((g, p)),
            Loaded::Plain(_) => None,
        })
        .collect();
    let blended = if layered.is_empty() {
        None
    } else {
        let (b, how) = blend_layers(&layered, octant, &camera, args.perspective)?;
        report.layered_order = Some(how);
        report.layered_triangles = b.mesh.triangles.len();
        Some(b)
    };
    if let Some(b) = &blended {
        scene.meshes.push(MeshItem::blended(
            &b.mesh,
            b.palette.clone(),
            &b.triangle_palette,
            &b.order,
        ));
    }
    let image = render(
        &scene,
        &camera,
        &RenderOptions {
            supersample: args.supersample,
            background,
            ..Default::default()
        },
    )
    .map_err(|e| CliError::msg(e.to_string()))?;
    let png = image.to_png().map_err(|e| CliError::msg(e.to_string()))?;
    voxlod_io::atomic::write_atomically(&args.output, |w| std::io::Write::write_all(w, &png))?;
    report.seconds = start.elapsed().as_secs_f64();
    if args.json {
        return print_json(&report);
    }
    println!(
        "{} opaque and {} layered triangles at {}x{} ({}x{} samples per pixel) in {:.2} s -> {}",
        super::common::thousands(report.opaque_triangles),
        super::common::thousands(report.layered_triangles),
        width,
        height,
        args.supersample,
        args.supersample,
        report.seconds,
        args.output.display()
    );
    Ok(())
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
