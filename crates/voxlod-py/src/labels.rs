//! Label maps (segmentations) to meshes for Python: the facade's `voxlod::labels` (one closed,
//! outward mesh per structure, each with its own chain of levels of detail; the indicator of
//! each label thresholded at ½ and filtered as in paper §4, see `src/labels.rs` of the
//! library). The map arrives as a C-ordered `(nz, ny, nx)` float32 array of integer values
//! (the Python half converts integer maps; every value up to 2²⁴ is exact in float32). Cost: one
//! pass to find the labels, then per label the pyramid's cost over its box, labels in parallel
//! (`mesh_labels`) a few per core at a time: the GIL is released for each group and Ctrl-C is
//! checked between groups.

use numpy::PyReadonlyArray3;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use voxlod::labels::{find_labels, mesh_labels, select_labels, voxel_volume, LabelError};
use voxlod::labels::{LabelInfo, LabelOptions};

use crate::errors::{Failure, Kind};
use crate::facade::{filter_named, lod_level_dict, volume_from};

impl From<LabelError> for Failure {
    /// The map's own faults are bad input, a label asked for and absent a usage error, the
    /// pyramid's failures classed by the facade.
    fn from(e: LabelError) -> Failure {
        match e {
            LabelError::Missing(..) => Failure::new(Kind::Usage, e.to_string()),
            LabelError::NotALabel(..) | LabelError::NoLabels => {
                Failure::new(Kind::BadInput, e.to_string())
            }
            LabelError::Lod(e) => voxlod::Error::from(e).into(),
            LabelError::Sampling(e) => voxlod::Error::from(e).into(),
            LabelError::Envelope(e) => voxlod::Error::from(e).into(),
        }
    }
}

/// The options of `labels`: level count, filter, radius in voxels, normals.
type LabelArgs = (usize, String, f64, bool);

fn label_options(args: LabelArgs, labels: Option<Vec<i64>>) -> PyResult<LabelOptions> {
    let (levels, filter, radius, normals) = args;
    let mut options = LabelOptions::for_levels(levels);
    options.lod.pyramid.filter = filter_named(&filter)?;
    options.lod.pyramid.radius_voxels = radius;
    options.lod.normals = normals;
    options.labels = labels;
    Ok(options)
}

/// `labels(map, spacing, origin, labels, (levels, filter, radius, normals))`: per label (in
/// increasing order) a dict of its `label`, `voxels`, `voxel_volume` and `levels` (each as
/// `lod_volume`'s levels).
#[pyfunction]
#[pyo3(signature = (map, spacing, origin, labels, options))]
pub fn labels<'py>(
    py: Python<'py>,
    map: PyReadonlyArray3<'py, f32>,
    spacing: [f64; 3],
    origin: [f64; 3],
    labels: Option<Vec<i64>>,
    options: LabelArgs,
) -> PyResult<Vec<Bound<'py, PyDict>>> {
    let map = volume_from(&map, spacing, origin)?;
    let options = label_options(options, labels)?;
    let chosen: Vec<LabelInfo> = py.detach(|| {
        let all = find_labels(&map)?;
        select_labels(all, options.labels.as_deref()).map_err(Failure::from)
    })?;
    let mut out = Vec::with_capacity(chosen.len());
    let group = 2 * rayon::current_num_threads().max(1);
    for labels in chosen.chunks(group) {
        py.check_signals()?;
        let meshed =
            py.detach(|| mesh_labels(&map, labels, &options, &|_| ()).map_err(Failure::from))?;
        for (label, levels) in labels.iter().zip(meshed) {
            out.push(label_dict(py, &map, label, levels.map_err(Failure::from)?)?);
        }
    }
    Ok(out)
}

/// One label's dict: `label`, `voxels`, `voxel_volume` and its `levels`.
fn label_dict<'py>(
    py: Python<'py>,
    map: &voxlod::core::Volume,
    label: &LabelInfo,
    levels: Vec<voxlod::lod::LodLevel>,
) -> PyResult<Bound<'py, PyDict>> {
    let dict = PyDict::new(py);
    dict.set_item("label", label.value)?;
    dict.set_item("voxels", label.voxels)?;
    dict.set_item("voxel_volume", voxel_volume(map, label.voxels))?;
    let levels = levels
        .into_iter()
        .map(|level| lod_level_dict(py, level))
        .collect::<PyResult<Vec<_>>>()?;
    dict.set_item("levels", levels)?;
    Ok(dict)
}

/// One chunk's labels: values, voxel counts, and first and last index of each (array-axis
/// order, in the whole map).
type ChunkLabels = (Vec<i64>, Vec<usize>, Vec<[usize; 3]>, Vec<[usize; 3]>);

/// `chunk_labels(chunk, offset)`, for `voxlod.dask.labels` on a worker: the labels of one chunk
/// of a map whose first sample is at `offset` (array-axis order), found as `voxlod.labels` finds
/// them ([`find_labels`]), with their boxes in the whole map's indices. A sample that is not a
/// label is named by its index in the whole map.
#[pyfunction]
pub fn chunk_labels(
    py: Python<'_>,
    chunk: PyReadonlyArray3<'_, f32>,
    offset: [usize; 3],
) -> PyResult<ChunkLabels> {
    let chunk = volume_from(&chunk, [1.0; 3], [0.0; 3])?;
    let found = py.detach(|| find_labels(&chunk));
    let [oz, oy, ox] = offset;
    let found = found.map_err(|e| match e {
        LabelError::NotALabel(i, j, k, v) => LabelError::NotALabel(i + ox, j + oy, k + oz, v),
        other => other,
    });
    let found = found.map_err(Failure::from)?;
    let zyx = |at: [usize; 3]| [at[2] + oz, at[1] + oy, at[0] + ox];
    Ok((
        found.iter().map(|l| l.value).collect(),
        found.iter().map(|l| l.voxels).collect(),
        found.iter().map(|l| zyx(l.min)).collect(),
        found.iter().map(|l| zyx(l.max)).collect(),
    ))
}
