//! The labels of a map: each non-zero value with how many voxels carry it and their index box,
//! found in one pass over the map, and the labels a caller asks for chosen among them.
//!
//! Cost: one read of the map, in parallel over slabs of z; a run of equal labels along x costs
//! one look-up, so a map of large structures is read at about the speed of memory.

use rayon::prelude::*;
use rustc_hash::FxHashMap;
use serde::Serialize;
use voxlod_core::LabelVolume;

use crate::LabelsError;

/// One label of a map: its value, how many voxels carry it, and their index box.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct LabelInfo {
    /// The label value (never 0, the background).
    pub value: u32,
    /// How many voxels carry it.
    pub voxels: u64,
    /// Smallest voxel index along x, y, z.
    pub min: [usize; 3],
    /// Largest voxel index along x, y, z.
    pub max: [usize; 3],
}

impl LabelInfo {
    fn new(value: u32, at: [usize; 3]) -> LabelInfo {
        LabelInfo {
            value,
            voxels: 0,
            min: at,
            max: at,
        }
    }

    /// Takes in `count` voxels from `first` to `last` (inclusive, on one row along x).
    fn add_run(&mut self, first: [usize; 3], last: [usize; 3], count: u64) {
        self.voxels += count;
        for a in 0..3 {
            self.min[a] = self.min[a].min(first[a]);
            self.max[a] = self.max[a].max(last[a]);
        }
    }

    fn merge(&mut self, other: &LabelInfo) {
        self.add_run(other.min, other.max, other.voxels);
    }
}

/// The non-zero labels of `map`, in increasing order, with their voxel counts and boxes; empty
/// when the map is all background.
pub fn find_labels(map: &LabelVolume) -> Vec<LabelInfo> {
    let [nx, ny, nz] = map.grid.dims;
    let slab = nx * ny;
    let found = (0..nz)
        .into_par_iter()
        .fold(FxHashMap::<u32, LabelInfo>::default, |mut found, k| {
            let slice = &map.values[k * slab..(k + 1) * slab];
            for (j, row) in slice.chunks_exact(nx).enumerate() {
                scan_row(row, j, k, &mut found);
            }
            found
        })
        .reduce(FxHashMap::default, |mut a, b| {
            for (value, info) in b {
                a.entry(value)
                    .and_modify(|i| i.merge(&info))
                    .or_insert(info);
            }
            a
        });
    let mut labels: Vec<LabelInfo> = found.into_values().collect();
    labels.sort_unstable_by_key(|l| l.value);
    labels
}

/// Adds the runs of one row (`j`, `k`) to `found`.
fn scan_row(row: &[u32], j: usize, k: usize, found: &mut FxHashMap<u32, LabelInfo>) {
    let mut i = 0;
    while i < row.len() {
        let value = row[i];
        let start = i;
        while i < row.len() && row[i] == value {
            i += 1;
        }
        if value != 0 {
            let (first, last) = ([start, j, k], [i - 1, j, k]);
            found
                .entry(value)
                .or_insert_with(|| LabelInfo::new(value, first))
                .add_run(first, last, (i - start) as u64);
        }
    }
}

/// The labels to mesh: all of `all`, or those of `wanted` in its order (each must be in `all`).
/// Fails on a map of background alone and on a label the map lacks, naming the ones it holds
/// (the first twenty).
pub fn select_labels(
    all: Vec<LabelInfo>,
    wanted: Option<&[u32]>,
) -> Result<Vec<LabelInfo>, LabelsError> {
    if all.is_empty() {
        return Err(LabelsError::NoLabels);
    }
    let Some(wanted) = wanted else {
        return Ok(all);
    };
    let present = || {
        let mut names: Vec<String> = all.iter().take(20).map(|l| l.value.to_string()).collect();
        if all.len() > 20 {
            names.push(format!("… {} labels in all", all.len()));
        }
        names.join(", ")
    };
    wanted
        .iter()
        .map(|w| {
            all.binary_search_by_key(w, |l| l.value)
                .map(|n| all[n].clone())
                .map_err(|_| LabelsError::Missing(*w, present()))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use voxlod_core::Grid;

    /// A 4 × 3 × 2 map: label 5 on a run of three and one more voxel, label 9 alone.
    fn map() -> LabelVolume {
        let grid = Grid::new([4, 3, 2], [1.0; 3], [0.0; 3]).unwrap();
        let mut values = vec![0; 24];
        values[0..3].fill(5); // (0..3, 0, 0)
        values[12 + 4 + 3] = 5; // (3, 1, 1)
        values[12 + 8 + 1] = 9; // (1, 2, 1)
        LabelVolume::from_vec(grid, values).unwrap()
    }

    #[test]
    fn labels_are_found_with_counts_and_boxes() {
        let found = find_labels(&map());
        assert_eq!(
            found,
            vec![
                LabelInfo {
                    value: 5,
                    voxels: 4,
                    min: [0, 0, 0],
                    max: [3, 1, 1]
                },
                LabelInfo {
                    value: 9,
                    voxels: 1,
                    min: [1, 2, 1],
                    max: [1, 2, 1]
                },
            ]
        );
    }

    #[test]
    fn the_labels_asked_for_come_in_their_order() {
        let chosen = select_labels(find_labels(&map()), Some(&[9, 5])).unwrap();
        assert_eq!(chosen.iter().map(|l| l.value).collect::<Vec<_>>(), [9, 5]);
    }

    #[test]
    fn a_missing_label_names_the_present_ones() {
        let error = select_labels(find_labels(&map()), Some(&[7])).unwrap_err();
        assert_eq!(error.to_string(), "the map has no label 7 (it holds 5, 9)");
    }

    #[test]
    fn background_alone_is_refused() {
        let grid = Grid::new([2, 2, 2], [1.0; 3], [0.0; 3]).unwrap();
        let empty = LabelVolume::from_vec(grid, vec![0; 8]).unwrap();
        assert!(matches!(
            select_labels(find_labels(&empty), None),
            Err(LabelsError::NoLabels)
        ));
    }
}
