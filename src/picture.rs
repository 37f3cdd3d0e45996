//! Meshes and layered shells drawn to a picture in one call, with the software rasterizer
//! ([`voxlod_render`]): plain meshes opaque through a z-buffer with Lambert shading, their
//! dangling edges as lines (the thick edges of Low–Tan clustering as wide as their `width`
//! attribute, shaded with the patent's dynamic normal) and their isolated points as squares;
//! layered shells (paper §3) alpha-blended back to front, in the order the file stores for the
//! view's octant, or computed afresh from the volume grids the files record for a perspective
//! camera or several layered inputs ([`voxlod_layers::scene_order`]). Cost: the rasterizing,
//! O(pixels × supersampling² + triangles), and for a computed order O(T log T).

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use voxlod_clustering::thick_edges::{dynamic_normal, NORMAL, WIDTH};
use voxlod_core::glam::{DVec3, Vec3};
use voxlod_core::{Bounds, PolyMesh, TriangleMesh};
use voxlod_gltf::GlbScene;
use voxlod_layers::{recover_cells, scene_order, CellTriangles, LayersError, Octant, View};
use voxlod_render::{
    render, Camera, Image, LineItem, MeshItem, PointItem, RenderError, RenderOptions, Scene,
};

use crate::{error::Error, files::is_glb, files::read_glb, InvalidOption};

/// The colour of an opaque surface (linear RGB): a light steel grey.
pub const SURFACE_COLOR: [f32; 3] = [0.85, 0.86, 0.9];
/// The colour of dangling edges facing the light.
const WIRE: [f32; 3] = [0.95, 0.55, 0.2];
/// The colour of isolated points.
const POINT_COLOR: [f32; 3] = [0.3, 0.7, 0.95];
/// The widest line or point, in pixels: the largest image side.
const WIDEST: f32 = 16384.0;

/// A view direction scaled so that its largest component is ±1 (which keeps its length
/// finite), refusing a zero one (the option `view`).
pub fn view_direction(view: DVec3) -> Result<DVec3, Error> {
    let largest = view.abs().max_element();
    if largest == 0.0 || !largest.is_finite() {
        let value = format!("{},{},{}", view.x, view.y, view.z);
        let problem = if largest == 0.0 {
            "the view direction has zero length"
        } else {
            "the view direction is not finite"
        };
        return Err(InvalidOption::new("view", value, problem).into());
    }
    Ok(view / largest)
}

/// One input of [`draw`].
#[derive(Clone, Debug)]
pub enum Drawable {
    /// A mesh with its dangling edges and isolated points, drawn opaque.
    Plain(PolyMesh),
    /// Layered shells as a `.glb` of [`crate::layers()`] holds them, blended; `name` (the file)
    /// is what errors about it say.
    Layered {
        /// The layers, their colours, the eight stored orders, the volume grid.
        scene: GlbScene,
        /// The file's name.
        name: String,
    },
}

/// Reads an input of [`draw`]: a `.glb` (layered shells, or a plain mesh when it stores no
/// orders), or any mesh format with its dangling edges and isolated points.
pub fn read_drawable(path: impl AsRef<Path>) -> Result<Drawable, Error> {
    let path = path.as_ref();
    if !is_glb(path) {
        return Ok(Drawable::Plain(voxlod_io::read_poly_mesh(path)?));
    }
    let scene = read_glb(path)?;
    Ok(if scene.is_layered() {
        Drawable::Layered {
            scene,
            name: path.display().to_string(),
        }
    } else {
        Drawable::Plain(PolyMesh::from(scene.mesh))
    })
}

/// Options of [`draw`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DrawOptions {
    /// The direction the camera looks along, eye to scene; its octant picks a layered file's
    /// stored order.
    pub view: DVec3,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// N×N samples per pixel (1 to 32).
    pub supersample: u32,
    /// A perspective camera instead of an orthographic one.
    pub perspective: bool,
    /// Vertical field of view of the perspective camera, degrees (more than 0, less than 180).
    pub fov: f64,
    /// Width of dangling edges without a `width` attribute, in pixels.
    pub line_width: f32,
    /// Side of isolated points, in pixels.
    pub point_size: f32,
    /// Linear RGB of uncovered pixels, each component in [0, 1].
    pub background: [f32; 3],
}

