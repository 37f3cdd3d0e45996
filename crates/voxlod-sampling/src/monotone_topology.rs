//! Topology that only ever simplifies along the pyramid: no level has more handles (genus) than
//! the level above it.
//!
//! **Beyond the paper.** He et al. (1995, §2 and §5) promise that holes and tunnels fade as the
//! filter widens, and for solid parts they do; but a wall thinner than the filter fades unevenly
//! and perforates first (a hollow printed part goes from genus 0 to 39 in one level). Nothing in
//! the paper prevents that; this module does, per level, on the filtered volume before
//! marching cubes. [`monotone_level`] takes the level's density, the isodensity and what the
//! previous (finer) level became, and returns the density to contour, whose surface has a genus
//! no greater than the previous level's, with a [`TopologyRecord`] of what changed.
//!
//! **How, and why this way.** Two rules, the second only when the first is not enough:
//!
//! 1. *Cavities stay filled.* The samples of a finer level's cavities (outside samples enclosed
//!    by the inside, see [`mod@crate::digital_topology`]), and what a finer level already kept
//!    filled, count as solid from then on: their filtered density (the level's own filter and
//!    radius, summed over the finer level's samples) is added to the level's, as if the object
//!    had been filled before filtering (the filter is linear), and they are kept inside. A
//!    hollow part whose wall gets too thin for the filter therefore closes up and turns solid
//!    from outside, with its outer surface where the filled part's would be, instead of
//!    perforating: what the viewer sees from outside is the wall, and filling what it hid
//!    removes no visible detail (a cavity of a coarser level is dropped at once, which also
//!    saves its triangles). It costs two labelling passes, and a small convolution where there
//!    are cavities.
//! 2. *A guarded threshold.* If the level still has more handles than the previous one (a
//!    perforating sheet, a scan's thin parts), the inside set is grown and shrunk towards the
//!    threshold `value >= iso` one sample at a time, most certain samples first, starting from
//!    the previous level's filled inside set carried onto this grid (a sample is in it when any
//!    finer sample inside its voxel is). A sample is added only when the inside around it is at
//!    most one piece (`T6 <= 1`) and removed only when the outside around it is exactly one
//!    piece (`T̄18 = 1`); by [`mod@crate::digital_topology`]'s local numbers neither can open a
//!    tunnel, so the genus cannot exceed the start's, while handles may still close, pieces
//!    vanish and cavities open. A perforation stays closed by a membrane one sample thick.
//!    When the carried set itself has too many handles (a finer level's thin wall, resampled
//!    onto a coarser grid), it is dilated up to [`MonotoneOptions::max_dilations`] times; and the
//!    guaranteed fallback starts from the whole grid but its border (genus 0), which the guard
//!    carves down to the level with every handle closed.
//!
//! Topology-aware thresholding (rule 2) alone would also fill hollow parts, but rule 1 is what
//! makes them fill everywhere at once rather than wherever the carving reaches last; and
//! thresholding against a finer level's topology, rather than smoothing the density until the
//! handles go, keeps the paper's filter untouched wherever topology does not change. The genus
//! is checked after each stage by [`digital_topology`], which is exactly the genus of the
//! contoured level (tests compare with marching cubes).
//!
//! The samples whose side changes get the value mirrored about `iso` (clamped to the volume's
//! range), so that marching cubes places the surface between them and their neighbours as it
//! would for a real crossing.
//!
//! **Cost.** Rule 1: O(N) for N samples, and nothing beyond the plain threshold's genus check
//! when the finer levels kept nothing filled; the filled density sums weights only where a
//! filter's support straddles the filled set's boundary (a table of counts settles the rest).
//! Rule 2: O(N) for the genus checks plus O(D log D) for the D samples that disagree with the
//! start (a band around the surface; the fallback makes D the whole outside). The plain
//! threshold's genus check and labelling serve every stage that keeps its inside set. The
//! O(N) passes run on all threads; the guarded threshold's queue is sequential (its order
//! decides the result). About 24 bytes per sample at most.

use std::borrow::Cow;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

