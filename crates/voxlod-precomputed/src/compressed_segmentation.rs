//! Neuroglancer's `compressed_segmentation` chunk encoding, decoded (neuroglancer's
//! `sliceview/compressed_segmentation/README.md`; no Rust crate decodes it). A chunk of one
//! channel is cut into blocks of `block` voxels; each block has a 64-bit header (its lookup
//! table's offset in the low 24 bits and its bits per voxel in the high 8 of the first word,
//! its packed values' offset in the second), offsets in 32-bit words from the channel's start,
//! which the buffer's first word gives. Each voxel's value indexes the block's table of labels
//! (one or two words each, for 32- or 64-bit labels), packed least significant bit first.
//!
//! Cost: one pass over the chunk's voxels.

/// The labels of a chunk of `dims` voxels (x fastest) in blocks of `block` voxels, from its
/// little-endian 32-bit `words`; `wide` for 64-bit labels. Fails, with the reason, on offsets
/// or bit widths outside the buffer or the format.
pub fn decode(
    words: &[u32],
    dims: [usize; 3],
    block: [usize; 3],
    wide: bool,
) -> Result<Vec<u64>, String> {
    if block.contains(&0) {
        return Err(format!("block size {block:?}"));
    }
    let start = *words.first().ok_or("an empty chunk")? as usize;
    let grid: [usize; 3] = std::array::from_fn(|a| dims[a].div_ceil(block[a]));
    let word = |n: usize| {
        words
            .get(n)
            .copied()
            .ok_or(format!("offset {n} past the chunk"))
    };
    let mut out = vec![0u64; dims.iter().product()];
    for b in 0..grid.iter().product::<usize>() {
        let at = [b % grid[0], b / grid[0] % grid[1], b / (grid[0] * grid[1])];
        let header = word(start + 2 * b)?;
        let (table, bits) = (
            start + (header & 0xff_ffff) as usize,
            (header >> 24) as usize,
        );
        let values = start + word(start + 2 * b + 1)? as usize;
        if !matches!(bits, 0 | 1 | 2 | 4 | 8 | 16 | 32) {
            return Err(format!("block {b}: {bits} bits per voxel"));
        }
        let origin: [usize; 3] = std::array::from_fn(|a| at[a] * block[a]);
        for v in 0..block.iter().product::<usize>() {
            let local = [
                v % block[0],
                v / block[0] % block[1],
                v / (block[0] * block[1]),
            ];
            let p: [usize; 3] = std::array::from_fn(|a| origin[a] + local[a]);
            if (0..3).any(|a| p[a] >= dims[a]) {
                continue;
            }
            let index = if bits == 0 {
                0
            } else {
                let bit = v * bits;
                ((word(values + bit / 32)? >> (bit % 32)) as u64 & ((1u64 << bits) - 1)) as usize
            };
            let label = if wide {
                let low = word(table + 2 * index)? as u64;
                low | (word(table + 2 * index + 1)? as u64) << 32
            } else {
                word(table + index)? as u64
            };
            out[(p[2] * dims[1] + p[1]) * dims[0] + p[0]] = label;
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_hand_encoded_chunk_of_two_blocks_decodes() {
        // A 3 × 2 × 2 chunk in 2 × 2 × 2 blocks: labels 5 and 7 at (0,0,0) and (1,0,0) in the
        // first block (2 bits a voxel, table [0, 5, 7]), 9 at (2,1,1) in the second (1 bit,
        // table [0, 9]); as the compressed-segmentation package writes it.
        let words = [
            1,
            0x0200_0005,
            4,
            0x0100_0009,
            8,
            0b1001,
            0,
            5,
            7,
            1 << 6,
            0,
            9,
        ];
        let labels = decode(&words, [3, 2, 2], [2, 2, 2], false).unwrap();
        let mut expected = vec![0u64; 12];
        (expected[0], expected[1], expected[11]) = (5, 7, 9);
        assert_eq!(labels, expected);
    }

    #[test]
    fn offsets_past_the_chunk_are_named() {
        let words = [1, 0x0200_0005, 40];
        let error = decode(&words, [2, 2, 2], [2, 2, 2], false).unwrap_err();
        assert_eq!(error, "offset 41 past the chunk");
    }
}
