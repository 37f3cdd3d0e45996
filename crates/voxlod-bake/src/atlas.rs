//! A UV atlas for a level that has none: its charts grown, parameterized and packed by
//! xatlas (through [`crate::xatlas`]), cut along creases (edges that bend by more than
//! [`AtlasOptions::crease_degrees`], see [`crate::creases`]), with a padding of texels
//! between charts, on a texture of a given size or at a given texel density.
//!
//! The result is the level unwelded at chart borders: each vertex belongs to one chart and
//! has texture coordinates in [0, 1] (v down the image, as glTF has it), its position and
//! normal, and the level vertex it copies. The charts are made on the level with its slivers
//! snapped shut ([`crate::slivers`]); the triangles that lost their area there take corners of
//! the charts around them.
//!
//! Cost: xatlas's (near-linear in the triangles for the charts of each piece, the pieces side
//! by side; packing tries [`AtlasOptions::attempts`] places per chart), about three packings
//! for a fixed size (more where many small charts crowd it), and one rasterisation to measure
//! the utilisation.

use std::collections::HashMap;
use std::time::Instant;

use serde::{Deserialize, Serialize};
use voxlod_core::glam::{Vec2, Vec3};
use voxlod_core::memory::check_allocation;
use voxlod_core::TriangleMesh;

use crate::creases::crease;
use crate::pieces::pieces;
use crate::slivers::{median_edge, snapped, SNAP_VOXELS};
use crate::xatlas::{ChartOptions, Generated, PackOptions, Xatlas};
use crate::{raster, BakeError};

/// The chart of a triangle xatlas left out (degenerate: no area).
pub const NO_CHART: u32 = u32::MAX;

/// The largest texture side an atlas may have (what common GPUs take).
pub const MAX_TEXTURE: u32 = 16384;

/// Bytes per texel that an atlas and a bake hold at once: the coverage, the baked texels and
/// their dilation map, the images and their PNG encoding.
pub const BAKE_BYTES_PER_TEXEL: u64 = raster::BYTES_PER_TEXEL + 16 + 4 + 16 + 16;

/// How large the texture is.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TextureSize {
    /// A square texture of this many texels a side.
    Texels(u32),
    /// Texels per world unit along the surface; the texture is as large as the charts need.
    Density(f32),
}

/// Options of [`atlas`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct AtlasOptions {
    /// The texture's size, or the texel density it follows.
    pub texture: TextureSize,
    /// Texels of gutter around each chart.
    pub padding: u32,
    /// Edges that bend by more than this many degrees are chart borders.
    pub crease_degrees: f32,
    /// Places xatlas tries per chart when packing (0: every place, slow).
    pub attempts: u32,
    /// A chart may take at most the area of this many of the level's triangles of mean area
    /// (0: no limit). xatlas's parameterization costs more than linear time in a chart's size
    /// (a conjugate-gradient solve and a quadratic check of its border), so large charts of a
    /// large level are slow to make.
    pub max_chart_triangles: u32,
    /// The level is charted in compact pieces of at most this many triangles, side by side
    /// on xatlas's threads ([`crate::pieces`]; 0: one piece). xatlas charts one connected mesh
    /// on one thread in more than linear time in its size.
    pub piece_triangles: u32,
    /// Edges of the level shorter than this (world units) have their ends joined while the
    /// charts are made ([`crate::slivers`]: xatlas mis-scales charts that hold slivers); the
    /// atlas keeps the level's own positions. `None`: [`SNAP_VOXELS`] of the level's median
    /// edge length; `Some(0.0)`: nothing is joined.
    pub sliver_edge: Option<f32>,
}

impl Default for AtlasOptions {
    /// A 1024² texture, 4 texels of padding, creases above 60°, charts of at most about 1024
    /// triangles, pieces of at most 4096, slivers of the level's median edge length.
    fn default() -> Self {
        AtlasOptions {
            texture: TextureSize::Texels(1024),
            padding: 4,
            crease_degrees: 60.0,
            attempts: 1024,
            max_chart_triangles: 1024,
            piece_triangles: 4096,
            sliver_edge: None,
        }
    }
}

impl AtlasOptions {
    /// A square texture of `texels` a side, the rest default.
    pub fn for_texture(texels: u32) -> Self {
        AtlasOptions {
            texture: TextureSize::Texels(texels),
            ..AtlasOptions::default()
        }
    }

