//! Triangle rasterization into one tile of samples: exact integer edge functions, a z-buffer,
//! and alpha blending.
//!
//! Vertices are snapped to 1/256 of a sample and the three edge functions are evaluated in 64-bit
//! integers at sample centres, stepping incrementally along rows. A sample exactly on an edge
//! belongs to one side only (a fixed tie-break by edge direction that is opposite for the two
//! triangles sharing the edge), so a closed mesh covers every sample once: no cracks, and no
//! doubled blending along the edges of translucent layers. Depth and shading are interpolated
//! from the barycentric weights, shading perspective-correctly with the vertices' 1/w.
//!
//! Cost: O(1) setup per triangle and tile, then O(samples of the clipped bounding box).

/// A vertex on screen: position in output pixels, depth key (affine on screen, larger farther),
/// 1/w, and Lambert shade (NaN: shade the triangle flat from its face).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ScreenVertex {
    /// Output pixels from the left edge.
    pub x: f32,
    /// Output pixels from the top edge.
    pub y: f32,
    /// The camera's depth key (see [`crate::camera::ScreenPoint::depth_key`]).
    pub z: f32,
    /// 1 / view depth (perspective), 1 (orthographic).
    pub w: f32,
    /// Lambert shade in [0, 1], or NaN for the triangle's flat shade.
    pub shade: f32,
}

impl ScreenVertex {
    /// A vertex that is not drawn (before a perspective camera's near plane): all NaN.
    pub const CULLED: ScreenVertex = ScreenVertex {
        x: f32::NAN,
        y: f32::NAN,
        z: f32::NAN,
        w: f32::NAN,
        shade: f32::NAN,
    };

    /// Whether this is [`ScreenVertex::CULLED`].
    pub fn is_culled(&self) -> bool {
        self.x.is_nan()
    }
}

/// The samples of one tile.
pub struct Tile {
    /// First sample column of the tile in the whole sample grid.
    pub x0: i64,
    /// First sample row of the tile in the whole sample grid.
    pub y0: i64,
    /// Samples per side.
    pub size: usize,
    /// Linear RGB of each sample, row by row.
    pub color: Vec<[f32; 3]>,
    /// Depth key of the nearest opaque surface at each sample (infinity: none).
    pub depth: Vec<f32>,
    /// Coverage of each sample: 1 under an opaque surface, else the composite of the blended
    /// alphas (`c ← c + (1 − c) α` per layer).
    pub coverage: Vec<f32>,
}

impl Tile {
    /// A tile of `size × size` samples at the origin of the sample grid.
    pub fn new(size: usize) -> Tile {
        Tile {
            x0: 0,
            y0: 0,
            size,
            color: vec![[0.0; 3]; size * size],
            depth: vec![f32::INFINITY; size * size],
            coverage: vec![0.0; size * size],
        }
    }

    /// Moves the tile to first sample (x0, y0) and fills it with `background`, uncovered, at
    /// infinite depth.
    pub fn clear(&mut self, x0: i64, y0: i64, background: [f32; 3]) {
        self.x0 = x0;
        self.y0 = y0;
        self.color.fill(background);
        self.depth.fill(f32::INFINITY);
        self.coverage.fill(0.0);
    }
}

/// Sub-sample positions per sample side: vertices snap to 1/256 of a sample.
const SUB: i64 = 256;

#[inline]
fn on_edge_included(dx: i64, dy: i64) -> bool {
    dy > 0 || (dy == 0 && dx > 0)
}

/// A triangle snapped to the sub-sample lattice, counter-clockwise on screen.
struct Snapped {
    /// Corners in 1/[`SUB`] of a sample.
    p: [(i64, i64); 3],
    /// The screen vertices, in the same order as `p`.
    v: [ScreenVertex; 3],
    /// Twice the area in snapped units, positive.
    area2: i64,
    /// Whether vertices 1 and 2 were swapped to make the order counter-clockwise.
    swapped: bool,
}

