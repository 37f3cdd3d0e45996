//! The input's solids and their contoured grids, made once for the whole chain of budgets:
//! the voxel search runs once for a chain, not once per budget.
//!
//! **Solids** ([`with_solids`]): the input as given; with its closed cavities filled, where they
//! hold at least [`CAVITY_SHARE`] of its volume, so that a hollow part whose wall the budget
//! cannot afford turns solid instead of perforating; with the hollows it nearly encloses
//! filled and lined (module `enclosed`); where it has closed and open parts, the closed ones as
//! a solid with shells around the open ones (module `open_parts`). Each is built once, all at
//! once on the cores.
//!
//! **Grids** ([`Grids`]): a solid filtered at a resolution (radius one voxel, as the paper's
//! pyramid, He et al. 1995 §2–3) and contoured at its isodensities (§4) is the same for every
//! budget that asks for it (budgets near each other, 1/128 of the input and 300, ask for the
//! same grids; one budget's coarser neighbour can be the next budget's first grid). The budgets'
//! first grids are planned together, made once each and in parallel, the finest first; a grid a
//! budget's search asks for later (finer where too few triangles came out, coarser where the
//! collapse stalled) is made once and kept for the budgets after it.
//!
//! Cost: per distinct (solid, resolution), one sampling (the lattice lines' crossings, O(N²)
//! lines, and the density, O(N³)) and one marching cubes pass for all isodensities; the levels
//! are kept until the chain's voxel search ends.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use rayon::prelude::*;
use voxlod_contouring::marching_cubes_multi;
use voxlod_core::cavities::fill_cavities;
use voxlod_core::{TriangleMesh, Volume};
use voxlod_metrics::MeshDistance;
use voxlod_sampling::closing::closing_fill;
use voxlod_sampling::{
    filtered_density, level_grid, DensityOptions, MeshSolid, MeshSolidOptions, Solid,
    ThresholdSolid,
};

use crate::candidate::Fill;
use crate::enclosed::hollow_volumes;
use crate::input::Input;
use crate::open_parts::{add_open_shells, split_open_parts};
use crate::{BudgetError, PortfolioOptions};

/// The isodensities contoured (module `voxel`).
pub const ISOS: [f32; 3] = [0.5, 0.25, 0.15];

/// The input as one solid of the voxel candidates: what of its inside is filled, the solid
/// sampled, and the open parts sampled as shells beside it (module `open_parts`).
#[derive(Clone, Copy)]
pub struct Sampled<'a> {
    /// What the solid fills.
    pub fill: Fill,
    /// The solid (with [`Fill::OpenShells`], of the closed parts only).
    pub solid: &'a dyn Solid,
    /// The open parts, whose shells join the solid (with [`Fill::OpenShells`] only).
    pub shells: Option<&'a MeshDistance>,
}

/// The isodensities a solid is contoured at: all of [`ISOS`] for the input as given, with its
/// closed cavities filled, and with its open parts as shells; only 0.5 where its hollows are
/// filled or lined (module `enclosed`), whose walls are thick by construction.
pub fn isos_of(fill: Fill) -> &'static [f32] {
    match fill {
        Fill::None | Fill::Cavities | Fill::OpenShells => &ISOS,
        Fill::Hollows | Fill::HollowLining => &ISOS[..1],
    }
}

/// The cavities of the input hold at least this fraction of its volume for the filled solid to
/// be sampled too: a tiny void (a scan's bubble) changes no voxel level a budget affords.
pub const CAVITY_SHARE: f64 = 0.01;

/// What the solids are made of, owned: the meshes' solids and the hollows' volumes.
struct Made {
    given: MeshSolid,
    filled: Option<MeshSolid>,
    open: Option<(MeshSolid, MeshDistance)>,
    hollows: Vec<(Fill, Volume)>,
}

/// `then` called with the input's solids for the voxel candidates (module docs), the input as
/// given first, all built at once on the cores. With `remesh`, parts that pass through each
/// other are sampled as their union (`MeshSolidOptions::union`), as a proxy of a scene needs.
pub fn with_solids<R>(
    input: &Input,
    remesh: bool,
    then: impl FnOnce(&[Sampled]) -> Result<R, BudgetError>,
) -> Result<R, BudgetError> {
    let options = MeshSolidOptions {
        union: remesh,
        ..MeshSolidOptions::default()
    };
    let given = MeshSolid::new_with(&input.mesh, options)?;
    let (hollows, (filled, open)) = rayon::join(
        || hollow_volumes(input, &given),
        || {
            rayon::join(
                || filled_solid(input, options),
                || open_shells_solid(input, options),
            )
        },
    );
    let made = Made {
        given,
        filled: filled?,
        open: open?,
        hollows: hollows?,
    };
    let thresholds: Vec<(Fill, ThresholdSolid)> = (made.hollows.iter())
        .filter_map(|(fill, volume)| Some((*fill, ThresholdSolid::new(volume, 0.5).ok()?)))
        .collect();
    fn plain(fill: Fill, solid: &MeshSolid) -> Sampled<'_> {
        Sampled {
            fill,
            solid,
            shells: None,
        }
    }
    let mut solids = vec![plain(Fill::None, &made.given)];
    solids.extend(made.filled.as_ref().map(|s| plain(Fill::Cavities, s)));
    solids.extend(made.open.as_ref().map(|(solid, shells)| Sampled {
        fill: Fill::OpenShells,
        solid,
        shells: Some(shells),
    }));
    solids.extend(thresholds.iter().map(|(fill, solid)| Sampled {
        fill: *fill,
        solid,
        shells: None,
    }));
    then(&solids)
}

