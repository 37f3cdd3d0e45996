//! The direct route of paper §4 (the scan's data filtered itself, §2.3's reconstruction filter,
//! `voxlod::sampling::direct`) block by block on a Dask cluster, for
//! `voxlod.dask.lod_volume(..., direct=True)`: the levels of `voxlod.lod_volume(...,
//! direct=True)`, same triangles and vertices.
//!
//! The client plans the levels as the single process does (the same grids and radii), then per
//! level calls the Python half with the level's blocks and their windows of the scan
//! ([`voxlod::sampling::BlockwiseDirect::scan_window`]: the block's span grown by the filter's
//! reach). One task per block, on a worker, reads its window once and filters the block's
//! samples ([`fill_direct_block`], [`voxlod::sampling::BlockwiseDirect::fill_block`]: the dense
//! route's code over the window, bit for bit). The client gathers them into the level's dense
//! grid and finishes the level as `voxlod::lod_with` does for `Source::Direct`: the genus kept
//! from rising (the chain's cavities filled with the scan's largest value), marching cubes at
//! the iso value, cleaning, topology. The scan's finite range (the background outside the scan
//! and the iso value's check) comes from one reduction over the scan before the levels.
//!
//! Beyond the paper, which filters the whole volume in one process. The facade has no hook for
//! a direct level sampled elsewhere (`voxlod::lod::LodSource::Direct` holds the whole scan), so
//! [`finish_level`] repeats the few public steps `lod_with` runs on a sampled level. Cost on
//! the client: each level's dense density (4 bytes a sample, as the single process holds it),
//! the monotone chain's previous level, and the mesh.

use std::time::Instant;
use voxlod::PyramidError;

use numpy::{PyArray1, PyReadonlyArray1, PyReadonlyArray3};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use voxlod::contouring::{clean_mesh, marching_cubes, ContourOptions, PLAIN_CLAMP};
use voxlod::core::validate::{find_defect, Requirements};
use voxlod::core::{mesh_topology, Grid, Orientation, Placement, Volume, WorldTransform};
use voxlod::lod::{LodError, LodLevel};
use voxlod::sampling::density::estimated_bytes;
use voxlod::sampling::{plan_levels_with, BlockwiseDirect, LevelPlan, MonotoneChain};

use crate::arrays::{column, volume_slice};
use crate::contour::scanned_copy;
use crate::errors::{usage, Failure, Kind};
use crate::facade::{lod_level_dict, lod_options, LevelArgs};
use crate::threshold_blockwise::{block_windows, scan_grid};

/// The scan as the client and the workers both describe it: NumPy shape, spacing and origin
/// (array-axis order), its smallest and largest finite sample, the scan samples per side a
/// block's window aims at, and the levels' options.
type DirectArgs = ([usize; 3], [f64; 3], [f64; 3], (f32, f32), usize, LevelArgs);

/// The levels of a scan filtered directly, planned as `voxlod::lod_with` plans them.
struct DirectPlan {
    options: voxlod::LodOptions,
    iso: f32,
    /// The scan's largest finite sample (what the genus step fills cavities with).
    high: f32,
    plans: Vec<LevelPlan>,
    levels: Vec<BlockwiseDirect>,
    /// Grid space to the scan's world (the identity for a scan given by spacing and origin).
    placement: Placement,
}

/// Plans the levels of the scan `args` describes, after checking the iso value against its
/// range as `voxlod::Source::Direct` does.
fn direct_plan(args: &DirectArgs) -> PyResult<DirectPlan> {
    let (shape, spacing, origin, (low, high), window, levels) = args.clone();
    let scan = scan_grid(shape, spacing, origin)?;
    let options = lod_options(levels)?;
    let refuse = |e: PyramidError| -> PyErr { Failure::from(voxlod::Error::from(e)).into() };
    if low.is_nan() || high.is_nan() || low > high {
        return Err(refuse(PyramidError::NoFiniteSamples));
    }
    let iso = options
        .iso
        .ok_or_else(|| refuse(PyramidError::IsoRequired))?;
    if !iso.is_finite() || iso <= low || iso > high {
        let (min, max) = (low, high);
        return Err(refuse(PyramidError::IsoOutsideData { iso, min, max }));
    }
    let pyramid = &options.pyramid;
    let dense = |grid: &Grid, q: usize| estimated_bytes(grid, q).into();
    let plans = plan_levels_with(&scan.bounds(), pyramid, &dense).map_err(Failure::from)?;
    let levels = plans
        .iter()
        .map(|p| BlockwiseDirect::new(scan, &p.grid, pyramid.filter, p.radius, low, window))
        .collect::<Result<Vec<_>, _>>()
        .map_err(Failure::from)?;
    let world = WorldTransform::of(&scan, &Orientation::default());
    Ok(DirectPlan {
        options,
        iso,
        high,
        plans,
        levels,
        placement: Placement::of(&world, None),
    })
}

