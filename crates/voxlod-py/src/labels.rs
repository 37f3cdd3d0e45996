//! Label maps (segmentations) to meshes for Python: the facade's `voxlod::labels` (one closed,
//! outward mesh per structure, each with its own chain of levels of detail; the indicator of
//! each label thresholded at ½ and filtered as in paper §4, see `src/labels.rs` of the
//! library). The map arrives as a C-ordered `(nz, ny, nx)` uint32 array (the Python half
//! converts other integer and float maps, refusing values that are no labels). Cost: one
//! pass to find the labels, then per label the pyramid's cost over its box, labels in parallel
//! (`mesh_labels`) a few per core at a time: the GIL is released for each group and Ctrl-C is
//! checked between groups.

use numpy::PyReadonlyArray3;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use voxlod::labels::{find_labels, mesh_labels, select_labels, voxel_volume, LabelError};
use voxlod::labels::{LabelInfo, LabelOptions};

use voxlod::core::{memory, Grid, LabelVolume};
use voxlod::precomputed::{write_layer, write_layer_filtered, PrecomputedOptions, Sharding};
use voxlod::surfaces::smoothing::Pressure;
use voxlod::surfaces::{LabelSurfaces, SmoothingOptions, Surface, SurfaceOptions};

use crate::arrays::volume_slice;
use crate::errors::{Failure, Kind};
use crate::facade::{filter_named, lod_level_dict, mesh_dict, mesh_from, MeshIn};

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
    map: PyReadonlyArray3<'py, u32>,
    spacing: [f64; 3],
    origin: [f64; 3],
    labels: Option<Vec<i64>>,
    options: LabelArgs,
) -> PyResult<Vec<Bound<'py, PyDict>>> {
    let map = label_volume_from(&map, spacing, origin)?;
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
    map: &LabelVolume,
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

/// A label map from a C-ordered `(nz, ny, nx)` uint32 array, spacing and origin in axis order:
/// its copy asked of the memory limit first.
pub(crate) fn label_volume_from(
    array: &PyReadonlyArray3<'_, u32>,
    spacing: [f64; 3],
    origin: [f64; 3],
) -> PyResult<LabelVolume> {
    let (values, dims) = volume_slice(array, "volume")?;
    let zyx = |v: [f64; 3]| [v[2], v[1], v[0]];
    let grid = Grid::new(dims, zyx(spacing), zyx(origin)).map_err(Failure::from)?;
    memory::check_allocation("the label map", memory::bytes_of::<u32>(values.len()))
        .map_err(Failure::from)?;
    Ok(LabelVolume::from_vec(grid, values.to_vec()).map_err(Failure::from)?)
}

/// One chunk's labels: values, voxel counts, and first and last index of each (array-axis
/// order, in the whole map).
type ChunkLabels = (Vec<u32>, Vec<u64>, Vec<[usize; 3]>, Vec<[usize; 3]>);

/// `chunk_labels(chunk, offset)`, for `voxlod.dask.labels` on a worker: the labels of one uint32
/// chunk of a map whose first sample is at `offset` (array-axis order), found as
/// `voxlod.labels` finds them (`voxlod::surfaces::find_labels`, one pass), with their boxes in
/// the whole map's indices.
#[pyfunction]
pub fn chunk_labels(
    py: Python<'_>,
    chunk: PyReadonlyArray3<'_, u32>,
    offset: [usize; 3],
) -> PyResult<ChunkLabels> {
    let chunk = label_volume_from(&chunk, [1.0; 3], [0.0; 3])?;
    let found = py.detach(|| voxlod::surfaces::find_labels(&chunk));
    let [oz, oy, ox] = offset;
    let zyx = |at: [usize; 3]| [at[2] + oz, at[1] + oy, at[0] + ox];
    Ok((
        found.iter().map(|l| l.value).collect(),
        found.iter().map(|l| l.voxels).collect(),
        found.iter().map(|l| zyx(l.min)).collect(),
        found.iter().map(|l| zyx(l.max)).collect(),
    ))
}

