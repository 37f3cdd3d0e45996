//! Marching cubes over a [`BrickVolume`]: the mesh [`crate::marching_cubes`] gives for the same
//! samples (same triangles, same vertex positions and normals bit for bit; only the order of
//! vertices and triangles differs), visiting only the bricks the surface can touch.
//!
//! Paper §2 contours each filtered volume with marching cubes; far from the surface the filtered
//! density is exactly 0 or 1, so a sparse volume stores one value per brick there. This
//! extraction is beyond the paper and follows the dense one's rules exactly:
//!
//! - **One classification.** A sample is inside when `value >= iso`, the cells' triangles come
//!   from [`crate::tables`], so every cell gets the case and triangles it gets in the dense path.
//! - **Active bricks.** Each brick is first classified as all outside, all inside or mixed (a
//!   uniform brick by its one value). The cells and the edges whose lower sample lies in brick
//!   `b` have all their samples in `b` and its seven upper neighbours; when those eight are all
//!   inside or all outside, `b` holds no crossed edge and no surface cell and is skipped.
//! - **Vertex identity from the global edge.** Each crossed edge belongs to the brick of its
//!   lower sample; every active brick lists its crossed edges in order of their local index, and
//!   a vertex's number is its brick's first vertex plus its rank in that list. A cell on a brick
//!   face finds the vertices of the neighbour's edges by the same rule, so the vertices on brick
//!   faces are shared and the mesh is closed exactly where the dense one is.
//! - **Passes.** (1) per active brick, in parallel: its crossed edges and its triangle count;
//!   (2) prefix sums; (3) per active brick, in parallel, into its own part of the output: the
//!   vertices of its edges (placed by [`crate::edge_vertex`], shared with the dense path) and the
//!   triangles of its cells. Output order: bricks in index order, then samples z, y, x.
//!
//! **Cost.** O(bricks) to classify uniform bricks, O(B³) per leaf and per active brick, plus
//! O(V log B + T); memory: one byte and one index per brick, 4 bytes per vertex for the edge
//! lists, and the mesh.

use rayon::prelude::*;
use voxlod_core::bricks::brick_origin;
use voxlod_core::{memory, Brick, BrickVolume, TriangleMesh};

use crate::edge_vertex::{repair_zero_normals, VertexPlacer};
use crate::marching_cubes::{check_clamp, ContourError, ContourOptions};
use crate::tables::{tables, EDGE_AXIS, EDGE_CORNERS};

const OUTSIDE: u8 = 0;
const INSIDE: u8 = 1;
const MIXED: u8 = 2;
const INACTIVE: u32 = u32::MAX;

/// Extracts the isosurface of `volume` at `options.iso`: the triangles and vertices of
/// [`crate::marching_cubes`] on the same samples. See the module documentation.
pub fn sparse_marching_cubes(
    volume: &BrickVolume,
    options: &ContourOptions,
) -> Result<TriangleMesh, ContourError> {
    let iso = options.iso;
    if !iso.is_finite() {
        return Err(ContourError::NonFiniteIso(iso));
    }
    let clamp = check_clamp(options.clamp)?;
    if volume.grid.dims.iter().any(|&d| d < 2) {
        return Ok(TriangleMesh::default());
    }
    memory::check_allocation(
        "the brick states of sparse marching cubes",
        memory::bytes_of::<u64>(volume.brick_count()),
    )?;
    let states = brick_states(volume, iso);
    let active = active_bricks(volume, &states);
    let mut active_of = vec![INACTIVE; volume.brick_count()];
    for (n, &b) in active.iter().enumerate() {
        active_of[b as usize] = n as u32;
    }
    let scan = |&b: &u32| BrickScan::new(volume, iso, b as usize);
    let counts: Vec<(Vec<u32>, u32)> = active
        .par_iter()
        .map(|b| {
            let s = scan(b);
            (s.crossed_edges(), s.triangle_count())
        })
        .collect();
    let (edges, triangle_counts): (Vec<Vec<u32>>, Vec<u32>) = counts.into_iter().unzip();
    let vertex_counts: Vec<usize> = edges.iter().map(Vec::len).collect();
    let total_vertices: u64 = vertex_counts.iter().map(|&c| c as u64).sum();
    if total_vertices >= u32::MAX as u64 {
        return Err(ContourError::TooManyVertices(total_vertices));
    }
    let triangle_counts: Vec<usize> = triangle_counts.iter().map(|&c| c as usize).collect();
    let total_triangles: usize = triangle_counts.iter().sum();
    let normal_factor = if options.normals { 2 } else { 1 };
    memory::check_allocation(
        "the marching cubes mesh",
        memory::bytes_of::<glam::Vec3>(total_vertices as usize) * normal_factor
            + memory::bytes_of::<[u32; 3]>(total_triangles),
    )?;
    let vertex_base = prefix_sums(&vertex_counts);
    let lookup = VertexLookup {
        shift: volume.brick_size().trailing_zeros(),
        volume,
        active_of: &active_of,
        vertex_base: &vertex_base,
        edges: &edges,
    };
    let mut mesh = TriangleMesh {
        positions: vec![glam::Vec3::ZERO; total_vertices as usize],
        normals: vec![
            glam::Vec3::ZERO;
            if options.normals {
                total_vertices as usize
            } else {
                0
            }
        ],
        triangles: vec![[0; 3]; total_triangles],
    };
    let placer = VertexPlacer::new(volume, &volume.grid, iso, clamp);
    let positions = split_by(&mut mesh.positions, &vertex_counts);
    let normals = if options.normals {
        split_by(&mut mesh.normals, &vertex_counts)
    } else {
        active.iter().map(|_| &mut [][..]).collect()
    };
    let triangles = split_by(&mut mesh.triangles, &triangle_counts);
    active
        .par_iter()
        .zip(positions)
        .zip(normals)
        .zip(triangles)
        .enumerate()
        .for_each(|(n, (((b, pos), nor), tri))| {
            let s = scan(b);
            for ((&key, p), slot) in edges[n].iter().zip(pos.iter_mut()).zip(0..) {
                let (sample, axis) = s.edge_sample(key);
                let (position, normal) = placer.edge_vertex(sample, axis, options.normals);
                *p = position;
                if options.normals {
                    nor[slot] = normal;
                }
            }
            s.write_triangles(&lookup, tri);
        });
    if options.normals {
        repair_zero_normals(&mut mesh);
    }
    Ok(mesh)
}