/// The input with its closed cavities filled, where they hold at least [`CAVITY_SHARE`] of it.
fn filled_solid(
    input: &Input,
    options: MeshSolidOptions,
) -> Result<Option<MeshSolid>, BudgetError> {
    let Some(filled) = fill_cavities(&input.mesh) else {
        return Ok(None);
    };
    let (before, after) = (input.mesh.signed_volume(), filled.mesh.signed_volume());
    if after - before < CAVITY_SHARE * after.abs() {
        return Ok(None);
    }
    Ok(Some(MeshSolid::new_with(&filled.mesh, options)?))
}

/// The closed parts as a solid and the open ones to put shells around, where the input has
/// both.
fn open_shells_solid(
    input: &Input,
    options: MeshSolidOptions,
) -> Result<Option<(MeshSolid, MeshDistance)>, BudgetError> {
    let Some(split) = split_open_parts(input) else {
        return Ok(None);
    };
    let solid = MeshSolid::new_with(&split.closed, options)?;
    Ok(Some((solid, MeshDistance::new(&split.open)?)))
}

/// One solid contoured on one grid: a level per isodensity of [`isos_of`] its fill.
pub type Contoured = Arc<Vec<TriangleMesh>>;

/// The chain's contoured grids (module docs), keyed by (solid, resolution).
pub struct Grids<'a> {
    input: &'a Input,
    solids: &'a [Sampled<'a>],
    options: &'a PortfolioOptions,
    made: Mutex<HashMap<(usize, usize), Contoured>>,
}

impl<'a> Grids<'a> {
    /// The grids of `plan` ((solid, resolution) pairs, repeats allowed) made at once, in
    /// parallel; others are made as they are asked for.
    pub fn new(
        input: &'a Input,
        solids: &'a [Sampled<'a>],
        options: &'a PortfolioOptions,
        plan: &[(usize, usize)],
    ) -> Result<Grids<'a>, BudgetError> {
        let grids = Grids {
            input,
            solids,
            options,
            made: Mutex::new(HashMap::new()),
        };
        let mut keys = plan.to_vec();
        keys.sort_unstable();
        keys.dedup();
        // The finest first: they take longest.
        keys.sort_by_key(|&(_, r)| std::cmp::Reverse(r));
        let made: Vec<((usize, usize), Contoured)> = keys
            .par_iter()
            .map(|&key| Ok((key, Arc::new(grids.contour(key)?))))
            .collect::<Result<_, BudgetError>>()?;
        grids.lock().extend(made);
        Ok(grids)
    }

    /// The solids the grids sample.
    pub fn solids(&self) -> &'a [Sampled<'a>] {
        self.solids
    }

    /// Solid `solid` contoured at `resolution`: made before, or now (without holding others
    /// up; two budgets asking at once may both make it, and the first kept is what both use
    /// afterwards).
    pub fn levels(&self, solid: usize, resolution: usize) -> Result<Contoured, BudgetError> {
        let key = (solid, resolution);
        if let Some(found) = self.lock().get(&key) {
            return Ok(found.clone());
        }
        let made = Arc::new(self.contour(key)?);
        Ok(self.lock().entry(key).or_insert(made).clone())
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, HashMap<(usize, usize), Contoured>> {
        // A panic elsewhere cannot leave the map half-written: entries are inserted whole.
        self.made.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// Solid `key.0` filtered at resolution `key.1` (radius one voxel, as the paper's pyramid),
    /// its open parts' shells added where it has them, its gaps closed where the options ask,
    /// and contoured at each of [`isos_of`] its fill.
    fn contour(
        &self,
        (solid, resolution): (usize, usize),
    ) -> Result<Vec<TriangleMesh>, BudgetError> {
        let sampled = self.solids[solid];
        let radius = self.input.voxel(resolution);
        let grid = level_grid(&self.input.bounds, resolution, radius)?;
        let density_options = DensityOptions::new(self.options.filter, radius);
        let (mut density, _) = filtered_density(sampled.solid, &grid, &density_options)?;
        if let Some(open) = sampled.shells {
            add_open_shells(&mut density, open, radius)?;
        }
        if let Some(gap) = self.options.close_gaps {
            close_gaps(&mut density, gap)?;
        }
        let isos = isos_of(sampled.fill);
        let levels =
            marching_cubes_multi(&density, isos, false).map_err(|e| BudgetError::NoLevel {
                budget: 0,
                why: format!("marching cubes: {e}"),
            })?;
        Ok(levels.into_iter().map(|l| l.mesh).collect())
    }
}

/// `density` with the gaps of its solid (isodensity 1/2) narrower than `gap` (mesh units)
/// closed: a morphological closing by a ball of radius `gap / 2`, rounded to whole samples
/// ([`closing_fill`]: dilated, what the outside cannot reach kept, eroded again), whose new
/// samples are raised to 1. A gap under a sample's width is left to the filter. Cost:
/// O(N³) for N³ samples.
fn close_gaps(density: &mut voxlod_core::Volume, gap: f64) -> Result<(), BudgetError> {
    let radius = (0.5 * gap / density.grid.spacing[0]).round() as usize;
    if radius == 0 {
        return Ok(());
    }
    let dims = density.grid.dims;
    let inside: Vec<bool> = density.as_slice().iter().map(|&d| d >= 0.5).collect();
    let closing = closing_fill(&inside, dims, radius)?;
    let values = density.as_slice_mut();
    for i in closing.filled {
        values[i] = 1.0;
    }
    Ok(())
}
