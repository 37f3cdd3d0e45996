//! Drawing a scene: opaque meshes through a z-buffer, thick lines and points, then translucent
//! meshes alpha-blended in the order given (back to front), each sample of an N×N grid per pixel
//! averaged into the pixel.
//!
//! **Pipeline.** (1) Every vertex is projected and shaded once (Lambert, two-sided:
//! `ambient + (1 − ambient) |n · l|` from the vertex normals, or flat from the face when a mesh
//! has none), in parallel. Lines and points become screen-space quads of their width. (2) The
//! draws — opaque triangles, line and point quads, then blended triangles in their order — are
//! binned into square tiles of the image, in parallel over chunks of the draw list, each chunk
//! keeping its draws in order. (3) Tiles are drawn in parallel: each walks its draws chunk by
//! chunk, so blended triangles reach every sample in the given order, into a tile of N×N samples
//! per pixel that is averaged into the image at the end. Memory stays per tile, so a 16×16
//! supersampled reference costs no more memory than one tile per thread.
//!
//! Assets ([`AssetItem`], module [`crate::looks`]) are drawn with their looks: their opaque and
//! masked triangles with the opaque draws, their `BLEND` triangles after the blended meshes, in
//! storage order; each sample's colour comes from the material, vertex colours and texture.
//!
//! Blended triangles are z-tested against the opaque surfaces but write no depth: the order,
//! not a z-buffer, decides which translucent layer covers which. Triangles with a vertex before a
//! perspective camera's near plane, or reaching far outside the image, are skipped.
//!
//! Cost: O(V + T) to transform and bin, plus O(covered samples) to fill.

use glam::{DVec3, Vec3};
use rayon::prelude::*;
use voxlod_core::{Bounds, TriangleMesh};

use crate::looks::{AssetItem, Lit};
use crate::raster::{raster_fragments, raster_triangle, ScreenVertex, Tile};
use crate::{Camera, Image, RenderError};

/// How to draw.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderOptions {
    /// Samples per pixel side (1 to 32): N×N samples per pixel, box-filtered.
    pub supersample: u32,
    /// Linear RGB of uncovered pixels.
    pub background: [f32; 3],
    /// Light that reaches surfaces facing away from it.
    pub ambient: f32,
    /// Direction towards the light; `None`: a headlight from slightly above and left of the eye.
    pub light: Option<DVec3>,
}

impl Default for RenderOptions {
    /// One sample per pixel, dark background, ambient 0.15, headlight.
    fn default() -> Self {
        RenderOptions {
            supersample: 1,
            background: [0.05, 0.06, 0.08],
            ambient: 0.15,
            light: None,
        }
    }
}

impl RenderOptions {
    /// The unit direction towards the light for `camera`: [`RenderOptions::light`], or the
    /// headlight.
    pub fn light_direction(&self, camera: &Camera) -> Result<DVec3, RenderError> {
        match self.light {
            Some(l) => crate::camera::check_direction(l),
            None => Ok((-camera.forward + 0.35 * camera.up - 0.25 * camera.right).normalize()),
        }
    }

    /// The Lambert shade of a surface of unit normal `n` (either side lit):
    /// `ambient + (1 − ambient) |n · light|`.
    #[inline]
    pub fn shade(&self, n: Vec3, light: Vec3) -> f32 {
        let ambient = self.ambient.clamp(0.0, 1.0);
        ambient + (1.0 - ambient) * n.dot(light).abs()
    }

    /// The 16×16 supersampled reference of the antialiasing comparisons.
    pub fn reference() -> Self {
        RenderOptions {
            supersample: 16,
            ..Default::default()
        }
    }
}

