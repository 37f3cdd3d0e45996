//! The quadrature lattice: families of lines parallel to one axis, finer than the sample grid,
//! along which the inside function is known exactly as a list of crossings.
//!
//! For a grid with spacing `h` and `lines_per_voxel = q`, the family along axis `a` holds the
//! lines at `u = origin_u + m h_u / q`, `v = origin_v + n h_v / q` for `m` in
//! `0..=(dims_u - 1) q` and `n` in `0..=(dims_v - 1) q`, where `(u, v)` are the other two axes in
//! cyclic order. Every sample row of the grid is one of these lines (`m = j q`, `n = k q`).
//! Positions along a line are measured in the grid's index units of axis `a`: sample `i` sits
//! at `t = i`, lattice point `p` at `t = p / q`.
//!
//! Lines are stored tile by tile (`TILE × TILE` lines per tile) so that a tile's crossings are
//! contiguous and tiles can be filled in parallel.
//!
//! This is the quadrature of paper §2, equation 1 across the lines (beyond the paper, which
//! convolves a voxelised object with a discrete filter). Memory: 4 bytes of offset per line and
//! 4 bytes per crossing; a line's crossings are found in O(1).

use rayon::prelude::*;
use voxlod_core::{Axis, Grid};

/// Lines per tile side. 64 rather than 16: a mesh's triangle (a few lattice steps across at
/// the bunny's 256) then straddles fewer tiles, so fewer BVH queries and triangle set-ups
/// per crossing (the bunny's crossings at 256 take a fifth less time than with 16); 128 gains
/// nothing more.
pub const TILE: usize = 64;

/// One family of lattice lines: those parallel to `axis`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LineFamily {
    /// The axis the lines run along.
    pub axis: Axis,
    /// The sample grid the lattice refines.
    pub grid: Grid,
    /// Lines per voxel side, across each of the two other axes (at least 1).
    pub lines_per_voxel: usize,
}

impl LineFamily {
    /// The family along `axis` over `grid`, `lines_per_voxel` lines per voxel side.
    pub fn new(axis: Axis, grid: Grid, lines_per_voxel: usize) -> Self {
        debug_assert!(lines_per_voxel >= 1);
        LineFamily {
            axis,
            grid,
            lines_per_voxel,
        }
    }

    /// The other two axes `(u, v)`, in cyclic order.
    pub fn cross_axes(&self) -> (Axis, Axis) {
        self.axis.others()
    }

    /// Lattice points along one axis: `(dims - 1) q + 1`.
    pub fn lattice_len(&self, axis: Axis) -> usize {
        (self.grid.dims[axis.index()] - 1) * self.lines_per_voxel + 1
    }

    /// Number of lines across `u` and across `v`.
    pub fn line_counts(&self) -> (usize, usize) {
        let (u, v) = self.cross_axes();
        (self.lattice_len(u), self.lattice_len(v))
    }

    /// Number of lines in the family.
    pub fn line_count(&self) -> usize {
        let (lu, lv) = self.line_counts();
        lu * lv
    }

    /// Number of tiles across `u` and `v`.
    pub fn tile_counts(&self) -> (usize, usize) {
        let (lu, lv) = self.line_counts();
        (lu.div_ceil(TILE), lv.div_ceil(TILE))
    }

    /// Storage slot of line (m, n): tile-major, then row-major inside the tile.
    #[inline]
    pub fn slot(&self, m: usize, n: usize) -> usize {
        let (tiles_u, _) = self.tile_counts();
        let tile = (n / TILE) * tiles_u + m / TILE;
        tile * TILE * TILE + (n % TILE) * TILE + m % TILE
    }

    /// World coordinates `(u, v)` of line (m, n).
    #[inline]
    pub fn line_position(&self, m: usize, n: usize) -> (f64, f64) {
        let (u, v) = self.cross_axes();
        let q = self.lines_per_voxel as f64;
        let g = &self.grid;
        (
            g.origin[u.index()] + m as f64 * g.spacing[u.index()] / q,
            g.origin[v.index()] + n as f64 * g.spacing[v.index()] / q,
        )
    }

