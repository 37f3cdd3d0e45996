//! `voxlod.gaussian_filter`, the drop-in for `scipy.ndimage.gaussian_filter` on 3-D `float32`
//! and `float64` arrays: [`voxlod_sampling::gaussian_filter`] (separable, SciPy's taps and
//! border modes, in parallel) on the array's own memory, the result handed to NumPy without a
//! copy. σ and the array's axes are given in NumPy order and turned to voxlod's x, y, z here.

use numpy::{Element, PyArray3, PyReadonlyArray3};
use pyo3::prelude::*;
use voxlod_sampling::gaussian_filter::{gaussian_filter as filter_samples, FilterSample};
use voxlod_sampling::{BoundaryMode, GaussianFilterOptions};

use crate::arrays::{volume_array, volume_slice};
use crate::errors::{usage, Failure};

fn filter<'py, T: FilterSample + Element>(
    py: Python<'py>,
    volume: PyReadonlyArray3<'py, T>,
    sigma: [f64; 3],
    truncate: f64,
    mode: &str,
    cval: f64,
) -> PyResult<Bound<'py, PyArray3<T>>> {
    let mode = BoundaryMode::from_name(mode, cval).ok_or_else(|| {
        usage(format!(
            "mode {mode:?} is not one of 'reflect', 'mirror', 'nearest', 'wrap', 'constant'"
        ))
    })?;
    let (samples, dims) = volume_slice(&volume, "input")?;
    let options = GaussianFilterOptions {
        // NumPy's axes 0, 1, 2 are z, y, x.
        sigma: [sigma[2], sigma[1], sigma[0]],
        truncate,
        mode,
    };
    let filtered = py.detach(|| filter_samples(samples, dims, &options).map_err(Failure::from))?;
    volume_array(py, filtered, [dims[2], dims[1], dims[0]])
}

/// `gaussian_filter(input, sigma, truncate, mode, cval)` for a C-contiguous `float32` or
/// `float64` array: see the module documentation.
#[pyfunction]
pub fn gaussian_filter<'py>(
    py: Python<'py>,
    input: &Bound<'py, PyAny>,
    sigma: [f64; 3],
    truncate: f64,
    mode: &str,
    cval: f64,
) -> PyResult<Bound<'py, PyAny>> {
    if let Ok(single) = input.extract::<PyReadonlyArray3<'py, f32>>() {
        return Ok(filter(py, single, sigma, truncate, mode, cval)?.into_any());
    }
    match input.extract::<PyReadonlyArray3<'py, f64>>() {
        Ok(double) => Ok(filter(py, double, sigma, truncate, mode, cval)?.into_any()),
        Err(_) => Err(usage("`input` must be a 3-D float32 or float64 array")),
    }
}
