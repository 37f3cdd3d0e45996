//! Blockwise marching cubes for `voxlod.dask`: one task contours one block of a volume (with a
//! one-sample halo) into a piece keyed by global edge and cell indices
//! ([`voxlod_contouring::block_marching_cubes`]); the client stitches the pieces into the mesh
//! `voxlod.marching_cubes` gives for the whole volume. Everything is in NumPy axis order on the
//! Python side; keys are voxlod's (x = axis 2), used only between these two functions.

use numpy::{PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArray3};
use pyo3::prelude::*;
use voxlod_contouring::{block_marching_cubes, stitch_blocks, Block, BlockPiece, ContourOptions};
use voxlod_core::TriangleMesh;

use crate::arrays::{column, faces_i32, points_xyz, points_zyx, rows, volume_slice};
use crate::contour::{nan_error, next_above, scanned_copy};
use crate::errors::{usage, Failure};

/// A piece as NumPy arrays: verts (index units, axis order), faces, normals, edge keys, cell keys.
type Piece<'py> = (
    Bound<'py, PyArray2<f32>>,
    Bound<'py, PyArray2<i32>>,
    Bound<'py, PyArray2<f32>>,
    Bound<'py, PyArray1<u64>>,
    Bound<'py, PyArray1<u64>>,
);

/// `contour_block(block, level, offset, own_start, own_stop, shape)`: the piece of the cells
/// `own_start .. own_stop` (indices into `block`, NumPy axis order) of a block whose first
/// sample is `offset` in a volume of `shape`. Vertices are in global index units. Inside is
/// above `level`, as in `voxlod.marching_cubes`.
#[pyfunction]
pub fn contour_block<'py>(
    py: Python<'py>,
    block: PyReadonlyArray3<'py, f32>,
    level: f32,
    offset: [usize; 3],
    own_start: [usize; 3],
    own_stop: [usize; 3],
    shape: [usize; 3],
) -> PyResult<Piece<'py>> {
    let (samples, dims) = volume_slice(&block, "block")?;
    let zyx = |v: [usize; 3]| [v[2], v[1], v[0]];
    let (own_start, own_stop) = (zyx(own_start), zyx(own_stop));
    let block = Block {
        offset: zyx(offset),
        cells: std::array::from_fn(|a| own_start[a]..own_stop[a]),
        global_dims: zyx(shape),
    };
    let piece = py.detach(|| -> Result<BlockPiece, Failure> {
        let (mut volume, scan) = scanned_copy(samples, dims)?;
        if let Some(at) = scan.first_nan(dims) {
            return Err(nan_error("the block", at));
        }
        volume.grid.origin = block.offset.map(|o| o as f64);
        let options = ContourOptions::at(next_above(level));
        Ok(block_marching_cubes(&volume, &block, &options)?)
    })?;
    let BlockPiece { mesh, edges, cells } = piece;
    Ok((
        rows(py, points_zyx(mesh.positions)),
        rows(py, faces_i32(mesh.triangles, false)),
        rows(py, points_zyx(mesh.normals)),
        column(py, edges),
        column(py, cells),
    ))
}

/// The stitched mesh as NumPy arrays: verts, faces, normals.
type Stitched<'py> = (
    Bound<'py, PyArray2<f32>>,
    Bound<'py, PyArray2<i32>>,
    Bound<'py, PyArray2<f32>>,
);

/// A piece as it comes back from a task.
type PieceIn<'py> = (
    PyReadonlyArray2<'py, f32>,
    PyReadonlyArray2<'py, i32>,
    PyReadonlyArray2<'py, f32>,
    PyReadonlyArray1<'py, u64>,
    PyReadonlyArray1<'py, u64>,
);

/// One piece back from NumPy, checked.
fn piece_from(piece: &PieceIn<'_>) -> PyResult<BlockPiece> {
    let (verts, faces, normals, edges, cells) = piece;
    let as_rows = |a: &PyReadonlyArray2<'_, f32>| -> PyResult<Vec<[f32; 3]>> {
        let view = a.as_array();
        if view.ncols() != 3 {
            return Err(usage("piece arrays of points must have 3 columns"));
        }
        Ok(view
            .rows()
            .into_iter()
            .map(|r| [r[0], r[1], r[2]])
            .collect())
    };
    let vertex_count = verts.as_array().nrows();
    let faces = faces.as_array();
    let mut triangles = Vec::with_capacity(faces.nrows());
    for f in faces.rows() {
        if f.len() != 3 || f.iter().any(|&v| v < 0 || v as usize >= vertex_count) {
            return Err(usage("a piece's face refers to a vertex it does not have"));
        }
        triangles.push([f[0] as u32, f[1] as u32, f[2] as u32]);
    }
    let edges = edges.as_array().to_vec();
    let cells = cells.as_array().to_vec();
    if edges.len() != vertex_count || cells.len() != triangles.len() {
        return Err(usage(
            "a piece has keys for a different number of vertices or faces",
        ));
    }
    Ok(BlockPiece {
        mesh: TriangleMesh {
            positions: points_xyz(&as_rows(verts)?),
            normals: points_xyz(&as_rows(normals)?),
            triangles,
        },
        edges,
        cells,
    })
}

/// `stitch_blocks(pieces)`: the pieces of every block as one mesh (verts, faces, normals), the
/// whole-volume mesh index for index.
#[pyfunction]
pub fn stitch<'py>(py: Python<'py>, pieces: Vec<PieceIn<'py>>) -> PyResult<Stitched<'py>> {
    let pieces: Vec<BlockPiece> = pieces.iter().map(piece_from).collect::<PyResult<_>>()?;
    let mesh = py.detach(|| stitch_blocks(&pieces).map_err(Failure::from))?;
    Ok((
        rows(py, points_zyx(mesh.positions)),
        rows(py, faces_i32(mesh.triangles, false)),
        rows(py, points_zyx(mesh.normals)),
    ))
}
