//! Z-curve (Morton) order of octree nodes, as neuroglancer's manifests require: x's bit `i` is
//! bit `3i` of the code, y's `3i + 1`, z's `3i + 2`. Cost: a few operations per node.

/// The bits of a 16-bit value spread to every third bit (bit `i` to bit `3i`).
#[inline]
fn spread(v: u32) -> u64 {
    let mut x = (v & 0xffff) as u64;
    x = (x | x << 16) & 0x0000_ff00_00ff;
    x = (x | x << 8) & 0x00f0_0f00_f00f;
    x = (x | x << 4) & 0x0c30_c30c_30c3;
    x = (x | x << 2) & 0x2492_4924_9249;
    x
}

/// The Morton code of a node position (32 bits per axis, so 96 bits). Cost: a few dozen
/// operations.
#[inline]
pub fn code(p: [u32; 3]) -> u128 {
    let half = |shift: u32| -> u128 {
        let [x, y, z] = p.map(|c| spread(c >> shift));
        (x | y << 1 | z << 2) as u128
    };
    half(0) | half(16) << 48
}

/// Every third bit of `x` (bit `3i` to bit `i`), 16 of them: the inverse of [`spread`].
#[inline]
fn compact(x: u64) -> u32 {
    let mut x = x & 0x2492_4924_9249;
    x = (x | x >> 2) & 0x0c30_c30c_30c3;
    x = (x | x >> 4) & 0x00f0_0f00_f00f;
    x = (x | x >> 8) & 0x0000_ff00_00ff;
    x = (x | x >> 16) & 0xffff;
    x as u32
}

/// The node position of a Morton code made by [`code`].
#[inline]
pub fn decode(code: u128) -> [u32; 3] {
    std::array::from_fn(|a| compact((code >> a) as u64) | compact((code >> (48 + a)) as u64) << 16)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_interleave_x_fastest() {
        assert_eq!(code([1, 0, 0]), 1);
        assert_eq!(code([0, 1, 0]), 2);
        assert_eq!(code([0, 0, 1]), 4);
        assert_eq!(code([2, 0, 0]), 8);
        assert_eq!(code([3, 3, 3]), 63);
        assert!(code([1, 1, 1]) < code([2, 0, 0]));
    }

    #[test]
    fn codes_match_bit_by_bit_interleaving() {
        let naive = |p: [u32; 3]| {
            let mut out = 0u128;
            for bit in 0..32 {
                for (a, &v) in p.iter().enumerate() {
                    out |= (((v >> bit) & 1) as u128) << (3 * bit + a);
                }
            }
            out
        };
        let mut seed = 12345u64;
        for _ in 0..1000 {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1);
            let p = [
                seed as u32,
                (seed >> 21) as u32,
                (seed >> 40) as u32 ^ 0xdead_beef,
            ];
            assert_eq!(code(p), naive(p), "{p:?}");
            assert_eq!(decode(code(p)), p);
        }
        assert_eq!(code([u32::MAX; 3]), (1u128 << 96) - 1);
    }
}
