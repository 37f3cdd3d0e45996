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
//! Blended triangles are z-tested against the opaque surfaces but write no depth: the order,
//! not a z-buffer, decides which translucent layer covers which. Triangles with a vertex before a
//! perspective camera's near plane, or reaching far outside the image, are skipped.
//!
//! Cost: O(V + T) to transform and bin, plus O(covered samples) to fill.

use glam::{DVec3, Vec3};
use rayon::prelude::*;
use voxlod_core::{Bounds, TriangleMesh};

use crate::raster::{raster_triangle, ScreenVertex, Tile};
use crate::{Camera, Image, RenderError};

/// How to draw.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderOptions {
    /// Samples per pixel side (1 to 32): N×N samples per pixel, box-filtered.
    pub supersample: u32,
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
    pub mesh: &'a TriangleMesh,
    /// Linear RGBA colours; alpha is used when blending.
    pub palette: Vec<[f32; 4]>,
    /// Palette entry of each triangle (entry 0 for all when `None`).
    pub triangle_palette: Option<&'a [u16]>,
    /// Triangles in drawing order (all, in storage order, when `None`).
    pub order: Option<&'a [u32]>,
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
    pub positions: &'a [Vec3],
    pub lines: &'a [[u32; 2]],
    pub color: [f32; 3],
    pub width: f32,
}

/// Points drawn as squares of `size` pixels.
#[derive(Clone, Copy, Debug)]
pub struct PointItem<'a> {
    pub positions: &'a [Vec3],
    pub points: &'a [u32],
    pub color: [f32; 3],
    pub size: f32,
}

/// Everything to draw. Blended meshes are drawn after everything else, in their order here.
#[derive(Clone, Debug, Default)]
pub struct Scene<'a> {
    pub meshes: Vec<MeshItem<'a>>,
    pub lines: Vec<LineItem<'a>>,
    pub points: Vec<PointItem<'a>>,
}