/// A triangle mesh to draw, opaque or blended.
#[derive(Clone, Debug)]
pub struct MeshItem<'a> {
    /// The triangles; shaded from its normals, or flat per face when it has none.
    pub mesh: &'a TriangleMesh,
    /// Linear RGBA colours; alpha is used when blending.
    pub palette: Vec<[f32; 4]>,
    /// Palette entry of each triangle (entry 0 for all when `None`).
    pub triangle_palette: Option<&'a [u16]>,
    /// Triangles in drawing order (all, in storage order, when `None`).
    pub order: Option<&'a [u32]>,
    /// Alpha-blended after everything opaque, in `order`, writing no depth; else opaque.
    pub blend: bool,
}

impl<'a> MeshItem<'a> {
    /// An opaque mesh of one colour.
    pub fn opaque(mesh: &'a TriangleMesh, color: [f32; 3]) -> MeshItem<'a> {
        MeshItem {
            mesh,
            palette: vec![[color[0], color[1], color[2], 1.0]],
            triangle_palette: None,
            order: None,
            blend: false,
        }
    }

    /// A translucent mesh drawn in `order` with per-triangle colours from `palette`.
    pub fn blended(
        mesh: &'a TriangleMesh,
        palette: Vec<[f32; 4]>,
        triangle_palette: &'a [u16],
        order: &'a [u32],
    ) -> MeshItem<'a> {
        MeshItem {
            mesh,
            palette,
            triangle_palette: Some(triangle_palette),
            order: Some(order),
            blend: true,
        }
    }
}

/// Line segments drawn `width` pixels wide, opaque and unshaded.
#[derive(Clone, Copy, Debug)]
pub struct LineItem<'a> {
    /// The vertices the lines refer to.
    pub positions: &'a [Vec3],
    /// Segments, as pairs of indices into `positions`.
    pub lines: &'a [[u32; 2]],
    /// Linear RGB.
    pub color: [f32; 3],
    /// Width in output pixels.
    pub width: f32,
}

/// Points drawn as squares of `size` pixels.
#[derive(Clone, Copy, Debug)]
pub struct PointItem<'a> {
    /// The vertices the points refer to.
    pub positions: &'a [Vec3],
    /// Indices into `positions` of the points to draw.
    pub points: &'a [u32],
    /// Linear RGB.
    pub color: [f32; 3],
    /// Side of the square in output pixels.
    pub size: f32,
}

/// Everything to draw. Blended meshes are drawn after everything else, in their order here,
/// then the assets' blended triangles.
#[derive(Clone, Debug, Default)]
pub struct Scene<'a> {
    /// Opaque and blended meshes.
    pub meshes: Vec<MeshItem<'a>>,
    /// Assets drawn with their looks (materials, vertex colours, base colour textures).
    pub assets: Vec<AssetItem<'a>>,
    /// Thick line segments (drawn opaque, after the opaque meshes).
    pub lines: Vec<LineItem<'a>>,
    /// Square points (drawn opaque, after the lines).
    pub points: Vec<PointItem<'a>>,
}

