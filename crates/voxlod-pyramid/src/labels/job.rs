//! The label maps' one call, [`labels()`]: the map's labels found, the ones asked for chosen,
//! each meshed with its levels ([`super::mesh_labels`]) and checked, every failure a
//! [`PyramidError`] of its class.
//!
//! Cost: that of [`super::mesh_labels`] (one pass over the map, then each label's box through
//! the pyramid, the labels in parallel within the memory limit), plus one pass over each
//! level's vertices to check them.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;

use voxlod_core::validate::{find_defect, Requirements};

use super::{
    find_labels, mesh_labels_until, select_labels, voxel_volume, LabelError, LabelInfo,
    LabelOptions, LabelSource,
};
use crate::error::{InvalidOption, PyramidError};
use crate::lod::LodLevel;
use crate::progress::{Control, ProgressFn, Tracker};

/// One label of a map with its levels.
#[derive(Clone, Debug)]
pub struct LabelLevels {
    /// The label: its value, how many voxels carry it, their index box.
    pub label: LabelInfo,
    /// Its voxels' volume, voxel count times the voxel's volume, in world units cubed.
    pub voxel_volume: f64,
    /// Its levels, finest first, in the frame of [`LabelOptions::frame`]; a level may be empty
    /// (a structure thinner than the filter at that level).
    pub levels: Vec<LodLevel>,
}

/// What [`labels()`] returns.
#[derive(Clone, Debug)]
pub struct LabelMeshes {
    /// The labels meshed: every non-zero label in increasing order, or those of
    /// [`LabelOptions::labels`] in its order.
    pub labels: Vec<LabelLevels>,
}

impl From<LabelError> for PyramidError {
    /// A label asked for that the map lacks is a wrong option (`labels`); a sample that is not
    /// an integer, or a map of background alone, is bad input; the rest keep their class.
    fn from(e: LabelError) -> PyramidError {
        match e {
            LabelError::NotALabel(i, j, k, value) => PyramidError::NotALabel {
                at: [i, j, k],
                value,
            },
            LabelError::Missing(label, present) => InvalidOption::new(
                "labels",
                label,
                format!("the map has no label {label} (it holds {present})"),
            )
            .into(),
            LabelError::NoLabels => PyramidError::NoLabels,
            LabelError::Lod(e) => e.into(),
            LabelError::Sampling(e) => e.into(),
            LabelError::Envelope(e) => PyramidError::from(e).context("`then_envelope`"),
        }
    }
}

/// Every non-zero label of `map` (or those of `options.labels`) as closed, outward meshes,
/// each with its levels (paper §2 and §4 on each label's indicator; see the module
/// [`crate::labels`]), meshed in parallel within the memory limit.
///
/// `progress` hears one [`crate::Event::Step`] per label meshed (`what` is `"meshed"`, `level`
/// 0; `total` is the number of labels) and may stop the work: the labels not yet started are
/// then skipped and the call returns [`PyramidError::Cancelled`].
///
/// Fails on a sample that is not an integer label ([`PyramidError::NotALabel`]), a map of
/// background alone ([`PyramidError::NoLabels`]), a label asked for that the map lacks
/// (an invalid `labels` option), work beyond the memory limit, and a label whose meshing
/// fails or whose surface leaves the 32-bit coordinates (the error names the label; with
/// several, the first in the order of the result).
///
/// ```
/// use voxlod_core::{Grid, Volume};
/// use voxlod_pyramid::labels::{labels, LabelOptions};
/// use voxlod_pyramid::run_to_end;
///
/// // A 6 × 6 × 6 map holding one 2 × 2 × 2 block of label 7.
/// let grid = Grid::new([6, 6, 6], [1.0; 3], [0.0; 3]).unwrap();
/// let values = (0..grid.len())
///     .map(|n| [n % 6, n / 6 % 6, n / 36])
///     .map(|at| if at.iter().all(|&a| (2..4).contains(&a)) { 7.0 } else { 0.0 })
///     .collect();
/// let map = Volume::from_vec(grid, values).unwrap();
/// let meshes = labels(&map, &LabelOptions::default(), &run_to_end)?;
/// assert_eq!(meshes.labels.len(), 1);
/// assert_eq!((meshes.labels[0].label.value, meshes.labels[0].label.voxels), (7, 8));
/// assert!(!meshes.labels[0].levels[0].mesh.is_empty());
/// # Ok::<(), voxlod_pyramid::PyramidError>(())
/// ```
pub fn labels<M: LabelSource>(
    map: &M,
    options: &LabelOptions,
    progress: &ProgressFn,
) -> Result<LabelMeshes, PyramidError> {
    let chosen = select_labels(find_labels(map)?, options.labels.as_deref())?;
    let tracker = Mutex::new(Tracker::start(progress, chosen.len())?);
    let stopped = AtomicBool::new(false);
    let meshed = mesh_labels_until(map, &chosen, options, &|_| {
        let mut tracker = tracker
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner());
        if tracker.step(0, "meshed").is_ok() {
            return Control::Continue;
        }
        stopped.store(true, Ordering::Relaxed);
        Control::Stop
    })?;
    if stopped.load(Ordering::Relaxed) {
        return Err(PyramidError::Cancelled);
    }
    let mut labels = Vec::with_capacity(chosen.len());
    for (label, levels) in chosen.into_iter().zip(meshed) {
        let levels = levels.expect("a label is left out only after a stop");
        let in_label = |e: PyramidError| e.context(format!("label {}", label.value));
        let levels = levels.map_err(|e| in_label(e.into()))?;
        for level in &levels {
            if let Some(defect) = find_defect(&level.mesh, &Requirements::computed()) {
                return Err(in_label(PyramidError::ComputedBeyondRange {
                    defect,
                    cause: "the map's extent is too large for 32-bit coordinates",
                }));
            }
        }
        labels.push(LabelLevels {
            voxel_volume: voxel_volume(map, label.voxels),
            label,
            levels,
        });
    }
    Ok(LabelMeshes { labels })
}
