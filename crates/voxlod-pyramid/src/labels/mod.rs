//! Label maps (segmentations) to meshes: one closed, outward mesh per structure, each with its
//! own chain of levels of detail.
//!
//! A label map holds an integer per voxel (0 is background). Each label `L` becomes a solid
//! through its inside function, the indicator `[value == L]` thresholded at ½ by trilinear
//! interpolation (paper §4, the thresholding route, applied to the indicator); that solid is
//! filtered and contoured by the same pyramid as any thresholded scan ([`crate::lod`], paper
//! §2), so `levels`, the filter and the radius mean what they mean for `voxlod lod`. The
//! indicator is cut to the label's bounding box plus one voxel, so a small structure in a large
//! map costs what its box costs; level 0 samples at the map's finest spacing. Meshes are moved
//! into the map's world (direction cosines and frame, `voxlod_core::world`). [`labels()`] is the
//! one call: the labels found, chosen, meshed and checked, every failure a `PyramidError`; the
//! steps it takes are public for callers that mesh a map piece by piece.
//!
//! Beyond the paper: the paper treats one object per volume; the per-label split and the
//! label table are ours. Cost: one pass over the map to find the labels and their boxes, then
//! per label one copy of its box and the pyramid's cost for that box; [`mesh_labels`] meshes
//! the labels in parallel, largest box first, with the boxes in flight kept within the memory
//! budget.

use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;
use serde::Serialize;
use voxlod_core::glam::DVec3;
use voxlod_core::{memory, Frame, Grid, Placement, TriangleMesh, Volume};
use voxlod_sampling::density::estimated_bytes;
use voxlod_sampling::pyramid::plan_levels_with;
use voxlod_sampling::{PyramidOptions, SamplingError, ThresholdSolid};

use voxlod_core::mesh_topology;
use voxlod_envelope::EnvelopeError;

use crate::lod::{build_level, plan, LevelOptions, LodError, LodLevel, LodSource};
use crate::progress::Control;
use crate::then_envelope::{simplify_level, ThenEnvelope};

mod job;
mod source;

pub use job::{labels, LabelLevels, LabelMeshes};
pub use source::LabelSource;

/// How label meshes are made.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LabelOptions {
    /// The pyramid (levels, filter, radius); its `resolutions` are replaced per label by
    /// halving from the map's own resolution over the label's box: only their count is used.
    pub lod: LevelOptions,
    /// Only these label values (all non-zero labels when `None`).
    pub labels: Option<Vec<i64>>,
    /// The frame of the meshes: the map's own when `None`.
    pub frame: Option<Frame>,
    /// Then simplify each level by simplification envelopes, as `LodOptions::then_envelope`.
    pub then_envelope: Option<ThenEnvelope>,
}

impl Default for LabelOptions {
    /// One level at the map's resolution, hyper-cone of one voxel, isodensity ½.
    fn default() -> Self {
        let mut lod = LevelOptions::default();
        lod.pyramid.resolutions.truncate(1);
        LabelOptions {
            lod,
            labels: None,
            frame: None,
            then_envelope: None,
        }
    }
}

impl LabelOptions {
    /// `levels` levels, each at half the resolution of the one before.
    pub fn for_levels(levels: usize) -> Self {
        let mut options = LabelOptions::default();
        options.lod.pyramid.resolutions = vec![0; levels.max(1)];
        options
    }
}

/// One label of a map: its value, how many voxels carry it, and their index box.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct LabelInfo {
    /// The label value.
    pub value: i64,
    /// How many voxels carry it.
    pub voxels: usize,
    /// Smallest index along x, y, z.
    pub min: [usize; 3],
    /// Largest index along x, y, z.
    pub max: [usize; 3],
}