impl Scene<'_> {
    /// Bounds of the vertices that are drawn.
    pub fn bounds(&self) -> Bounds {
        let mut b = Bounds::EMPTY;
        for m in &self.meshes {
            b = b.union(&m.mesh.bounds());
        }
        for a in &self.assets {
            for t in &a.asset.mesh.triangles {
                for &v in t {
                    b.grow(a.asset.mesh.positions[v as usize].as_dvec3());
                }
            }
        }
        for l in &self.lines {
            for line in l.lines {
                for &v in line {
                    if let Some(p) = l.positions.get(v as usize) {
                        b.grow(p.as_dvec3());
                    }
                }
            }
        }
        for p in &self.points {
            for &v in p.points {
                if let Some(q) = p.positions.get(v as usize) {
                    b.grow(q.as_dvec3());
                }
            }
        }
        b
    }

    fn check(&self) -> Result<(), RenderError> {
        for (i, m) in self.meshes.iter().enumerate() {
            m.mesh
                .validate()
                .map_err(|e| RenderError::Invalid(format!("mesh {i}: {e}")))?;
            let t = m.mesh.triangles.len();
            if m.palette.is_empty() {
                return Err(RenderError::Invalid(format!("mesh {i}: empty palette")));
            }
            if let Some(tp) = m.triangle_palette {
                if tp.len() != t || tp.iter().any(|&p| p as usize >= m.palette.len()) {
                    return Err(RenderError::Invalid(format!(
                        "mesh {i}: the triangle palette does not fit the mesh"
                    )));
                }
            }
            if let Some(o) = m.order {
                if o.iter().any(|&x| x as usize >= t) {
                    return Err(RenderError::Invalid(format!(
                        "mesh {i}: the order names a triangle beyond its {t}"
                    )));
                }
            }
        }
        for (i, a) in self.assets.iter().enumerate() {
            a.check(i)?;
        }
        for (i, l) in self.lines.iter().enumerate() {
            let n = l.positions.len() as u32;
            if l.lines.iter().flatten().any(|&v| v >= n) {
                return Err(RenderError::Invalid(format!(
                    "lines {i}: a vertex index is out of range"
                )));
            }
        }
        for (i, p) in self.points.iter().enumerate() {
            let n = p.positions.len() as u32;
            if p.points.iter().any(|&v| v >= n) {
                return Err(RenderError::Invalid(format!(
                    "points {i}: a vertex index is out of range"
                )));
            }
        }
        Ok(())
    }
}

/// Where a draw's triangle comes from: mesh `source` (or the generated quads when `source` is
/// the number of meshes, or asset `source − meshes − 1` beyond), triangle `tri`.
#[derive(Clone, Copy, Debug)]
struct Draw {
    source: u32,
    tri: u32,
}

/// Screen-space geometry of a source.
struct Prepared {
    vertices: Vec<ScreenVertex>,
    /// Flat shade per triangle (meshes without normals), else empty.
    flat: Vec<f32>,
}

/// Renders `scene` as seen by `camera` (see the module documentation).
///
/// # Errors
///
/// [`RenderError::BadSize`] for an image side outside 1 to 16384 pixels,
/// [`RenderError::BadSupersample`] outside 1 to 32, [`RenderError::Invalid`] for a mesh, palette,
/// order or index that does not fit, [`RenderError::ZeroViewDirection`] or
/// [`RenderError::NonFiniteView`] for a bad light direction, and the memory budget's refusal
/// ([`RenderError::Core`]).
///
/// # Example
///
/// A unit square seen from above fills, at one sample per pixel, the pixels whose centres it
/// holds: a quarter of a 32×32 image framed on a box twice its size.
///
/// ```
/// use glam::{DVec3, Vec3};
/// use voxlod_core::{Bounds, TriangleMesh};
/// use voxlod_render::{render, Camera, MeshItem, Projection, RenderOptions, Scene};
///
/// let square = TriangleMesh::new(
///     vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
///     vec![[0, 1, 2], [0, 2, 3]],
/// );
/// let frame = Bounds::new(DVec3::new(-0.5, -0.5, -0.5), DVec3::new(1.5, 1.5, 0.5));
/// let mut camera = Camera::fit(DVec3::NEG_Z, &frame, 32, 32, None)?;
/// camera.projection = Projection::Orthographic { half_height: 1.0 }; // 2 units across 32 px
/// let scene = Scene {
///     meshes: vec![MeshItem::opaque(&square, [1.0, 0.5, 0.2])],
///     ..Default::default()
/// };
/// let image = render(&scene, &camera, &RenderOptions::default())?;
/// let covered = image.coverage.iter().filter(|&&c| c == 1.0).count();
/// assert_eq!(covered, 16 * 16);
/// # Ok::<(), voxlod_render::RenderError>(())
/// ```
pub fn render(
    scene: &Scene,
    camera: &Camera,
    options: &RenderOptions,
) -> Result<Image, RenderError> {
    check_request(scene, camera, options)?;
    let light = options.light_direction(camera)?.as_vec3();
    // (1) Project and shade; lines and points become quads.
    let mut prepared = prepare_meshes(scene, camera, options, light);
    let quads = Quads::of(scene, camera);
    prepared.push(quads.prepared);
    prepared.extend(prepare_assets(scene, camera, options, light));
    let sources = Sources {
        scene,
        prepared,
        lit: Lit {
            light,
            ambient: options.ambient,
        },
        quad_source: scene.meshes.len() as u32,
        quad_triangles: quads.triangles,
        quad_colors: quads.colors,
    };
    let draws = DrawList::of(scene, sources.quad_triangles.len());
    // (2) Bin.
    let tiling = Tiling::new(camera.width, camera.height, options.supersample);
    let bins = bin_draws(&draws.draws, &sources, &tiling);
    // (3) Draw the tiles.
    let tiles: Vec<(Vec<[f32; 3]>, Vec<f32>)> = (0..tiling.count)
        .into_par_iter()
        .map_init(
            || Tile::new((tiling.tile_px * options.supersample) as usize),
            |tile, t| draw_tile(tile, t, &draws, &bins, &sources, &tiling, options),
        )
        .collect();
    Ok(assemble(tiles, &tiling, options.background))
}