/// Level `k`'s dense density from the cluster: `run_level(k, [(block, window_start,
/// window_stop), ...])` answers each block's samples ([`fill_direct_block`]).
fn gather_level(
    py: Python<'_>,
    run_level: &Py<PyAny>,
    k: usize,
    level: &BlockwiseDirect,
) -> PyResult<Volume> {
    let blocks = block_windows(
        (0..level.block_count()).map(|n| (level.block_at(n), level.scan_window(level.block_at(n)))),
    );
    let answers = run_level.call1(py, (k, blocks.clone()))?;
    let answers: Vec<PyReadonlyArray1<'_, f32>> = answers.extract(py)?;
    if answers.len() != blocks.len() {
        return Err(usage(
            "the cluster answered for a different number of blocks",
        ));
    }
    let mut density = level.empty_level().map_err(Failure::from)?;
    for (answer, (block, _, _)) in answers.iter().zip(&blocks) {
        level
            .place_block(&mut density, *block, answer.as_slice()?)
            .map_err(Failure::from)?;
    }
    Ok(density)
}

/// What `voxlod::lod_with` does with a sampled direct level: the genus step, marching cubes,
/// cleaning, placement, topology, and the check that the vertices stayed finite.
fn finish_level(
    plan: &DirectPlan,
    p: &LevelPlan,
    density: Volume,
    chain: &mut Option<MonotoneChain>,
    sample_seconds: f64,
) -> Result<LodLevel, voxlod::Error> {
    let options = &plan.options;
    let start = Instant::now();
    let (density, monotone) = match chain {
        Some(chain) => {
            let filter = p.density_options(&options.pyramid);
            let (adjusted, record) = chain
                .next(&density, plan.iso, &filter)
                .map_err(LodError::from)?;
            (adjusted, Some(record))
        }
        None => (density, None),
    };
    let monotone_seconds = start.elapsed().as_secs_f64();
    let start = Instant::now();
    let contour = ContourOptions {
        iso: plan.iso,
        normals: options.normals,
        clamp: (options.clean).map_or(PLAIN_CLAMP, |c| c.contour_clamp()),
    };
    let mut mesh = marching_cubes(&density, &contour).map_err(LodError::from)?;
    drop(density);
    if let Some(clean) = &options.clean {
        mesh = clean_mesh(&mesh, p.voxel_size, clean)
            .map_err(LodError::from)?
            .0;
    }
    plan.placement.apply(&mut mesh);
    let contour_seconds = start.elapsed().as_secs_f64();
    if let Some(defect) = find_defect(&mesh, &Requirements::computed()) {
        return Err(PyramidError::ComputedBeyondRange {
            defect,
            cause: "the object's extent or position is too large for 32-bit coordinates",
        }
        .into());
    }
    let topology = mesh_topology(&mesh);
    Ok(LodLevel {
        resolution: p.resolution,
        plan: *p,
        mesh,
        topology,
        density: None,
        sample_seconds,
        contour_seconds,
        band: None,
        envelope: None,
        monotone,
        monotone_seconds,
        clean_skipped: false,
    })
}

/// Calls `progress(done, total, what)` and checks Ctrl-C: an error stops the work.
fn report(
    py: Python<'_>,
    progress: &Option<Py<PyAny>>,
    done: usize,
    total: usize,
    what: String,
) -> PyResult<()> {
    py.check_signals()?;
    let Some(progress) = progress else {
        return Ok(());
    };
    let answer = progress.call1(py, (done, total, what))?;
    if answer.is_none(py) || answer.is_truthy(py)? {
        return Ok(());
    }
    Err(Failure::from(voxlod::Error::Cancelled).into())
}

