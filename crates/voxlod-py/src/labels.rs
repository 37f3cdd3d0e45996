//! Label maps (segmentations) to meshes for Python: the facade's `voxlod::labels` (one closed,
//! outward mesh per structure, each with its own chain of levels of detail; the indicator of
//! each label thresholded at ½ and filtered as in paper §4, see `src/labels.rs` of the
//! library). The map arrives as a C-ordered `(nz, ny, nx)` float32 array of integer values
//! (the Python half converts integer maps; every value up to 2²⁴ is exact in float32). Cost: one
//! pass to find the labels, then per label the pyramid's cost over its box; the GIL is released
//! for each label and Ctrl-C is checked between labels.

use numpy::PyReadonlyArray3;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use voxlod::labels::{find_labels, label_levels, select_labels, voxel_volume, LabelError};
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
    let mut options = LabelOptions::with_levels(levels);
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
    for label in &chosen {
        py.check_signals()?;
        let levels = py.detach(|| label_levels(&map, label, &options).map_err(Failure::from))?;
        let dict = PyDict::new(py);
        dict.set_item("label", label.value)?;
        dict.set_item("voxels", label.voxels)?;
        dict.set_item("voxel_volume", voxel_volume(&map, label.voxels))?;
        let levels = levels
            .into_iter()
            .map(|level| lod_level_dict(py, level))
            .collect::<PyResult<Vec<_>>>()?;
        dict.set_item("levels", levels)?;
        out.push(dict);
    }
    Ok(out)
}