/// Why a label map cannot be meshed.
#[derive(Debug, thiserror::Error)]
pub enum LabelError {
    /// A sample is not an integer.
    #[error("sample ({0}, {1}, {2}) holds {3}, which is not an integer label")]
    NotALabel(usize, usize, usize, f32),
    /// A label asked for is not in the map.
    #[error("the map has no label {0} (it holds {1})")]
    Missing(i64, String),
    /// Only background.
    #[error("the map holds no label other than 0")]
    NoLabels,
    /// Filtering or contouring failed.
    #[error(transparent)]
    Lod(#[from] LodError),
    /// The indicator or its solid could not be made.
    #[error(transparent)]
    Sampling(#[from] SamplingError),
    /// The envelope step failed.
    #[error("`then_envelope`: {0}")]
    Envelope(#[from] EnvelopeError),
}

/// The non-zero labels of a map, in increasing order, with their voxel counts and boxes.
pub fn find_labels<M: LabelSource>(map: &M) -> Result<Vec<LabelInfo>, LabelError> {
    let mut found: std::collections::BTreeMap<i64, LabelInfo> = Default::default();
    let [nx, ny, nz] = map.grid().dims;
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let v = map.label(i, j, k)?;
                if v == 0 {
                    continue;
                }
                let at = [i, j, k];
                let info = found.entry(v).or_insert(LabelInfo {
                    value: v,
                    voxels: 0,
                    min: at,
                    max: at,
                });
                info.voxels += 1;
                for (a, &index) in at.iter().enumerate() {
                    info.min[a] = info.min[a].min(index);
                    info.max[a] = info.max[a].max(index);
                }
            }
        }
    }
    Ok(found.into_values().collect())
}