/// The vertices snapped to 1/[`SUB`] of a sample (`n` samples per pixel side) and put in
/// counter-clockwise order on screen, with twice their area in snapped units; `None` for a
/// triangle of zero area.
#[inline]
fn snap_counter_clockwise(v: [ScreenVertex; 3], n: u32) -> Option<Snapped> {
    let scale = n as f32 * SUB as f32;
    let fx = |a: f32| (a * scale).round() as i64;
    let mut p = [
        (fx(v[0].x), fx(v[0].y)),
        (fx(v[1].x), fx(v[1].y)),
        (fx(v[2].x), fx(v[2].y)),
    ];
    let mut v = v;
    let mut area2 = (p[1].0 - p[0].0) * (p[2].1 - p[0].1) - (p[1].1 - p[0].1) * (p[2].0 - p[0].0);
    if area2 == 0 {
        return None;
    }
    let swapped = area2 < 0;
    if swapped {
        p.swap(1, 2);
        v.swap(1, 2);
        area2 = -area2;
    }
    Some(Snapped {
        p,
        v,
        area2,
        swapped,
    })
}

/// The samples (first x, last x, first y, last y, in the whole sample grid) whose centres
/// (`s·SUB + SUB/2`) lie in the box of `p`, clipped to the tile; `None` when none do.
#[inline]
fn sample_box(p: &[(i64, i64); 3], tile: &Tile) -> Option<(i64, i64, i64, i64)> {
    let size = tile.size as i64;
    sample_box_in(p, tile.x0, tile.y0, size, size)
}

/// [`sample_box`] clipped to the `width × height` samples from (x0, y0).
#[inline]
fn sample_box_in(
    p: &[(i64, i64); 3],
    x0: i64,
    y0: i64,
    width: i64,
    height: i64,
) -> Option<(i64, i64, i64, i64)> {
    let min_x = p[0].0.min(p[1].0).min(p[2].0);
    let max_x = p[0].0.max(p[1].0).max(p[2].0);
    let min_y = p[0].1.min(p[1].1).min(p[2].1);
    let max_y = p[0].1.max(p[1].1).max(p[2].1);
    let first = |m: i64| (m - SUB / 2 + SUB - 1).div_euclid(SUB);
    let last = |m: i64| (m - SUB / 2).div_euclid(SUB);
    let sx0 = first(min_x).max(x0);
    let sx1 = last(max_x).min(x0 + width - 1);
    let sy0 = first(min_y).max(y0);
    let sy1 = last(max_y).min(y0 + height - 1);
    (sx0 <= sx1 && sy0 <= sy1).then_some((sx0, sx1, sy0, sy1))
}

/// The three edge functions of a counter-clockwise triangle, `E_k(P) = a_k P.x + b_k P.y + c_k`
/// in snapped units; edge k is opposite vertex k, from vertex k+1 to vertex k+2. A sample is
/// inside when `E_k + bias_k ≥ 0` for all three (the bias excludes the edges that belong to
/// the neighbour).
struct EdgeFunctions {
    a: [i64; 3],
    b: [i64; 3],
    c: [i64; 3],
    bias: [i64; 3],
}

impl EdgeFunctions {
    #[inline]
    fn new(p: &[(i64, i64); 3]) -> EdgeFunctions {
        let mut e = EdgeFunctions {
            a: [0; 3],
            b: [0; 3],
            c: [0; 3],
            bias: [0; 3],
        };
        for k in 0..3 {
            let (s, end) = (p[(k + 1) % 3], p[(k + 2) % 3]);
            let (dx, dy) = (end.0 - s.0, end.1 - s.1);
            // E(P) = dx (P.y − s.y) − dy (P.x − s.x)
            e.a[k] = -dy;
            e.b[k] = dx;
            e.c[k] = dy * s.0 - dx * s.1;
            e.bias[k] = if on_edge_included(dx, dy) { 0 } else { -1 };
        }
        e
    }