use rayon::prelude::*;
use serde::Serialize;
use thiserror::Error;
use voxlod_core::grid::FACE_OFFSETS as FACES;
use voxlod_core::{memory, CoreError, Grid, Volume};

use crate::digital_topology::{
    coordinates, digital_topology, inside_samples, local_numbers, step, topology_and_outside,
    DigitalTopology,
};
use crate::run_components::RunComponents;
use crate::{DensityOptions, SamplingError};

/// How [`monotone_level`] keeps the genus from rising.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct MonotoneOptions {
    /// Keep the finer levels' cavities inside (rule 1).
    pub fill_cavities: bool,
    /// Dilations of the carried inside set tried before the fallback (rule 2).
    pub max_dilations: usize,
    /// The density of solid material, given to filled cavities: 1 for solids; for a scan
    /// filtered directly, the value of the material in the data's units.
    pub fill_density: f32,
}

impl Default for MonotoneOptions {
    /// Both rules, up to three dilations.
    fn default() -> Self {
        MonotoneOptions {
            fill_cavities: true,
            max_dilations: 3,
            fill_density: 1.0,
        }
    }
}

impl MonotoneOptions {
    /// For a scan filtered directly: filled cavities get `material`, in the data's units.
    pub fn direct(material: f32) -> Self {
        MonotoneOptions {
            fill_density: material,
            ..Default::default()
        }
    }

    /// The guarded threshold alone: cavities may open where the guard allows it.
    pub fn guard_only() -> Self {
        MonotoneOptions {
            fill_cavities: false,
            ..Default::default()
        }
    }
}

/// Which rule decided the level.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum MonotoneStage {
    /// The plain threshold (the first level, or nothing to fill and no handle gained).
    Unchanged,
    /// Rule 1 alone.
    CavitiesFilled,
    /// Rule 2, starting from the previous level's set.
    Guarded,
    /// Rule 2, starting from the whole grid (every handle closed).
    GuardedFromHull,
}

/// What [`monotone_level`] changed, for the level's report.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct TopologyRecord {
    /// The rule that decided the level.
    pub stage: MonotoneStage,
    /// The plain threshold's topology.
    pub raw: DigitalTopology,
    /// The topology of the returned volume's surface.
    pub result: DigitalTopology,
    /// The previous level's, if any.
    pub previous: Option<DigitalTopology>,
    /// Handles fewer than the previous level.
    pub handles_removed: u64,
    /// Handles the plain threshold had beyond the result (the perforations prevented).
    pub handles_prevented: u64,
    /// Surface components (inside pieces and cavities) gained (> 0) or lost since the previous.
    pub surfaces_gained: i64,
    /// Samples made inside by rule 1.
    pub samples_filled: usize,
    /// Samples below `iso` that rule 2 kept inside.
    pub samples_kept_inside: usize,
    /// Samples at or above `iso` that rule 2 kept outside.
    pub samples_kept_outside: usize,
}

/// What a level became, carried to the next call of [`monotone_level`].
#[derive(Clone, Debug, PartialEq)]
pub struct LevelShape {
    /// The level's grid.
    pub grid: Grid,
    /// The topology of the level's surface.
    pub topology: DigitalTopology,
    /// Inside samples and cavities (the solid seen from outside).
    filled: Vec<bool>,
    /// Samples the next level must keep inside: this level's cavities and what it kept filled.
    kept_filled: Vec<bool>,
}

/// A level with monotone topology.
#[derive(Clone, Debug)]
pub struct MonotoneLevel {
    /// The density to contour (the input's where nothing changed).
    pub volume: Volume,
    /// What changed.
    pub record: TopologyRecord,
    /// Pass it to the next level's call.
    pub shape: LevelShape,
}

