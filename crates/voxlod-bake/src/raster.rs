//! The atlas's triangles rasterised in texture space: for each texel, the triangle that
//! covers it and the barycentric weights of the point it stands for.
//!
//! A texel whose centre lies inside a triangle is *inside* it, at its centre. A texel that
//! no triangle's interior reaches but that a triangle touches (its centre within half a
//! texel diagonal of the triangle: conservative coverage) is a *border* texel of the nearest
//! such triangle, at the triangle's point nearest its centre. Border texels are baked like
//! inside ones, so that bilinear filtering at a chart's edge reads the chart's own looks.
//! Every point is pulled a hair into its triangle (a thousandth of the way to its centroid),
//! so that no ray is cast exactly along an edge or a neighbouring face's plane.
//!
//! Cost: O(texels in the triangles' boxes) on all cores, the atlas cut into bands of rows.

use rayon::prelude::*;
use voxlod_core::glam::{DVec3, Vec2};
use voxlod_metrics::closest_point_on_triangle;

/// No triangle covers the texel.
pub const UNCOVERED: u32 = u32::MAX;

/// What one texel stands for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cover {
    /// The atlas triangle, or [`UNCOVERED`].
    pub triangle: u32,
    /// Barycentric weights of the point on it.
    pub weights: [f32; 3],
    /// Whether it is a border texel (conservatively covered) rather than an inside one.
    pub border: bool,
}

impl Default for Cover {
    fn default() -> Self {
        Cover {
            triangle: UNCOVERED,
            weights: [0.0; 3],
            border: false,
        }
    }
}

/// The texels of an atlas, row by row from the top (v = 0).
#[derive(Clone, Debug, PartialEq)]
pub struct Coverage {
    /// Texels across.
    pub width: usize,
    /// Texels down.
    pub height: usize,
    /// `width × height` texels.
    pub texels: Vec<Cover>,
}

impl Coverage {
    /// How many texels a triangle covers (inside or border).
    pub fn covered(&self) -> usize {
        self.texels
            .iter()
            .filter(|c| c.triangle != UNCOVERED)
            .count()
    }
}

/// Rows per band of the parallel rasterisation.
const BAND: usize = 32;

/// How far a texel's point is pulled toward its triangle's centroid (a fraction of the way).
const INSET: f32 = 1e-3;

/// Barycentric weights clamped to the triangle and pulled toward its centroid by [`INSET`].
fn inset(w: [f32; 3]) -> [f32; 3] {
    let w = w.map(|w| w.clamp(0.0, 1.0) * (1.0 - INSET) + INSET / 3.0);
    let sum = w[0] + w[1] + w[2];
    w.map(|w| w / sum)
}

/// Bytes per texel of a coverage.
pub const BYTES_PER_TEXEL: u64 = std::mem::size_of::<Cover>() as u64;

/// The coverage of a `width × height` texture by `triangles` at texture coordinates `uv`
/// (0..1, v down; see the module documentation). Triangles of no area in texture space
/// cover nothing. The memory is the caller's to check ([`BYTES_PER_TEXEL`]).
pub fn coverage(uv: &[Vec2], triangles: &[[u32; 3]], width: usize, height: usize) -> Coverage {
    let scale = Vec2::new(width as f32, height as f32);
    let corners: Vec<[Vec2; 3]> = triangles
        .iter()
        .map(|t| t.map(|v| uv[v as usize] * scale))
        .collect();
    let bands = height.div_ceil(BAND).max(1);
    let mut binned: Vec<Vec<u32>> = vec![Vec::new(); bands];
    for (t, c) in corners.iter().enumerate() {
        if signed_area(c) == 0.0 {
            continue;
        }
        let (lo, hi) = row_range(c, height);
        for band in binned.iter_mut().take(hi / BAND + 1).skip(lo / BAND) {
            band.push(t as u32);
        }
    }
    let mut texels = vec![Cover::default(); width * height];
    texels
        .par_chunks_mut(width * BAND)
        .zip(binned.par_iter())
        .enumerate()
        .for_each(|(band, (rows, triangles))| {
            let first_row = band * BAND;
            for &t in triangles {
                fill_inside(rows, first_row, width, t, &corners[t as usize]);
            }
            let mut distance = vec![f32::INFINITY; rows.len()];
            for &t in triangles {
                fill_border(
                    rows,
                    &mut distance,
                    first_row,
                    width,
                    t,
                    &corners[t as usize],
                );
            }
        });
    Coverage {
        width,
        height,
        texels,
    }
}