/// `lod_direct_blockwise(shape, spacing, origin, (low, high), window, levels, run_level,
/// progress)`: the levels of `voxlod.lod_volume(direct=True)`, each level's blocks filtered by
/// `run_level(level, [(block, window_start, window_stop), ...])` (windows in array-axis
/// order), which returns one array of [`fill_direct_block`] per block. `(low, high)` is the
/// scan's finite range, `window` the scan samples per side a block's window aims at.
#[pyfunction]
#[pyo3(signature = (shape, spacing, origin, range, window, levels, run_level, progress=None))]
#[allow(clippy::too_many_arguments)]
pub fn lod_direct_blockwise<'py>(
    py: Python<'py>,
    shape: [usize; 3],
    spacing: [f64; 3],
    origin: [f64; 3],
    range: (f32, f32),
    window: usize,
    levels: LevelArgs,
    run_level: Py<PyAny>,
    progress: Option<Py<PyAny>>,
) -> PyResult<(Vec<Bound<'py, PyDict>>, Vec<String>)> {
    let plan = direct_plan(&(shape, spacing, origin, range, window, levels))?;
    let mut chain = plan.options.monotone.map(|mut monotone| {
        monotone.fill_density = plan.high;
        MonotoneChain::new(monotone)
    });
    let total = 2 * plan.plans.len();
    report(py, &progress, 0, total, "started".into())?;
    let (mut out, mut warnings) = (Vec::new(), Vec::new());
    let mut empty = 0;
    for (k, (p, level)) in plan.plans.iter().zip(&plan.levels).enumerate() {
        let start = Instant::now();
        let density = gather_level(py, &run_level, k, level)?;
        let seconds = start.elapsed().as_secs_f64();
        report(
            py,
            &progress,
            2 * k + 1,
            total,
            format!("level {k} sampled"),
        )?;
        let built = py
            .detach(|| finish_level(&plan, p, density, &mut chain, seconds))
            .map_err(|e| Failure::from(e.context(format!("level {}", p.level))))?;
        report(
            py,
            &progress,
            2 * k + 2,
            total,
            format!("level {k} contoured"),
        )?;
        if built.mesh.is_empty() {
            empty += 1;
            warnings.push(format!(
                "level {k}: the filter of radius {:.4} removed the whole object (no density \
                 reaches {}); the level is empty",
                p.radius, plan.iso
            ));
        }
        out.push(lod_level_dict(py, built)?);
    }
    if empty == plan.plans.len() {
        let (iso, first) = (plan.iso, &plan.plans[0]);
        let (voxel_size, radius) = (first.voxel_size, first.radius);
        return Err(Failure::from(voxlod::Error::from(PyramidError::NoSurface {
            iso,
            voxel_size,
            radius,
        }))
        .into());
    }
    Ok((out, warnings))
}

/// `fill_direct_block(window, scan, level, block)`, on a worker: the filtered samples (x
/// fastest over the block's box) of block `block` (x, y, z) of level `level` of the scan `scan`
/// (the client's arguments), from `window`, its samples `window_start .. window_stop` as the
/// client named them.
#[pyfunction]
pub fn fill_direct_block<'py>(
    py: Python<'py>,
    window: PyReadonlyArray3<'py, f32>,
    scan: DirectArgs,
    level: usize,
    block: [usize; 3],
) -> PyResult<Bound<'py, PyArray1<f32>>> {
    let plan = direct_plan(&scan)?;
    let count = plan.levels.len();
    let level = plan
        .levels
        .get(level)
        .ok_or_else(|| usage(format!("level {level} of {count}")))?;
    let (samples, dims) = volume_slice(&window, "window")?;
    let values = py.detach(|| -> Result<Vec<f32>, Failure> {
        let (volume, found) = scanned_copy(samples, dims)?;
        if let Some([a, b, c]) = found.first_nan(dims) {
            let (start, _) = level.scan_window(block);
            let at = [a + start[2], b + start[1], c + start[0]];
            return Err(Failure::new(
                Kind::BadInput,
                format!("the scan has NaN at index {at:?}; filtering needs numbers"),
            ));
        }
        Ok(level.fill_block(block, &volume)?)
    })?;
    Ok(column(py, values))
}
