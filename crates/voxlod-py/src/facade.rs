//! The library facade (`voxlod::lod`, `read_mesh`, `inspect`, `compare`, …) for Python: meshes
//! in and out as `(vertices, faces)` NumPy arrays in world (x, y, z) coordinates, volumes as
//! C-ordered arrays of shape `(nz, ny, nx)` with spacing and origin in array-axis order,
//! reports as dicts (through the library's serde `Serialize`, the same keys as the command
//! line's `--json`). The long calls take an optional progress callable and stop on Ctrl-C.

use std::path::PathBuf;
use std::sync::Mutex;

use glam::Vec3;
use numpy::{IntoPyArray, PyArray2, PyArray3, PyReadonlyArray2, PyReadonlyArray3};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use serde::Serialize;
use voxlod::core::{Grid, TriangleMesh, Volume};
use voxlod::io::{Endian, RawLayout, RawType};
use voxlod::sampling::{Filter, PyramidOptions};
use voxlod::{Control, Event, Progress};

use crate::arrays::{faces_i32, rows, volume_array, volume_slice};
use crate::errors::{usage, Failure};

/// A mesh as NumPy arrays: vertices (x, y, z), faces, normals (empty when there are none).
type MeshArrays<'py> = (
    Bound<'py, PyArray2<f32>>,
    Bound<'py, PyArray2<i32>>,
    Bound<'py, PyArray2<f32>>,
);

fn mesh_arrays(py: Python<'_>, mesh: TriangleMesh) -> MeshArrays<'_> {
    let xyz =
        |points: Vec<Vec3>| -> Vec<[f32; 3]> { points.into_iter().map(|p| p.to_array()).collect() };
    (
        rows(py, xyz(mesh.positions)),
        rows(py, faces_i32(mesh.triangles, false)),
        rows(py, xyz(mesh.normals)),
    )
}

/// A mesh from Python: `(n, 3)` float32 vertices and `(m, 3)` uint32 faces.
pub(crate) type MeshIn<'py> = (PyReadonlyArray2<'py, f32>, PyReadonlyArray2<'py, u32>);

/// The mesh of `(vertices, faces)` (checked by the library).
pub(crate) fn mesh_from(mesh: &MeshIn<'_>) -> PyResult<TriangleMesh> {
    let (v, f) = (mesh.0.as_array(), mesh.1.as_array());
    if v.ncols() != 3 || f.ncols() != 3 {
        return Err(usage("vertices and faces must have 3 columns"));
    }
    let positions = v
        .rows()
        .into_iter()
        .map(|r| Vec3::new(r[0], r[1], r[2]))
        .collect();
    let triangles = f.rows().into_iter().map(|r| [r[0], r[1], r[2]]).collect();
    Ok(TriangleMesh::new(positions, triangles))
}

/// A report as a Python dict, through its JSON form.
pub(crate) fn as_dict<'py>(
    py: Python<'py>,
    report: &impl Serialize,
) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(report)
        .map_err(|e| usage(format!("the report could not be encoded: {e}")))?;
    py.import("json")?.call_method1("loads", (text,))
}

/// The progress callable and Ctrl-C as the library's progress-and-cancel callback; the Python
/// error that stopped the work (KeyboardInterrupt, or the callable's own) is kept to be raised.
struct Watch {
    callback: Option<Py<PyAny>>,
    raised: Mutex<Option<PyErr>>,
}

impl Watch {
    fn new(callback: Option<Py<PyAny>>) -> Watch {
        Watch {
            callback,
            raised: Mutex::new(None),
        }
    }

    fn ask(&self, progress: Progress<'_>) -> Control {
        Python::attach(|py| {
            let answer = py.check_signals().and_then(|()| match &self.callback {
                None => Ok(true),
                Some(callback) => {
                    let what = describe(&progress.event);
                    let answer = callback.call1(py, (progress.done, progress.total, what))?;
                    Ok(answer.is_none(py) || answer.is_truthy(py)?)
                }
            });
            match answer {
                Ok(true) => Control::Continue,
                Ok(false) => Control::Stop,
                Err(e) => {
                    *self.raised.lock().unwrap_or_else(|p| p.into_inner()) = Some(e);
                    Control::Stop
                }
            }
        })
    }

