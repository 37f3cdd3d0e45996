//! The stored model space and the fragments' quantization grid (neuroglancer `meshes.md`,
//! "multi-resolution mesh fragment data file format").
//!
//! A level-k node at grid position `c` covers `grid_origin + chunk · 2^k · [c, c + 1]`, and a
//! quantized coordinate `x ∈ 0 ..= M`, `M = 2^bits − 1`, stands for
//! `grid_origin + chunk · 2^k · (c + x / M)`. Every node of a level therefore lies on one global
//! lattice of step `chunk · 2^k / M`; we round each position to that lattice once, by its global
//! index `n = round((p − grid_origin) · M / (chunk · 2^k))`, and store `x = n − c · M`. A vertex
//! on the face between two nodes gets the same `n` from both, hence the same point after
//! dequantization, bit for bit. Ties round up, so a node's midplane (`x = M/2`, half-way between
//! two lattice points since `M` is odd) is stored at `(M + 1)/2`, which is exactly where
//! neuroglancer splits a node into its eight children: a coarse node's vertices on its
//! midplanes sit half a step, `chunk · 2^k / (2M)`, off the finer nodes' faces, which the
//! format cannot avoid (the faces and the midplanes of a node are never both on its lattice).

use voxlod_core::glam::DVec3;
use voxlod_core::WorldTransform;

use crate::PrecomputedError;

/// The map from the label map's world to the stored model space (neuroglancer voxels).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StoredFrame {
    /// World position of voxel (0, 0, 0)'s centre.
    pub origin: DVec3,
    /// World size of a voxel.
    pub spacing: DVec3,
    /// The layer's `voxel_offset`: where voxel (0, 0, 0)'s lower corner is stored.
    pub voxel_offset: [i64; 3],
}

impl StoredFrame {
    /// The frame of a map placed by `world`; refuses oblique directions (precomputed volumes are
    /// axis-aligned) and offsets beyond ±2⁵³ voxels.
    pub fn of(world: &WorldTransform) -> Result<StoredFrame, PrecomputedError> {
        if world.direction != voxlod_core::glam::DMat3::IDENTITY {
            return Err(PrecomputedError::LabelMap(format!(
                "its index axes are oblique or flipped (direction {:?}); neuroglancer precomputed \
                 volumes are axis-aligned: resample the map onto axis-aligned axes first",
                world.direction.to_cols_array()
            )));
        }
        let ratio = world.origin / world.spacing;
        if !ratio.is_finite() || ratio.abs().max_element() > 9.0e15 {
            return Err(PrecomputedError::LabelMap(format!(
                "origin {:?} is out of reach in voxels of {:?}",
                world.origin.to_array(),
                world.spacing.to_array()
            )));
        }
        Ok(StoredFrame {
            origin: world.origin,
            spacing: world.spacing,
            voxel_offset: ratio.round().to_array().map(|v| v as i64),
        })
    }

    /// Where a world point is stored (voxel units, the centre of voxel `i` at
    /// `voxel_offset + i + ½`).
    #[inline]
    pub fn to_stored(&self, world: DVec3) -> DVec3 {
        let offset = DVec3::from_array(self.voxel_offset.map(|v| v as f64));
        (world - self.origin) / self.spacing + offset + 0.5
    }
}

/// The quantization lattice of one level of detail.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lattice {
    /// The octree's origin (stored model space).
    pub grid_origin: DVec3,
    /// Size of a node of this level (`chunk · 2^k`).
    pub node: DVec3,
    /// `2^bits − 1`.
    pub max: u32,
}

impl Lattice {
    /// The lattice of level `lod` for nodes of `chunk` at level 0.
    pub fn new(grid_origin: DVec3, chunk: DVec3, lod: usize, bits: u32) -> Lattice {
        Lattice {
            grid_origin,
            node: chunk * (1u64 << lod) as f64,
            max: ((1u64 << bits) - 1) as u32,
        }
    }

    /// The quantized coordinates of `p` within the node at `cell` (clamped to the node, which
    /// only matters for points rounded across its faces).
    #[inline]
    pub fn quantize(&self, p: DVec3, cell: [u32; 3]) -> [u32; 3] {
        let m = self.max as f64;
        std::array::from_fn(|a| {
            let global = ((p[a] - self.grid_origin[a]) / self.node[a] * m).round();
            let local = global - cell[a] as f64 * m;
            local.clamp(0.0, m) as u32
        })
    }

    /// The stored model position of quantized coordinates `x` in the node at `cell`
    /// (neuroglancer's formula, with zero vertex offsets).
    #[inline]
    pub fn dequantize(&self, x: [u32; 3], cell: [u32; 3]) -> DVec3 {
        let m = self.max as f64;
        DVec3::from_array(std::array::from_fn(|a| {
            self.grid_origin[a] + self.node[a] * (cell[a] as f64 + x[a] as f64 / m)
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_face_vertex_has_the_same_point_in_both_nodes() {
        let lattice = Lattice::new(DVec3::splat(-3.0), DVec3::splat(8.0), 1, 10);
        let p = DVec3::new(13.0, 0.37, 2.9); // x = -3 + 16: the face between nodes 0 and 1
        let left = lattice.quantize(p, [0, 0, 0]);
        let right = lattice.quantize(p, [1, 0, 0]);
        assert_eq!(left[0], 1023);
        assert_eq!(right[0], 0);
        assert_eq!(left[1..], right[1..]);
        assert_eq!(
            lattice.dequantize(left, [0, 0, 0]),
            lattice.dequantize(right, [1, 0, 0])
        );
    }

    #[test]
    fn a_midplane_vertex_goes_where_neuroglancer_splits() {
        let lattice = Lattice::new(DVec3::ZERO, DVec3::splat(4.0), 2, 10);
        let q = lattice.quantize(DVec3::splat(8.0), [0, 0, 0]);
        assert_eq!(q, [512; 3]);
    }

    #[test]
    fn the_origin_rounds_to_whole_voxels() {
        let world = WorldTransform {
            origin: DVec3::new(2.0, -3.0, 0.4),
            spacing: DVec3::new(1.0, 0.5, 2.0),
            direction: voxlod_core::glam::DMat3::IDENTITY,
            frame: voxlod_core::Frame::Unknown,
        };
        let frame = StoredFrame::of(&world).unwrap();
        assert_eq!(frame.voxel_offset, [2, -6, 0]);
        assert_eq!(
            frame.to_stored(DVec3::new(2.0, -3.0, 0.4)),
            DVec3::new(2.5, -5.5, 0.5)
        );
    }
}