/// Refuses an image size outside 1 to 16384, a supersampling outside 1 to 32, a scene whose
/// items do not fit together, and an image the memory budget cannot hold.
fn check_request(
    scene: &Scene,
    camera: &Camera,
    options: &RenderOptions,
) -> Result<(), RenderError> {
    let (width, height) = (camera.width, camera.height);
    if !(1..=16384).contains(&width) || !(1..=16384).contains(&height) {
        return Err(RenderError::BadSize(width, height));
    }
    let n = options.supersample;
    if !(1..=32).contains(&n) {
        return Err(RenderError::BadSupersample(n));
    }
    scene.check()?;
    voxlod_core::memory::check_allocation(
        &format!("a {width}x{height} image"),
        voxlod_core::memory::bytes_of::<[f32; 4]>(width as usize * height as usize),
    )?;
    Ok(())
}

/// Where `p` lands on screen, or [`ScreenVertex::CULLED`] before a perspective camera's near
/// plane; the shade is left NaN.
#[inline]
fn project(camera: &Camera, p: Vec3) -> ScreenVertex {
    match camera.project(p.as_dvec3()) {
        Some(s) => ScreenVertex {
            x: s.x as f32,
            y: s.y as f32,
            z: s.depth_key as f32,
            w: s.w_inv as f32,
            shade: f32::NAN,
        },
        None => ScreenVertex::CULLED,
    }
}

/// Every mesh's vertices projected and shaded from their normals, or, for a mesh without
/// normals, a flat shade per triangle; in parallel.
fn prepare_meshes(
    scene: &Scene,
    camera: &Camera,
    options: &RenderOptions,
    light: Vec3,
) -> Vec<Prepared> {
    (scene.meshes.iter())
        .map(|m| {
            let mesh = m.mesh;
            prepare(
                &mesh.positions,
                &mesh.normals,
                &mesh.triangles,
                camera,
                options,
                light,
            )
        })
        .collect()
}

/// Every asset's vertices projected and shaded, as [`prepare_meshes`] does for meshes.
fn prepare_assets(
    scene: &Scene,
    camera: &Camera,
    options: &RenderOptions,
    light: Vec3,
) -> Vec<Prepared> {
    (scene.assets.iter())
        .map(|a| {
            let mesh = &a.asset.mesh;
            prepare(
                &mesh.positions,
                &mesh.normals,
                &mesh.triangles,
                camera,
                options,
                light,
            )
        })
        .collect()
}

