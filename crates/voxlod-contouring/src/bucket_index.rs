//! The number of each bucket of the cleaning guard (`local_crossings.rs`) by its integer key,
//! in a two-level dense table instead of a hash map, so that the guard's reads of the 27
//! buckets around a triangle are two array loads each rather than a hash and a probe.
//!
//! Beyond the paper. The keys the table can hold span the keys of the input's triangles, one
//! bucket wider on every side (cleaning moves a vertex to a midpoint or a centroid of its
//! neighbours, inside the input's bounding box, so its triangles' keys stay in this span). The
//! span is cut into blocks of 4³ buckets: a coarse array holds, per block, the place of its 64
//! numbers in a fine array, and only blocks that hold a bucket get one, so memory follows the
//! surface (256 bytes per occupied block, 4 per block of the span), not the volume. A key
//! outside the span (never on a cleaning's mesh) goes to a hash map. Cost: O(1) per read and
//! insert.

use rustc_hash::FxHashMap;

/// Buckets per block along each axis, as a shift.
const SHIFT: u32 = 2;
/// Buckets per block.
const BLOCK: usize = 1 << (3 * SHIFT);
/// An absent block or bucket.
const NONE: u32 = u32::MAX;

/// Bucket numbers by key. See the module documentation.
pub(crate) struct BucketIndex {
    /// The smallest key of the span.
    lo: [i64; 3],
    /// Blocks of the span along each axis.
    blocks: [usize; 3],
    /// Per block of the span: the index of its first number in `fine`, or [`NONE`].
    coarse: Vec<u32>,
    /// The numbers of the occupied blocks' buckets, [`BLOCK`] per block, [`NONE`] if absent.
    fine: Vec<u32>,
    /// Numbers of the keys outside the span.
    outside: FxHashMap<[i64; 3], u32>,
}

impl BucketIndex {
    /// An empty index for keys from `lo` to `hi` (inclusive), widened by one on every side.
    pub(crate) fn new(lo: [i64; 3], hi: [i64; 3]) -> BucketIndex {
        let lo = lo.map(|k| k.saturating_sub(1));
        // No keys (lo above hi) or a span beyond i64 tabulate nothing.
        let blocks = [0, 1, 2].map(|a| {
            let span = hi[a].saturating_add(2).checked_sub(lo[a]).unwrap_or(0);
            (span.max(0) as usize).div_ceil(1 << SHIFT)
        });
        let total = blocks[0]
            .checked_mul(blocks[1])
            .and_then(|n| n.checked_mul(blocks[2]));
        // A span too large to tabulate (not a marching-cubes level) leaves every key outside.
        let (blocks, total) = match total {
            Some(n) if n <= u32::MAX as usize / BLOCK => (blocks, n),
            _ => ([0; 3], 0),
        };
        BucketIndex {
            lo,
            blocks,
            coarse: vec![NONE; total],
            fine: Vec::new(),
            outside: FxHashMap::default(),
        }
    }

    /// The block of `key` in `coarse` and the bucket's place within the block, if in the span.
    #[inline]
    fn place(&self, key: [i64; 3]) -> Option<(usize, usize)> {
        let mut block = 0usize;
        let mut within = 0usize;
        for a in (0..3).rev() {
            let d = key[a].wrapping_sub(self.lo[a]);
            let b = (d >> SHIFT) as usize;
            if d < 0 || b >= self.blocks[a] {
                return None;
            }
            block = block * self.blocks[a] + b;
            within = (within << SHIFT) | (d as usize & ((1 << SHIFT) - 1));
        }
        Some((block, within))
    }

    /// The number of the bucket `key`, if it has one.
    #[inline]
    pub(crate) fn get(&self, key: [i64; 3]) -> Option<u32> {
        let Some((block, within)) = self.place(key) else {
            return self.outside.get(&key).copied();
        };
        let first = self.coarse[block];
        if first == NONE {
            return None;
        }
        let b = self.fine[first as usize + within];
        (b != NONE).then_some(b)
    }

    /// The number of the bucket `key`, which becomes `fresh` if it had none.
    pub(crate) fn get_or_insert(&mut self, key: [i64; 3], fresh: u32) -> u32 {
        let Some((block, within)) = self.place(key) else {
            return *self.outside.entry(key).or_insert(fresh);
        };
        if self.coarse[block] == NONE {
            self.coarse[block] = self.fine.len() as u32;
            self.fine.resize(self.fine.len() + BLOCK, NONE);
        }
        let slot = &mut self.fine[self.coarse[block] as usize + within];
        if *slot == NONE {
            *slot = fresh;
        }
        *slot
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_in_and_outside_the_span_get_the_numbers_a_hash_map_gives() {
        let mut index = BucketIndex::new([-3, 0, 5], [6, 2, 9]);
        let mut reference: FxHashMap<[i64; 3], u32> = FxHashMap::default();
        let mut count = 0u32;
        for z in 2..13 {
            for y in -4..6 {
                for x in -6..10 {
                    let key = [x, y, z];
                    assert_eq!(index.get(key), reference.get(&key).copied());
                    if (x * 7 + y * 3 + z) % 4 == 0 {
                        let b = *reference.entry(key).or_insert(count);
                        assert_eq!(index.get_or_insert(key, count), b);
                        count += (b == count) as u32;
                        // A second insert keeps the first number.
                        assert_eq!(index.get_or_insert(key, count), b);
                    }
                }
            }
        }
        assert!(!index.outside.is_empty() && index.fine.len() > BLOCK);
        for (key, &b) in &reference {
            assert_eq!(index.get(*key), Some(b));
        }
    }
}