    /// The error to raise for `failure`: the Python one that stopped the work, if any.
    fn error(&self, failure: Failure) -> PyErr {
        let raised = self.raised.lock().unwrap_or_else(|p| p.into_inner()).take();
        raised.unwrap_or_else(|| failure.into())
    }
}

/// Runs `work` without the GIL, with `progress` and Ctrl-C as its progress-and-cancel callback.
pub(crate) fn watched<T: Send>(
    py: Python<'_>,
    progress: Option<Py<PyAny>>,
    work: impl FnOnce(&voxlod::ProgressFn) -> Result<T, voxlod::Error> + Send,
) -> PyResult<T> {
    let watch = Watch::new(progress);
    let ask = |p: Progress<'_>| watch.ask(p);
    let result = py.detach(|| work(&ask).map_err(Failure::from));
    result.map_err(|f| watch.error(f))
}

fn describe(event: &Event<'_>) -> String {
    match event {
        Event::Started => "started".into(),
        Event::Step { level, what } => format!("level {level} {what}"),
        Event::LodLevel(level) => format!("level at {} done", level.resolution),
        Event::EnvelopeLevel(_) => "envelope level done".into(),
    }
}

pub(crate) fn filter_named(name: &str) -> PyResult<Filter> {
    match name {
        "hypercone" | "hyper-cone" => Ok(Filter::Hypercone),
        "gaussian" => Ok(Filter::GAUSSIAN),
        _ => Err(usage(format!(
            "filter {name:?} is not 'hypercone' or 'gaussian'"
        ))),
    }
}

/// The options shared by `lod_mesh` and `lod_volume`: resolutions, filter, radius in voxels,
/// isodensity, normals, and whether the resolutions were given (else a mesh's finest level is
/// chosen from its triangle count, at most the first resolution: `voxlod::Finest`).
pub(crate) type LevelArgs = (Vec<usize>, String, f64, Option<f32>, bool, bool);

pub(crate) fn lod_options(levels: LevelArgs) -> PyResult<voxlod::LodOptions> {
    let (resolutions, filter, radius, iso, normals, given) = levels;
    let pyramid = PyramidOptions {
        resolutions,
        radius_voxels: radius,
        filter: filter_named(&filter)?,
        ..PyramidOptions::default()
    };
    Ok(voxlod::LodOptions {
        pyramid,
        iso,
        normals,
        finest: if given {
            voxlod::Finest::Given
        } else {
            voxlod::Finest::InputTriangles
        },
        ..Default::default()
    })
}

/// Runs `lod_with` without the GIL and returns each level as a dict of arrays and figures.
pub(crate) fn run_lod<'py>(
    py: Python<'py>,
    source: &voxlod::Source<'_>,
    options: &voxlod::LodOptions,
    progress: Option<Py<PyAny>>,
) -> PyResult<(Vec<Bound<'py, PyDict>>, Vec<String>)> {
    let lod = watched(py, progress, |ask| voxlod::lod_with(source, options, ask))?;
    let warnings = with_repairs(&lod);
    let levels = lod
        .levels
        .into_iter()
        .map(|level| lod_level_dict(py, level))
        .collect::<PyResult<_>>()?;
    Ok((levels, warnings))
}

/// The warnings of `lod`, after a first one saying what preparing a mesh repaired (the
/// command line's line on standard error), if anything.
pub(crate) fn with_repairs(lod: &voxlod::Lod) -> Vec<String> {
    let repairs = lod.preparation.and_then(|p| p.repairs());
    let repairs = repairs.map(|r| format!("the mesh was prepared: {r}"));
    repairs
        .into_iter()
        .chain(lod.warnings.iter().cloned())
        .collect()
}