/// Vertices projected and shaded from their normals (or, with none, a flat shade per
/// triangle), in parallel.
fn prepare(
    positions: &[Vec3],
    normals: &[Vec3],
    triangles: &[[u32; 3]],
    camera: &Camera,
    options: &RenderOptions,
    light: Vec3,
) -> Prepared {
    let lambert = |n: Vec3| options.shade(n, light);
    let with_normals = !normals.is_empty();
    let vertices: Vec<ScreenVertex> = (0..positions.len())
        .into_par_iter()
        .map(|i| {
            let mut v = project(camera, positions[i]);
            if with_normals && !v.is_culled() {
                v.shade = lambert(normals[i].normalize_or_zero());
            }
            v
        })
        .collect();
    let flat = if with_normals {
        Vec::new()
    } else {
        triangles
            .par_iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| positions[v as usize]);
                lambert((b - a).cross(c - a).normalize_or_zero())
            })
            .collect()
    };
    Prepared { vertices, flat }
}

/// The scene's lines and points as screen-space quads of their width, two triangles each.
struct Quads {
    prepared: Prepared,
    triangles: Vec<[u32; 3]>,
    colors: Vec<[f32; 4]>,
}

impl Quads {
    /// The quads of every line and point of `scene`, lines first.
    fn of(scene: &Scene, camera: &Camera) -> Quads {
        let mut quads = Quads {
            prepared: Prepared {
                vertices: Vec::new(),
                flat: Vec::new(),
            },
            triangles: Vec::new(),
            colors: Vec::new(),
        };
        for l in &scene.lines {
            quads.add_lines(l, camera);
        }
        for p in &scene.points {
            quads.add_points(p, camera);
        }
        quads
    }

    fn push(&mut self, corners: [ScreenVertex; 4], color: [f32; 3]) {
        let base = self.prepared.vertices.len() as u32;
        self.prepared.vertices.extend_from_slice(&corners);
        for t in [[0, 1, 2], [0, 2, 3]] {
            self.triangles.push(t.map(|k| base + k));
            self.prepared.flat.push(1.0);
            self.colors.push([color[0], color[1], color[2], 1.0]);
        }
    }

    /// Each segment as a rectangle `width` pixels across, centred on it.
    fn add_lines(&mut self, l: &LineItem, camera: &Camera) {
        let half = 0.5 * l.width.max(0.0);
        for &[a, b] in l.lines {
            let (pa, pb) = (
                project(camera, l.positions[a as usize]),
                project(camera, l.positions[b as usize]),
            );
            if pa.is_culled() || pb.is_culled() || half == 0.0 {
                continue;
            }
            let (dx, dy) = (pb.x - pa.x, pb.y - pa.y);
            let len = (dx * dx + dy * dy).sqrt();
            let (nx, ny) = if len > 1e-6 {
                (-dy / len * half, dx / len * half)
            } else {
                (half, 0.0)
            };
            let off = |v: ScreenVertex, s: f32| ScreenVertex {
                x: v.x + s * nx,
                y: v.y + s * ny,
                shade: 1.0,
                ..v
            };
            self.push(
                [off(pa, 1.0), off(pb, 1.0), off(pb, -1.0), off(pa, -1.0)],
                l.color,
            );
        }
    }

    /// Each point as a square `size` pixels across, centred on it.
    fn add_points(&mut self, p: &PointItem, camera: &Camera) {
        let half = 0.5 * p.size.max(0.0);
        for &v in p.points {
            let c = project(camera, p.positions[v as usize]);
            if c.is_culled() || half == 0.0 {
                continue;
            }
            let at = |sx: f32, sy: f32| ScreenVertex {
                x: c.x + sx * half,
                y: c.y + sy * half,
                shade: 1.0,
                ..c
            };
            self.push(
                [at(-1.0, -1.0), at(1.0, -1.0), at(1.0, 1.0), at(-1.0, 1.0)],
                p.color,
            );
        }
    }
}

/// Everything a draw refers to: the meshes, their prepared vertices, and the quads (source
/// `quad_source`, the last of `prepared`).
struct Sources<'s, 'a> {
    scene: &'s Scene<'a>,
    prepared: Vec<Prepared>,
    /// How normal-mapped samples are lit.
    lit: Lit,
    quad_source: u32,
    quad_triangles: Vec<[u32; 3]>,
    quad_colors: Vec<[f32; 4]>,
}