impl Scene<'_> {
    /// Bounds of the vertices that are drawn.
    pub fn bounds(&self) -> Bounds {
        let mut b = Bounds::EMPTY;
        for m in &self.meshes {
            b = b.union(&m.mesh.bounds());
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
/// the number of meshes), triangle `tri`.
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
pub fn render(
    scene: &Scene,
    camera: &Camera,
    options: &RenderOptions,
) -> Result<Image, RenderError> {
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
    let light = options.light_direction(camera)?.as_vec3();
    let lambert = |n: Vec3| options.shade(n, light);

    // (1) Project and shade.
    let project = |p: Vec3| -> ScreenVertex {
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
    };
    let mut prepared: Vec<Prepared> = scene
        .meshes
        .iter()
        .map(|m| {
            let mesh = m.mesh;
            let with_normals = !mesh.normals.is_empty();
            let vertices: Vec<ScreenVertex> = (0..mesh.positions.len())
                .into_par_iter()
                .map(|i| {
                    let mut v = project(mesh.positions[i]);
                    if with_normals && !v.is_culled() {
                        v.shade = lambert(mesh.normals[i].normalize_or_zero());
                    }
                    v
                })
                .collect();
            let flat = if with_normals {
                Vec::new()
            } else {
                mesh.triangles
                    .par_iter()
                    .map(|t| {
                        let [a, b, c] = t.map(|v| mesh.positions[v as usize]);
                        lambert((b - a).cross(c - a).normalize_or_zero())
                    })
                    .collect()
            };
            Prepared { vertices, flat }
        })
        .collect();
    // Lines and points as quads.
    let mut quads = Prepared {
        vertices: Vec::new(),
        flat: Vec::new(),
    };
    let mut quad_colors: Vec<[f32; 4]> = Vec::new();
    let mut quad_tris: Vec<[u32; 3]> = Vec::new();
    let mut push_quad = |corners: [ScreenVertex; 4], color: [f32; 3]| {
        let base = quads.vertices.len() as u32;
        quads.vertices.extend_from_slice(&corners);
        for t in [[0, 1, 2], [0, 2, 3]] {
            quad_tris.push(t.map(|k| base + k));
            quads.flat.push(1.0);
            quad_colors.push([color[0], color[1], color[2], 1.0]);
        }
    };
    for l in &scene.lines {
        let half = 0.5 * l.width.max(0.0);
        for &[a, b] in l.lines {
            let (pa, pb) = (
                project(l.positions[a as usize]),
                project(l.positions[b as usize]),
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
            push_quad(
                [off(pa, 1.0), off(pb, 1.0), off(pb, -1.0), off(pa, -1.0)],
                l.color,
            );
        }
    }
    for p in &scene.points {
        let half = 0.5 * p.size.max(0.0);
        for &v in p.points {
            let c = project(p.positions[v as usize]);
            if c.is_culled() || half == 0.0 {
                continue;
            }
            let at = |sx: f32, sy: f32| ScreenVertex {
                x: c.x + sx * half,
                y: c.y + sy * half,
                shade: 1.0,
                ..c
            };
            push_quad(
                [at(-1.0, -1.0), at(1.0, -1.0), at(1.0, 1.0), at(-1.0, 1.0)],
                p.color,
            );
        }
    }
    let quad_source = prepared.len() as u32;
    prepared.push(quads);

    // The draw list, in drawing order.
    let mut draws: Vec<Draw> = Vec::new();
    for (s, m) in scene.meshes.iter().enumerate().filter(|(_, m)| !m.blend) {
        draws.extend((0..m.mesh.triangles.len() as u32).map(|tri| Draw {
            source: s as u32,
            tri,
        }));
    }
    draws.extend((0..quad_tris.len() as u32).map(|tri| Draw {
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

    let corners = |d: Draw| -> [ScreenVertex; 3] {
        let tri = if d.source == quad_source {
            quad_tris[d.tri as usize]
        } else {
            scene.meshes[d.source as usize].mesh.triangles[d.tri as usize]
        };
        let verts = &prepared[d.source as usize].vertices;
        tri.map(|v| verts[v as usize])
    };
    let material = |d: Draw| -> ([f32; 4], f32) {
        if d.source == quad_source {
            return (quad_colors[d.tri as usize], 1.0);
        }
        let m = &scene.meshes[d.source as usize];
        let c = m.palette[m
            .triangle_palette
            .map_or(0, |tp| tp[d.tri as usize] as usize)];
        let flat = prepared[d.source as usize]
            .flat
            .get(d.tri as usize)
            .copied()
            .unwrap_or(1.0);
        (c, flat)
    };

    // (2) Bin.
    let tile_px = (128 / n).clamp(8, 32);
    let tiles_x = width.div_ceil(tile_px);
    let tiles_y = height.div_ceil(tile_px);
    let tile_count = (tiles_x * tiles_y) as usize;
    let guard = 8.0 * width.max(height) as f32;
    let tile_range = |v: &[ScreenVertex; 3]| -> Option<(u32, u32, u32, u32)> {
        if v.iter().any(|x| x.is_culled()) {
            return None;
        }
        let min_x = v[0].x.min(v[1].x).min(v[2].x);
        let max_x = v[0].x.max(v[1].x).max(v[2].x);
        let min_y = v[0].y.min(v[1].y).min(v[2].y);
        let max_y = v[0].y.max(v[1].y).max(v[2].y);
        if !(max_x >= 0.0 && max_y >= 0.0 && min_x <= width as f32 && min_y <= height as f32) {
            return None;
        }
        if min_x < -guard || min_y < -guard || max_x > guard || max_y > guard {
            return None;
        }
        let t = tile_px as f32;
        let tx0 = (min_x.max(0.0) / t) as u32;
        let ty0 = (min_y.max(0.0) / t) as u32;
        let tx1 = ((max_x / t) as u32).min(tiles_x - 1);
        let ty1 = ((max_y / t) as u32).min(tiles_y - 1);
        Some((tx0, ty0, tx1, ty1))
    };
    let chunk = (draws.len() / (4 * rayon::current_num_threads().max(1))).max(4096);
    let bins: Vec<(Vec<u32>, Vec<u32>)> = draws
        .par_chunks(chunk)
        .enumerate()
        .map(|(ci, ds)| {
            let ranges: Vec<Option<(u32, u32, u32, u32)>> =
                ds.iter().map(|&d| tile_range(&corners(d))).collect();
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
        .collect();

    // (3) Draw the tiles.
    let side = (tile_px * n) as usize;
    let samples = (n * n) as f32;
    let tiles: Vec<(Vec<[f32; 3]>, Vec<f32>)> = (0..tile_count)
        .into_par_iter()
        .map_init(
            || Tile::new(side),
            |tile, t| {
                let (tx, ty) = (t as u32 % tiles_x, t as u32 / tiles_x);
                tile.clear(
                    (tx * tile_px * n) as i64,
                    (ty * tile_px * n) as i64,
                    options.background,
                );
                for (start, items) in &bins {
                    for &k in &items[start[t] as usize..start[t + 1] as usize] {
                        let d = draws[k as usize];
                        let (rgba, flat) = material(d);
                        raster_triangle(
                            tile,
                            corners(d),
                            n,
                            flat,
                            rgba,
                            k as usize >= first_blended,
                        );
                    }
                }
                // Box filter N×N samples into each pixel.
                let px = tile_px as usize;
                let mut rgb = vec![[0.0f32; 3]; px * px];
                let mut cov = vec![0.0f32; px * px];
                for y in 0..side {
                    for x in 0..side {
                        let s = y * side + x;
                        let p = (y / n as usize) * px + x / n as usize;
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
            },
        )
        .collect();
    let mut image = Image::new(width, height, options.background);
    for (t, (rgb, cov)) in tiles.into_iter().enumerate() {
        let (tx, ty) = (t as u32 % tiles_x, t as u32 / tiles_x);
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
    Ok(image)
}