/// One level of detail as a dict of its mesh arrays, resolution, plan, topology and times.
pub(crate) fn lod_level_dict(
    py: Python<'_>,
    level: voxlod::LodLevel,
) -> PyResult<Bound<'_, PyDict>> {
    let dict = mesh_dict(py, level.mesh)?;
    dict.set_item("resolution", level.resolution)?;
    dict.set_item("plan", as_dict(py, &level.plan)?)?;
    dict.set_item("topology", as_dict(py, &level.topology)?)?;
    dict.set_item("genus", level.topology.genus)?;
    dict.set_item("sample_seconds", level.sample_seconds)?;
    dict.set_item("contour_seconds", level.contour_seconds)?;
    Ok(dict)
}

/// `lod_mesh((vertices, faces), (resolutions, filter, radius, iso, normals), progress)`.
#[pyfunction]
#[pyo3(signature = (mesh, levels, progress=None))]
pub fn lod_mesh<'py>(
    py: Python<'py>,
    mesh: MeshIn<'py>,
    levels: LevelArgs,
    progress: Option<Py<PyAny>>,
) -> PyResult<(Vec<Bound<'py, PyDict>>, Vec<String>)> {
    let mesh = mesh_from(&mesh)?;
    let options = lod_options(levels)?;
    run_lod(py, &voxlod::Source::Mesh(&mesh), &options, progress)
}

/// A voxlod volume from a C-ordered `(nz, ny, nx)` array, spacing and origin in axis order.
pub(crate) fn volume_from(
    array: &PyReadonlyArray3<'_, f32>,
    spacing: [f64; 3],
    origin: [f64; 3],
) -> PyResult<Volume> {
    let (samples, dims) = volume_slice(array, "volume")?;
    let zyx = |v: [f64; 3]| [v[2], v[1], v[0]];
    let grid = Grid::new(dims, zyx(spacing), zyx(origin)).map_err(Failure::from)?;
    let volume = crate::contour::owned_volume(samples, dims)?;
    Ok(Volume { grid, ..volume })
}

/// `lod_volume(volume, spacing, origin, threshold, (resolutions, filter, radius, iso, normals),
/// progress)`: thresholded when `threshold` is given, else filtered directly.
#[pyfunction]
#[pyo3(signature = (volume, spacing, origin, threshold, levels, progress=None))]
pub fn lod_volume<'py>(
    py: Python<'py>,
    volume: PyReadonlyArray3<'py, f32>,
    spacing: [f64; 3],
    origin: [f64; 3],
    threshold: Option<f32>,
    levels: LevelArgs,
    progress: Option<Py<PyAny>>,
) -> PyResult<(Vec<Bound<'py, PyDict>>, Vec<String>)> {
    let volume = volume_from(&volume, spacing, origin)?;
    let options = lod_options(levels)?;
    let source = match threshold {
        Some(threshold) => voxlod::Source::Threshold {
            volume: &volume,
            threshold,
        },
        None => voxlod::Source::Direct(&volume),
    };
    run_lod(py, &source, &options, progress)
}

/// `read_mesh(path)`: vertices, faces, normals (empty when the file has none).
#[pyfunction]
pub fn read_mesh(py: Python<'_>, path: PathBuf) -> PyResult<MeshArrays<'_>> {
    let mesh = py.detach(|| voxlod::read_mesh(&path).map_err(Failure::from))?;
    Ok(mesh_arrays(py, mesh))
}

/// `write_mesh(path, vertices, faces)`.
#[pyfunction]
pub fn write_mesh(py: Python<'_>, path: PathBuf, mesh: MeshIn<'_>) -> PyResult<()> {
    let mut mesh = mesh_from(&mesh)?;
    py.detach(|| {
        mesh.compute_vertex_normals();
        voxlod::write_mesh(&path, &mesh).map_err(Failure::from)
    })?;
    Ok(())
}

/// The layout of a headerless raw file from `(shape, dtype, endian, spacing, origin)`, all in
/// array-axis order.
type RawArgs = ([usize; 3], String, String, [f64; 3], [f64; 3]);

/// A volume as NumPy: samples `(nz, ny, nx)`, spacing and origin in axis order.
type VolumeArrays<'py> = (Bound<'py, PyArray3<f32>>, [f64; 3], [f64; 3]);