    /// `texels_per_unit` texels per world unit, the rest default.
    pub fn for_density(texels_per_unit: f32) -> Self {
        AtlasOptions {
            texture: TextureSize::Density(texels_per_unit),
            ..AtlasOptions::default()
        }
    }

    fn check(&self) -> Result<(), BakeError> {
        let bad = |s: String| Err(BakeError::Invalid(s));
        match self.texture {
            TextureSize::Texels(n) if n < 8 => return bad(format!("a {n}² texture is too small")),
            TextureSize::Density(d) if !(d.is_finite() && d > 0.0) => {
                return bad(format!("texel density {d} is not a positive number"))
            }
            _ => {}
        }
        if let Some(e) = self.sliver_edge.filter(|e| !(e.is_finite() && *e >= 0.0)) {
            return bad(format!("sliver edge {e} is not a number of at least 0"));
        }
        if !(0.0..=180.0).contains(&self.crease_degrees) {
            return bad(format!(
                "crease angle {}° is not in 0..=180",
                self.crease_degrees
            ));
        }
        Ok(())
    }
}

/// A level with texture coordinates (see the module documentation).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Atlas {
    /// Vertex positions, copied from the level.
    pub positions: Vec<Vec3>,
    /// Unit normals (the level's, split at creases).
    pub normals: Vec<Vec3>,
    /// Texture coordinates in [0, 1], v down.
    pub uv: Vec<Vec2>,
    /// The level's triangles, in its order, naming the atlas's vertices.
    pub triangles: Vec<[u32; 3]>,
    /// The level vertex each vertex copies.
    pub level_vertex: Vec<u32>,
    /// The chart of each triangle, or [`NO_CHART`] for a triangle of no area where the charts
    /// were made: its corners are copies in the charts around it, and it covers no texel.
    pub chart: Vec<u32>,
    /// How many charts.
    pub chart_count: usize,
    /// Texture width in texels.
    pub width: u32,
    /// Texture height in texels.
    pub height: u32,
    /// Covered texels (inside or at the border of a triangle) over all texels.
    pub utilisation: f64,
    /// Triangles whose texture-space winding is against their chart's (folds).
    pub flipped: usize,
    /// Texels of gutter around each chart: [`AtlasOptions::padding`], or less where the
    /// charts do not fit one texture of the size asked with it (many small charts).
    pub padding: u32,
    /// Seconds taken.
    pub seconds: f64,
}

impl Atlas {
    /// Which texel stands for which point of which charted triangle ([`raster::coverage`]).
    pub fn coverage(&self) -> raster::Coverage {
        let (w, h) = (self.width as usize, self.height as usize);
        // A triangle in no chart is given no area, so it covers nothing.
        let charted = |(t, &c): (&[u32; 3], &u32)| if c == NO_CHART { [0; 3] } else { *t };
        let triangles: Vec<[u32; 3]> = self
            .triangles
            .iter()
            .zip(&self.chart)
            .map(charted)
            .collect();
        raster::coverage(&self.uv, &triangles, w, h)
    }
}

/// The atlas of `level` (see the module documentation). Refuses an empty or invalid level,
/// bad options, a texture larger than [`MAX_TEXTURE`] or than the memory limit allows (asked
/// before xatlas packs), and a level xatlas cannot chart.
pub fn atlas(level: &TriangleMesh, options: &AtlasOptions) -> Result<Atlas, BakeError> {
    let start = Instant::now();
    options.check()?;
    check_level(level)?;
    if let TextureSize::Texels(n) = options.texture {
        check_texture(n, n)?;
    }
    let sliver_edge = (options.sliver_edge).unwrap_or_else(|| SNAP_VOXELS * median_edge(level));
    let charted = snapped(level, sliver_edge);
    let creased = crease(&charted, options.crease_degrees);
    let positions: Vec<[f32; 3]> = creased.positions.iter().map(|p| p.to_array()).collect();
    let normals: Vec<[f32; 3]> = creased.normals.iter().map(|n| n.to_array()).collect();
    let cut = pieces(
        &creased.positions,
        &creased.triangles,
        options.piece_triangles as usize,
    );
    let mut xatlas =
        Xatlas::new(&positions, &normals, &creased.triangles, &cut).map_err(BakeError::Atlas)?;
    xatlas.charts(ChartOptions {
        // Creases are always chart borders.
        normal_seam_metric_weight: 2000.0,
        max_chart_area: max_chart_area(level, options.max_chart_triangles),
        ..ChartOptions::default()
    });
    let (generated, padding) = pack(&mut xatlas, level, options)?;
    let mut atlas = Atlas {
        positions: Vec::with_capacity(generated.vertices.len()),
        normals: Vec::with_capacity(generated.vertices.len()),
        uv: Vec::with_capacity(generated.vertices.len()),
        triangles: generated.triangles,
        level_vertex: Vec::with_capacity(generated.vertices.len()),
        chart: Vec::new(),
        chart_count: generated.chart_count as usize,
        width: generated.width,
        height: generated.height,
        padding,
        ..Atlas::default()
    };
    let size = Vec2::new(generated.width as f32, generated.height as f32);
    for v in &generated.vertices {
        let g = v.input as usize;
        atlas
            .positions
            .push(level.positions[creased.level_vertex[g] as usize]);
        atlas.normals.push(creased.normals[g]);
        atlas.level_vertex.push(creased.level_vertex[g]);
        atlas
            .uv
            .push((Vec2::from(v.uv) / size).clamp(Vec2::ZERO, Vec2::ONE));
    }
    atlas.chart = atlas
        .triangles
        .iter()
        .map(|t| generated.vertices[t[0] as usize].chart.unwrap_or(NO_CHART))
        .collect();
    charted_corners(&mut atlas);
    atlas.flipped = count_flipped(&atlas);
    let coverage = atlas.coverage();
    atlas.utilisation = coverage.covered() as f64 / coverage.texels.len() as f64;
    atlas.seconds = start.elapsed().as_secs_f64();
    Ok(atlas)
}

