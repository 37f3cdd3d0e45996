//! Marching cubes block by block, for volumes contoured in pieces on several machines (the
//! Python package's Dask path), and the stitching of the pieces into the one mesh that
//! [`crate::marching_cubes`] gives for the whole volume.
//!
//! Not in the paper, which contours each filtered volume in one piece (§2); this splits that
//! same extraction over blocks of cells.
//!
//! **Keys.** A vertex of marching cubes lies on one grid edge, named by its *global edge key*
//! `3 · (x + nx · (y + ny · z)) + axis`, (x, y, z) the edge's first sample in the whole grid of
//! `nx × ny × nz` samples; a triangle belongs to one cell, named by its *global cell key*
//! `x + (nx − 1) · (y + (ny − 1) · z)`. Blocks that share a face compute the vertices of its
//! edges from the same two samples, so the keys identify them across blocks.
//!
//! **A block** is a sub-volume (its samples, copied out of the whole) whose cells in
//! [`Block::cells`] are the block's own; the sub-volume may reach further (a halo), so that the
//! gradient normals at the block's border see the same neighbours as in the whole volume. The
//! block is contoured with [`marching_cubes_with_cells`], the triangles of cells outside its own
//! are dropped, and every kept vertex gets its key: [`crate::marching_cubes`] orders its
//! vertices by z, y, x and then edge axis over the crossed edges, and the same order is
//! enumerated here from the samples.
//!
//! **Stitching** ([`stitch_blocks`]) keeps one vertex per key, in key order (which is the
//! z, y, x, axis order of the whole-volume extraction), and the triangles in cell-key order
//! (stable, so a cell's triangles keep their table order): the result is the whole-volume mesh,
//! index for index, with positions equal to f32 rounding.
//!
//! **Cost.** One extraction of the block (see [`crate::marching_cubes`]), one more read of its
//! samples to enumerate the crossed edges, and O(V log V + T log T) to stitch.

use std::ops::Range;

use thiserror::Error;
use voxlod_core::{memory, TriangleMesh, Volume};

use crate::marching_cubes::{marching_cubes_with_cells, CellMesh, ContourError, ContourOptions};

/// Why a block could not be contoured or the pieces stitched.
#[derive(Debug, Error)]
pub enum BlockError {
    /// The block's cells or samples reach past its sub-volume or the whole grid.
    #[error("the block does not fit its grid: {0}")]
    OutsideGrid(String),
    /// The extraction failed (32-bit limits, the memory limit).
    #[error(transparent)]
    Contour(#[from] ContourError),
}

/// Where a sub-volume sits in the whole grid, and which of its cells are its own.
#[derive(Clone, Debug, PartialEq)]
pub struct Block {
    /// Global sample index of the sub-volume's first sample.
    pub offset: [usize; 3],
    /// The block's own cells, in the sub-volume's cell indices, per axis x, y, z.
    pub cells: [Range<usize>; 3],
    /// Samples of the whole grid along x, y, z.
    pub global_dims: [usize; 3],
}

/// One block's part of the surface: vertices with their global edge keys, triangles with their
/// global cell keys.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BlockPiece {
    /// The vertices (world positions, gradient normals) and triangles of the block's cells.
    pub mesh: TriangleMesh,
    /// Global edge key of each vertex.
    pub edges: Vec<u64>,
    /// Global cell key of each triangle.
    pub cells: Vec<u64>,
}

