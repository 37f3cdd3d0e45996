//! One primitive of an asset level as the streams of its accessors: its triangles' vertices
//! compacted, each attribute as floats, or quantized for `EXT_meshopt_compression` over
//! `KHR_mesh_quantization` (glTF 2.0 §3.11 for the normalized integers):
//!
//! | attribute | quantized as | read back within |
//! |---|---|---|
//! | `POSITION` | unsigned 14-bit integers in `u16` (+1 padding) on the grid shared by every level, undone by the level node's uniform scale and translation | half a grid step per component (the box's longest side / 16383 / 2) |
//! | `NORMAL` | normalized `i8` (+1 padding) | 0.5 / 127 per component, before the reader renormalizes |
//! | `TANGENT` | normalized `i8`, w ±127 | xyz as normals; w exactly ±1 |
//! | `TEXCOORD_0`, `TEXCOORD_1` | normalized `u16` where every value of the set in the primitive is in 0..=1 | 0.5 / 65535 |
//! | the same, with a value outside 0..=1 | **kept float** (a tiling or atlas set; no `KHR_texture_transform` is added, so a material's own transform stays as it is) | exact |
//! | `COLOR_0` | normalized `u16` RGBA (linear colours are clamped to 0..=1 anyway; 8 bits would band dark linear values) | 0.5 / 65535 |
//!
//! Before quantizing, the triangles and vertices are reordered for the vertex cache and fetch
//! ([`crate::streams::cache_order`]), which keeps the triangles and their count.
//!
//! Cost: linear in the primitive's corners.

use std::collections::HashMap;

use voxlod_asset::AssetMesh;
use voxlod_core::glam::{Vec2, Vec3, Vec4};

use crate::streams::{
    cache_order, flat_floats, float_stream, index_stream, quantized_positions, snorm8, unorm16,
    Component, Quantization, Stream, StreamKind,
};
use crate::GltfError;

/// A primitive's vertex columns (an empty column: the level has no such attribute) and its
/// triangles, as indices into the columns.
pub(crate) struct Columns {
    pub positions: Vec<Vec3>,
    /// Unit length (+z for a zero normal).
    pub normals: Vec<Vec3>,
    /// xyz unit, w ±1.
    pub tangents: Vec<Vec4>,
    pub uv: [Vec<Vec2>; 2],
    /// Clamped to 0..=1.
    pub colors: Vec<Vec4>,
    pub indices: Vec<u32>,
}

/// A stream and the attribute it is (`None` for the indices).
pub(crate) type Named = (Option<String>, Stream);

impl Columns {
    /// The vertices `triangles` use, in order of first use, with their attributes.
    pub fn gather(m: &AssetMesh, triangles: &[[u32; 3]]) -> Columns {
        let mut new_index: HashMap<u32, u32> = HashMap::new();
        let mut from: Vec<usize> = Vec::new();
        let indices: Vec<u32> = triangles
            .iter()
            .flatten()
            .map(|&v| {
                *new_index.entry(v).or_insert_with(|| {
                    from.push(v as usize);
                    (from.len() - 1) as u32
                })
            })
            .collect();
        fn pick<T: Copy>(column: &[T], from: &[usize]) -> Vec<T> {
            if column.is_empty() {
                return Vec::new();
            }
            from.iter().map(|&v| column[v]).collect()
        }
        Columns {
            positions: pick(&m.positions, &from),
            normals: pick(&m.normals, &from).into_iter().map(unit).collect(),
            tangents: pick(&m.tangents, &from)
                .into_iter()
                .map(|t| unit(t.truncate()).extend(if t.w < 0.0 { -1.0 } else { 1.0 }))
                .collect(),
            uv: [pick(&m.uv[0], &from), pick(&m.uv[1], &from)],
            colors: pick(&m.colors, &from)
                .into_iter()
                .map(|c| c.clamp(Vec4::ZERO, Vec4::ONE))
                .collect(),
            indices,
        }
    }

