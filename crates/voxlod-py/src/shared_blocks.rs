//! The shared surface's volume restoring block by block, for `voxlod.dask.labels` with
//! `shared`: each block (a chunk of the map grown by a margin) gives its share of the
//! restoring's sums (`shared_sums`), one task per block; the sums of every block, added,
//! give the round's pressure for the whole map (`shared_pressure`), as one process solves
//! it. The label tasks then smooth their boxes with those pressures (`label_surfaces` with
//! `pressures`) and land on the one-process positions bit for bit (crate `voxlod-labels`,
//! `smoothing/sums.rs`).

use numpy::PyReadonlyArray3;
use pyo3::prelude::*;
use voxlod::surfaces::smoothing::{
    restoring_pressure, restoring_sums, Owned, PairSums, RestoringSums,
};
use voxlod::surfaces::surface_nets::{surface_nets, SurfaceNetsOptions};

use crate::errors::Failure;
use crate::labels::{label_volume_from, pressure_from, shared_smoothing, PressureIn};

/// Sums per label pair as Python holds them: the pairs `[inside, outside]`, each pair's sum
/// in units (a Python int: 128-bit), and the unit.
type SumsOut = (Vec<[u32; 2]>, Vec<i128>, f64);

/// One block's `(before, volumes, weights)`.
type BlockSums = (SumsOut, SumsOut, SumsOut);

fn sums_out(p: PairSums) -> SumsOut {
    let (pairs, sums) = p.sums.into_iter().unzip();
    (pairs, sums, p.unit)
}

fn sums_in((pairs, sums, unit): SumsOut) -> PairSums {
    PairSums {
        unit,
        sums: pairs.into_iter().zip(sums).collect(),
    }
}

/// `shared_sums(block, spacing, origin, offset, owned_lo, owned_hi, smooth, pressures)`: the
/// restoring's sums of the triangles and vertices whose corners lie in `owned_lo .. owned_hi`
/// (the whole map's corner indices, array-axis order), from `block`, the whole map's samples
/// from `offset` on (`origin` the whole map's), smoothed by `smooth` iterations with
/// `pressures` (the rounds so far) applied. The margin around the owned corners must hold
/// what they see: `2 · smooth + 3 + rounds` voxels (`voxlod.dask.shared_halo`). The GIL is
/// released while meshing.
#[pyfunction]
#[pyo3(signature = (block, spacing, origin, offset, owned_lo, owned_hi, smooth, pressures))]
#[allow(clippy::too_many_arguments)]
pub fn shared_sums(
    py: Python<'_>,
    block: PyReadonlyArray3<'_, u32>,
    spacing: [f64; 3],
    origin: [f64; 3],
    offset: [u32; 3],
    owned_lo: [u32; 3],
    owned_hi: [u32; 3],
    smooth: Option<usize>,
    pressures: Vec<PressureIn>,
) -> PyResult<BlockSums> {
    let map = label_volume_from(&block, spacing, origin)?;
    let xyz = |[z, y, x]: [u32; 3]| [x, y, z];
    let nets = SurfaceNetsOptions {
        offset: xyz(offset),
        ..SurfaceNetsOptions::default()
    };
    let mut options = shared_smoothing(smooth);
    options.pressures = Some(pressures.into_iter().map(pressure_from).collect());
    let owned = Owned {
        lo: xyz(owned_lo),
        hi: xyz(owned_hi),
    };
    let sums = py.detach(|| -> Result<RestoringSums, Failure> {
        let mut surface = surface_nets(&map, &nets).map_err(voxlod::Error::from)?;
        Ok(restoring_sums(&mut surface, &options, owned).map_err(voxlod::Error::from)?)
    })?;
    Ok((
        sums_out(sums.before),
        sums_out(sums.volumes),
        sums_out(sums.weights),
    ))
}

/// `shared_pressure(blocks, smooth)`: the next restoring round's pressure from every block's
/// `shared_sums`, as `(labels, pressures)`, or `None` when every label's volume is within the
/// tolerance (the restoring stops there).
#[pyfunction]
pub fn shared_pressure(blocks: Vec<BlockSums>, smooth: Option<usize>) -> Option<PressureIn> {
    let mut parts = (Vec::new(), Vec::new(), Vec::new());
    for (before, volumes, weights) in blocks {
        parts.0.push(sums_in(before));
        parts.1.push(sums_in(volumes));
        parts.2.push(sums_in(weights));
    }
    let sums = RestoringSums {
        before: PairSums::merged(parts.0),
        volumes: PairSums::merged(parts.1),
        weights: PairSums::merged(parts.2),
    };
    restoring_pressure(&sums, &shared_smoothing(smooth)).map(|p| (p.labels, p.values))
}
