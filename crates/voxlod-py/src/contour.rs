//! `voxlod.marching_cubes`, the drop-in for `skimage.measure.marching_cubes`: voxlod's
//! table-driven marching cubes ([`voxlod_contouring::marching_cubes_with_cells`]) with
//! scikit-image's conventions around it.
//!
//! - A sample is inside when it is *above* the level (scikit-image's rule; voxlod's own is
//!   `>=`), so the extraction runs at the next `f32` above the level.
//! - Vertices in index units along array axes 0, 1, 2 (the Python half multiplies by the
//!   spacing, as scikit-image does); normals point down the gradient in index space.
//! - Triangles wind as scikit-image's do: for `descent` (the object above the level) the signed
//!   volume in array-axis coordinates is negative, for `ascent` positive.
//! - `values`: per vertex, the largest corner range (max − min) of the cells whose triangles use
//!   it, as scikit-image reports.
//! - `mask`: a cell is contoured when the mask is true at its corner of highest indices, as in
//!   scikit-image.
//!
//! NumPy's samples are read in place, never copied: one parallel pass looks for NaN and the
//! range (scikit-image refuses a level outside it), then
//! [`voxlod_contouring::marching_cubes::marching_cubes_of_samples`] extracts the surface with its
//! normals and `values` in the same passes; the arrays go to NumPy without a copy. Cost: one read
//! of the volume more than the extraction (the range check scikit-image's signature requires),
//! plus an in-place pass over the vertices to put them in array-axis order. With a `mask`, the
//! cells of the triangles are kept instead, the masked ones dropped, and `values` found per
//! triangle.

use numpy::{PyArray1, PyArray2, PyReadonlyArray3};
use pyo3::prelude::*;
use rayon::prelude::*;
use voxlod_contouring::block_marching_cubes::retain_cells;
use voxlod_contouring::marching_cubes::{marching_cubes_of_samples, SampleSurface, Wanted};
use voxlod_contouring::CellMesh;
use voxlod_core::{memory, Grid, TriangleMesh, Volume};

use crate::arrays::{column, faces_i32, points_zyx, rows, volume_slice};
use crate::errors::{Failure, Kind};

/// What [`marching_cubes`] returns to Python: verts, faces, normals, values.
type Surface<'py> = (
    Bound<'py, PyArray2<f32>>,
    Bound<'py, PyArray2<i32>>,
    Bound<'py, PyArray2<f32>>,
    Bound<'py, PyArray1<f32>>,
);

/// The smallest `f32` above `value`.
pub fn next_above(value: f32) -> f32 {
    if value.is_nan() || value == f32::INFINITY {
        return value;
    }
    if value == 0.0 {
        return f32::from_bits(1);
    }
    let bits = value.to_bits();
    f32::from_bits(if value > 0.0 { bits + 1 } else { bits - 1 })
}

/// What one pass over the samples found: the first NaN (flat index) and the range of the
/// others.
#[derive(Clone, Copy)]
pub struct Scan {
    first_nan: Option<usize>,
    lo: f32,
    hi: f32,
}

impl Scan {
    const EMPTY: Scan = Scan {
        first_nan: None,
        lo: f32::INFINITY,
        hi: f32::NEG_INFINITY,
    };

    /// The scan of `samples`, the chunk whose first sample has flat index `start`: the range
    /// in sixteen lanes that the compiler turns into vector minima and maxima (NaN never
    /// compares below or above, so it leaves the range alone, as `f32::min` does), and a NaN
    /// flag per lane; the NaN's position is looked for only when there is one.
    fn of(samples: &[f32], start: usize) -> Scan {
        const LANES: usize = 16;
        let mut lo = [f32::INFINITY; LANES];
        let mut hi = [f32::NEG_INFINITY; LANES];
        let mut nan = [false; LANES];
        let mut take = |l: usize, v: f32| {
            nan[l] |= v.is_nan();
            lo[l] = if v < lo[l] { v } else { lo[l] };
            hi[l] = if v > hi[l] { v } else { hi[l] };
        };
        let lanes = samples.chunks_exact(LANES);
        let rest = lanes.remainder();
        for chunk in lanes {
            for (l, &v) in chunk.iter().enumerate() {
                take(l, v);
            }
        }
        for (l, &v) in rest.iter().enumerate() {
            take(l, v);
        }
        let first_nan = if nan.contains(&true) {
            samples.iter().position(|v| v.is_nan()).map(|i| start + i)
        } else {
            None
        };
        Scan {
            first_nan,
            lo: lo.into_iter().fold(f32::INFINITY, f32::min),
            hi: hi.into_iter().fold(f32::NEG_INFINITY, f32::max),
        }
    }