/// Twice the signed area of a texture-space triangle.
fn signed_area([a, b, c]: &[Vec2; 3]) -> f32 {
    (b - a).perp_dot(c - a)
}

/// The rows (inclusive) a triangle's box touches, one texel wider each way, within the atlas.
fn row_range(c: &[Vec2; 3], height: usize) -> (usize, usize) {
    let lo = c.iter().map(|p| p.y).fold(f32::INFINITY, f32::min) - 1.0;
    let hi = c.iter().map(|p| p.y).fold(f32::NEG_INFINITY, f32::max) + 1.0;
    let clamp = |y: f32| (y.floor().max(0.0) as usize).min(height.saturating_sub(1));
    (clamp(lo), clamp(hi))
}

/// The columns (inclusive) a triangle's box touches, one texel wider each way.
fn column_range(c: &[Vec2; 3], width: usize) -> (usize, usize) {
    let lo = c.iter().map(|p| p.x).fold(f32::INFINITY, f32::min) - 1.0;
    let hi = c.iter().map(|p| p.x).fold(f32::NEG_INFINITY, f32::max) + 1.0;
    let clamp = |x: f32| (x.floor().max(0.0) as usize).min(width.saturating_sub(1));
    (clamp(lo), clamp(hi))
}

/// Barycentric weights of `p` in the triangle (any winding; the triangle not degenerate).
fn weights_of(c: &[Vec2; 3], p: Vec2) -> [f32; 3] {
    let area = signed_area(c);
    let w1 = (p - c[0]).perp_dot(c[2] - c[0]) / area;
    let w2 = (c[1] - c[0]).perp_dot(p - c[0]) / area;
    [1.0 - w1 - w2, w1, w2]
}

/// Marks the texels of the band whose centres lie inside triangle `t` (a texel already
/// inside another triangle keeps it).
fn fill_inside(rows: &mut [Cover], first_row: usize, width: usize, t: u32, c: &[Vec2; 3]) {
    let height = rows.len() / width;
    let (lo, hi) = row_range(c, first_row + height);
    let (left, right) = column_range(c, width);
    for y in lo.max(first_row)..=hi.min(first_row + height - 1) {
        for x in left..=right {
            let centre = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            let w = weights_of(c, centre);
            let texel = &mut rows[(y - first_row) * width + x];
            if w.iter().all(|&w| w >= 0.0) && texel.triangle == UNCOVERED {
                *texel = Cover {
                    triangle: t,
                    weights: inset(w),
                    border: false,
                };
            }
        }
    }
}

/// Marks as border texels of triangle `t` the band's texels outside every triangle whose
/// centres lie within half a texel diagonal of it, where it is the nearest so far.
fn fill_border(
    rows: &mut [Cover],
    distance: &mut [f32],
    first_row: usize,
    width: usize,
    t: u32,
    c: &[Vec2; 3],
) {
    let height = rows.len() / width;
    let (lo, hi) = row_range(c, first_row + height);
    let (left, right) = column_range(c, width);
    let corners = c.map(|p| DVec3::new(p.x as f64, p.y as f64, 0.0));
    for y in lo.max(first_row)..=hi.min(first_row + height - 1) {
        for x in left..=right {
            let i = (y - first_row) * width + x;
            if rows[i].triangle != UNCOVERED && !rows[i].border {
                continue;
            }
            let centre = DVec3::new(x as f64 + 0.5, y as f64 + 0.5, 0.0);
            let near = closest_point_on_triangle(centre, corners);
            let d = (near - centre).length() as f32;
            if d > std::f32::consts::FRAC_1_SQRT_2 || d >= distance[i] {
                continue;
            }
            distance[i] = d;
            let w = weights_of(c, Vec2::new(near.x as f32, near.y as f32));
            rows[i] = Cover {
                triangle: t,
                weights: inset(w),
                border: true,
            };
        }
    }
}