impl Sources<'_, '_> {
    /// The screen vertices of a draw's triangle.
    #[inline]
    fn corners(&self, d: Draw) -> [ScreenVertex; 3] {
        let tri = if d.source < self.quad_source {
            self.scene.meshes[d.source as usize].mesh.triangles[d.tri as usize]
        } else if d.source == self.quad_source {
            self.quad_triangles[d.tri as usize]
        } else {
            self.asset(d).asset.mesh.triangles[d.tri as usize]
        };
        let verts = &self.prepared[d.source as usize].vertices;
        tri.map(|v| verts[v as usize])
    }

    /// Whether a draw is culled when seen from its back ([`AssetItem::culls_back`]).
    #[inline]
    fn culls_back(&self, d: Draw) -> bool {
        d.source > self.quad_source && self.asset(d).culls_back(d.tri as usize)
    }

    /// The asset of a draw beyond the quads.
    #[inline]
    fn asset(&self, d: Draw) -> &AssetItem<'_> {
        &self.scene.assets[(d.source - self.quad_source - 1) as usize]
    }

    /// A draw's flat shade (1 where its vertices carry shades).
    #[inline]
    fn flat(&self, d: Draw) -> f32 {
        self.prepared[d.source as usize]
            .flat
            .get(d.tri as usize)
            .copied()
            .unwrap_or(1.0)
    }

    /// A draw's colour (RGBA) and flat shade.
    #[inline]
    fn material(&self, d: Draw) -> ([f32; 4], f32) {
        if d.source == self.quad_source {
            return (self.quad_colors[d.tri as usize], 1.0);
        }
        let m = &self.scene.meshes[d.source as usize];
        let c = m.palette[m
            .triangle_palette
            .map_or(0, |tp| tp[d.tri as usize] as usize)];
        let flat = self.prepared[d.source as usize]
            .flat
            .get(d.tri as usize)
            .copied()
            .unwrap_or(1.0);
        (c, flat)
    }
}

/// The draws in drawing order: opaque triangles, line and point quads, then the blended
/// triangles, mesh by mesh in their orders (from `first_blended` on).
struct DrawList {
    draws: Vec<Draw>,
    first_blended: usize,
}

impl DrawList {
    fn of(scene: &Scene, quad_triangles: usize) -> DrawList {
        let quad_source = scene.meshes.len() as u32;
        let mut draws: Vec<Draw> = Vec::new();
        for (s, m) in scene.meshes.iter().enumerate().filter(|(_, m)| !m.blend) {
            draws.extend((0..m.mesh.triangles.len() as u32).map(|tri| Draw {
                source: s as u32,
                tri,
            }));
        }
        for (k, a) in scene.assets.iter().enumerate() {
            let source = quad_source + 1 + k as u32;
            draws.extend(
                (0..a.asset.mesh.triangles.len())
                    .filter(|&t| !a.blends(t))
                    .map(|t| Draw {
                        source,
                        tri: t as u32,
                    }),
            );
        }
        draws.extend((0..quad_triangles as u32).map(|tri| Draw {
            source: quad_source,
            tri,
        }));
        let first_blended = draws.len();
        for (s, m) in scene.meshes.iter().enumerate().filter(|(_, m)| m.blend) {
            match m.order {
                Some(o) => draws.extend(o.iter().map(|&tri| Draw {
                    source: s as u32,
                    tri,
                })),
                None => draws.extend((0..m.mesh.triangles.len() as u32).map(|tri| Draw {
                    source: s as u32,
                    tri,
                })),
            }
        }
        for (k, a) in scene.assets.iter().enumerate() {
            let source = quad_source + 1 + k as u32;
            draws.extend(
                (0..a.asset.mesh.triangles.len())
                    .filter(|&t| a.blends(t))
                    .map(|t| Draw {
                        source,
                        tri: t as u32,
                    }),
            );
        }
        DrawList {
            draws,
            first_blended,
        }
    }
}