/// Contours the block's own cells of `volume`. See the module documentation.
pub fn block_marching_cubes(
    volume: &Volume,
    block: &Block,
    options: &ContourOptions,
) -> Result<BlockPiece, BlockError> {
    let dims = volume.grid.dims;
    let cell_dims = dims.map(|n| n.saturating_sub(1));
    for axis in 0..3 {
        let own = &block.cells[axis];
        let global_end = block.offset[axis] + dims[axis];
        if own.end > cell_dims[axis] || global_end > block.global_dims[axis] {
            return Err(BlockError::OutsideGrid(format!(
                "cells {own:?} along axis {axis} of a block of {} samples at {} in a grid of {}",
                dims[axis], block.offset[axis], block.global_dims[axis]
            )));
        }
    }
    let whole = marching_cubes_with_cells(volume, options)?;
    let vertex_count = whole.mesh.positions.len();
    let own = |cell: u32| {
        let c = cell as usize;
        let (i, j, k) = (
            c % cell_dims[0],
            (c / cell_dims[0]) % cell_dims[1],
            c / (cell_dims[0] * cell_dims[1]),
        );
        block.cells[0].contains(&i) && block.cells[1].contains(&j) && block.cells[2].contains(&k)
    };
    let (mesh, kept_cells, kept_vertices) = retain_cells(whole, own);
    let edges = crossed_edges(volume, options.iso);
    // The same classification as the extraction's: one crossed edge per vertex, in order.
    debug_assert_eq!(edges.len(), vertex_count);
    let global_cell_dims = block.global_dims.map(|n| n.saturating_sub(1) as u64);
    let [gx, gy, _] = block.global_dims.map(|n| n as u64);
    let global = |local: [usize; 3]| -> [u64; 3] {
        std::array::from_fn(|a| (local[a] + block.offset[a]) as u64)
    };
    let edges = kept_vertices
        .iter()
        .map(|&v| {
            let (sample, axis) = edges[v as usize];
            let [x, y, z] = global(sample);
            3 * (x + gx * (y + gy * z)) + axis as u64
        })
        .collect();
    let cells = kept_cells
        .iter()
        .map(|&c| {
            let c = c as usize;
            let local = [
                c % cell_dims[0],
                (c / cell_dims[0]) % cell_dims[1],
                c / (cell_dims[0] * cell_dims[1]),
            ];
            let [x, y, z] = global(local);
            x + global_cell_dims[0] * (y + global_cell_dims[1] * z)
        })
        .collect();
    Ok(BlockPiece { mesh, edges, cells })
}

/// Keeps the triangles of `surface` whose cell passes `keep`, and the vertices they use (in
/// their order). Returns the mesh, the cells of its triangles, and for each kept vertex its
/// index in `surface`.
pub fn retain_cells(
    surface: CellMesh,
    keep: impl Fn(u32) -> bool,
) -> (TriangleMesh, Vec<u32>, Vec<u32>) {
    let CellMesh { mesh, cells } = surface;
    let mut used = vec![false; mesh.positions.len()];
    let mut triangles = Vec::with_capacity(mesh.triangles.len());
    let mut kept_cells = Vec::with_capacity(cells.len());
    for (triangle, &cell) in mesh.triangles.iter().zip(&cells) {
        if keep(cell) {
            triangle.iter().for_each(|&v| used[v as usize] = true);
            triangles.push(*triangle);
            kept_cells.push(cell);
        }
    }
    let mut new_index = vec![u32::MAX; mesh.positions.len()];
    let mut kept_vertices = Vec::new();
    for (v, _) in used.iter().enumerate().filter(|(_, &u)| u) {
        new_index[v] = kept_vertices.len() as u32;
        kept_vertices.push(v as u32);
    }
    let pick = |values: &[glam::Vec3]| -> Vec<glam::Vec3> {
        if values.is_empty() {
            return Vec::new();
        }
        kept_vertices.iter().map(|&v| values[v as usize]).collect()
    };
    let trimmed = TriangleMesh {
        positions: pick(&mesh.positions),
        normals: pick(&mesh.normals),
        triangles: triangles
            .into_iter()
            .map(|t| t.map(|v| new_index[v as usize]))
            .collect(),
    };
    (trimmed, kept_cells, kept_vertices)
}

/// The crossed edges of `volume` at `iso` (first sample, axis), in the order of the vertices of
/// [`crate::marching_cubes`]: by z, y, x, then axis, a sample inside when `value >= iso`.
fn crossed_edges(volume: &Volume, iso: f32) -> Vec<([usize; 3], u8)> {
    let [nx, ny, nz] = volume.grid.dims;
    if nx < 2 || ny < 2 || nz < 2 {
        return Vec::new();
    }
    let data = volume.as_slice();
    let inside = |i: usize| data[i] >= iso;
    let mut edges = Vec::new();
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let at = i + nx * (j + ny * k);
                let here = inside(at);
                let steps = [
                    (i + 1 < nx).then_some(1),
                    (j + 1 < ny).then_some(nx),
                    (k + 1 < nz).then_some(nx * ny),
                ];
                for (axis, step) in steps.into_iter().enumerate() {
                    if step.is_some_and(|s| inside(at + s) != here) {
                        edges.push(([i, j, k], axis as u8));
                    }
                }
            }
        }
    }
    edges
}