/// Per brick: all outside, all inside, or mixed (samples past the grid ignored).
fn brick_states(volume: &BrickVolume, iso: f32) -> Vec<u8> {
    let b = volume.brick_size();
    let dims = volume.grid.dims;
    let brick_dims = volume.brick_dims();
    (0..volume.brick_count())
        .into_par_iter()
        .map(|index| match volume.brick(index) {
            Brick::Uniform(v) => (v >= iso) as u8,
            Brick::Leaf(values) => {
                let origin = brick_origin(brick_dims, b, index);
                let extent = [0, 1, 2].map(|a| (dims[a] - origin[a]).min(b));
                let (mut any_in, mut any_out) = (false, false);
                for k in 0..extent[2] {
                    for j in 0..extent[1] {
                        let row = &values[b * (j + b * k)..][..extent[0]];
                        for &v in row {
                            let inside = v >= iso;
                            any_in |= inside;
                            any_out |= !inside;
                        }
                    }
                }
                match (any_in, any_out) {
                    (true, false) => INSIDE,
                    (false, _) => OUTSIDE,
                    _ => MIXED,
                }
            }
        })
        .collect()
}

/// Bricks whose brick and seven upper neighbours are not all inside or all outside, in order.
fn active_bricks(volume: &BrickVolume, states: &[u8]) -> Vec<u32> {
    let [bx, by, bz] = volume.brick_dims();
    (0..states.len())
        .into_par_iter()
        .filter(|&index| {
            let (i, j, k) = (index % bx, (index / bx) % by, index / (bx * by));
            let first = states[index];
            if first == MIXED {
                return true;
            }
            (0..8).any(|c| {
                let n = [i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1)];
                n[0] < bx
                    && n[1] < by
                    && n[2] < bz
                    && states[n[0] + bx * (n[1] + by * n[2])] != first
            })
        })
        .map(|index| index as u32)
        .collect()
}

/// Starts of consecutive runs of the given lengths.
fn prefix_sums(counts: &[usize]) -> Vec<u32> {
    let mut running = 0u32;
    counts
        .iter()
        .map(|&c| {
            let start = running;
            running += c as u32;
            start
        })
        .collect()
}

/// `data` cut into consecutive parts of the given lengths.
fn split_by<'a, T>(mut data: &'a mut [T], lengths: &[usize]) -> Vec<&'a mut [T]> {
    let mut parts = Vec::with_capacity(lengths.len());
    for &n in lengths {
        let (part, rest) = data.split_at_mut(n);
        parts.push(part);
        data = rest;
    }
    parts
}

/// Finds the mesh index of the vertex on a global edge.
struct VertexLookup<'a> {
    volume: &'a BrickVolume,
    shift: u32,
    active_of: &'a [u32],
    vertex_base: &'a [u32],
    edges: &'a [Vec<u32>],
}

impl VertexLookup<'_> {
    /// The vertex on the edge from global sample `p` along `axis` (which must be crossed).
    #[inline]
    fn vertex(&self, p: [usize; 3], axis: usize) -> u32 {
        let owner = self.volume.brick_index(p.map(|c| c >> self.shift));
        let n = self.active_of[owner] as usize;
        let key = edge_key(self.volume.brick_size(), p, axis);
        let rank = self.edges[n]
            .binary_search(&key)
            .expect("a crossed edge is listed by the brick of its lower sample");
        self.vertex_base[n] + rank as u32
    }
}