/// `atlas` with the corners of the triangles it left out of every chart (those of no area
/// where the charts were made) moved to a copy of the same level vertex in a chart: for each
/// such triangle the chart holding copies of most of its corners, then any chart. Such a
/// triangle then takes the looks around it rather than those where its unmapped texture
/// coordinates point. A corner whose level vertex has no charted copy (every triangle around
/// it lost its area) keeps its vertex, which takes the texture coordinates of the triangle's
/// nearest charted corner. The triangles' charts stay [`NO_CHART`]. Cost: O(V + T).
fn charted_corners(atlas: &mut Atlas) {
    let (triangles, triangle_chart) = (&mut atlas.triangles, &atlas.chart);
    let level_vertex = &atlas.level_vertex;
    // The chart of each atlas vertex that some charted triangle uses.
    let mut chart = vec![NO_CHART; level_vertex.len()];
    for (t, &c) in triangles.iter().zip(triangle_chart.iter()) {
        if c != NO_CHART {
            t.iter().for_each(|&v| chart[v as usize] = c);
        }
    }
    let loose = |t: &[u32; 3]| t.iter().any(|&v| chart[v as usize] == NO_CHART);
    // The charted copies (chart, vertex) of the level vertices of loose triangles.
    let mut copies: HashMap<u32, Vec<(u32, u32)>> = HashMap::new();
    for t in triangles.iter().filter(|t| loose(t)) {
        for &v in t {
            copies.entry(level_vertex[v as usize]).or_default();
        }
    }
    for (v, &c) in chart.iter().enumerate() {
        if c != NO_CHART {
            if let Some(list) = copies.get_mut(&level_vertex[v]) {
                list.push((c, v as u32));
            }
        }
    }
    for t in triangles.iter_mut().filter(|t| loose(t)) {
        let of = |v: u32| &copies[&level_vertex[v as usize]];
        let corners = t.map(of);
        let holds = |c: u32| {
            corners
                .iter()
                .filter(|l| l.iter().any(|x| x.0 == c))
                .count()
        };
        let best = corners
            .iter()
            .flat_map(|l| l.iter().map(|x| x.0))
            .max_by_key(|&c| holds(c));
        for (v, list) in t.iter_mut().zip(corners) {
            let pick = list.iter().find(|x| Some(x.0) == best).or(list.first());
            if let Some(&(_, copy)) = pick {
                *v = copy;
            }
        }
    }
    lone_corners_mapped(atlas, &chart);
}

/// Each corner of a triangle in no chart whose vertex `charted` (the chart of each vertex)
/// puts in no chart takes the texture coordinates of the triangle's nearest charted corner.
fn lone_corners_mapped(atlas: &mut Atlas, charted: &[u32]) {
    for (t, &c) in atlas.triangles.iter().zip(&atlas.chart) {
        let lone = |v: &&u32| charted[**v as usize] == NO_CHART;
        if c != NO_CHART || !t.iter().any(|v| lone(&v)) {
            continue;
        }
        for &v in t.iter().filter(lone) {
            let p = atlas.positions[v as usize];
            let away = |w: &&u32| atlas.positions[**w as usize].distance_squared(p);
            let others = t.iter().filter(|w| !lone(w));
            if let Some(&w) = others.min_by(|a, b| away(a).total_cmp(&away(b))) {
                atlas.uv[v as usize] = atlas.uv[w as usize];
            }
        }
    }
}