/// `read_volume(path, raw=None)`: the samples as `(nz, ny, nx)` float32, spacing and origin in
/// axis order.
#[pyfunction]
#[pyo3(signature = (path, raw=None))]
pub fn read_volume(
    py: Python<'_>,
    path: PathBuf,
    raw: Option<RawArgs>,
) -> PyResult<VolumeArrays<'_>> {
    let layout = match raw {
        None => None,
        Some((shape, dtype, endian, spacing, origin)) => {
            let dtype: RawType = dtype.parse().map_err(|e| usage(format!("{e}")))?;
            let endian: Endian = endian.parse().map_err(|e| usage(format!("{e}")))?;
            let mut layout = RawLayout::new([shape[2], shape[1], shape[0]], dtype, endian);
            layout.spacing = [spacing[2], spacing[1], spacing[0]];
            layout.origin = [origin[2], origin[1], origin[0]];
            Some(layout)
        }
    };
    let volume =
        py.detach(|| voxlod::read_volume(&path, layout.as_ref()).map_err(Failure::from))?;
    let [nx, ny, nz] = volume.grid.dims;
    let (spacing, origin) = (volume.grid.spacing, volume.grid.origin);
    let samples = volume.values.into_raw_vec_and_offset().0;
    Ok((
        volume_array(py, samples, [nz, ny, nx])?,
        [spacing[2], spacing[1], spacing[0]],
        [origin[2], origin[1], origin[0]],
    ))
}

/// `write_volume(path, volume, spacing, origin)`.
#[pyfunction]
pub fn write_volume(
    py: Python<'_>,
    path: PathBuf,
    volume: PyReadonlyArray3<'_, f32>,
    spacing: [f64; 3],
    origin: [f64; 3],
) -> PyResult<()> {
    let volume = volume_from(&volume, spacing, origin)?;
    py.detach(|| voxlod::write_volume(&path, &volume).map_err(Failure::from))?;
    Ok(())
}

/// `inspect(vertices, faces, welded)`: the report of `voxlod inspect --json` for one mesh, and
/// its notes.
#[pyfunction]
pub fn inspect<'py>(
    py: Python<'py>,
    mesh: MeshIn<'py>,
    welded: bool,
) -> PyResult<(Bound<'py, PyAny>, Vec<String>)> {
    let mesh = mesh_from(&mesh)?;
    let options = voxlod::InspectOptions { welded };
    let inspection = py.detach(|| voxlod::inspect(&mesh, &options).map_err(Failure::from))?;
    Ok((as_dict(py, &inspection.report)?, inspection.notes))
}

/// `compare(a_vertices, a_faces, b_vertices, b_faces, samples, seed)`: the distance report
/// (Hausdorff, mean, RMS, absolute and as fractions of the diagonal, per side) and warnings.
#[pyfunction]
#[pyo3(signature = (a, b, samples, seed=None))]
pub fn compare<'py>(
    py: Python<'py>,
    a: MeshIn<'py>,
    b: MeshIn<'py>,
    samples: usize,
    seed: Option<u64>,
) -> PyResult<Bound<'py, PyAny>> {
    let (a, b) = (mesh_from(&a)?, mesh_from(&b)?);
    let mut options = voxlod::CompareOptions::for_samples(samples);
    if let Some(seed) = seed {
        options.distance.seed = seed;
    }
    let comparison = py.detach(|| voxlod::compare(&a, &b, &options).map_err(Failure::from))?;
    as_dict(py, &comparison)
}

/// A dict of a mesh's `vertices`, `faces` and `normals` arrays.
pub(crate) fn mesh_dict(py: Python<'_>, mesh: TriangleMesh) -> PyResult<Bound<'_, PyDict>> {
    let dict = PyDict::new(py);
    let (v, f, n) = mesh_arrays(py, mesh);
    dict.set_item("vertices", v)?;
    dict.set_item("faces", f)?;
    dict.set_item("normals", n)?;
    Ok(dict)
}

/// A dict of a level's mesh arrays and its `report`.
fn level_dict<'py>(
    py: Python<'py>,
    mesh: TriangleMesh,
    report: &impl Serialize,
) -> PyResult<Bound<'py, PyDict>> {
    let dict = mesh_dict(py, mesh)?;
    dict.set_item("report", as_dict(py, report)?)?;
    Ok(dict)
}