/// Why a level's topology could not be kept monotone.
#[derive(Debug, Error)]
pub enum MonotoneError {
    #[error("the isodensity {0} is not a finite number")]
    /// The isodensity is NaN or infinite.
    NonFiniteIso(f32),
    #[error("the level would have genus {genus} after the level above had {previous}, even from a genus-0 start")]
    /// Even the genus-0 fallback kept more handles than the level above (a defect).
    Unresolved {
        /// The level's genus.
        genus: u64,
        /// The level above's.
        previous: u64,
    },
    #[error(transparent)]
    /// Labelling or memory failed.
    Sampling(#[from] SamplingError),
    #[error(transparent)]
    /// A buffer would not fit in memory.
    Core(#[from] CoreError),
}

/// The density of one level, adjusted so that its surface has no more handles than
/// `previous`'s (the level above, finer), and the record of what changed. See the module
/// documentation. Without `previous` the level is returned as it is, with its topology.
pub fn monotone_level(
    volume: &Volume,
    iso: f32,
    filter: &DensityOptions,
    previous: Option<&LevelShape>,
    options: &MonotoneOptions,
) -> Result<MonotoneLevel, MonotoneError> {
    monotone_cow(Cow::Borrowed(volume), iso, filter, previous, options)
}

/// [`monotone_level`] on a borrowed or owned density: an owned one becomes the returned volume
/// without a copy.
fn monotone_cow(
    volume: Cow<Volume>,
    iso: f32,
    filter: &DensityOptions,
    previous: Option<&LevelShape>,
    options: &MonotoneOptions,
) -> Result<MonotoneLevel, MonotoneError> {
    if !iso.is_finite() {
        return Err(MonotoneError::NonFiniteIso(iso));
    }
    let n = volume.grid.len();
    memory::check_allocation(
        "keeping the topology of a level",
        memory::bytes_of::<u64>(3 * n),
    )?;
    let dims = volume.grid.dims;
    let raw = inside_samples(&volume, iso)?;
    let (raw_topology, raw_outside) = topology_and_outside(dims, &raw)?;
    let Some(previous) = previous else {
        let decided = Decided::new(raw.clone(), vec![false; n], MonotoneStage::Unchanged);
        let checked = (raw_topology, raw_outside);
        return finish(volume, iso, None, (&raw, raw_topology), decided, checked);
    };
    // Rule 1 changes nothing when the finer levels kept nothing filled.
    let fills = options.fill_cavities && previous.kept_filled.par_iter().any(|&k| k);
    let (locked, volume) = if fills {
        let locked = carry_nearest(&previous.kept_filled, &previous.grid, &volume.grid);
        let filled = fill_density(volume, previous, filter, options.fill_density)?;
        (locked, Cow::Owned(filled))
    } else {
        (vec![false; n], volume)
    };
    let values = volume.as_slice();
    let filled: Vec<bool> = (values.par_iter().zip(&locked))
        .map(|(&v, &l)| v >= iso || l)
        .collect();
    let settle = |volume: Cow<Volume>, decided, checked| {
        finish(
            volume,
            iso,
            Some(previous),
            (&raw, raw_topology),
            decided,
            checked,
        )
    };
    let checked = if filled == raw {
        (raw_topology, raw_outside)
    } else {
        topology_and_outside(dims, &filled)?
    };
    if checked.0.genus <= previous.topology.genus {
        let stage = if filled == raw {
            MonotoneStage::Unchanged
        } else {
            MonotoneStage::CavitiesFilled
        };
        let decided = Decided::new(filled, locked, stage);
        return settle(volume, decided, checked);
    }
    let (start, stage) = guard_start(&volume, previous, &locked, options)?;
    let guarded = guarded_threshold(&volume, iso, start, &locked)?;
    let checked = topology_and_outside(dims, &guarded)?;
    if checked.0.genus <= previous.topology.genus {
        let decided = Decided::new(guarded, locked, stage);
        return settle(volume, decided, checked);
    }
    let mut genus = checked.0.genus;
    if stage != MonotoneStage::GuardedFromHull {
        let guarded = guarded_threshold(&volume, iso, hull(dims, &locked), &locked)?;
        let checked = topology_and_outside(dims, &guarded)?;
        if checked.0.genus <= previous.topology.genus {
            let decided = Decided::new(guarded, locked, MonotoneStage::GuardedFromHull);
            return settle(volume, decided, checked);
        }
        genus = checked.0.genus;
    }
    Err(MonotoneError::Unresolved {
        genus,
        previous: previous.topology.genus,
    })
}

/// A pyramid's levels made monotone one after another, finest first: [`monotone_level`] with
/// the previous level's shape carried along.
#[derive(Clone, Debug, Default)]
pub struct MonotoneChain {
    /// The rules to apply.
    pub options: MonotoneOptions,
    previous: Option<LevelShape>,
}

impl MonotoneChain {
    /// A chain with no level yet.
    pub fn new(options: MonotoneOptions) -> MonotoneChain {
        MonotoneChain {
            options,
            previous: None,
        }
    }

    /// The next (coarser) level: its density to contour and what changed.
    pub fn next(
        &mut self,
        volume: &Volume,
        iso: f32,
        filter: &DensityOptions,
    ) -> Result<(Volume, TopologyRecord), MonotoneError> {
        self.next_cow(Cow::Borrowed(volume), iso, filter)
    }

    /// [`MonotoneChain::next`] taking the level's density by value: it becomes the returned
    /// volume without a copy (the same values as `next` gives).
    pub fn next_owned(
        &mut self,
        volume: Volume,
        iso: f32,
        filter: &DensityOptions,
    ) -> Result<(Volume, TopologyRecord), MonotoneError> {
        self.next_cow(Cow::Owned(volume), iso, filter)
    }

    fn next_cow(
        &mut self,
        volume: Cow<Volume>,
        iso: f32,
        filter: &DensityOptions,
    ) -> Result<(Volume, TopologyRecord), MonotoneError> {
        let level = monotone_cow(volume, iso, filter, self.previous.as_ref(), &self.options)?;
        self.previous = Some(level.shape);
        Ok((level.volume, level.record))
    }
}

/// The inside set a level settled on, before its volume is adjusted.
struct Decided {
    inside: Vec<bool>,
    locked: Vec<bool>,
    stage: MonotoneStage,
}

impl Decided {
    fn new(inside: Vec<bool>, locked: Vec<bool>, stage: MonotoneStage) -> Decided {
        Decided {
            inside,
            locked,
            stage,
        }
    }
}

/// The guard's start: the previous level's filled set carried over (dilated as needed), or the
/// whole grid but its border.
fn guard_start(
    volume: &Volume,
    previous: &LevelShape,
    locked: &[bool],
    options: &MonotoneOptions,
) -> Result<(Vec<bool>, MonotoneStage), MonotoneError> {
    let dims = volume.grid.dims;
    let carried = carry_covering(&previous.filled, &previous.grid, &volume.grid);
    let mut start: Vec<bool> = carried.iter().zip(locked).map(|(&c, &l)| c || l).collect();
    for attempt in 0..=options.max_dilations {
        if digital_topology(dims, &start)?.genus <= previous.topology.genus {
            return Ok((start, MonotoneStage::Guarded));
        }
        if attempt < options.max_dilations {
            start = dilate(dims, &start);
        }
    }
    Ok((hull(dims, locked), MonotoneStage::GuardedFromHull))
}

/// Adjusts `volume` (the level's density, with filled cavities) to `decided.inside`, whose
/// topology and labelled outside are `checked`, and records what changed since the plain
/// threshold `raw` (of topology `raw_topology`).
fn finish(
    volume: Cow<Volume>,
    iso: f32,
    previous: Option<&LevelShape>,
    (raw, raw_topology): (&[bool], DigitalTopology),
    decided: Decided,
    (result, outside): (DigitalTopology, RunComponents),
) -> Result<MonotoneLevel, MonotoneError> {
    let mut adjusted = volume.into_owned();
    // The first level keeps its plain threshold (`decided.inside` is `raw`, nothing locked):
    // no value changes and nothing is counted, so the pass is skipped.
    let counts = match previous {
        Some(_) => adjust(&mut adjusted, iso, raw, &decided),
        None => [0; 3],
    };
    let record = TopologyRecord {
        stage: decided.stage,
        raw: raw_topology,
        result,
        previous: previous.map(|p| p.topology),
        handles_removed: previous.map_or(0, |p| p.topology.genus.saturating_sub(result.genus)),
        handles_prevented: raw_topology.genus.saturating_sub(result.genus),
        surfaces_gained: previous.map_or(0, |p| {
            result.surfaces() as i64 - p.topology.surfaces() as i64
        }),
        samples_filled: counts[0],
        samples_kept_inside: counts[1],
        samples_kept_outside: counts[2],
    };
    let cavities = outside.enclosed();
    let filled = (decided.inside.par_iter().zip(&cavities)).map(|(&a, &c)| a || c);
    let kept = (decided.locked.par_iter().zip(&cavities)).map(|(&a, &c)| a || c);
    let shape = LevelShape {
        grid: adjusted.grid,
        topology: result,
        filled: filled.collect(),
        kept_filled: kept.collect(),
    };
    Ok(MonotoneLevel {
        volume: adjusted,
        record,
        shape,
    })
}

/// Mirrors about `iso` the values of `volume` whose side `decided.inside` changed, and counts
/// the samples filled, kept inside and kept outside since the plain threshold `raw`.
fn adjust(volume: &mut Volume, iso: f32, raw: &[bool], decided: &Decided) -> [usize; 3] {
    let (low, high) = volume.range().unwrap_or((iso, iso));
    volume
        .as_slice_mut()
        .par_iter_mut()
        .enumerate()
        .map(|(i, value)| {
            let (now, above) = (decided.inside[i], *value >= iso);
            let filled = now && !raw[i] && (above || decided.locked[i]);
            let (mut kept_inside, mut kept_outside) = (false, false);
            if now && !above {
                kept_inside = !decided.locked[i];
                *value = mirrored_inside(*value, iso, high);
            } else if !now && above {
                kept_outside = true;
                *value = mirrored_outside(*value, iso, low);
            }
            [filled as usize, kept_inside as usize, kept_outside as usize]
        })
        .reduce(|| [0; 3], |a, b| [a[0] + b[0], a[1] + b[1], a[2] + b[2]])
}

/// A value below `iso` (or NaN) mirrored to inside, within the volume's range.
fn mirrored_inside(value: f32, iso: f32, high: f32) -> f32 {
    if !value.is_finite() {
        return iso;
    }
    iso + (iso - value).min(high - iso).max(0.0)
}

/// A value at or above `iso` mirrored to strictly below it, within the volume's range.
fn mirrored_outside(value: f32, iso: f32, low: f32) -> f32 {
    let mirrored = iso - (value - iso).min(iso - low);
    if mirrored < iso {
        mirrored
    } else {
        iso.next_down()
    }
}

/// The level's density plus the filtered density of what `previous` kept filled (its cavities
/// and what it kept filled itself), each finer sample standing for its voxel of solid of
/// density `material`; weights normalised over the finer samples within the support. A sample
/// whose support holds no kept sample is left as it is and one whose support holds only kept
/// samples gains `material` (the normalised weights sum to exactly 1 there), both known from a
/// table of counts; only the supports across the kept set's boundary are summed.
fn fill_density(
    volume: Cow<Volume>,
    previous: &LevelShape,
    filter: &DensityOptions,
    material: f32,
) -> Result<Volume, MonotoneError> {
    let grid = volume.grid;
    let mut out = volume.into_owned();
    let from = &previous.grid;
    let Some((lo, hi)) = set_box(&previous.kept_filled, from) else {
        return Ok(out);
    };
    let counts = BoxCounts::new(&previous.kept_filled, from.dims, lo, hi)?;
    let radius = filter.radius;
    let reach = |c: f64, a: usize| -> (usize, usize) {
        let r = radius / from.spacing[a];
        let lo = (c - r).ceil().max(lo[a] as f64);
        let hi = (c + r).floor().min(hi[a] as f64);
        (lo.max(0.0) as usize, hi.max(-1.0) as isize as usize)
    };
    out.as_slice_mut()
        .par_iter_mut()
        .enumerate()
        .for_each(|(i, value)| {
            let f = coordinates_in(&grid, i, from);
            let ranges = [reach(f[0], 0), reach(f[1], 1), reach(f[2], 2)];
            if ranges.iter().any(|&(a, b)| a > b || b == usize::MAX) {
                return;
            }
            let kept = counts.count(ranges);
            if kept == 0 {
                return;
            }
            let weights = |k: usize, j: usize, i: usize| {
                let d =
                    from.position(i as f64, j as f64, k as f64) - from.position(f[0], f[1], f[2]);
                filter.filter.weight(d.length(), radius)
            };
            let all = ranges
                .iter()
                .map(|&(a, b)| (b - a + 1) as u64)
                .product::<u64>();
            let (mut filled, mut total) = (0.0f64, 0.0f64);
            for k in ranges[2].0..=ranges[2].1 {
                for j in ranges[1].0..=ranges[1].1 {
                    for i in ranges[0].0..=ranges[0].1 {
                        let w = weights(k, j, i);
                        if kept == all && w > 0.0 {
                            // filled and total would add the same weights in the same order.
                            *value += material;
                            return;
                        }
                        total += w;
                        if previous.kept_filled[from.index(i, j, k)] {
                            filled += w;
                        }
                    }
                }
            }
            if filled > 0.0 {
                *value += (filled / total) as f32 * material;
            }
        });
    Ok(out)
}

/// Counts of a set's samples in index boxes, from a table of prefix sums over the set's box.
struct BoxCounts {
    lo: [usize; 3],
    size: [usize; 3],
    /// `prefix[(i + 1) + (size0 + 1) ((j + 1) + (size1 + 1) (k + 1))]`: samples in the box
    /// from `lo` to `lo + (i, j, k)`.
    prefix: Vec<u32>,
}

impl BoxCounts {
    fn new(
        set: &[bool],
        dims: [usize; 3],
        lo: [usize; 3],
        hi: [usize; 3],
    ) -> Result<BoxCounts, MonotoneError> {
        let size = [0, 1, 2].map(|a| hi[a] - lo[a] + 1);
        let (sx, sy) = (size[0] + 1, size[1] + 1);
        let slice = sx * sy;
        memory::check_allocation(
            "the filled samples' counts",
            memory::bytes_of::<u32>(slice * (size[2] + 1)),
        )?;
        let mut prefix = vec![0u32; slice * (size[2] + 1)];
        // Each z slice's 2D prefix sums in parallel, then the slices accumulated along z.
        prefix[slice..]
            .par_chunks_mut(slice)
            .enumerate()
            .for_each(|(k, plane)| {
                for j in 0..size[1] {
                    let mut row = 0u32;
                    for i in 0..size[0] {
                        let at = lo[0] + i + dims[0] * (lo[1] + j + dims[1] * (lo[2] + k));
                        row += set[at] as u32;
                        plane[(i + 1) + sx * (j + 1)] = plane[(i + 1) + sx * j] + row;
                    }
                }
            });
        for k in 1..=size[2] {
            let (below, above) = prefix.split_at_mut(k * slice);
            let below = &below[(k - 1) * slice..];
            (above[..slice].par_iter_mut().zip(below)).for_each(|(a, &b)| *a += b);
        }
        Ok(BoxCounts { lo, size, prefix })
    }

    /// Samples of the set in the index box `ranges` (inclusive, within the set's box).
    fn count(&self, ranges: [(usize, usize); 3]) -> u64 {
        let (sx, sy) = (self.size[0] + 1, self.size[1] + 1);
        let at = |i: usize, j: usize, k: usize| self.prefix[i + sx * (j + sy * k)] as i64;
        let [(i0, i1), (j0, j1), (k0, k1)] =
            [0, 1, 2].map(|a| (ranges[a].0 - self.lo[a], ranges[a].1 - self.lo[a] + 1));
        let sum = at(i1, j1, k1) - at(i0, j1, k1) - at(i1, j0, k1) - at(i1, j1, k0)
            + at(i0, j0, k1)
            + at(i0, j1, k0)
            + at(i1, j0, k0)
            - at(i0, j0, k0);
        sum as u64
    }
}

/// The index box of the samples in `set`, or `None` when it is empty. Row by row along x on
/// all threads: a row's first and last set samples bound x, and a row with any gives its y and
/// z (one pass over the flags, no per-sample index arithmetic).
fn set_box(set: &[bool], grid: &Grid) -> Option<([usize; 3], [usize; 3])> {
    let dims = grid.dims;
    let widen = |a: ([usize; 3], [usize; 3]), b: ([usize; 3], [usize; 3])| {
        (
            [0, 1, 2].map(|k| a.0[k].min(b.0[k])),
            [0, 1, 2].map(|k| a.1[k].max(b.1[k])),
        )
    };
    let (lo, hi) = (set.par_chunks(dims[0]).enumerate())
        .filter_map(|(r, row)| {
            let first = row.iter().position(|&s| s)?;
            let last = row.iter().rposition(|&s| s)?;
            let (y, z) = (r % dims[1], r / dims[1]);
            Some(([first, y, z], [last, y, z]))
        })
        .reduce(|| ([usize::MAX; 3], [0; 3]), widen);
    (lo[0] != usize::MAX).then_some((lo, hi))
}

/// World position of sample `index` of `grid` as fractional sample coordinates of `other`.
fn coordinates_in(grid: &Grid, index: usize, other: &Grid) -> [f64; 3] {
    let p = coordinates(grid.dims, index);
    let world = grid.position(p[0] as f64, p[1] as f64, p[2] as f64);
    let o = other.origin_vec();
    let s = other.spacing_vec();
    let f = (world - o) / s;
    [f.x, f.y, f.z]
}

/// `set` (on `from`) read at the nearest sample to every sample of `to`; outside `from` is out.
fn carry_nearest(set: &[bool], from: &Grid, to: &Grid) -> Vec<bool> {
    (0..to.len())
        .into_par_iter()
        .map(|i| {
            let f = coordinates_in(to, i, from);
            let mut q = [0usize; 3];
            for a in 0..3 {
                let r = f[a].round();
                if !(r >= 0.0 && r < from.dims[a] as f64) {
                    return false;
                }
                q[a] = r as usize;
            }
            set[from.index(q[0], q[1], q[2])]
        })
        .collect()
}

/// `set` (on `from`) carried to `to`: a sample is in when any sample of `from` within its voxel
/// (half a spacing of `to` either way) is, or else its nearest is.
fn carry_covering(set: &[bool], from: &Grid, to: &Grid) -> Vec<bool> {
    let nearest = carry_nearest(set, from, to);
    (0..to.len())
        .into_par_iter()
        .map(|i| {
            let f = coordinates_in(to, i, from);
            let mut range = [(0usize, 0usize); 3];
            for a in 0..3 {
                let half = 0.5 * to.spacing[a] / from.spacing[a];
                let lo = (f[a] - half).ceil().max(0.0);
                let hi = (f[a] + half).floor().min(from.dims[a] as f64 - 1.0);
                if lo > hi {
                    return nearest[i];
                }
                range[a] = (lo as usize, hi as usize);
            }
            (range[2].0..=range[2].1).any(|k| {
                (range[1].0..=range[1].1)
                    .any(|j| (range[0].0..=range[0].1).any(|i| set[from.index(i, j, k)]))
            })
        })
        .collect()
}

/// One step of dilation through the face neighbours.
fn dilate(dims: [usize; 3], set: &[bool]) -> Vec<bool> {
    (0..set.len())
        .into_par_iter()
        .map(|i| {
            set[i] || {
                let p = coordinates(dims, i);
                FACES
                    .iter()
                    .any(|&o| step(dims, p, o).is_some_and(|q| set[q]))
            }
        })
        .collect()
}

/// Every sample but the grid's border, and the locked ones: a genus-0 start.
fn hull(dims: [usize; 3], locked: &[bool]) -> Vec<bool> {
    (0..locked.len())
        .into_par_iter()
        .map(|i| {
            let p = coordinates(dims, i);
            locked[i] || (0..3).all(|a| p[a] > 0 && p[a] + 1 < dims[a])
        })
        .collect()
}

/// From `start`, moves the inside set towards `value >= iso` (and `locked`, always inside) one
/// sample at a time, the farthest from `iso` first, never opening a tunnel: a sample is added
/// only when `T6 <= 1` and removed only when `T̄18 = 1`. The result has no more handles than
/// `start`. Cost: O(D log D) for the D samples that disagree along the way.
pub fn guarded_threshold(
    volume: &Volume,
    iso: f32,
    start: Vec<bool>,
    locked: &[bool],
) -> Result<Vec<bool>, MonotoneError> {
    let dims = volume.grid.dims;
    let values = volume.as_slice();
    let wants = |i: usize| locked[i] || values[i] >= iso;
    // Positive floats order like their bits; NaN is the least certain.
    let certainty = |i: usize| -> u32 {
        let d = (values[i] - iso).abs();
        if locked[i] {
            u32::MAX
        } else if d.is_nan() {
            0
        } else {
            d.to_bits()
        }
    };
    let mut inside = start;
    // Keys are distinct (the index breaks ties), so the order of pops is the same however the
    // heap is built.
    let disagreeing: Vec<(u32, Reverse<usize>)> = (0..inside.len())
        .into_par_iter()
        .filter(|&i| inside[i] != wants(i))
        .map(|i| (certainty(i), Reverse(i)))
        .collect();
    let mut heap = BinaryHeap::from(disagreeing);
    memory::check_allocation(
        "the guarded threshold's queue",
        memory::bytes_of::<(u32, usize)>(heap.len() * 4),
    )?;
    while let Some((_, Reverse(i))) = heap.pop() {
        let want = wants(i);
        if inside[i] == want {
            continue;
        }
        let local = local_numbers(dims, &inside, i);
        let allowed = if want {
            local.inside <= 1
        } else {
            local.outside == 1
        };
        if !allowed {
            continue;
        }
        inside[i] = want;
        let p = coordinates(dims, i);
        for o in NEIGHBOURS_26 {
            if let Some(q) = step(dims, p, o) {
                if inside[q] != wants(q) {
                    heap.push((certainty(q), Reverse(q)));
                }
            }
        }
    }
    Ok(inside)
}

const NEIGHBOURS_26: [[i64; 3]; 26] = {
    let mut out = [[0i64; 3]; 26];
    let mut n = 0;
    let mut c = 0;
    while c < 27 {
        if c != 13 {
            out[n] = [c % 3 - 1, (c / 3) % 3 - 1, c / 9 - 1];
            n += 1;
        }
        c += 1;
    }
    out
};

#[cfg(test)]
mod tests {
    use super::*;

    /// The box of every set sample, sample by sample: the reference for [`set_box`].
    fn set_box_per_sample(set: &[bool], dims: [usize; 3]) -> Option<([usize; 3], [usize; 3])> {
        let mut found: Option<([usize; 3], [usize; 3])> = None;
        for (i, _) in set.iter().enumerate().filter(|(_, &s)| s) {
            let p = coordinates(dims, i);
            let (lo, hi) = found.get_or_insert((p, p));
            *lo = [0, 1, 2].map(|k| lo[k].min(p[k]));
            *hi = [0, 1, 2].map(|k| hi[k].max(p[k]));
        }
        found
    }

    #[test]
    fn the_set_box_by_rows_is_the_box_of_every_sample() {
        let dims = [7, 5, 6];
        let grid = Grid::new(dims, [1.0, 0.5, 2.0], [0.0; 3]).unwrap();
        let n = dims.iter().product::<usize>();
        assert_eq!(set_box(&vec![false; n], &grid), None);
        let mut seed = 12345u64;
        for round in 0..200 {
            let mut set = vec![false; n];
            // From one sample (an edge or a corner of the grid) to a scattered tenth of them.
            for _ in 0..=(round % 9) * (round % 4) {
                seed = seed
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                set[(seed >> 33) as usize % n] = true;
            }
            set[[0, n - 1, dims[0] - 1, n - dims[0]][round % 4]] |= round % 3 == 0;
            assert_eq!(
                set_box(&set, &grid),
                set_box_per_sample(&set, dims),
                "{round}"
            );
            assert!(set_box(&set, &grid).is_some());
        }
    }
}