/// Local key of the edge from sample `p` along `axis` within its brick: the order of the lists.
#[inline]
fn edge_key(b: usize, p: [usize; 3], axis: usize) -> u32 {
    let m = b - 1;
    (((p[0] & m) + b * ((p[1] & m) + b * (p[2] & m))) * 3 + axis) as u32
}

/// The classification of one brick's samples and of the first sample past it on each axis.
struct BrickScan {
    b: usize,
    origin: [usize; 3],
    /// Samples of the brick and its upper halo present in the grid, per axis.
    extent: [usize; 3],
    dims: [usize; 3],
    /// `(b + 1)³` flags, x fastest: sample `origin + (i, j, k)` is inside.
    inside: Vec<bool>,
}

impl BrickScan {
    fn new(volume: &BrickVolume, iso: f32, brick: usize) -> BrickScan {
        let b = volume.brick_size();
        let dims = volume.grid.dims;
        let origin = brick_origin(volume.brick_dims(), b, brick);
        let extent = [0, 1, 2].map(|a| (dims[a] - origin[a]).min(b + 1));
        let side = b + 1;
        let mut inside = vec![false; side * side * side];
        for k in 0..extent[2] {
            for j in 0..extent[1] {
                for i in 0..extent[0] {
                    let v = volume.get(origin[0] + i, origin[1] + j, origin[2] + k);
                    inside[i + side * (j + side * k)] = v >= iso;
                }
            }
        }
        BrickScan {
            b,
            origin,
            extent,
            dims,
            inside,
        }
    }

    #[inline]
    fn at(&self, i: usize, j: usize, k: usize) -> bool {
        let side = self.b + 1;
        self.inside[i + side * (j + side * k)]
    }

    /// Local samples of the brick itself (without the halo) present in the grid.
    fn own(&self) -> [usize; 3] {
        self.extent.map(|e| e.min(self.b))
    }

    /// Keys of the crossed edges whose lower sample lies in the brick, increasing.
    fn crossed_edges(&self) -> Vec<u32> {
        let [ox, oy, oz] = self.own();
        let mut keys = Vec::new();
        for k in 0..oz {
            for j in 0..oy {
                for i in 0..ox {
                    let here = self.at(i, j, k);
                    let next = [(i + 1, j, k), (i, j + 1, k), (i, j, k + 1)];
                    for (axis, (ni, nj, nk)) in next.into_iter().enumerate() {
                        let n = [ni, nj, nk];
                        if n[axis] < self.extent[axis] && self.at(ni, nj, nk) != here {
                            let p = [self.origin[0] + i, self.origin[1] + j, self.origin[2] + k];
                            keys.push(edge_key(self.b, p, axis));
                        }
                    }
                }
            }
        }
        keys
    }

    /// The global sample and axis of an edge key of this brick.
    fn edge_sample(&self, key: u32) -> ([usize; 3], usize) {
        let (local, axis) = (key as usize / 3, key as usize % 3);
        let b = self.b;
        let l = [local % b, (local / b) % b, local / (b * b)];
        ([0, 1, 2].map(|a| self.origin[a] + l[a]), axis)
    }

    /// Calls `visit(local cell, case)` for every cell of the brick with mixed corners.
    fn for_each_mixed_cell(&self, mut visit: impl FnMut([usize; 3], u8)) {
        // Cells whose eight samples exist: one fewer than the samples where the grid ends.
        let cells = [0, 1, 2]
            .map(|a| (self.dims[a] - 1 - self.origin[a].min(self.dims[a] - 1)).min(self.b));
        for k in 0..cells[2] {
            for j in 0..cells[1] {
                for i in 0..cells[0] {
                    let mut case = 0u8;
                    for c in 0..8 {
                        let inside = self.at(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1));
                        case |= (inside as u8) << c;
                    }
                    if case != 0 && case != 0xff {
                        visit([i, j, k], case);
                    }
                }
            }
        }
    }

    fn triangle_count(&self) -> u32 {
        let table = tables();
        let mut count = 0u32;
        self.for_each_mixed_cell(|_, case| count += table.triangle_count[case as usize] as u32);
        count
    }

    /// Writes the triangles of the brick's cells, in cell order, into `out`.
    fn write_triangles(&self, lookup: &VertexLookup, out: &mut [[u32; 3]]) {
        let table = tables();
        let mut written = 0;
        self.for_each_mixed_cell(|cell, case| {
            let n = table.triangle_count[case as usize] as usize;
            for t in &table.triangles[case as usize][..n] {
                out[written] = t.map(|e| {
                    let corner = EDGE_CORNERS[e as usize].0 as usize;
                    let p = [0, 1, 2].map(|a| self.origin[a] + cell[a] + ((corner >> a) & 1));
                    lookup.vertex(p, EDGE_AXIS[e as usize] as usize)
                });
                written += 1;
            }
        });
        debug_assert_eq!(written, out.len());
    }
}