/// The labels to mesh: all, or the ones asked for (each must exist).
pub fn select_labels(
    all: Vec<LabelInfo>,
    wanted: Option<&[i64]>,
) -> Result<Vec<LabelInfo>, LabelError> {
    if all.is_empty() {
        return Err(LabelError::NoLabels);
    }
    let Some(wanted) = wanted else {
        return Ok(all);
    };
    let present = || {
        all.iter()
            .map(|l| l.value.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    };
    wanted
        .iter()
        .map(|w| {
            all.iter()
                .find(|l| l.value == *w)
                .cloned()
                .ok_or_else(|| LabelError::Missing(*w, present()))
        })
        .collect()
}

/// The index range and grid of `label`'s box grown by one voxel (clamped to the map), its first
/// sample placed in the map's world.
fn label_box<M: LabelSource>(
    map: &M,
    label: &LabelInfo,
) -> Result<([usize; 3], [usize; 3], Grid), LabelError> {
    let g = map.grid();
    let lo: [usize; 3] = std::array::from_fn(|a| label.min[a].saturating_sub(1));
    let hi: [usize; 3] = std::array::from_fn(|a| (label.max[a] + 1).min(g.dims[a] - 1));
    let dims: [usize; 3] = std::array::from_fn(|a| hi[a] - lo[a] + 1);
    // The box's first sample, in the world: the cut keeps the map's direction, so its own grid
    // space starts there (see `voxlod_core::world`).
    let origin = map
        .world()
        .index_to_world(DVec3::new(lo[0] as f64, lo[1] as f64, lo[2] as f64));
    let grid = Grid::new(dims, g.spacing, origin.to_array()).map_err(SamplingError::from)?;
    Ok((lo, hi, grid))
}

/// The indicator of `label` (1 inside, 0 outside) over its box grown by one voxel (clamped to
/// the map), placed in the map's world.
pub fn label_indicator<M: LabelSource>(map: &M, label: &LabelInfo) -> Result<Volume, LabelError> {
    let (lo, hi, grid) = label_box(map, label)?;
    memory::check_allocation("the label's indicator", memory::bytes_of::<f32>(grid.len()))
        .map_err(SamplingError::from)?;
    let mut values = Vec::with_capacity(grid.len());
    for k in lo[2]..=hi[2] {
        for j in lo[1]..=hi[1] {
            values.extend((lo[0]..=hi[0]).map(|i| f32::from(map.holds(i, j, k, label.value))));
        }
    }
    let indicator = Volume::from_vec(grid, values).map_err(SamplingError::from)?;
    Ok(indicator.oriented(map.orientation()))
}

/// The pyramid of one label: level 0 at the map's finest spacing over the indicator's box, each
/// further level at half the resolution; `levels` comes from `options`.
fn label_pyramid(g: &Grid, options: &LabelOptions) -> PyramidOptions {
    let finest = g.spacing.iter().cloned().fold(f64::INFINITY, f64::min);
    let longest = g.bounds().longest_extent();
    let native = ((longest / finest).round() as usize).max(2);
    let levels = options.lod.pyramid.resolutions.len().max(1);
    let mut pyramid = options.lod.pyramid.clone();
    pyramid.resolutions = (0..levels).map(|k| (native >> k).max(2)).collect();
    pyramid
}

/// One label's meshes, level by level, in the map's world.
pub fn label_levels<M: LabelSource>(
    map: &M,
    label: &LabelInfo,
    options: &LabelOptions,
) -> Result<Vec<LodLevel>, LabelError> {
    let indicator = label_indicator(map, label)?;
    let solid = ThresholdSolid::new(&indicator, 0.5)?;
    let source = LodSource::Solid(&solid);
    let lod = LevelOptions {
        pyramid: label_pyramid(&indicator.grid, options),
        ..options.lod.clone()
    };
    // The pipeline places each level in the map's world (the indicator keeps its transform);
    // only a change of frame is left to do.
    let to_frame = options.frame.map_or(Placement::IDENTITY, |target| {
        Placement::between_frames(map.orientation().frame, target)
    });
    plan(&source, &lod)?
        .iter()
        .map(|p| {
            let mut level = build_level(&source, p, &lod)?;
            to_frame.apply(&mut level.mesh);
            if let Some(step) = &options.then_envelope {
                let (mesh, report) = simplify_level(&level.mesh, step, p.voxel_size)?;
                level.mesh = mesh;
                level.envelope = report;
                level.topology = mesh_topology(&level.mesh);
            }
            Ok(level)
        })
        .collect()
}

/// Bytes one label needs at its peak, estimated before any is allocated: its indicator box and
/// the densest of its levels' sampling ([`voxlod_sampling::density::estimated_bytes`]), or
/// `u64::MAX` when its levels cannot even be planned (it then fails on its own, with the reason).
pub fn label_estimated_bytes<M: LabelSource>(
    map: &M,
    label: &LabelInfo,
    options: &LabelOptions,
) -> u64 {
    let Ok((_, _, grid)) = label_box(map, label) else {
        return u64::MAX;
    };
    let pyramid = label_pyramid(&grid, options);
    let dense = |grid: &Grid, q: usize| estimated_bytes(grid, q).into();
    let Ok(plans) = plan_levels_with(&grid.bounds(), &pyramid, &dense) else {
        return u64::MAX;
    };
    let sampling = plans
        .iter()
        .map(|p| {
            let q = p.density_options(&pyramid).lines_per_voxel(p.voxel_size);
            estimated_bytes(&p.grid, q)
        })
        .max()
        .unwrap_or(0);
    memory::bytes_of::<f32>(grid.len()).saturating_add(sampling)
}

/// Labels in groups whose estimated bytes together fit in `budget`, each group's largest
/// first; the groups in decreasing size. A label larger than the budget is a group of its own
/// (its sampling then refuses it with the figures).
fn groups_within(mut sized: Vec<(usize, u64)>, budget: u64) -> Vec<Vec<usize>> {
    sized.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
    let mut groups: Vec<Vec<usize>> = Vec::new();
    let mut used = 0u64;
    for (index, bytes) in sized {
        if groups.is_empty() || used.saturating_add(bytes) > budget {
            groups.push(Vec::new());
            used = 0;
        }
        used = used.saturating_add(bytes);
        groups.last_mut().expect("a group was pushed").push(index);
    }
    groups
}

/// Every label's levels ([`label_levels`]), the labels meshed in parallel (rayon), largest box
/// first, in groups whose estimated peak memory ([`label_estimated_bytes`]) fits in the memory
/// budget together (`voxlod_core::memory`), so the boxes in flight never exceed it. Returns one
/// result per label, in the order of `labels`; `done` is called as each label finishes (from
/// any thread). Beyond the paper; each label's meshes are the same as [`label_levels`] gives.
pub fn mesh_labels<M: LabelSource>(
    map: &M,
    labels: &[LabelInfo],
    options: &LabelOptions,
    done: &(dyn Fn(&LabelInfo) + Sync),
) -> Result<Vec<Meshed>, LabelError> {
    let meshed = mesh_labels_until(map, labels, options, &|label| {
        done(label);
        Control::Continue
    })?;
    Ok(meshed
        .into_iter()
        .map(|r| r.expect("a label is left out only after a stop"))
        .collect())
}

/// One label's levels, or why it could not be meshed.
type Meshed = Result<Vec<LodLevel>, LabelError>;

/// [`mesh_labels`], where `done` may answer [`Control::Stop`]: the labels not yet started are
/// then left out (`None`); those in flight finish.
fn mesh_labels_until<M: LabelSource>(
    map: &M,
    labels: &[LabelInfo],
    options: &LabelOptions,
    done: &(dyn Fn(&LabelInfo) -> Control + Sync),
) -> Result<Vec<Option<Meshed>>, LabelError> {
    let budget = memory::available_bytes().map_err(SamplingError::from)?;
    let sized = labels
        .iter()
        .enumerate()
        .map(|(n, l)| (n, label_estimated_bytes(map, l, options)))
        .collect();
    let stopped = AtomicBool::new(false);
    let mut results: Vec<Option<Meshed>> = labels.iter().map(|_| None).collect();
    for group in groups_within(sized, budget) {
        let meshed: Vec<(usize, Option<Meshed>)> = group
            .into_par_iter()
            .with_max_len(1)
            .map(|n| {
                if stopped.load(Ordering::Relaxed) {
                    return (n, None);
                }
                let levels = label_levels(map, &labels[n], options);
                if done(&labels[n]) == Control::Stop {
                    stopped.store(true, Ordering::Relaxed);
                }
                (n, Some(levels))
            })
            .collect();
        for (n, levels) in meshed {
            results[n] = levels;
        }
        if stopped.load(Ordering::Relaxed) {
            break;
        }
    }
    Ok(results)
}

/// Volume of `voxels` voxels of the map, in world units cubed.
pub fn voxel_volume<M: LabelSource>(map: &M, voxels: usize) -> f64 {
    voxels as f64 * map.grid().spacing.iter().product::<f64>()
}

/// Every mesh in one, with a per-vertex `label` attribute (for one `.vtp` or `.ply` of all
/// structures).
pub fn merge_labelled(meshes: &[(i64, &TriangleMesh)]) -> voxlod_core::PolyMesh {
    let mut all = TriangleMesh::default();
    let mut labels = Vec::new();
    for (value, mesh) in meshes {
        let base = all.positions.len() as u32;
        all.positions.extend_from_slice(&mesh.positions);
        if mesh.normals.len() == mesh.positions.len() {
            all.normals.extend_from_slice(&mesh.normals);
        }
        all.triangles
            .extend(mesh.triangles.iter().map(|t| t.map(|v| v + base)));
        labels.extend(std::iter::repeat_n(*value as f32, mesh.positions.len()));
    }
    if all.normals.len() != all.positions.len() {
        all.normals.clear();
    }
    voxlod_core::PolyMesh {
        mesh: all,
        vertex_attributes: vec![voxlod_core::Attribute {
            name: "label".into(),
            values: labels,
        }],
        ..Default::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn groups_fill_the_budget_largest_first_and_a_label_over_it_goes_alone() {
        // Sizes by index: 0 → 5, 1 → 40, 2 → 30, 3 → 20, 4 → 100 (over the budget of 60).
        let sized = vec![(0, 5), (1, 40), (2, 30), (3, 20), (4, 100)];
        assert_eq!(
            groups_within(sized, 60),
            vec![vec![4], vec![1], vec![2, 3, 0]]
        );
        assert_eq!(groups_within(Vec::new(), 60), Vec::<Vec<usize>>::new());
        // Equal sizes keep the labels' order.
        assert_eq!(
            groups_within(vec![(0, 10), (1, 10), (2, 10)], 1000),
            vec![vec![0, 1, 2]]
        );
    }

    /// A 24 × 20 × 18 map: label 5 a ball, label 2 a box touching it, label 9 one voxel.
    fn three_label_map() -> Volume {
        let grid = Grid::new([24, 20, 18], [1.0, 1.0, 1.5], [3.0, -2.0, 1.0]).unwrap();
        let mut values = vec![0.0f32; grid.len()];
        for k in 0..18 {
            for j in 0..20 {
                for i in 0..24 {
                    let d = DVec3::new(i as f64 - 8.0, j as f64 - 9.0, 1.5 * (k as f64 - 8.0));
                    values[grid.index(i, j, k)] = if d.length() <= 6.0 {
                        5.0
                    } else if (14..=20).contains(&i)
                        && (4..=15).contains(&j)
                        && (3..=12).contains(&k)
                    {
                        2.0
                    } else if (i, j, k) == (21, 17, 15) {
                        9.0
                    } else {
                        0.0
                    };
                }
            }
        }
        Volume::from_vec(grid, values).unwrap()
    }

    #[test]
    fn labels_meshed_in_parallel_are_the_ones_meshed_one_by_one_in_the_given_order() {
        let map = three_label_map();
        let mut labels = find_labels(&map).unwrap();
        assert_eq!(
            labels.iter().map(|l| l.value).collect::<Vec<_>>(),
            vec![2, 5, 9]
        );
        labels.reverse(); // any order the caller gives is kept
        let options = LabelOptions::for_levels(2);
        let finished = std::sync::Mutex::new(Vec::new());
        let meshed = mesh_labels(&map, &labels, &options, &|l| {
            finished.lock().unwrap().push(l.value)
        })
        .unwrap();
        assert_eq!(meshed.len(), 3);
        let mut finished = finished.into_inner().unwrap();
        finished.sort();
        assert_eq!(finished, vec![2, 5, 9]);
        for (label, levels) in labels.iter().zip(meshed) {
            let levels = levels.unwrap();
            let alone = label_levels(&map, label, &options).unwrap();
            assert_eq!(levels.len(), 2);
            // The one voxel of label 9 may filter away; the other two are surfaces.
            assert!(label.value == 9 || !levels[0].mesh.is_empty());
            for (a, b) in levels.iter().zip(&alone) {
                assert_eq!(a.mesh.positions, b.mesh.positions, "label {}", label.value);
                assert_eq!(a.mesh.triangles, b.mesh.triangles, "label {}", label.value);
            }
        }
    }

    #[test]
    fn the_estimate_grows_with_the_box_and_covers_the_indicator() {
        let map = three_label_map();
        let labels = find_labels(&map).unwrap();
        let options = LabelOptions::default();
        let bytes: Vec<u64> = labels
            .iter()
            .map(|l| label_estimated_bytes(&map, l, &options))
            .collect();
        // Label 5's box (13 × 13 × 9 voxels, grown by one) is the largest, label 9's the least.
        assert!(bytes[1] > bytes[0] && bytes[0] > bytes[2], "{bytes:?}");
        for (label, &b) in labels.iter().zip(&bytes) {
            let indicator = label_indicator(&map, label).unwrap();
            assert!(b > memory::bytes_of::<f32>(indicator.grid.len()), "{b}");
        }
    }

    #[test]
    fn a_label_map_of_u32_gives_the_samples_meshes_and_holds_labels_beyond_two_to_the_24() {
        let samples = three_label_map();
        // The same map with label 5 as 2³² − 1, which no f32 sample holds exactly.
        let big = u32::MAX;
        let values = (samples.as_slice().iter())
            .map(|&v| if v == 5.0 { big } else { v as u32 })
            .collect();
        let labels = voxlod_core::LabelVolume::from_vec(samples.grid, values).unwrap();
        let found = find_labels(&labels).unwrap();
        let values: Vec<i64> = found.iter().map(|l| l.value).collect();
        assert_eq!(values, [2, 9, i64::from(big)]);
        let of_samples = find_labels(&samples).unwrap(); // 2, 5, 9
        assert_eq!(
            (found[2].voxels, found[2].min, found[2].max),
            (of_samples[1].voxels, of_samples[1].min, of_samples[1].max)
        );
        let options = LabelOptions::for_levels(2);
        let ours = label_levels(&labels, &found[2], &options).unwrap();
        let theirs = label_levels(&samples, &of_samples[1], &options).unwrap();
        for (a, b) in ours.iter().zip(&theirs) {
            assert!(!a.mesh.is_empty());
            assert_eq!(a.mesh, b.mesh);
        }
    }
}