    /// World coordinate along the axis of index-unit position `t`.
    #[inline]
    pub fn world_t(&self, t: f64) -> f64 {
        let a = self.axis.index();
        self.grid.origin[a] + t * self.grid.spacing[a]
    }

    /// Index-unit position of world coordinate `w` along the axis.
    #[inline]
    pub fn index_t(&self, w: f64) -> f64 {
        let a = self.axis.index();
        (w - self.grid.origin[a]) / self.grid.spacing[a]
    }

    /// The lines of tile (tu, tv): ranges of m and n.
    pub fn tile_lines(
        &self,
        tu: usize,
        tv: usize,
    ) -> (std::ops::Range<usize>, std::ops::Range<usize>) {
        let (lu, lv) = self.line_counts();
        (
            tu * TILE..((tu + 1) * TILE).min(lu),
            tv * TILE..((tv + 1) * TILE).min(lv),
        )
    }
}

/// The sorted crossings of every line of a family: where the inside function changes, in index
/// units along the axis. An even number per line for a well-behaved solid; parity decides.
#[derive(Clone, Debug)]
pub struct LineCrossings {
    /// The lines these crossings lie on.
    pub family: LineFamily,
    /// `offsets[slot]..offsets[slot + 1]` indexes `t` for the line stored at `slot`.
    pub offsets: Vec<u32>,
    /// The crossings of every line, line after line, each line's sorted, in index units
    /// along the family's axis.
    pub t: Vec<f32>,
}

impl LineCrossings {
    /// Crossings of line (m, n); lines outside the lattice have none.
    #[inline]
    pub fn line(&self, m: isize, n: isize) -> &[f32] {
        self.lookup().line(m, n)
    }

    /// The family's line counts and tiling worked out once, for many [`LineLookup::line`]
    /// calls in a loop.
    #[inline]
    pub fn lookup(&self) -> LineLookup<'_> {
        let (lu, lv) = self.family.line_counts();
        LineLookup {
            counts: (lu, lv),
            tiles_u: lu.div_ceil(TILE),
            offsets: &self.offsets,
            t: &self.t,
        }
    }

    /// Assembles the crossings from one sorted list per tile, each holding its lines in
    /// row-major order with `(local line, t)` pairs. The tiles are copied in parallel, each
    /// into its own part of `offsets` and of `t` (sized once from the lists' lengths).
    pub fn from_tiles(family: LineFamily, tiles: Vec<Vec<(u16, f32)>>) -> LineCrossings {
        let per_tile = TILE * TILE;
        let slots = family.tile_counts().0 * family.tile_counts().1 * per_tile;
        debug_assert!(tiles.len() * per_tile <= slots);
        // Where each tile's crossings start in `t`.
        let mut starts = Vec::with_capacity(tiles.len() + 1);
        let mut total = 0usize;
        for list in &tiles {
            starts.push(total as u32);
            total += list.len();
        }
        assert!(total <= u32::MAX as usize, "crossings exceed u32 offsets");
        let mut offsets = vec![0u32; slots + 1];
        let mut t = vec![0f32; total];
        let mut parts = Vec::with_capacity(tiles.len());
        let mut rest = t.as_mut_slice();
        for list in &tiles {
            let (part, tail) = rest.split_at_mut(list.len());
            parts.push(part);
            rest = tail;
        }
        let (tiled, beyond) = offsets[1..].split_at_mut(tiles.len() * per_tile);
        tiled
            .par_chunks_mut(per_tile)
            .zip(parts)
            .zip(tiles.par_iter().zip(&starts))
            .for_each(|((ends, part), (list, &start))| {
                for &(local, _) in list {
                    ends[local as usize] += 1;
                }
                let mut end = start;
                for e in ends.iter_mut() {
                    end += *e;
                    *e = end;
                }
                for (dst, &(_, v)) in part.iter_mut().zip(list) {
                    *dst = v;
                }
            });
        beyond.fill(total as u32);
        LineCrossings { family, offsets, t }
    }

    /// Replaces the crossings of the lines at the given storage slots.
    pub fn replace_lines(&mut self, mut lines: Vec<(usize, Vec<f32>)>) {
        if lines.is_empty() {
            return;
        }
        lines.sort_unstable_by_key(|l| l.0);
        let slots = self.offsets.len() - 1;
        let mut offsets = Vec::with_capacity(slots + 1);
        let mut t = Vec::with_capacity(self.t.len());
        let mut next = lines.iter().peekable();
        offsets.push(0u32);
        for slot in 0..slots {
            match next.peek() {
                Some((s, new)) if *s == slot => {
                    t.extend_from_slice(new);
                    next.next();
                }
                _ => t.extend_from_slice(
                    &self.t[self.offsets[slot] as usize..self.offsets[slot + 1] as usize],
                ),
            }
            offsets.push(t.len() as u32);
        }
        self.offsets = offsets;
        self.t = t;
    }

    /// Total number of crossings.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// No crossings at all: the solid misses every line.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }
}