/// Refuses a level with no triangles, an index out of range or a coordinate not finite.
fn check_level(level: &TriangleMesh) -> Result<(), BakeError> {
    let bad = |s: String| Err(BakeError::Invalid(format!("the level {s}")));
    if level.triangles.is_empty() {
        return bad("has no triangles".into());
    }
    let n = level.positions.len();
    if let Some(t) = level
        .triangles
        .iter()
        .position(|t| t.iter().any(|&v| v as usize >= n))
    {
        return bad(format!(
            "triangle {t} names a vertex beyond its {n} vertices"
        ));
    }
    if let Some(v) = level.positions.iter().position(|p| !p.is_finite()) {
        return bad(format!("vertex {v} is not finite"));
    }
    Ok(())
}

/// Refuses a texture larger than [`MAX_TEXTURE`] a side or than the memory limit allows for
/// an atlas and its bake.
pub fn check_texture(width: u32, height: u32) -> Result<(), BakeError> {
    let texels = width as u64 * height as u64;
    check_allocation(
        &format!("a {width}×{height} texture and its bake"),
        texels.saturating_mul(BAKE_BYTES_PER_TEXEL),
    )?;
    if width.max(height) > MAX_TEXTURE {
        return Err(BakeError::Invalid(format!(
            "a {width}×{height} texture is larger than the {MAX_TEXTURE} texels a side GPUs take"
        )));
    }
    Ok(())
}

/// Packs the charts into one atlas: at a fixed size, as densely as one texture holds every
/// chart ([`pack_square`]), the padding halved where the charts do not fit with it; at a
/// density, checking the size it needs first. Returns the packing and its padding.
fn pack(
    xatlas: &mut Xatlas,
    level: &TriangleMesh,
    options: &AtlasOptions,
) -> Result<(Generated, u32), BakeError> {
    let base = PackOptions {
        attempts: options.attempts.min(i32::MAX as u32) as i32,
        texels_per_unit: 0.0,
        resolution: 0,
        max_chart_size: MAX_TEXTURE,
        block_align: false,
        conservative: options.padding > 0,
        padding: options.padding,
    };
    match options.texture {
        TextureSize::Density(d) => {
            // Charts cover about half the atlas: ask for the size that would be.
            let side = (2.0 * surface_area(level) as f64).sqrt() * d as f64;
            let side = side.min(u32::MAX as f64) as u32;
            check_texture(side, side)?;
            let generated = xatlas
                .pack(PackOptions {
                    texels_per_unit: d,
                    ..base
                })
                .map_err(BakeError::Atlas)?;
            check_texture(generated.width, generated.height)?;
            Ok((generated, options.padding))
        }
        TextureSize::Texels(n) => {
            let mut padded = base;
            loop {
                if let Some(packed) = pack_square(xatlas, n, surface_area(level), &padded)? {
                    return Ok((packed, padded.padding));
                }
                if padded.padding <= 1 {
                    return Err(BakeError::Atlas(format!(
                        "the charts do not fit one {n}² texture, even with {} texels of padding",
                        padded.padding
                    )));
                }
                padded.padding /= 2;
            }
        }
    }
}

/// Packings into an atlas as large as the charts need tried at most for a square texture
/// before packing into the texture itself.
const SCALED_PACKINGS: usize = 4;

/// The side, as a share of the texture's, at which a packing is dense enough.
const SQUARE_FILL: f32 = 0.95;

