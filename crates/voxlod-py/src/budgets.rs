//! Levels by triangle budget or error target from Python: `voxlod.lod(v, f,
//! triangles=[20000, 5000], error="0.5%")` runs the library's budget pipeline
//! ([`voxlod::lod_by_budget`]: the voxel level that filters away what a budget cannot afford, then a
//! geometric stage, He et al. 1995 §5) and returns each level with its budget report. Cost: the
//! pipeline's, without the GIL.

use pyo3::prelude::*;
use pyo3::types::PyDict;
use voxlod::budget::{ErrorTarget, Then};
use voxlod::Source;

use crate::errors::usage;
use crate::facade::{
    as_dict, filter_named, lod_level_dict, mesh_from, watched, with_repairs, LevelArgs, MeshIn,
};

/// What the budget pipeline is asked besides the levels' filter: the budgets, the error target
/// (`"0.5"` in mesh units or `"0.5%"` of the diagonal), the geometric stage, closed levels, and
/// the search's time cap in CPU seconds.
pub(crate) type BudgetArgs = (Option<Vec<usize>>, Option<String>, String, bool, f64);

/// `lod_budgets((vertices, faces), levels, (triangles, error, then, closed, time_cap),
/// progress)`: each level's dict has the pipeline's report under `"budget"`.
#[pyfunction]
#[pyo3(signature = (mesh, levels, budgets, progress=None))]
pub fn lod_budgets<'py>(
    py: Python<'py>,
    mesh: MeshIn<'py>,
    levels: LevelArgs,
    budgets: BudgetArgs,
    progress: Option<Py<PyAny>>,
) -> PyResult<(Vec<Bound<'py, PyDict>>, Vec<String>)> {
    let (triangles, error, then, closed, time_cap) = budgets;
    let mesh = mesh_from(&mesh)?;
    let error = error
        .map(|e| e.parse::<ErrorTarget>())
        .transpose()
        .map_err(|m| usage(format!("error: {m}")))?;
    let then = then
        .parse::<Then>()
        .map_err(|m| usage(format!("then: {m}")))?;
    if time_cap.is_nan() || time_cap < 0.0 {
        return Err(usage(format!(
            "time_cap ({time_cap}) must be 0 or more seconds (float('inf') for no cap)"
        )));
    }
    // The levels' resolutions are chosen per budget: only the filter, its radius, the
    // isodensity and the normals apply.
    let (_, filter, radius_voxels, iso, normals, _) = levels;
    let options = voxlod::BudgetOptions {
        triangles: triangles.unwrap_or_default(),
        error,
        then,
        filter: filter_named(&filter)?,
        radius_voxels,
        iso,
        normals,
        closed,
        time_cap,
        ..voxlod::BudgetOptions::default()
    };
    let lod = watched(py, progress, |ask| {
        voxlod::lod_by_budget_with(&Source::Mesh(&mesh), &options, ask)
    })?;
    let warnings = with_repairs(&lod);
    let mut out = Vec::with_capacity(lod.levels.len());
    for (level, report) in lod.levels.into_iter().zip(&lod.budgets) {
        let dict = lod_level_dict(py, level)?;
        dict.set_item("budget", as_dict(py, report)?)?;
        out.push(dict);
    }
    Ok((out, warnings))
}
