//! A least-significant-digit radix sort for the elimination's simplex keys.
//!
//! Keys are packed cluster ids, so they use few bits (3 × 16 for 40 000 clusters); the sort
//! makes one counting pass per digit of up to 11 bits (2048 counters, in L1), skips digits that
//! are the same in every key, and is stable. Cost O(n · bits / 11).

/// Sorts `items` by `key(item)`, of which only the low `bits` bits may be set.
pub(crate) fn radix_sort_by_key<T: Copy + Default>(
    items: &mut Vec<T>,
    bits: u32,
    key: impl Fn(&T) -> u64,
) {
    debug_assert!(bits <= 64);
    if items.len() < 64 || bits == 0 {
        items.sort_by_key(&key);
        return;
    }
    let passes = bits.div_ceil(11);
    let width = bits.div_ceil(passes);
    let mask = (1u64 << width) - 1;
    let mut scratch: Vec<T> = vec![T::default(); items.len()];
    let mut counts = vec![0usize; 1 << width];
    for pass in 0..passes {
        let shift = pass * width;
        counts.iter_mut().for_each(|c| *c = 0);
        for it in items.iter() {
            counts[((key(it) >> shift) & mask) as usize] += 1;
        }
        if counts.contains(&items.len()) {
            continue; // every key has the same digit here
        }
        let mut sum = 0;
        for c in counts.iter_mut() {
            let n = *c;
            *c = sum;
            sum += n;
        }
        for it in items.iter() {
            let d = ((key(it) >> shift) & mask) as usize;
            scratch[counts[d]] = *it;
            counts[d] += 1;
        }
        std::mem::swap(items, &mut scratch);
    }
}

/// Bits needed to store any value below `count` (at least 1).
pub(crate) fn bits_for(count: usize) -> u32 {
    (usize::BITS - count.saturating_sub(1).leading_zeros()).max(1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sorts_like_the_standard_sort_and_is_stable() {
        let mut x = 12345u64;
        let mut items: Vec<(u64, u32)> = (0..5000)
            .map(|i| {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                (x & ((1 << 37) - 1) & !0xF0, i)
            })
            .collect();
        items.extend((0..100).map(|i| (42, 10_000 + i)));
        let mut expected = items.clone();
        expected.sort_by_key(|e| e.0); // stable
        radix_sort_by_key(&mut items, 37, |e| e.0);
        assert_eq!(items, expected);
    }

    #[test]
    fn bit_counts() {
        assert_eq!(bits_for(0), 1);
        assert_eq!(bits_for(1), 1);
        assert_eq!(bits_for(2), 1);
        assert_eq!(bits_for(3), 2);
        assert_eq!(bits_for(1 << 16), 16);
        assert_eq!(bits_for((1 << 16) + 1), 17);
    }
}
