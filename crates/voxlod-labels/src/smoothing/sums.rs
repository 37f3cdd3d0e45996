//! Exact sums per label pair for the volume restoring ([`super::smooth`], step 5): each term
//! is cut once to a fixed point and the terms are summed as integers, so a sum depends
//! neither on the order of its terms nor on how they are split among threads or tasks. A block
//! of a map (the blockwise route: `voxlod.dask.labels` with `shared`) and the whole map give the
//! same sums for the same triangles, and so the same pressures and positions, bit for bit.
//!
//! The fixed point is a power of two: 2⁻⁴⁸ of the largest power of two not above the voxel's
//! volume for the volumes (grid units cubed), 2⁻⁴⁸ of that volume to the power 4/3 for the Gram
//! weights (gradients squared, grid units to the fourth), each term cut to a whole number of
//! units: below the float rounding of the terms themselves, so the sums are as close as float
//! sums. That matters: a map filled with labels keeps its total volume, and its pressures stay
//! bounded only while the labels' volume errors sum to nearly nothing (at 2⁻²⁴, the 512³
//! Voronoi map's restoring diverged). The sums are 128-bit integers: room for 2³¹ terms of
//! coordinates up to 2¹⁶ voxels from the map's first corner. Cost: a few float and integer
//! operations per term.

use rustc_hash::FxHashMap;
use voxlod_core::glam::Vec3;

/// Sums per label pair `[inside, outside]` (the background 0 included), in units of `unit`,
/// sorted by pair without repeats.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PairSums {
    /// The value of one unit (a power of two).
    pub unit: f64,
    /// Per pair, its sum in units.
    pub sums: Vec<([u32; 2], i128)>,
}

impl PairSums {
    /// The sums of `parts` added per pair (parts with no pair may have any unit; the others
    /// must share theirs).
    pub fn merged(parts: impl IntoIterator<Item = PairSums>) -> PairSums {
        let mut unit = 0.0;
        let mut all: Vec<([u32; 2], i128)> = Vec::new();
        for part in parts {
            if part.sums.is_empty() {
                continue;
            }
            debug_assert!(unit == 0.0 || unit == part.unit, "sums of different units");
            unit = part.unit;
            all.extend(part.sums);
        }
        summed(&mut all);
        PairSums { unit, sums: all }
    }

    /// The labels other than 0 of the pairs, sorted.
    pub fn labels(&self) -> Vec<u32> {
        let mut labels: Vec<u32> = (self.sums.iter())
            .flat_map(|(p, _)| p.iter().copied())
            .filter(|&l| l != 0)
            .collect();
        labels.sort_unstable();
        labels.dedup();
        labels
    }
}

/// Sorts `entries` by key and adds the values of equal keys into one entry.
pub(super) fn summed<K: Ord + Copy>(entries: &mut Vec<(K, i128)>) {
    entries.sort_unstable_by_key(|e| e.0);
    entries.dedup_by(|next, kept| {
        let same = next.0 == kept.0;
        if same {
            kept.1 += next.1;
        }
        same
    });
}

/// A fixed point: terms are cut to whole units of `unit` (`scale` its inverse).
#[derive(Clone, Copy, Debug)]
pub(super) struct Quantum {
    scale: f64,
    unit: f64,
}

/// Bits below the unit of a quantum (module docs).
const FRACTION_BITS: i32 = 48;

/// A term in units is split at this power of two into a high part and a low part, each
/// within 64 bits.
const SPLIT: f64 = 4_294_967_296.0;

/// Terms are held below this many units, 2⁹⁴ (2⁴⁶ voxels cubed: coordinates some 2¹⁶ voxels
/// from the map's first corner), so that 2³¹ of them sum within 128 bits.
const LARGEST: f64 = 19_807_040_628_566_084_398_385_987_584.0;

impl Quantum {
    /// The quantum of volumes on a grid of this spacing.
    pub(super) fn volume(spacing: Vec3) -> Quantum {
        Quantum::at(exponent(spacing) - FRACTION_BITS)
    }

    /// The quantum of Gram weights on a grid of this spacing.
    pub(super) fn weight(spacing: Vec3) -> Quantum {
        Quantum::at((4 * exponent(spacing)).div_euclid(3) - FRACTION_BITS)
    }

    fn at(power: i32) -> Quantum {
        Quantum {
            scale: 2f64.powi(-power),
            unit: 2f64.powi(power),
        }
    }

    /// `x` in whole units, what lies below the unit dropped (toward zero; 0 for NaN). Exact
    /// but for that: the scaling is by a power of two, and the high part's remainder is taken
    /// exactly before it is cut. Beyond 2⁹⁴ units, held there.
    #[inline]
    pub(super) fn fixed(&self, x: f64) -> i128 {
        let s = x * self.scale;
        if s.is_nan() {
            return 0;
        }
        if s.abs() >= LARGEST {
            return s.clamp(-LARGEST, LARGEST) as i128;
        }
        // SAFETY: |s| < 2⁹⁴, so the high part is below 2⁶² and the remainder below 2³² in
        // magnitude: both convert without overflow (the checked conversion costs a term
        // twice as much in the restoring's passes).
        let high = unsafe { (s * (1.0 / SPLIT)).to_int_unchecked::<i64>() };
        let low = unsafe { (s - high as f64 * SPLIT).to_int_unchecked::<i64>() };
        ((high as i128) << 32) + low as i128
    }