/// [`LineCrossings::line`] with the family's sizes computed once ([`LineCrossings::lookup`]).
#[derive(Clone, Copy, Debug)]
pub struct LineLookup<'c> {
    counts: (usize, usize),
    tiles_u: usize,
    offsets: &'c [u32],
    t: &'c [f32],
}

impl<'c> LineLookup<'c> {
    /// Crossings of line (m, n); lines outside the lattice have none.
    #[inline]
    pub fn line(&self, m: isize, n: isize) -> &'c [f32] {
        let (lu, lv) = self.counts;
        if m < 0 || n < 0 || m as usize >= lu || n as usize >= lv {
            return &[];
        }
        let (m, n) = (m as usize, n as usize);
        let tile = (n / TILE) * self.tiles_u + m / TILE;
        let slot = tile * TILE * TILE + (n % TILE) * TILE + m % TILE;
        &self.t[self.offsets[slot] as usize..self.offsets[slot + 1] as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lattice_contains_the_sample_rows() {
        let g = Grid::new([5, 4, 3], [2.0, 1.0, 0.5], [1.0, 2.0, 3.0]).unwrap();
        let f = LineFamily::new(Axis::X, g, 4);
        assert_eq!(f.line_counts(), (13, 9));
        // Sample row (j, k) = (2, 1) is line (8, 4).
        let (u, v) = f.line_position(8, 4);
        let p = g.position(0.0, 2.0, 1.0);
        assert_eq!((u, v), (p.y, p.z));
        assert_eq!(f.world_t(2.0), 5.0);
        assert_eq!(f.index_t(5.0), 2.0);
        // Tile-major slots are a permutation.
        let mut seen = std::collections::HashSet::new();
        for n in 0..9 {
            for m in 0..13 {
                assert!(seen.insert(f.slot(m, n)));
            }
        }
    }

    #[test]
    fn the_lookup_finds_each_line_at_its_slot() {
        // 160 x 80 lines: three tiles across u, two across v, partial tiles at both ends.
        let g = Grid::new([41, 21, 3], [1.0; 3], [0.0; 3]).unwrap();
        let f = LineFamily::new(Axis::Z, g, 4);
        let (lu, lv) = f.line_counts();
        assert_eq!((lu, lv), (161, 81));
        assert_eq!(f.tile_counts(), (3, 2));
        // Line (m, n) gets m + 1000 n crossings' worth of identity: one crossing, its number.
        let (tu, tv) = f.tile_counts();
        let tiles = (0..tu * tv)
            .map(|id| {
                let (ms, ns) = f.tile_lines(id % tu, id / tu);
                let mut list = Vec::new();
                for (row, n) in ns.enumerate() {
                    for (col, m) in ms.clone().enumerate() {
                        list.push(((row * TILE + col) as u16, (m + 1000 * n) as f32));
                    }
                }
                list
            })
            .collect();
        let crossings = LineCrossings::from_tiles(f, tiles);
        let lookup = crossings.lookup();
        for n in -1..=lv as isize {
            for m in -1..=lu as isize {
                let outside = m < 0 || n < 0 || m >= lu as isize || n >= lv as isize;
                let expected: &[f32] = if outside {
                    &[]
                } else {
                    &[(m + 1000 * n) as f32]
                };
                assert_eq!(lookup.line(m, n), expected, "line ({m}, {n})");
                assert_eq!(crossings.line(m, n), expected);
            }
        }
    }
}