/// Joins the pieces of every block of a grid into one mesh: the mesh
/// [`crate::marching_cubes`] gives for the whole grid. See the module documentation.
pub fn stitch_blocks(pieces: &[BlockPiece]) -> Result<TriangleMesh, BlockError> {
    let vertices: usize = pieces.iter().map(|p| p.edges.len()).sum();
    let triangles: usize = pieces.iter().map(|p| p.cells.len()).sum();
    memory::check_allocation(
        "the stitched mesh",
        memory::bytes_of::<(u64, u32, u32)>(vertices)
            + memory::bytes_of::<(u64, [u32; 3])>(triangles)
            + memory::bytes_of::<glam::Vec3>(2 * vertices),
    )
    .map_err(ContourError::from)?;
    // Every vertex by key, then one index per distinct key.
    let mut by_key: Vec<(u64, u32, u32)> = Vec::with_capacity(vertices);
    for (p, piece) in pieces.iter().enumerate() {
        by_key.extend(
            piece
                .edges
                .iter()
                .enumerate()
                .map(|(v, &key)| (key, p as u32, v as u32)),
        );
    }
    by_key.sort_unstable();
    let mut remap: Vec<Vec<u32>> = pieces.iter().map(|p| vec![0; p.edges.len()]).collect();
    let with_normals = pieces.iter().all(|p| !p.mesh.normals.is_empty());
    let mut mesh = TriangleMesh::default();
    let mut last_key = None;
    for &(key, p, v) in &by_key {
        if last_key != Some(key) {
            last_key = Some(key);
            let piece = &pieces[p as usize].mesh;
            mesh.positions.push(piece.positions[v as usize]);
            if with_normals {
                mesh.normals.push(piece.normals[v as usize]);
            }
        }
        remap[p as usize][v as usize] = (mesh.positions.len() - 1) as u32;
    }
    let mut all: Vec<(u64, [u32; 3])> = Vec::with_capacity(triangles);
    for (p, piece) in pieces.iter().enumerate() {
        let triangles = piece.cells.iter().zip(&piece.mesh.triangles);
        all.extend(triangles.map(|(&cell, t)| (cell, t.map(|v| remap[p][v as usize]))));
    }
    // A stable sort by cell key: a cell's triangles all come from one piece, in table order.
    all.sort_by_key(|&(cell, _)| cell);
    mesh.triangles = all.into_iter().map(|(_, t)| t).collect();
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;
    use voxlod_core::Grid;

    /// A gyroid-like field on a grid with anisotropic spacing and an offset origin.
    fn field(dims: [usize; 3]) -> Volume {
        let grid = Grid::new(dims, [0.5, 0.7, 0.6], [-3.0, 1.0, 2.5]).unwrap();
        let mut data = Vec::with_capacity(grid.len());
        for k in 0..dims[2] {
            for j in 0..dims[1] {
                for i in 0..dims[0] {
                    let (x, y, z) = (i as f32 * 0.45, j as f32 * 0.5, k as f32 * 0.4);
                    data.push(x.sin() * y.cos() + y.sin() * z.cos() + z.sin() * x.cos());
                }
            }
        }
        Volume::from_vec(grid, data).unwrap()
    }

    /// The samples `lo..hi` (per axis) of `volume` as a volume of their own.
    fn sub_volume(volume: &Volume, lo: [usize; 3], hi: [usize; 3]) -> Volume {
        let dims = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
        let g = volume.grid;
        let origin = std::array::from_fn(|a| g.origin[a] + lo[a] as f64 * g.spacing[a]);
        let grid = Grid::new(dims, g.spacing, origin).unwrap();
        let mut data = Vec::with_capacity(grid.len());
        for k in lo[2]..hi[2] {
            for j in lo[1]..hi[1] {
                for i in lo[0]..hi[0] {
                    data.push(volume.get(i, j, k));
                }
            }
        }
        Volume::from_vec(grid, data).unwrap()
    }

    /// Contours `volume` in blocks of `size` cells with a halo of `halo` samples, and stitches.
    fn blockwise(volume: &Volume, size: usize, halo: usize, iso: f32) -> TriangleMesh {
        let dims = volume.grid.dims;
        let cells = dims.map(|n| n - 1);
        let mut pieces = Vec::new();
        for z0 in (0..cells[2]).step_by(size) {
            for y0 in (0..cells[1]).step_by(size) {
                for x0 in (0..cells[0]).step_by(size) {
                    let start = [x0, y0, z0];
                    let lo: [usize; 3] = std::array::from_fn(|a| start[a].saturating_sub(halo));
                    let hi: [usize; 3] =
                        std::array::from_fn(|a| (start[a] + size + 1 + halo).min(dims[a]));
                    let own = std::array::from_fn(|a| {
                        start[a] - lo[a]..(start[a] + size).min(cells[a]) - lo[a]
                    });
                    let block = Block {
                        offset: lo,
                        cells: own,
                        global_dims: dims,
                    };
                    let sub = sub_volume(volume, lo, hi);
                    pieces.push(
                        block_marching_cubes(&sub, &block, &ContourOptions::at(iso)).unwrap(),
                    );
                }
            }
        }
        stitch_blocks(&pieces).unwrap()
    }

    #[test]
    fn stitched_blocks_are_the_whole_volume_mesh() {
        let volume = field([37, 29, 33]);
        let whole = crate::marching_cubes(&volume, &ContourOptions::at(0.1)).unwrap();
        assert!(whole.triangle_count() > 1000);
        for (size, halo) in [(8, 1), (16, 1), (11, 0)] {
            let stitched = blockwise(&volume, size, halo, 0.1);
            assert_eq!(stitched.triangles, whole.triangles, "blocks of {size}");
            assert_eq!(stitched.positions.len(), whole.positions.len());
            for (a, b) in stitched.positions.iter().zip(&whole.positions) {
                assert!((*a - *b).abs().max_element() < 1e-5, "{a} vs {b}");
            }
            if halo == 1 {
                // With a one-sample halo the gradients see the same neighbours everywhere.
                for (a, b) in stitched.normals.iter().zip(&whole.normals) {
                    assert!((*a - *b).abs().max_element() < 1e-5, "normal {a} vs {b}");
                }
            }
        }
    }

    #[test]
    fn every_vertex_lies_on_its_keyed_edge() {
        let volume = field([20, 18, 15]);
        let dims = volume.grid.dims;
        let block = Block {
            offset: [0; 3],
            cells: [0..19, 0..17, 0..14],
            global_dims: dims,
        };
        let piece = block_marching_cubes(&volume, &block, &ContourOptions::at(0.2)).unwrap();
        assert!(!piece.edges.is_empty());
        for (p, &key) in piece.mesh.positions.iter().zip(&piece.edges) {
            let (sample, axis) = ((key / 3) as usize, (key % 3) as usize);
            let at = [
                sample % dims[0],
                (sample / dims[0]) % dims[1],
                sample / (dims[0] * dims[1]),
            ];
            let start = volume
                .grid
                .position(at[0] as f64, at[1] as f64, at[2] as f64);
            let offset = p.as_dvec3() - start;
            let along = offset[axis] / volume.grid.spacing[axis];
            assert!((0.0..=1.0).contains(&along), "{p} not on edge {key}");
            for other in (0..3).filter(|&a| a != axis) {
                assert!(offset[other].abs() < 1e-4, "{p} off edge {key}");
            }
        }
    }

    #[test]
    fn blocks_outside_the_grid_are_refused() {
        let volume = field([6, 6, 6]);
        let block = Block {
            offset: [2, 0, 0],
            cells: [0..5, 0..5, 0..5],
            global_dims: [7, 6, 6],
        };
        assert!(block_marching_cubes(&volume, &block, &ContourOptions::at(0.0)).is_err());
        let fits = Block {
            offset: [1, 0, 0],
            ..block
        };
        assert!(block_marching_cubes(&volume, &fits, &ContourOptions::at(0.0)).is_ok());
    }
}
