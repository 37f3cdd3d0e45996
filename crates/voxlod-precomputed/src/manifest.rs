//! The per-label manifest of neuroglancer's multi-resolution meshes (`meshes.md`, "manifest file
//! format"): the octree's shape and, per level of detail, its nodes in Z-curve order with the
//! byte size of each node's fragment. All numbers little-endian. Cost: linear in the nodes.

use std::path::Path;

use crate::PrecomputedError;

/// A manifest, as written and read.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Manifest {
    /// Size of a level-0 node in the stored model space.
    pub chunk_shape: [f32; 3],
    /// Corner of node (0, 0, 0).
    pub grid_origin: [f32; 3],
    /// Per level, its scale (multiplied by the mesh info's `lod_scale_multiplier`).
    pub lod_scales: Vec<f32>,
    /// Per level, an offset added to its vertices.
    pub vertex_offsets: Vec<[f32; 3]>,
    /// Per level, its nodes' grid positions, in Z-curve order.
    pub fragment_positions: Vec<Vec<[u32; 3]>>,
    /// Per level, the byte size of each node's fragment, in the same order.
    pub fragment_sizes: Vec<Vec<u32>>,
}

impl Manifest {
    /// The number of levels of detail.
    pub fn num_lods(&self) -> usize {
        self.lod_scales.len()
    }

    /// The total size of the fragment data the manifest describes.
    pub fn data_size(&self) -> u64 {
        self.fragment_sizes
            .iter()
            .flatten()
            .map(|&s| s as u64)
            .sum()
    }

    /// Where level `lod`'s fragments start in the fragment data.
    pub fn lod_start(&self, lod: usize) -> u64 {
        self.fragment_sizes[..lod]
            .iter()
            .flatten()
            .map(|&s| s as u64)
            .sum()
    }

    /// The binary manifest.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = Vec::new();
        let f = |out: &mut Vec<u8>, v: f32| out.extend_from_slice(&v.to_le_bytes());
        let u = |out: &mut Vec<u8>, v: u32| out.extend_from_slice(&v.to_le_bytes());
        self.chunk_shape.iter().for_each(|&v| f(&mut out, v));
        self.grid_origin.iter().for_each(|&v| f(&mut out, v));
        u(&mut out, self.num_lods() as u32);
        self.lod_scales.iter().for_each(|&v| f(&mut out, v));
        self.vertex_offsets
            .iter()
            .flatten()
            .for_each(|&v| f(&mut out, v));
        self.fragment_positions
            .iter()
            .for_each(|p| u(&mut out, p.len() as u32));
        for (positions, sizes) in self.fragment_positions.iter().zip(&self.fragment_sizes) {
            for a in 0..3 {
                positions.iter().for_each(|p| u(&mut out, p[a]));
            }
            sizes.iter().for_each(|&s| u(&mut out, s));
        }
        out
    }

    /// Reads a binary manifest; `path` names it in errors. Fails when the size does not match
    /// the counts it declares.
    pub fn from_bytes(bytes: &[u8], path: &Path) -> Result<Manifest, PrecomputedError> {
        let bad = |reason: String| PrecomputedError::Format {
            path: path.to_path_buf(),
            reason,
        };
        let word = |i: usize| -> Result<[u8; 4], PrecomputedError> {
            bytes
                .get(4 * i..4 * i + 4)
                .map(|w| [w[0], w[1], w[2], w[3]])
                .ok_or_else(|| bad(format!("{} bytes, too short for its counts", bytes.len())))
        };
        let f = |i: usize| word(i).map(f32::from_le_bytes);
        let u = |i: usize| word(i).map(u32::from_le_bytes);
        let lods = u(6)? as usize;
        if lods > 64 {
            return Err(bad(format!("{lods} levels of detail")));
        }
        let mut m = Manifest {
            chunk_shape: [f(0)?, f(1)?, f(2)?],
            grid_origin: [f(3)?, f(4)?, f(5)?],
            ..Manifest::default()
        };
        let mut at = 7;
        for k in 0..lods {
            m.lod_scales.push(f(at + k)?);
        }
        at += lods;
        for k in 0..lods {
            m.vertex_offsets
                .push([f(at + 3 * k)?, f(at + 3 * k + 1)?, f(at + 3 * k + 2)?]);
        }
        at += 3 * lods;
        let counts: Vec<usize> = (0..lods)
            .map(|k| u(at + k).map(|c| c as usize))
            .collect::<Result<_, _>>()?;
        at += lods;
        let total: usize = counts.iter().sum();
        if bytes.len() != 4 * (at + 4 * total) {
            return Err(bad(format!(
                "{} bytes where its {total} fragments take {}",
                bytes.len(),
                4 * (at + 4 * total)
            )));
        }
        for &n in &counts {
            let positions = (0..n)
                .map(|i| Ok([u(at + i)?, u(at + n + i)?, u(at + 2 * n + i)?]))
                .collect::<Result<Vec<_>, PrecomputedError>>()?;
            at += 3 * n;
            let sizes = (0..n).map(|i| u(at + i)).collect::<Result<Vec<_>, _>>()?;
            at += n;
            m.fragment_positions.push(positions);
            m.fragment_sizes.push(sizes);
        }
        Ok(m)
    }
}