/// Per label a dict of its mesh, and the smoothing's report.
type Surfaces<'py> = (Vec<Bound<'py, PyDict>>, Option<Bound<'py, PyDict>>);

/// `label_surfaces(map, spacing, origin, labels, shared, smooth, normals, triangles=None)`:
/// every label of a `(nz, ny, nx)` uint32 map meshed in one pass without a filter (the facade's
/// `voxlod::label_surfaces`: marching cubes per label, or with `shared` the surface nets shared
/// between neighbours, smoothed by `smooth` λ|μ iterations with the volumes kept), each reduced
/// to about `triangles` when given (`SurfaceOptions::triangles`). Returns per
/// label (in increasing order, or that of `labels`) a dict of `label`, `voxels`,
/// `voxel_volume`, `vertices`, `faces` and `normals` (area-weighted, empty when not asked for),
/// and the smoothing's report (`None` without `shared`). The GIL is released while meshing.
///
/// For the blockwise route (`voxlod.dask.labels` with `shared`): `offset` places `map` in the
/// whole map (its first sample's index there, array-axis order; `origin` is then the whole
/// map's), and `pressures` are the restoring's rounds solved over the whole map
/// (`shared_pressure`), applied instead of solving over `map` alone.
#[pyfunction]
#[pyo3(signature = (map, spacing, origin, labels, shared, smooth, normals, triangles=None,
                    offset=None, pressures=None))]
#[allow(clippy::too_many_arguments)]
pub fn label_surfaces<'py>(
    py: Python<'py>,
    map: PyReadonlyArray3<'py, u32>,
    spacing: [f64; 3],
    origin: [f64; 3],
    labels: Option<Vec<u32>>,
    shared: bool,
    smooth: Option<usize>,
    normals: bool,
    triangles: Option<usize>,
    offset: Option<[u32; 3]>,
    pressures: Option<Vec<PressureIn>>,
) -> PyResult<Surfaces<'py>> {
    let map = label_volume_from(&map, spacing, origin)?;
    let surface = if shared {
        let mut smoothing = shared_smoothing(smooth);
        smoothing.pressures = pressures.map(|p| p.into_iter().map(pressure_from).collect());
        Surface::Shared(smoothing)
    } else {
        Surface::MarchingCubes
    };
    let options = SurfaceOptions {
        surface,
        labels,
        frame: None,
        triangles,
        offset: offset.map_or([0; 3], |[z, y, x]| [x, y, z]),
    };
    let found = py.detach(|| voxlod::label_surfaces(&map, &options).map_err(Failure::from))?;
    let smoothing = smoothing_dict(py, &found)?;
    let mut out = Vec::with_capacity(found.labels.len());
    for mut l in found.labels {
        if normals {
            l.mesh.compute_vertex_normals();
        }
        let dict = mesh_dict(py, l.mesh)?;
        dict.set_item("label", l.label.value)?;
        dict.set_item("voxels", l.label.voxels)?;
        dict.set_item("voxel_volume", l.voxel_volume)?;
        out.push(dict);
    }
    Ok((out, smoothing))
}

/// The shared surface's smoothing with `smooth` iterations (the default's when `None`).
pub(crate) fn shared_smoothing(smooth: Option<usize>) -> SmoothingOptions {
    let mut smoothing = SmoothingOptions::default();
    smoothing.iterations = smooth.unwrap_or(smoothing.iterations);
    smoothing
}

/// One restoring round's pressure as Python holds it: labels and their pressures.
pub(crate) type PressureIn = (Vec<u32>, Vec<f64>);

pub(crate) fn pressure_from((labels, values): PressureIn) -> Pressure {
    Pressure { labels, values }
}

/// The smoothing's report as a dict (`None` without smoothing): iterations and restoring rounds
/// run, the worst label's relative volume change, vertices held by their half-voxel box.
fn smoothing_dict<'py>(
    py: Python<'py>,
    found: &LabelSurfaces,
) -> PyResult<Option<Bound<'py, PyDict>>> {
    let Some(r) = &found.smoothing else {
        return Ok(None);
    };
    let dict = PyDict::new(py);
    dict.set_item("iterations", r.iterations)?;
    dict.set_item("restore_rounds", r.restore_rounds)?;
    dict.set_item("worst_label", r.worst.map(|w| w.label))?;
    dict.set_item("worst_volume_change", r.worst.map(|w| w.relative()))?;
    dict.set_item("constrained_vertices", r.constrained_vertices)?;
    Ok(Some(dict))
}