    /// The streams as floats, vertices in their order: positions with bounds, the attributes
    /// the level has, then the indices.
    pub fn plain(&self) -> Vec<Named> {
        let mut out: Vec<Named> = vec![(
            Some("POSITION".into()),
            float_stream(StreamKind::Positions, &self.positions),
        )];
        let flat4 = |v: &[Vec4]| v.iter().flat_map(|x| x.to_array()).collect::<Vec<f32>>();
        if !self.normals.is_empty() {
            let s = float_stream(StreamKind::Normals, &self.normals);
            out.push((Some("NORMAL".into()), s));
        }
        if !self.tangents.is_empty() {
            let s = flat_floats(StreamKind::Tangents, &flat4(&self.tangents), 4);
            out.push((Some("TANGENT".into()), s));
        }
        for (set, uv) in self.uv.iter().enumerate() {
            if !uv.is_empty() {
                let values: Vec<f32> = uv.iter().flat_map(|t| t.to_array()).collect();
                let s = flat_floats(StreamKind::TexCoords, &values, 2);
                out.push((Some(format!("TEXCOORD_{set}")), s));
            }
        }
        if !self.colors.is_empty() {
            let s = flat_floats(StreamKind::Colors, &flat4(&self.colors), 4);
            out.push((Some("COLOR_0".into()), s));
        }
        out.push((None, index_stream(&self.indices, self.positions.len())));
        out
    }

    /// The streams quantized as the module's table says, positions on `grid`, triangles and
    /// vertices reordered for the cache and fetch.
    pub fn quantized(&self, grid: &Quantization) -> Result<Vec<Named>, GltfError> {
        let (indices, order) = cache_order(&self.indices, self.positions.len())?;
        let n = order.len();
        let positions = quantized_positions(order.iter().map(|&v| self.positions[v]), grid);
        let mut out: Vec<Named> = vec![(Some("POSITION".into()), positions)];
        let snorm = |kind, vectors: Vec<Vec4>| Stream {
            kind,
            bytes: vectors
                .iter()
                .flat_map(|v| v.to_array().map(snorm8))
                .collect(),
            stride: 4,
            count: n,
            component: Component::I8,
            normalized: true,
            bounds: None,
        };
        if !self.normals.is_empty() {
            let v = order.iter().map(|&k| self.normals[k].extend(0.0)).collect();
            out.push((Some("NORMAL".into()), snorm(StreamKind::Normals, v)));
        }
        if !self.tangents.is_empty() {
            let v = order.iter().map(|&k| self.tangents[k]).collect();
            out.push((Some("TANGENT".into()), snorm(StreamKind::Tangents, v)));
        }
        for (set, uv) in self.uv.iter().enumerate() {
            if uv.is_empty() {
                continue;
            }
            let values: Vec<f32> = order.iter().flat_map(|&k| uv[k].to_array()).collect();
            let s = if values.iter().all(|x| (0.0..=1.0).contains(x)) {
                unorm16_stream(StreamKind::TexCoords, &values, 2)
            } else {
                flat_floats(StreamKind::TexCoords, &values, 2)
            };
            out.push((Some(format!("TEXCOORD_{set}")), s));
        }
        if !self.colors.is_empty() {
            let values: Vec<f32> = order
                .iter()
                .flat_map(|&k| self.colors[k].to_array())
                .collect();
            let s = unorm16_stream(StreamKind::Colors, &values, 4);
            out.push((Some("COLOR_0".into()), s));
        }
        out.push((None, index_stream(&indices, n)));
        Ok(out)
    }
}

/// Values in 0..=1 as normalized `u16`, `width` per element (stride `2 · width`, a multiple of
/// 4 for the widths used here: 2 and 4).
fn unorm16_stream(kind: StreamKind, values: &[f32], width: usize) -> Stream {
    Stream {
        kind,
        bytes: values.iter().flat_map(|&x| unorm16(x)).collect(),
        stride: 2 * width,
        count: values.len() / width,
        component: Component::U16,
        normalized: true,
        bounds: None,
    }
}

/// A unit vector (the validator asks normals to be unit length); +z for a zero one.
fn unit(v: Vec3) -> Vec3 {
    let n = v.normalize_or_zero();
    if n == Vec3::ZERO {
        Vec3::Z
    } else {
        n
    }
}