/// Packs the charts of `area` world units² into one `n`² texture, as densely as a few
/// packings find. First by scaling: each packs at a density into an atlas as large as it
/// needs, and the next density is scaled by the texture's side over that atlas's longer side
/// (an atlas's side grows in proportion to the density where the charts are large beside
/// their padding), aiming just inside the texture; the first that fits with a side of at
/// least [`SQUARE_FILL`] of the texture's is kept, else the last that fitted in
/// [`SCALED_PACKINGS`] (the charts then lie in the texture's corner). Where none fitted (many
/// charts, whose padding does not shrink with the density), into the texture itself
/// ([`pack_into`]). `None` where the charts fit the texture at no density.
fn pack_square(
    xatlas: &mut Xatlas,
    n: u32,
    area: f32,
    base: &PackOptions,
) -> Result<Option<Generated>, BakeError> {
    // xatlas fills about 55 % of an atlas: start near the density at which that is the texture.
    let room = n.saturating_sub(2 * base.padding).max(1) as f32;
    let mut density = 0.75 * room / area.max(f32::MIN_POSITIVE).sqrt();
    let mut best: Option<Generated> = None;
    for _ in 0..SCALED_PACKINGS {
        let generated = xatlas
            .pack(PackOptions {
                texels_per_unit: density,
                ..*base
            })
            .map_err(BakeError::Atlas)?;
        let side = generated.width.max(generated.height).max(1);
        if generated.atlas_count == 1 && side <= n {
            best = Some(generated);
            if side as f32 >= SQUARE_FILL * n as f32 {
                break;
            }
        }
        // Aim at 99 % of the side; overshooting costs a packing, undershooting texels.
        density *= 0.99 * n as f32 / side as f32;
    }
    let Some(mut generated) = best else {
        return pack_into(xatlas, n, density, base);
    };
    (generated.width, generated.height) = (n, n);
    Ok(Some(generated))
}

/// Packs the charts into one `n`² texture itself (xatlas places them in a fixed image):
/// lowers the density from `density` by 15 % until the texture holds them, then bisects
/// between the last density that did not fit and the first that did; `None` where forty
/// steps down do not fit.
fn pack_into(
    xatlas: &mut Xatlas,
    n: u32,
    mut density: f32,
    base: &PackOptions,
) -> Result<Option<Generated>, BakeError> {
    let mut pack_at = |d: f32| {
        xatlas
            .pack(PackOptions {
                texels_per_unit: d,
                resolution: n,
                max_chart_size: n,
                ..*base
            })
            .map_err(BakeError::Atlas)
    };
    let mut too_dense = None;
    for _ in 0..40 {
        let generated = pack_at(density)?;
        if generated.atlas_count == 1 {
            return densest_fit(&mut pack_at, (density, generated), too_dense).map(Some);
        }
        too_dense = Some(density);
        density *= 0.85;
    }
    Ok(None)
}

/// Bisections between a density that fits one texture and one that does not.
const DENSITY_BISECTIONS: usize = 4;

/// The densest packing found by bisecting between `fit` (a density and its packing in one
/// texture) and `too_dense` (a density whose charts did not fit), in [`DENSITY_BISECTIONS`]
/// steps; `fit` itself without a failing density to bisect towards.
fn densest_fit(
    pack_at: &mut impl FnMut(f32) -> Result<Generated, BakeError>,
    fit: (f32, Generated),
    too_dense: Option<f32>,
) -> Result<Generated, BakeError> {
    let Some(mut hi) = too_dense else {
        return Ok(fit.1);
    };
    let (mut lo, mut best) = fit;
    for _ in 0..DENSITY_BISECTIONS {
        let mid = (lo * hi).sqrt();
        let generated = pack_at(mid)?;
        if generated.atlas_count == 1 {
            (lo, best) = (mid, generated);
        } else {
            hi = mid;
        }
    }
    Ok(best)
}

/// The area of `triangles` of the level's mean triangle area; 0 (xatlas's "no limit") where
/// that is the whole level or more.
fn max_chart_area(level: &TriangleMesh, triangles: u32) -> f32 {
    let n = level.triangles.len();
    if triangles == 0 || triangles as usize >= n {
        return 0.0;
    }
    surface_area(level) * triangles as f32 / n as f32
}

/// The level's surface area.
fn surface_area(level: &TriangleMesh) -> f32 {
    level
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| level.positions[v as usize]);
            (b - a).cross(c - a).length() / 2.0
        })
        .sum()
}

/// Triangles whose texture-space winding differs from the most common one of their chart.
fn count_flipped(atlas: &Atlas) -> usize {
    let mut votes = vec![(0usize, 0usize); atlas.chart_count];
    let sign: Vec<Option<bool>> = atlas
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| atlas.uv[v as usize]);
            let area = (b - a).perp_dot(c - a);
            (area != 0.0).then_some(area > 0.0)
        })
        .collect();
    for (s, &c) in sign.iter().zip(&atlas.chart) {
        if let (Some(s), Some(v)) = (s, votes.get_mut(c as usize)) {
            if *s {
                v.0 += 1
            } else {
                v.1 += 1
            }
        }
    }
    votes.iter().map(|&(p, n)| p.min(n)).sum()
}