/// One level of detail of a label in the layer: fragments, triangles, Draco bytes.
type LodFigures = (usize, usize, u64);

/// `write_precomputed(dir, map, spacing, origin, meshes, (lods, quantization_bits, nanometres,
/// sharding))`: the neuroglancer precomputed segmentation layer of a `(nz, ny, nx)` uint32 map
/// and its labels' meshes (`(label, [(vertices, faces), …])`, world coordinates as
/// `label_surfaces` gives them): one mesh per label, the finest, whose coarser levels the
/// facade's `voxlod::precomputed::write_layer` simplifies from it, or `lods` meshes per label,
/// its filtered levels, which `write_layer_filtered` writes as they are. `sharding` is
/// `"auto"`, `"always"` or `"never"`. Returns the layer's report as a dict (`carried`: the
/// labels with a level given empty, which holds the finer level's surface). The GIL is released
/// while writing.
#[pyfunction]
#[pyo3(signature = (dir, map, spacing, origin, meshes, options))]
pub fn write_precomputed<'py>(
    py: Python<'py>,
    dir: std::path::PathBuf,
    map: PyReadonlyArray3<'py, u32>,
    spacing: [f64; 3],
    origin: [f64; 3],
    meshes: Vec<(u32, Vec<MeshIn<'py>>)>,
    options: (usize, u32, f64, String),
) -> PyResult<Bound<'py, PyDict>> {
    let map = label_volume_from(&map, spacing, origin)?;
    let meshes = meshes
        .iter()
        .map(|(label, levels)| {
            let levels = levels.iter().map(mesh_from).collect::<PyResult<Vec<_>>>()?;
            Ok((*label, levels))
        })
        .collect::<PyResult<Vec<_>>>()?;
    let (lods, bits, nanometres, sharding) = options;
    let mut layer = PrecomputedOptions {
        lods,
        quantization_bits: bits,
        nanometres_per_unit: nanometres,
        ..PrecomputedOptions::default()
    };
    layer.sharding = match sharding.as_str() {
        "auto" => Sharding::Auto,
        "always" => Sharding::Always,
        "never" => Sharding::Never,
        other => {
            return Err(Failure::new(
                Kind::Usage,
                format!("sharding must be auto, always or never, not {other:?}"),
            )
            .into())
        }
    };
    // One mesh per label: its finest, the coarser levels simplified from it; else its levels.
    let finest = meshes.iter().all(|(_, levels)| levels.len() == 1);
    let report = py
        .detach(|| match finest {
            true => {
                let meshes: Vec<_> = (meshes.into_iter())
                    .map(|(label, mut levels)| (label, levels.remove(0)))
                    .collect();
                write_layer(&dir, &map, &meshes, &layer)
            }
            false => write_layer_filtered(&dir, &map, &meshes, &layer),
        })
        .map_err(|e| Failure::from(voxlod::Error::from(e)))?;
    let dict = PyDict::new(py);
    dict.set_item("dir", report.dir.display().to_string())?;
    dict.set_item("sharded", report.sharding.is_some())?;
    dict.set_item("volume_bytes", report.volume_bytes)?;
    dict.set_item("resolution", report.resolution)?;
    let labels: Vec<(u32, Vec<LodFigures>)> = report
        .labels
        .iter()
        .map(|l| {
            let lods = l.lods.iter().map(|d| (d.fragments, d.triangles, d.bytes));
            (l.label, lods.collect())
        })
        .collect();
    dict.set_item("labels", labels)?;
    let carried: Vec<u32> = (report.labels.iter())
        .filter(|l| l.lods.iter().any(|d| d.carried))
        .map(|l| l.label)
        .collect();
    dict.set_item("carried", carried)?;
    Ok(dict)
}