    /// Empty sums in this quantum.
    pub(super) fn sums(&self, sums: Vec<([u32; 2], i128)>) -> PairSums {
        PairSums {
            unit: self.unit,
            sums,
        }
    }
}

/// The exponent of the largest power of two not above the voxel's volume (its float bits:
/// exact on every machine, unlike a logarithm).
fn exponent(spacing: Vec3) -> i32 {
    let volume = spacing.x as f64 * spacing.y as f64 * spacing.z as f64;
    ((volume.to_bits() >> 52) & 0x7ff) as i32 - 1023
}

/// Sums per label pair over runs of one pair (consecutive triangles or vertices mostly share
/// theirs), in fixed point.
#[derive(Default)]
pub(super) struct PairRuns {
    sums: FxHashMap<[u32; 2], i128>,
    run: Option<([u32; 2], i128)>,
}

impl PairRuns {
    /// Adds `n` units to `pair`.
    #[inline]
    pub(super) fn add(&mut self, pair: [u32; 2], n: i128) {
        match &mut self.run {
            Some((p, sum)) if *p == pair => *sum += n,
            run => {
                if let Some((p, sum)) = run.take() {
                    *self.sums.entry(p).or_default() += sum;
                }
                *run = Some((pair, n));
            }
        }
    }

    /// The run in progress added to its pair.
    fn flush(&mut self) {
        if let Some((p, sum)) = self.run.take() {
            *self.sums.entry(p).or_default() += sum;
        }
    }

    /// Both sums together (the order of terms does not matter: the parallel passes fold
    /// their chunks into one per thread and join those).
    pub(super) fn joined(mut self, mut other: PairRuns) -> PairRuns {
        self.flush();
        other.flush();
        if self.sums.len() < other.sums.len() {
            std::mem::swap(&mut self, &mut other);
        }
        for (p, sum) in other.sums {
            *self.sums.entry(p).or_default() += sum;
        }
        self
    }

    /// The sums per pair, sorted by pair, in `quantum`.
    pub(super) fn sums(mut self, quantum: &Quantum) -> PairSums {
        self.flush();
        let mut out: Vec<([u32; 2], i128)> = self.sums.into_iter().collect();
        out.sort_unstable_by_key(|e| e.0);
        quantum.sums(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sums_do_not_depend_on_the_order_or_split_of_their_terms() {
        let q = Quantum::volume(Vec3::new(0.3, 0.7, 1.1));
        let term = |i: usize| ((i * 7919 % 1000) as f64 - 500.3) * 1.37e-3;
        let pair = |i: usize| [1, 2 + i.is_multiple_of(3) as u32];
        let runs_of = |indices: &mut dyn Iterator<Item = usize>| {
            let mut runs = PairRuns::default();
            for i in indices {
                runs.add(pair(i), q.fixed(term(i)));
            }
            runs
        };
        let forward = runs_of(&mut (0..1000)).sums(&q);
        let backward = runs_of(&mut (0..1000).rev()).sums(&q);
        let halves = PairSums::merged([
            runs_of(&mut (0..333)).sums(&q),
            runs_of(&mut (333..1000)).sums(&q),
        ]);
        let joined = (runs_of(&mut (500..1000)).joined(runs_of(&mut (0..500)))).sums(&q);
        assert_eq!(forward.sums.len(), 2);
        assert_eq!(forward, backward);
        assert_eq!(forward, halves);
        assert_eq!(forward, joined);
        for (p, sum) in &forward.sums {
            let exact: f64 = (0..1000).filter(|&i| pair(i) == *p).map(term).sum();
            assert!((*sum as f64 * forward.unit - exact).abs() < 1000.0 * q.unit);
        }
    }

    #[test]
    fn the_units_are_powers_of_two_below_the_voxel() {
        let q = Quantum::volume(Vec3::new(1.0, 1.0, 1.5));
        assert_eq!(q.unit, 2f64.powi(-48));
        let w = Quantum::weight(Vec3::new(2.0, 2.0, 2.0));
        assert_eq!(w.unit, 2f64.powi(4 - 48));
        assert_eq!(q.fixed(f64::NAN), 0);
        assert_eq!(q.fixed(f64::INFINITY) as f64, LARGEST);
        for x in [1.0, -2.75, 1e-3, 123456.789, -7e9, 3e12, -1e13] {
            let units = q.fixed(x);
            assert_eq!(units, (x * 2f64.powi(48)).trunc() as i128, "{x}");
        }
        assert_eq!((q.fixed(2.5 * q.unit), q.fixed(-3.5 * q.unit)), (2, -3));
    }
}