/// The image cut into square tiles of `tile_px` pixels (smaller for more samples per pixel).
struct Tiling {
    width: u32,
    height: u32,
    /// Samples per pixel side.
    n: u32,
    tile_px: u32,
    tiles_x: u32,
    tiles_y: u32,
    count: usize,
    /// Triangles reaching beyond ±`guard` pixels are skipped.
    guard: f32,
}

impl Tiling {
    fn new(width: u32, height: u32, n: u32) -> Tiling {
        let tile_px = (128 / n).clamp(8, 32);
        let tiles_x = width.div_ceil(tile_px);
        let tiles_y = height.div_ceil(tile_px);
        Tiling {
            width,
            height,
            n,
            tile_px,
            tiles_x,
            tiles_y,
            count: (tiles_x * tiles_y) as usize,
            guard: 8.0 * width.max(height) as f32,
        }
    }

    /// The tiles (first x, first y, last x, last y) a triangle's box touches; `None` for a
    /// culled triangle, one off the image, or one reaching beyond the guard band.
    #[inline]
    fn tile_range(&self, v: &[ScreenVertex; 3]) -> Option<(u32, u32, u32, u32)> {
        if v.iter().any(|x| x.is_culled()) {
            return None;
        }
        let min_x = v[0].x.min(v[1].x).min(v[2].x);
        let max_x = v[0].x.max(v[1].x).max(v[2].x);
        let min_y = v[0].y.min(v[1].y).min(v[2].y);
        let max_y = v[0].y.max(v[1].y).max(v[2].y);
        if !(max_x >= 0.0
            && max_y >= 0.0
            && min_x <= self.width as f32
            && min_y <= self.height as f32)
        {
            return None;
        }
        let guard = self.guard;
        if min_x < -guard || min_y < -guard || max_x > guard || max_y > guard {
            return None;
        }
        let t = self.tile_px as f32;
        let tx0 = (min_x.max(0.0) / t) as u32;
        let ty0 = (min_y.max(0.0) / t) as u32;
        let tx1 = ((max_x / t) as u32).min(self.tiles_x - 1);
        let ty1 = ((max_y / t) as u32).min(self.tiles_y - 1);
        Some((tx0, ty0, tx1, ty1))
    }
}

/// Whether a triangle shows the camera its back. A front face's corners turn counter-clockwise
/// as the viewer sees them (glTF 2.0 §3.7.2.1); screen rows run down, so in screen coordinates
/// a front face's signed area is negative and a back face's positive.
#[inline]
fn seen_from_behind(v: &[ScreenVertex; 3]) -> bool {
    let area = (v[1].x - v[0].x) * (v[2].y - v[0].y) - (v[2].x - v[0].x) * (v[1].y - v[0].y);
    area > 0.0
}

/// Bins the draws into tiles, in parallel over chunks of the draw list: per chunk, the start of
/// each tile's list (length tiles + 1) and the draws (indices into `draws`) in order.
fn bin_draws(draws: &[Draw], sources: &Sources, tiling: &Tiling) -> Vec<(Vec<u32>, Vec<u32>)> {
    let (tile_count, tiles_x) = (tiling.count, tiling.tiles_x);
    let chunk = (draws.len() / (4 * rayon::current_num_threads().max(1))).max(4096);
    draws
        .par_chunks(chunk)
        .enumerate()
        .map(|(ci, ds)| {
            let ranges: Vec<Option<(u32, u32, u32, u32)>> = ds
                .iter()
                .map(|&d| {
                    let corners = sources.corners(d);
                    let culled = sources.culls_back(d) && seen_from_behind(&corners);
                    (!culled).then(|| tiling.tile_range(&corners)).flatten()
                })
                .collect();
            let mut start = vec![0u32; tile_count + 1];
            for r in ranges.iter().flatten() {
                for ty in r.1..=r.3 {
                    for tx in r.0..=r.2 {
                        start[(ty * tiles_x + tx) as usize + 1] += 1;
                    }
                }
            }
            for t in 0..tile_count {
                start[t + 1] += start[t];
            }
            let mut fill = start.clone();
            let mut items = vec![0u32; start[tile_count] as usize];
            for (k, r) in ranges.iter().enumerate() {
                if let Some(r) = r {
                    for ty in r.1..=r.3 {
                        for tx in r.0..=r.2 {
                            let t = (ty * tiles_x + tx) as usize;
                            items[fill[t] as usize] = (ci * chunk + k) as u32;
                            fill[t] += 1;
                        }
                    }
                }
            }
            (start, items)
        })
        .collect()
}

