//! NumPy arrays in and out. Inputs are borrowed as slices when C-contiguous (the Python half
//! makes them so, copying only when the layout requires it); outputs are Rust vectors handed to
//! NumPy without a copy.
//!
//! Axis order: a C-ordered NumPy volume of shape `(n0, n1, n2)` varies fastest along axis 2, so
//! it is voxlod's volume with x = axis 2, y = axis 1, z = axis 0 (dims `[n2, n1, n0]`); points
//! leave Rust as (x, y, z) and are handed to Python in array-axis order (axis 0, 1, 2).

use glam::Vec3;
use ndarray::{Array1, Array2, Array3};
use numpy::{Element, IntoPyArray, PyArray1, PyArray2, PyArray3, PyReadonlyArray3};
use pyo3::prelude::*;

use crate::errors::usage;

/// The samples of a C-contiguous 3-D array, and voxlod's dims `[n2, n1, n0]` of it.
pub fn volume_slice<'a, T: Element>(
    array: &'a PyReadonlyArray3<'_, T>,
    name: &str,
) -> PyResult<(&'a [T], [usize; 3])> {
    let shape = array.as_array().shape().to_vec();
    let slice = array
        .as_slice()
        .map_err(|_| usage(format!("`{name}` must be a C-contiguous, aligned array")))?;
    Ok((slice, [shape[2], shape[1], shape[0]]))
}

/// Points (x, y, z) as rows in array-axis order (z, y, x), reusing the vector's memory.
pub fn points_zyx(points: Vec<Vec3>) -> Vec<[f32; 3]> {
    points.into_iter().map(|p| [p.z, p.y, p.x]).collect()
}

/// Points given in array-axis order (z, y, x) as voxlod's (x, y, z).
pub fn points_xyz(rows: &[[f32; 3]]) -> Vec<Vec3> {
    rows.iter().map(|r| Vec3::new(r[2], r[1], r[0])).collect()
}

/// An `(n, N)` array from rows, without a copy.
pub fn rows<T: Element, const N: usize>(
    py: Python<'_>,
    rows: Vec<[T; N]>,
) -> Bound<'_, PyArray2<T>> {
    Array2::from(rows).into_pyarray(py)
}

/// A 1-D array, without a copy.
pub fn column<T: Element>(py: Python<'_>, values: Vec<T>) -> Bound<'_, PyArray1<T>> {
    Array1::from(values).into_pyarray(py)
}

/// A 3-D array of NumPy shape `(n0, n1, n2)` from samples in C order, without a copy.
pub fn volume_array<T: Element>(
    py: Python<'_>,
    samples: Vec<T>,
    shape: [usize; 3],
) -> PyResult<Bound<'_, PyArray3<T>>> {
    let array = Array3::from_shape_vec(shape, samples)
        .map_err(|e| usage(format!("the samples do not fill the shape {shape:?}: {e}")))?;
    Ok(array.into_pyarray(py))
}

/// Triangles as `int32` rows (scikit-image's face type), reusing the vector's memory; with
/// `flip`, each triangle's winding reversed.
pub fn faces_i32(triangles: Vec<[u32; 3]>, flip: bool) -> Vec<[i32; 3]> {
    triangles
        .into_iter()
        .map(|[a, b, c]| {
            if flip {
                [a as i32, c as i32, b as i32]
            } else {
                [a as i32, b as i32, c as i32]
            }
        })
        .collect()
}