    fn merge(a: Scan, b: Scan) -> Scan {
        let first_nan = match (a.first_nan, b.first_nan) {
            (Some(x), Some(y)) => Some(x.min(y)),
            (x, y) => x.or(y),
        };
        Scan {
            first_nan,
            lo: a.lo.min(b.lo),
            hi: a.hi.max(b.hi),
        }
    }

    /// The first NaN sample, as (axis 0, axis 1, axis 2) indices of a volume of voxlod `dims`.
    pub fn first_nan(&self, dims: [usize; 3]) -> Option<[usize; 3]> {
        let at = self.first_nan?;
        let (x, y, z) = (
            at % dims[0],
            (at / dims[0]) % dims[1],
            at / (dims[0] * dims[1]),
        );
        Some([z, y, x])
    }

    /// The level asked for, or scikit-image's default (the middle of the range), checked
    /// against the range as scikit-image checks it.
    fn checked_level(&self, level: Option<f32>) -> Result<f32, Failure> {
        let (lo, hi) = (self.lo, self.hi);
        match level {
            None => Ok(0.5 * (lo + hi)),
            Some(level) if level >= lo && level <= hi => Ok(level),
            Some(level) => Err(Failure::new(
                Kind::Usage,
                format!("Surface level {level} must be within volume data range [{lo}, {hi}]."),
            )),
        }
    }
}

/// The [`Scan`] of `samples`, in parallel chunks.
pub fn scan(samples: &[f32]) -> Scan {
    const CHUNK: usize = 1 << 16;
    samples
        .par_chunks(CHUNK)
        .enumerate()
        .map(|(c, chunk)| Scan::of(chunk, c * CHUNK))
        .reduce(|| Scan::EMPTY, Scan::merge)
}

/// A voxlod volume (unit spacing, origin 0) holding a copy of the samples, and their [`Scan`]:
/// the copy runs in parallel chunks that also look for NaN and the range, so the input is read
/// once, not once for each.
pub fn scanned_copy(samples: &[f32], dims: [usize; 3]) -> Result<(Volume, Scan), Failure> {
    const CHUNK: usize = 1 << 16;
    let grid = Grid::unit(dims)?;
    memory::check_allocation(
        "a copy of the volume",
        memory::bytes_of::<f32>(samples.len()),
    )?;
    // Zeroed pages are mapped lazily: the threads that copy touch them first.
    let mut copy: Vec<f32> = memory::zeroed_vec(samples.len());
    let scan = copy
        .par_chunks_mut(CHUNK)
        .zip(samples.par_chunks(CHUNK))
        .enumerate()
        .map(|(c, (to, from))| {
            to.copy_from_slice(from);
            Scan::of(from, c * CHUNK)
        })
        .reduce(|| Scan::EMPTY, Scan::merge);
    Ok((Volume::from_vec(grid, copy)?, scan))
}

/// A voxlod volume (unit spacing, origin 0) holding a copy of the samples.
pub fn owned_volume(samples: &[f32], dims: [usize; 3]) -> Result<Volume, Failure> {
    Ok(scanned_copy(samples, dims)?.0)
}

/// The error for a NaN at `[a, b, c]` (array-axis indices) of `what`.
pub fn nan_error(what: &str, [a, b, c]: [usize; 3]) -> Failure {
    Failure::new(
        Kind::BadInput,
        format!("{what} has NaN at index ({a}, {b}, {c}); marching cubes needs numbers"),
    )
}

/// The (i, j, k) of linear cell index `cell` in a grid of `nx × ny × nz` samples.
fn cell_indices(cell: u32, nx: usize, ny: usize) -> (usize, usize, usize) {
    let c = cell as usize;
    (
        c % (nx - 1),
        (c / (nx - 1)) % (ny - 1),
        c / ((nx - 1) * (ny - 1)),
    )
}