/// Draws tile `t`: every draw binned to it, chunk by chunk in order, then the N×N samples of
/// each pixel box-filtered into the pixel's colour and coverage.
fn draw_tile(
    tile: &mut Tile,
    t: usize,
    draws: &DrawList,
    bins: &[(Vec<u32>, Vec<u32>)],
    sources: &Sources,
    tiling: &Tiling,
    options: &RenderOptions,
) -> (Vec<[f32; 3]>, Vec<f32>) {
    let (n, tile_px) = (tiling.n, tiling.tile_px);
    let (tx, ty) = (t as u32 % tiling.tiles_x, t as u32 / tiling.tiles_x);
    tile.clear(
        (tx * tile_px * n) as i64,
        (ty * tile_px * n) as i64,
        options.background,
    );
    for (start, items) in bins {
        for &k in &items[start[t] as usize..start[t + 1] as usize] {
            let d = draws.draws[k as usize];
            let blend = k as usize >= draws.first_blended;
            if d.source > sources.quad_source {
                let looks = sources.asset(d).triangle(d.tri as usize, sources.lit);
                raster_fragments(
                    tile,
                    sources.corners(d),
                    n,
                    sources.flat(d),
                    blend,
                    |w, shade| looks.sample(w, shade),
                );
                continue;
            }
            let (rgba, flat) = sources.material(d);
            raster_triangle(tile, sources.corners(d), n, flat, rgba, blend);
        }
    }
    box_filter(tile, tile_px as usize, n as usize)
}

/// The mean of each pixel's N×N samples: colour and coverage of the tile's `px × px` pixels.
fn box_filter(tile: &Tile, px: usize, n: usize) -> (Vec<[f32; 3]>, Vec<f32>) {
    let side = tile.size;
    let samples = (n * n) as f32;
    let mut rgb = vec![[0.0f32; 3]; px * px];
    let mut cov = vec![0.0f32; px * px];
    for y in 0..side {
        for x in 0..side {
            let s = y * side + x;
            let p = (y / n) * px + x / n;
            for (acc, v) in rgb[p].iter_mut().zip(tile.color[s]) {
                *acc += v;
            }
            cov[p] += tile.coverage[s];
        }
    }
    for (pixel, c) in rgb.iter_mut().zip(cov.iter_mut()) {
        for v in pixel.iter_mut() {
            *v /= samples;
        }
        *c /= samples;
    }
    (rgb, cov)
}

/// The image from its tiles (in tile order), cropping the tiles that overhang its edges.
fn assemble(tiles: Vec<(Vec<[f32; 3]>, Vec<f32>)>, tiling: &Tiling, background: [f32; 3]) -> Image {
    let (width, height, tile_px) = (tiling.width, tiling.height, tiling.tile_px);
    let mut image = Image::new(width, height, background);
    for (t, (rgb, cov)) in tiles.into_iter().enumerate() {
        let (tx, ty) = (t as u32 % tiling.tiles_x, t as u32 / tiling.tiles_x);
        for y in 0..tile_px {
            let iy = ty * tile_px + y;
            if iy >= height {
                break;
            }
            for x in 0..tile_px {
                let ix = tx * tile_px + x;
                if ix >= width {
                    break;
                }
                let (s, d) = ((y * tile_px + x) as usize, image.index(ix, iy));
                image.rgb[d] = rgb[s];
                image.coverage[d] = cov[s];
            }
        }
    }
    image
}