impl Default for DrawOptions {
    /// Along (−1, −1, −1), 800 × 800, one sample per pixel, orthographic (35° when
    /// perspective), edges 2 px, points 4 px, a dark background.
    fn default() -> Self {
        DrawOptions {
            view: DVec3::splat(-1.0),
            width: 800,
            height: 800,
            supersample: 1,
            perspective: false,
            fov: 35.0,
            line_width: 2.0,
            point_size: 4.0,
            background: RenderOptions::default().background,
        }
    }
}

/// Refuses options out of their range, naming the option. Cheap; call it to refuse bad options
/// before reading any input ([`draw`] calls it too).
pub fn check_draw_options(options: &DrawOptions) -> Result<(), Error> {
    if !(1..=32).contains(&options.supersample) {
        let problem = "choose 1 to 32 samples per pixel side";
        return Err(InvalidOption::new("supersample", options.supersample, problem).into());
    }
    let fov = options.fov;
    if !(fov > 0.0 && fov < 180.0) {
        let problem = "the field of view must be more than 0 and less than 180 degrees";
        return Err(InvalidOption::new("fov", fov, problem).into());
    }
    for (option, px) in [
        ("line_width", options.line_width),
        ("point_size", options.point_size),
    ] {
        if !(px > 0.0 && px <= WIDEST) {
            let problem = format!("choose more than 0 and at most {WIDEST} pixels");
            return Err(InvalidOption::new(option, px, problem).into());
        }
    }
    if let Some(c) = options
        .background
        .iter()
        .find(|c| !(0.0..=1.0).contains(*c))
    {
        let [r, g, b] = options.background;
        let problem = format!("each component is linear RGB from 0 to 1, not {c}");
        return Err(InvalidOption::new("background", format!("{r},{g},{b}"), problem).into());
    }
    view_direction(options.view)?;
    Ok(())
}

/// The picture and what went into it.
#[derive(Clone, Debug)]
pub struct Drawing {
    /// The image, linear RGB.
    pub image: Image,
    /// The octant of the view direction.
    pub octant: Octant,
    /// Triangles of the plain inputs.
    pub opaque_triangles: usize,
    /// Triangles of the layered inputs.
    pub layered_triangles: usize,
    /// Dangling edges of the plain inputs.
    pub lines: usize,
    /// Isolated points of the plain inputs.
    pub points: usize,
    /// How the layered triangles were ordered: `"stored"` (the file's order for the octant) or
    /// `"computed"` (from the volume grids); `None` without layered inputs.
    pub layered_order: Option<&'static str>,
}

/// Draws `inputs` framed along `options.view`.
///
/// ```
/// # fn main() -> Result<(), voxlod::Error> {
/// use voxlod::core::glam::{DVec3, Vec3};
/// let p = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
/// let t = vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]];
/// let tetra = voxlod::core::TriangleMesh::new(p, t);
/// let input = voxlod::Drawable::Plain(tetra.into());
/// let options = voxlod::DrawOptions { width: 40, height: 30, ..Default::default() };
/// let drawing = voxlod::draw(&[input], &options)?;
/// assert_eq!((drawing.image.width, drawing.image.height, drawing.opaque_triangles), (40, 30, 4));
/// # Ok(())
/// # }
/// ```
pub fn draw(inputs: &[Drawable], options: &DrawOptions) -> Result<Drawing, Error> {
    check_draw_options(options)?;
    let view = view_direction(options.view)?;
    let octant = Octant::of(view)?;
    let camera = frame(inputs, view, options)?;
    let render_options = RenderOptions {
        supersample: options.supersample,
        background: options.background,
        ..Default::default()
    };
    let mut groups = Vec::new();
    for (i, input) in inputs.iter().enumerate() {
        if let Drawable::Plain(m) = input {
            if !m.lines.is_empty() {
                let default_width = options.line_width;
                groups.extend(line_groups(i, m, &camera, &render_options, default_width)?);
            }
        }
    }
    let mut scene = Scene::default();
    let [opaque_triangles, lines, points] =
        add_plain(inputs, &groups, options.point_size, &mut scene);
    let blended = blend_inputs(inputs, octant, &camera, options.perspective)?;
    if let Some((b, _)) = &blended {
        scene.meshes.push(MeshItem::blended(
            &b.mesh,
            b.palette.clone(),
            &b.triangle_palette,
            &b.order,
        ));
    }
    Ok(Drawing {
        image: render(&scene, &camera, &render_options)?,
        octant,
        opaque_triangles,
        layered_triangles: blended.as_ref().map_or(0, |(b, _)| b.mesh.triangles.len()),
        lines,
        points,
        layered_order: blended.map(|(_, how)| how),
    })
}

