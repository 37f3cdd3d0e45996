//! `voxlod._voxlod`, the extension module of the Python package `voxlod` (the Python half is
//! `python/voxlod/`: argument handling, docstrings, type stubs, the Dask path).
//!
//! Every function takes NumPy arrays (borrowed, C-contiguous), releases the GIL while it works,
//! and returns NumPy arrays that own the Rust results without a copy. Failures are Python
//! exceptions of `voxlod.errors` with the library's message ([`errors`]); nothing here panics
//! on any input.

mod arrays;
mod blocks;
mod budgets;
mod contour;
mod direct_blockwise;
mod errors;
mod facade;
mod filter;
mod labels;
mod scene;
mod shared_blocks;
mod threshold_blockwise;

use pyo3::prelude::*;

/// The bytes voxlod allows itself now (`VOXLOD_MAX_MEMORY`, the machine, the container).
#[pyfunction]
fn memory_available() -> PyResult<u64> {
    voxlod_core::memory::available_bytes().map_err(|e| errors::Failure::from(e).into())
}

#[pymodule]
fn _voxlod(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(memory_available, m)?)?;
    m.add_function(wrap_pyfunction!(contour::marching_cubes, m)?)?;
    m.add_function(wrap_pyfunction!(filter::gaussian_filter, m)?)?;
    m.add_function(wrap_pyfunction!(blocks::contour_block, m)?)?;
    m.add_function(wrap_pyfunction!(blocks::stitch, m)?)?;
    m.add_function(wrap_pyfunction!(
        threshold_blockwise::lod_threshold_blockwise,
        m
    )?)?;
    m.add_function(wrap_pyfunction!(
        threshold_blockwise::fill_threshold_block,
        m
    )?)?;
    m.add_function(wrap_pyfunction!(direct_blockwise::lod_direct_blockwise, m)?)?;
    m.add_function(wrap_pyfunction!(direct_blockwise::fill_direct_block, m)?)?;
    m.add_function(wrap_pyfunction!(facade::lod_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(budgets::lod_budgets, m)?)?;
    m.add_function(wrap_pyfunction!(facade::lod_volume, m)?)?;
    m.add_function(wrap_pyfunction!(facade::read_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(facade::write_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(facade::read_volume, m)?)?;
    m.add_function(wrap_pyfunction!(facade::write_volume, m)?)?;
    m.add_function(wrap_pyfunction!(facade::inspect, m)?)?;
    m.add_function(wrap_pyfunction!(facade::compare, m)?)?;
    m.add_function(wrap_pyfunction!(facade::cluster, m)?)?;
    m.add_function(wrap_pyfunction!(facade::envelope, m)?)?;
    m.add_function(wrap_pyfunction!(facade::layers, m)?)?;
    m.add_function(wrap_pyfunction!(labels::labels, m)?)?;
    m.add_function(wrap_pyfunction!(labels::label_surfaces, m)?)?;
    m.add_function(wrap_pyfunction!(labels::write_precomputed, m)?)?;
    m.add_function(wrap_pyfunction!(labels::chunk_labels, m)?)?;
    m.add_function(wrap_pyfunction!(shared_blocks::shared_sums, m)?)?;
    m.add_function(wrap_pyfunction!(shared_blocks::shared_pressure, m)?)?;
    m.add(
        "RESTORE_ROUNDS",
        voxlod::surfaces::SmoothingOptions::default().restore_rounds,
    )?;
    m.add_function(wrap_pyfunction!(scene::read_scene, m)?)?;
    m.add_function(wrap_pyfunction!(scene::write_scene, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
