//! A texel's opacity measured by view rays, where the source lets light through (leaf cards,
//! fences, cloth masked or blended by alpha): a closed proxy stands for a crown of cards by
//! one surface, and a viewer looking through the point a texel stands for sees the source's
//! cards along the stretch of the view line that the proxy's volume holds, or passes between
//! them. The texel's opacity is the fraction of view lines through it that meet something,
//! its colour the mean colour they meet, so that the proxy drawn blended (glTF `BLEND`)
//! shows the mean of what the source shows through it: the same idea as the alpha of a
//! billboard cloud or an impostor, measured here per texel of a closed proxy. Beyond the
//! papers.
//!
//! The view lines: `rays` directions within 30° of the texel's normal, cosine weighted (a
//! surface seen head-on covers more of the screen than one seen edge-on), one in each of `rays`
//! rings of equal weight, at a place in its ring and an azimuth on a
//! golden-angle spiral drawn for the texel by a hash of its index: neighbouring texels look
//! along different lines, and [`smooth`] takes the mean over each texel's neighbours in its
//! chart, so that a few rays a texel give the opacity of many. Each line is followed from the
//! cage distance in front of the point to where it leaves the level (the first of the level's
//! triangles it meets from inside; the cage distance behind the point where it meets none, as
//! on an open level); what lies beyond is the level's other surfaces' to show. It meets the
//! source's first triangle facing the viewer (or seen from both sides) that is not clear there
//! (an alpha-masked texel below its cutoff is passed).
//!
//! Cost: per texel, `rays` casts into the level and as many into the source, O(log N) each.

use voxlod_core::glam::{Vec3, Vec4};

use crate::cast::{Cast, Clear};
use crate::source::SourceLooks;

/// What a texel's view rays met: the mean colour (linear RGB) and the opacity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Seen {
    /// The opacity-weighted mean of the linear base colours met (black where none was).
    pub colour: Vec3,
    /// The fraction of the rays that met the source, each counted by its opacity.
    pub opacity: f32,
}

/// sin² of the widest angle between a view line and the texel's normal (30°). Lines nearer
/// the surface travel far through the level and meet the source far to the side: over a
/// stack of cards a shell's thickness apart, a texel would take the colours of its
/// neighbours' cards, and the level would look blurred, though the squared error of its
/// pictures falls (BENCHMARKS.md, the see-through crown).
const CONE_SIN2: f32 = 0.25;

/// The golden angle, radians: successive spiral directions turn by it.
const GOLDEN_ANGLE: f32 = 2.399_963_2;

/// The view lines of a level against its source: `level` the level's own triangles, `source`
/// the source's, `rays` lines a texel, `cage` how far in front of a point a line begins.
pub struct ViewRays<'a> {
    /// The level's triangles, where a line leaves the level.
    pub level: &'a Cast,
    /// The source's triangles, what a line meets.
    pub source: &'a Cast,
    /// The source's looks: what is clear, what colour is seen.
    pub looks: &'a SourceLooks<'a>,
    /// Lines a texel.
    pub rays: u32,
    /// How far in front of the point a line begins (the bake's cage distance).
    pub cage: f32,
}

impl ViewRays<'_> {
    /// What the view lines through the level point `p` meet (module documentation). `normal`
    /// and `tangent` are unit and perpendicular; `draw` places the texel's lines
    /// ([`draw_of`]); `footprint` is the texel's side, over which textures are averaged.
    pub fn seen_through(
        &self,
        p: Vec3,
        (normal, tangent): (Vec3, Vec3),
        draw: (f32, f32),
        footprint: f32,
    ) -> Seen {
        let bitangent = normal.cross(tangent);
        let (mut met, mut colour) = (0.0f32, Vec3::ZERO);
        for i in 0..self.rays {
            let u = (i as f32 + draw.1) / self.rays as f32 * CONE_SIN2;
            let (radius, angle) = (u.sqrt(), i as f32 * GOLDEN_ANGLE + draw.0);
            let towards_viewer = (tangent * (radius * angle.cos())
                + bitangent * (radius * angle.sin())
                + normal * (1.0 - u).sqrt())
            .normalize();
            if let Some(seen) = self.met(p, towards_viewer, footprint) {
                met += seen.w;
                colour += seen.truncate() * seen.w;
            }
        }
        Seen {
            colour: if met > 0.0 { colour / met } else { Vec3::ZERO },
            opacity: met / self.rays.max(1) as f32,
        }
    }

    /// The colour and opacity the source shows along the view line through `p` from the unit
    /// direction `towards_viewer`, within the level; `None` where it shows nothing.
    fn met(&self, p: Vec3, towards_viewer: Vec3, footprint: f32) -> Option<Vec4> {
        let never: &Clear = &|_, _| false;
        let clear: &Clear = &|t, w| self.looks.clear(t, w);
        let (inward, cage) = (-towards_viewer, self.cage);
        // Where the line leaves the level: its first triangle facing along the line.
        let start = p + inward * (1e-4 * cage);
        let inside = (self.level)
            .first_hit(start, inward, inward, f32::INFINITY, never)
            .map_or(cage, |(_, t)| t);
        let from = p + towards_viewer * cage;
        let (found, _) =
            (self.source).first_hit(from, inward, towards_viewer, cage + inside, clear)?;
        Some(
            self.looks
                .seen_colour(found.triangle, found.weights, footprint),
        )
    }
}

/// Where texel `index`'s view lines lie: the spiral's turn (radians) and the place in each
/// ring (0 to 1), drawn by a hash of the index (neighbouring texels get unrelated draws).
pub fn draw_of(index: usize) -> (f32, f32) {
    let h = (index as u64 ^ 0x5851_F42D_4C95_7F2D).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    let unit = |bits: u64| (bits & 0xFF_FFFF) as f32 / (1u64 << 24) as f32;
    (unit(h >> 40) * std::f32::consts::TAU, unit(h >> 16))
}

/// Each measured texel's [`Seen`] as the mean of its own and its measured neighbours' in a
/// 3 × 3 window that lie in the same chart (`chart[i]`: texel i's chart), colours weighted by
/// opacity. `seen` holds `width × height` texels, row by row, `None` where not measured.
/// Cost: 9 reads a texel.
pub fn smooth(
    seen: &[Option<Seen>],
    chart: &[u32],
    width: usize,
    height: usize,
) -> Vec<Option<Seen>> {
    let at = |x: usize, y: usize| {
        seen[y * width + x]?;
        let (mut colour, mut opacity, mut count) = (Vec3::ZERO, 0.0f32, 0u32);
        for ny in y.saturating_sub(1)..(y + 2).min(height) {
            for nx in x.saturating_sub(1)..(x + 2).min(width) {
                let k = ny * width + nx;
                if let Some(s) = seen[k].filter(|_| chart[k] == chart[y * width + x]) {
                    colour += s.colour * s.opacity;
                    opacity += s.opacity;
                    count += 1;
                }
            }
        }
        Some(Seen {
            colour: if opacity > 0.0 {
                colour / opacity
            } else {
                Vec3::ZERO
            },
            opacity: opacity / count as f32,
        })
    };
    (0..width * height)
        .map(|i| at(i % width, i / width))
        .collect()
}