/// The camera along `view` that frames everything.
fn frame(inputs: &[Drawable], view: DVec3, options: &DrawOptions) -> Result<Camera, Error> {
    let mut bounds = Bounds::EMPTY;
    for input in inputs {
        bounds = bounds.union(&match input {
            Drawable::Plain(m) => m.bounds(),
            Drawable::Layered { scene, .. } => scene.mesh.bounds(),
        });
    }
    if bounds.is_empty() {
        return Err(RenderError::EmptyScene.into());
    }
    let fov = options.perspective.then_some(options.fov);
    Ok(Camera::fit(
        view,
        &bounds,
        options.width,
        options.height,
        fov,
    )?)
}

/// Dangling edges of one look, drawn as one line item.
struct LineGroup {
    input: usize,
    lines: Vec<[u32; 2]>,
    color: [f32; 3],
    width: f32,
}

/// The dangling edges of `m` grouped by pixel width (quarter pixels) and shade (1/32): per-line
/// widths from the `width` attribute and shades from the dynamic normal (Low–Tan) when the
/// mesh has them, else one group of `default_width` pixels, unshaded.
fn line_groups(
    input: usize,
    m: &PolyMesh,
    camera: &Camera,
    options: &RenderOptions,
    default_width: f32,
) -> Result<Vec<LineGroup>, Error> {
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
    let light = options.light_direction(camera)?.as_vec3();
    let mut groups: BTreeMap<(u32, u32), Vec<[u32; 2]>> = BTreeMap::new();
    for (i, &[a, b]) in m.lines.iter().enumerate() {
        let (pa, pb) = (m.mesh.positions[a as usize], m.mesh.positions[b as usize]);
        let mid = ((pa + pb) * 0.5).as_dvec3();
        let px = (widths.values[i] as f64 / camera.pixel_size_at(mid)).max(1.0);
        let shade = match normals {
            Some((x, y, z)) => {
                let stored = Vec3::new(x.values[i], y.values[i], z.values[i]);
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

/// The plain inputs' opaque meshes, points and line groups in the scene; their triangles,
/// dangling edges and isolated points counted.
fn add_plain<'a>(
    inputs: &'a [Drawable],
    groups: &'a [LineGroup],
    point_size: f32,
    scene: &mut Scene<'a>,
) -> [usize; 3] {
    let mut counts = [0; 3];
    for input in inputs {
        let Drawable::Plain(m) = input else { continue };
        counts[0] += m.mesh.triangles.len();
        counts[1] += m.lines.len();
        counts[2] += m.points.len();
        if !m.mesh.triangles.is_empty() {
            scene.meshes.push(MeshItem::opaque(&m.mesh, SURFACE_COLOR));
        }
        if !m.points.is_empty() {
            scene.points.push(PointItem {
                positions: &m.mesh.positions,
                points: &m.points,
                color: POINT_COLOR,
                size: point_size,
            });
        }
    }
    for g in groups {
        let Drawable::Plain(m) = &inputs[g.input] else {
            unreachable!("line groups come from plain meshes")
        };
        scene.lines.push(LineItem {
            positions: &m.mesh.positions,
            lines: &g.lines,
            color: g.color,
            width: g.width,
        });
    }
    counts
}

/// Every layered input in one blended mesh.
struct Blended {
    mesh: TriangleMesh,
    palette: Vec<[f32; 4]>,
    triangle_palette: Vec<u16>,
    order: Vec<u32>,
}

/// The layered inputs in one blended mesh in back-to-front order, and how it was ordered
/// (none without layered inputs).
fn blend_inputs(
    inputs: &[Drawable],
    octant: Octant,
    camera: &Camera,
    perspective: bool,
) -> Result<Option<(Blended, &'static str)>, Error> {
    let layered: Vec<(&GlbScene, &str)> = inputs
        .iter()
        .filter_map(|i| match i {
            Drawable::Layered { scene, name } => Some((scene, name.as_str())),
            Drawable::Plain(_) => None,
        })
        .collect();
    if layered.is_empty() {
        return Ok(None);
    }
    let (mut out, first_triangle) = concatenated(&layered)?;
    if let ([(g, name)], false) = (&layered[..], perspective) {
        out.order = stored_order(g, octant).map_err(|e| e.context(*name))?;
        return Ok(Some((out, "stored")));
    }
    let order = computed_order(&layered, camera, perspective)?;
    out.order = order
        .iter()
        .map(|&(o, t)| first_triangle[o as usize] + t)
        .collect();
    Ok(Some((out, "computed")))
}

/// The layered scenes in one mesh with a palette entry per layer, and each scene's first
/// triangle in it.
fn concatenated(layered: &[(&GlbScene, &str)]) -> Result<(Blended, Vec<u32>), Error> {
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
            let problem = format!("too many layers to draw at once (at most {})", u16::MAX);
            return Err(RenderError::Invalid(problem).into());
        }
        out.palette.extend(g.parts.iter().map(|p| p.color));
        out.triangle_palette
            .extend(g.triangle_parts().iter().map(|&p| p + palette_base as u16));
        out.mesh.positions.extend_from_slice(&g.mesh.positions);
        out.mesh
            .triangles
            .extend(g.mesh.triangles.iter().map(|t| t.map(|v| v + base)));
    }
    if layered.iter().all(|(g, _)| !g.mesh.normals.is_empty()) {
        for (g, _) in layered {
            out.mesh.normals.extend_from_slice(&g.mesh.normals);
        }
    }
    Ok((out, first_triangle))
}

/// The order a layered file stores for `octant`, as indices of its triangles.
fn stored_order(g: &GlbScene, octant: Octant) -> Result<Vec<u32>, Error> {
    let invalid = |problem: String| Error::from(LayersError::Gltf(problem));
    let stored = g.orders[octant.index()]
        .as_ref()
        .ok_or_else(|| invalid(format!("no {} order", octant.name())))?;
    let mut by_corners = HashMap::with_capacity(g.mesh.triangles.len());
    for (i, t) in g.mesh.triangles.iter().enumerate() {
        by_corners.insert(*t, i as u32);
    }
    stored
        .iter()
        .map(|t| {
            by_corners.get(t).copied().ok_or_else(|| {
                let name = octant.name();
                invalid(format!("the {name} order names a triangle no layer has"))
            })
        })
        .collect()
}

/// The back-to-front order of all layered scenes for the camera, computed from the volume
/// grids they record: (scene, triangle) pairs.
fn computed_order(
    layered: &[(&GlbScene, &str)],
    camera: &Camera,
    perspective: bool,
) -> Result<Vec<(u32, u32)>, Error> {
    let mut objects = Vec::new();
    let mut cells = Vec::new();
    for (g, name) in layered {
        let grid = g.grid.ok_or_else(|| {
            let problem = "the file records no volume grid, which a perspective camera and \
                           several layered files need (the layered shells of voxlod record it)";
            Error::from(LayersError::Gltf(problem.into())).context(*name)
        })?;
        let (positions, triangles) = (&g.mesh.positions, &g.mesh.triangles);
        cells.push(recover_cells(&grid, &g.placement, positions, triangles));
        objects.push(grid);
    }
    let objects: Vec<CellTriangles> = layered
        .iter()
        .zip(&cells)
        .zip(objects)
        .map(|(((g, _), c), grid)| CellTriangles {
            grid,
            placement: g.placement,
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
    Ok(scene_order(&objects, &view)?.order)
}

#[cfg(test)]
mod tests {
    use voxlod_core::glam::{DVec3, Vec3};
    use voxlod_core::{Attribute, Bounds, PolyMesh, TriangleMesh};
    use voxlod_render::{Camera, Projection, RenderOptions};

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
        let bounds = Bounds::new(DVec3::splat(-1.0), DVec3::splat(1.0));
        let mut cam = Camera::fit(DVec3::new(0.0, 0.0, 1.0), &bounds, 200, 200, None).unwrap();
        cam.projection = Projection::Orthographic { half_height: 1.0 };
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
