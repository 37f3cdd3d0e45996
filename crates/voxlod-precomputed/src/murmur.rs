//! MurmurHash3, x86 128-bit variant (Austin Appleby's public-domain algorithm), which the
//! sharded format applies to the little-endian bytes of a shifted chunk id (`sharded.md`).
//! Cost: one pass over the input.

const C1: u32 = 0x239b_961b;
const C2: u32 = 0xab0e_9789;
const C3: u32 = 0x38b3_4ae5;
const C4: u32 = 0xa1e3_8b93;

#[inline]
fn fmix(mut h: u32) -> u32 {
    h ^= h >> 16;
    h = h.wrapping_mul(0x85eb_ca6b);
    h ^= h >> 13;
    h = h.wrapping_mul(0xc2b2_ae35);
    h ^ (h >> 16)
}

/// One lane's mixing of a key word: multiply, rotate, multiply.
#[inline]
fn mix(k: u32, a: u32, r: u32, b: u32) -> u32 {
    k.wrapping_mul(a).rotate_left(r).wrapping_mul(b)
}

/// The 128-bit hash of `data` with `seed`, as four 32-bit words `h1..h4` (the digest's bytes
/// are their little-endian concatenation).
pub fn x86_128(data: &[u8], seed: u32) -> [u32; 4] {
    let mut h = [seed; 4];
    let consts = [(C1, 15, C2), (C2, 16, C3), (C3, 17, C4), (C4, 18, C1)];
    let (rot, add) = (
        [19, 17, 15, 13],
        [0x561c_cd1b, 0x0bca_a747, 0x96cd_1c35, 0x32ac_3b17],
    );
    let blocks = data.chunks_exact(16);
    let tail = blocks.remainder();
    for block in blocks {
        for lane in 0..4 {
            let w = &block[4 * lane..4 * lane + 4];
            let k = u32::from_le_bytes([w[0], w[1], w[2], w[3]]);
            let (a, r, b) = consts[lane];
            h[lane] ^= mix(k, a, r, b);
            h[lane] = h[lane]
                .rotate_left(rot[lane])
                .wrapping_add(h[(lane + 1) % 4]);
            h[lane] = h[lane].wrapping_mul(5).wrapping_add(add[lane]);
        }
    }
    for lane in (0..4).rev() {
        let bytes = tail.iter().skip(4 * lane).take(4);
        if bytes.len() == 0 {
            continue;
        }
        let k = bytes
            .enumerate()
            .fold(0u32, |k, (i, &b)| k ^ ((b as u32) << (8 * i)));
        let (a, r, b) = consts[lane];
        h[lane] ^= mix(k, a, r, b);
    }
    let len = data.len() as u32;
    h.iter_mut().for_each(|x| *x ^= len);
    let spread = |h: &mut [u32; 4]| {
        h[0] = h[0]
            .wrapping_add(h[1])
            .wrapping_add(h[2])
            .wrapping_add(h[3]);
        for lane in 1..4 {
            h[lane] = h[lane].wrapping_add(h[0]);
        }
    };
    spread(&mut h);
    h.iter_mut().for_each(|x| *x = fmix(*x));
    spread(&mut h);
    h
}

/// The sharded format's hash of a chunk id: the low 64 bits of `x86_128` of its 8
/// little-endian bytes, seed 0.
pub fn hash_u64(id: u64) -> u64 {
    let h = x86_128(&id.to_le_bytes(), 0);
    h[0] as u64 | (h[1] as u64) << 32
}