/// `cluster(vertices, faces, method, cells, levels)`: vertex clustering (Rossignac–Borrel or
/// Low–Tan); per level the triangles, dangling edges (`lines`), isolated points and report.
#[pyfunction]
pub fn cluster<'py>(
    py: Python<'py>,
    mesh: MeshIn<'py>,
    method: &str,
    cells: u32,
    levels: u32,
) -> PyResult<Vec<Bound<'py, PyDict>>> {
    let mesh = mesh_from(&mesh)?;
    let options = match method {
        "rossignac-borrel" => voxlod::ClusteringOptions::rossignac_borrel(cells),
        "low-tan" => voxlod::ClusteringOptions::low_tan(cells),
        _ => {
            return Err(usage(format!(
                "method {method:?} is not 'rossignac-borrel' or 'low-tan'"
            )))
        }
    }
    .with_levels(levels);
    let result = py.detach(|| voxlod::cluster(&mesh, &options).map_err(Failure::from))?;
    result
        .into_iter()
        .map(|level| {
            let lines: Vec<[u32; 2]> = level.mesh.lines;
            let points = level.mesh.points;
            let dict = level_dict(py, level.mesh.mesh, &level.report)?;
            dict.set_item("lines", ndarray::Array2::from(lines).into_pyarray(py))?;
            dict.set_item("points", crate::arrays::column(py, points))?;
            Ok(dict)
        })
        .collect()
}

/// `envelope((vertices, faces), epsilons, progress, relative=True, tight=False)`: simplification
/// envelopes, one level per ε (each from the one before), ε absolute or (with `relative`) a
/// fraction of the bounding-box diagonal.
#[pyfunction]
#[pyo3(signature = (mesh, epsilons, progress=None, *, relative=true, tight=false))]
pub fn envelope<'py>(
    py: Python<'py>,
    mesh: MeshIn<'py>,
    epsilons: Vec<f64>,
    progress: Option<Py<PyAny>>,
    relative: bool,
    tight: bool,
) -> PyResult<Vec<Bound<'py, PyDict>>> {
    use voxlod::envelope::Epsilon;
    let mesh = mesh_from(&mesh)?;
    let epsilons = epsilons
        .into_iter()
        .map(|e| {
            if relative {
                Epsilon::DiagonalFraction(e)
            } else {
                Epsilon::Absolute(e)
            }
        })
        .collect();
    let options = if tight {
        voxlod::EnvelopeSeriesOptions::tight(epsilons)
    } else {
        voxlod::EnvelopeSeriesOptions::paper(epsilons)
    };
    let series = watched(py, progress, |ask| {
        voxlod::envelope_with(&mesh, &options, ask)
    })?;
    series
        .levels
        .into_iter()
        .map(|level| level_dict(py, level.mesh, &level.report))
        .collect()
}

/// `layers(vertices, faces, error, resolution, filter, progress)`: multi-layer translucent
/// shells (paper §3), innermost first, each with its isodensity, translucency and alpha.
#[pyfunction]
#[pyo3(signature = (mesh, error, resolution, filter, progress=None))]
pub fn layers<'py>(
    py: Python<'py>,
    mesh: MeshIn<'py>,
    error: f64,
    resolution: usize,
    filter: &str,
    progress: Option<Py<PyAny>>,
) -> PyResult<Vec<Bound<'py, PyDict>>> {
    let mesh = mesh_from(&mesh)?;
    let options = voxlod::LayersOptions {
        resolution,
        plan: voxlod::layers::PlanOptions::new(filter_named(filter)?, error),
        ..Default::default()
    };
    let source = voxlod::Source::Mesh(&mesh);
    let shells = watched(py, progress, |ask| {
        voxlod::layers_with(&source, &options, ask)
    })?;
    shells
        .layered
        .mesh
        .layers
        .into_iter()
        .map(|layer| {
            let dict = mesh_dict(py, layer.mesh)?;
            dict.set_item("isodensity", layer.isodensity)?;
            dict.set_item("translucency", layer.translucency)?;
            dict.set_item("alpha", layer.alpha)?;
            Ok(dict)
        })
        .collect()
}