/// Per vertex, the largest corner range of the cells of the triangles that use it: the
/// ranges per triangle in parallel, then one pass to spread them to the vertices.
fn corner_ranges(
    data: &[f32],
    [nx, ny, _]: [usize; 3],
    surface: &TriangleMesh,
    cells: &[u32],
) -> Vec<f32> {
    let corners = [
        0,
        1,
        nx,
        nx + 1,
        nx * ny,
        nx * ny + 1,
        nx * ny + nx,
        nx * ny + nx + 1,
    ];
    let range_of = |cell: u32| {
        let (i, j, k) = cell_indices(cell, nx, ny);
        let base = i + nx * (j + ny * k);
        let (lo, hi) = corners
            .iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &o| {
                (lo.min(data[base + o]), hi.max(data[base + o]))
            });
        hi - lo
    };
    let ranges: Vec<f32> = cells.par_iter().map(|&c| range_of(c)).collect();
    let mut values = vec![0.0f32; surface.positions.len()];
    for (triangle, range) in surface.triangles.iter().zip(ranges) {
        for &v in triangle {
            values[v as usize] = values[v as usize].max(range);
        }
    }
    values
}

/// The surface with scikit-image's conventions, computed without the GIL: the mesh and the
/// per-vertex `values`.
fn extract(
    samples: &[f32],
    dims: [usize; 3],
    level: Option<f32>,
    mask: Option<&[bool]>,
) -> Result<(TriangleMesh, Vec<f32>), Failure> {
    let grid = Grid::unit(dims)?;
    let scan = scan(samples);
    if let Some(at) = scan.first_nan(dims) {
        return Err(nan_error("the volume", at));
    }
    let iso = next_above(scan.checked_level(level)?);
    let wanted = Wanted {
        normals: true,
        cells: mask.is_some(),
        corner_ranges: mask.is_none(),
    };
    let SampleSurface {
        mesh,
        cells,
        corner_ranges: values,
    } = marching_cubes_of_samples(samples, &grid, iso, wanted)?;
    let Some(mask) = mask else {
        return Ok((mesh, values));
    };
    let [nx, ny, _] = dims;
    let upper_corner = |cell: u32| {
        let (i, j, k) = cell_indices(cell, nx, ny);
        mask[(i + 1) + nx * ((j + 1) + ny * (k + 1))]
    };
    let (mesh, cells, _) = retain_cells(CellMesh { mesh, cells }, upper_corner);
    let values = corner_ranges(samples, dims, &mesh, &cells);
    Ok((mesh, values))
}

/// `marching_cubes(volume, level, descent, mask)`: see the module documentation; `level`
/// None is the middle of the data's range. The Python half checks the other arguments,
/// converts the volume to C-ordered `float32` and applies spacing.
#[pyfunction]
#[pyo3(signature = (volume, level, descent, mask=None))]
pub fn marching_cubes<'py>(
    py: Python<'py>,
    volume: PyReadonlyArray3<'py, f32>,
    level: Option<f32>,
    descent: bool,
    mask: Option<PyReadonlyArray3<'py, bool>>,
) -> PyResult<Surface<'py>> {
    let (samples, dims) = volume_slice(&volume, "volume")?;
    if dims.iter().any(|&n| n < 2) {
        return Err(crate::errors::usage("the volume must be at least 2x2x2"));
    }
    let mask_slice = match &mask {
        Some(m) => {
            let (slice, mask_dims) = volume_slice(m, "mask")?;
            if mask_dims != dims {
                return Err(crate::errors::usage(
                    "volume and mask must have the same shape",
                ));
            }
            Some(slice)
        }
        None => None,
    };
    let (mesh, values) = py.detach(|| extract(samples, dims, level, mask_slice))?;
    let TriangleMesh {
        positions,
        normals,
        triangles,
    } = mesh;
    Ok((
        rows(py, points_zyx(positions)),
        rows(py, faces_i32(triangles, !descent)),
        rows(py, points_zyx(normals)),
        column(py, values),
    ))
}