    /// Edge function `k` at the centre of sample (sx, sy).
    #[inline]
    fn at(&self, k: usize, sx: i64, sy: i64) -> i64 {
        self.a[k] * (sx * SUB + SUB / 2) + self.b[k] * (sy * SUB + SUB / 2) + self.c[k]
    }

    /// Calls `f(sx, sy, e)` for every sample of the box (first x, last x, first y, last y)
    /// inside the triangle, row by row, with its three edge functions `e`, stepped
    /// incrementally along each row.
    #[inline]
    fn for_each_inside(
        &self,
        (sx0, sx1, sy0, sy1): (i64, i64, i64, i64),
        mut f: impl FnMut(i64, i64, [i64; 3]),
    ) {
        let bias = self.bias;
        let step_x = self.a.map(|a| a * SUB);
        for sy in sy0..=sy1 {
            let mut e = [
                self.at(0, sx0, sy),
                self.at(1, sx0, sy),
                self.at(2, sx0, sy),
            ];
            for sx in sx0..=sx1 {
                if ((e[0] + bias[0]) | (e[1] + bias[1]) | (e[2] + bias[2])) >= 0 {
                    f(sx, sy, e);
                }
                e[0] += step_x[0];
                e[1] += step_x[1];
                e[2] += step_x[2];
            }
        }
    }
}

/// Draws one triangle into `tile`. `n` is the samples per pixel side; `flat` the shade to use
/// when the vertices carry none; `rgba` the colour and opacity; `blend` selects alpha blending
/// (z-tested, no depth write) over the z-buffered opaque write.
pub fn raster_triangle(
    tile: &mut Tile,
    v: [ScreenVertex; 3],
    n: u32,
    flat: f32,
    rgba: [f32; 4],
    blend: bool,
) {
    let [r, g, b, alpha] = rgba;
    raster_fragments(tile, v, n, flat, blend, |_, shade| {
        Some([r * shade, g * shade, b * shade, alpha])
    });
}

/// Draws one triangle into `tile` with a colour computed per sample: `fragment` receives the
/// perspective-correct barycentric weights of the vertices in the order given (they sum to 1)
/// and the interpolated shade, and returns the sample's linear RGBA, or `None` to leave the
/// sample untouched (an alpha-masked texel). It is called only for samples that pass the
/// z-test. `blend` as in [`raster_triangle`]: alpha-blended with no depth write, else written
/// opaque through the z-buffer. Cost: as [`raster_triangle`] plus one `fragment` per sample.
pub fn raster_fragments<F>(
    tile: &mut Tile,
    v: [ScreenVertex; 3],
    n: u32,
    flat: f32,
    blend: bool,
    mut fragment: F,
) where
    F: FnMut([f32; 3], f32) -> Option<[f32; 4]>,
{
    let Some(Snapped {
        p,
        v,
        area2,
        swapped,
    }) = snap_counter_clockwise(v, n)
    else {
        return;
    };
    let Some(samples) = sample_box(&p, tile) else {
        return;
    };
    let edges = EdgeFunctions::new(&p);
    let inv = 1.0 / area2 as f32;
    let shade_of = |i: usize| {
        if v[i].shade.is_nan() {
            flat
        } else {
            v[i].shade
        }
    };
    let (s0, s1, s2) = (shade_of(0), shade_of(1), shade_of(2));
    let (w0, w1, w2) = (v[0].w, v[1].w, v[2].w);
    let (z0, z1, z2) = (v[0].z, v[1].z, v[2].z);
    edges.for_each_inside(samples, |sx, sy, e| {
        let l0 = e[0] as f32 * inv;
        let l1 = e[1] as f32 * inv;
        let l2 = 1.0 - l0 - l1;
        let z = l0 * z0 + l1 * z1 + l2 * z2;
        let i = ((sy - tile.y0) as usize) * tile.size + (sx - tile.x0) as usize;
        if z >= tile.depth[i] {
            return;
        }
        let pw = 1.0 / (l0 * w0 + l1 * w1 + l2 * w2);
        let (q0, q1, q2) = (l0 * w0 * pw, l1 * w1 * pw, l2 * w2 * pw);
        let shade = q0 * s0 + q1 * s1 + q2 * s2;
        // Back to the caller's vertex order.
        let weights = if swapped { [q0, q2, q1] } else { [q0, q1, q2] };
        let Some(rgba) = fragment(weights, shade) else {
            return;
        };
        if blend {
            let dst = &mut tile.color[i];
            for ch in 0..3 {
                dst[ch] += (rgba[ch] - dst[ch]) * rgba[3];
            }
            tile.coverage[i] += (1.0 - tile.coverage[i]) * rgba[3];
        } else {
            tile.depth[i] = z;
            tile.color[i] = [rgba[0], rgba[1], rgba[2]];
            tile.coverage[i] = 1.0;
        }
    });
}

/// Marks in `covered` (`width × height` pixels, row by row, one sample per pixel) the pixels
/// whose centre the triangle `v` covers, by the same snapping and edge rule as
/// [`raster_triangle`]: what an opaque triangle does to a render's coverage, without depth or
/// shading. A triangle with a corner that is not finite is not drawn.
/// Cost: O(pixels of its clipped bounding box).
pub fn raster_coverage(covered: &mut [bool], width: usize, height: usize, v: [ScreenVertex; 3]) {
    if !v.iter().all(|c| c.x.is_finite() && c.y.is_finite()) {
        return;
    }
    let Some(Snapped { p, .. }) = snap_counter_clockwise(v, 1) else {
        return;
    };
    let Some(samples) = sample_box_in(&p, 0, 0, width as i64, height as i64) else {
        return;
    };
    EdgeFunctions::new(&p).for_each_inside(samples, |sx, sy, _| {
        covered[sy as usize * width + sx as usize] = true;
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sv(x: f32, y: f32) -> ScreenVertex {
        ScreenVertex {
            x,
            y,
            z: 1.0,
            w: 1.0,
            shade: 1.0,
        }
    }

    #[test]
    fn two_triangles_of_a_square_cover_each_sample_once() {
        // A square split along its diagonal, drawn blended at alpha 0.5: every sample inside
        // must be blended exactly once (0.5), never twice (0.75).
        for n in [1, 3] {
            let mut tile = Tile::new(16 * n as usize);
            tile.clear(0, 0, [0.0; 3]);
            let (a, b, c, d) = (sv(2.3, 2.0), sv(11.0, 2.7), sv(11.6, 12.0), sv(1.9, 11.1));
            raster_triangle(&mut tile, [a, b, c], n, 1.0, [1.0, 1.0, 1.0, 0.5], true);
            raster_triangle(&mut tile, [a, c, d], n, 1.0, [1.0, 1.0, 1.0, 0.5], true);
            let inside = tile.coverage.iter().filter(|&&x| x > 0.0).count();
            assert!(inside > 50 * (n * n) as usize);
            assert!(tile.coverage.iter().all(|&x| x == 0.0 || x == 0.5));
        }
    }

    #[test]
    fn z_buffer_keeps_the_nearest() {
        let mut tile = Tile::new(8);
        tile.clear(0, 0, [0.0; 3]);
        let mut far = [sv(0.0, 0.0), sv(8.0, 0.0), sv(0.0, 8.0)];
        for x in &mut far {
            x.z = 5.0;
        }
        let near = [sv(0.0, 0.0), sv(8.0, 0.0), sv(0.0, 8.0)];
        raster_triangle(&mut tile, near, 1, 1.0, [1.0, 0.0, 0.0, 1.0], false);
        raster_triangle(&mut tile, far, 1, 1.0, [0.0, 1.0, 0.0, 1.0], false);
        assert_eq!(tile.color[0], [1.0, 0.0, 0.0]);
        // Blending behind the opaque surface changes nothing.
        raster_triangle(&mut tile, far, 1, 1.0, [0.0, 0.0, 1.0, 0.5], true);
        assert_eq!(tile.color[0], [1.0, 0.0, 0.0]);
    }
}
