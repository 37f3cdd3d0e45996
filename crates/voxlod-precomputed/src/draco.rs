//! Draco encoding of mesh fragments, as neuroglancer's multi-resolution format wants them.
//!
//! Each fragment is a Draco triangle mesh whose only attribute is the position, three signed
//! 32-bit integers per vertex: the vertex's quantized coordinates `0 ..= 2^bits − 1` within its
//! octree node (`quantize.rs`). Integer attributes are coded losslessly by Draco, so the
//! decoder gets back exactly the integers written; neuroglancer reads them with Draco's own
//! dequantization turned off ("the built-in Draco attribute quantization is not supported",
//! `meshes.md`) and accepts `INT32` or `FLOAT32` positions, so no Draco quantization is applied
//! here.
//!
//! The encoder is the `draco-core` crate: pure Rust (no C++ build, no `unsafe`), whose output
//! is byte-identical to C++ Draco 1.5.7 for the same mesh and options, and which reads what
//! C++ Draco writes, so neuroglancer's WebAssembly decoder and DracoPy read our fragments. Its
//! encoder has no option to fix the quantization origin and range per fragment (C++ Draco's
//! `quantization_origin`/`quantization_range`), which is why the positions are quantized here
//! and handed over as integers.
//!
//! Cost: linear in the fragment's size, plus Draco's entropy table for the positions, which has
//! one entry per value up to the largest prediction correction, about the span of the
//! fragment's coordinates: up to 2^16 entries at 16 bits, 2^10 at 10. At 16 bits that table
//! (filled, and sorted when its rounded probabilities overshoot) costs more than the rest of a
//! small fragment's encoding; it is `draco-core`'s, like C++ Draco's.

use draco_core::{
    DataType, DecoderBuffer, EncoderBuffer, EncoderOptions, GeometryAttributeType, Mesh,
    MeshDecoder, MeshEncoder, PointAttribute, PointIndex,
};

use crate::PrecomputedError;

/// A fragment as integers: quantized positions and triangles (counter-clockwise from outside).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct QuantizedFragment {
    /// Quantized coordinates, each in `0 ..= 2^bits − 1`.
    pub positions: Vec<[u32; 3]>,
    /// Indices into `positions`.
    pub triangles: Vec<[u32; 3]>,
}

/// Encodes a fragment; an empty fragment (no triangle) encodes to no bytes, which the format
/// allows for octree nodes without geometry. Fails if Draco refuses the mesh.
pub fn encode(fragment: &QuantizedFragment) -> Result<Vec<u8>, PrecomputedError> {
    if fragment.triangles.is_empty() {
        return Ok(Vec::new());
    }
    let n = fragment.positions.len();
    let mut attribute = PointAttribute::new();
    attribute.init(
        GeometryAttributeType::Position,
        3,
        DataType::Int32,
        false,
        n,
    );
    let mut bytes: Vec<u8> = Vec::with_capacity(12 * n);
    for c in fragment.positions.as_flattened() {
        bytes.extend_from_slice(&(*c as i32).to_le_bytes());
    }
    attribute.buffer_mut().write(0, &bytes);
    let mut mesh = Mesh::new();
    mesh.set_num_points(n);
    mesh.add_attribute(attribute);
    // `set_faces_from_flat_indices` fills only the faces already allotted (it ignores the rest
    // silently in release builds), so the count comes first.
    mesh.set_num_faces(fragment.triangles.len());
    mesh.set_faces_from_flat_indices(fragment.triangles.as_flattened());
    let mut encoder = MeshEncoder::new();
    encoder.set_mesh(mesh);
    let mut buffer = EncoderBuffer::new();
    encoder
        .encode(&EncoderOptions::new(), &mut buffer)
        .map_err(|e| PrecomputedError::Draco(format!("encoding a fragment: {e}")))?;
    Ok(buffer.data().to_vec())
}

/// Decodes a fragment written by [`encode`] (or any Draco mesh with three-component integer
/// positions); no bytes decode to the empty fragment. Fails on a stream Draco cannot read or
/// positions that are not three non-negative integers.
pub fn decode(bytes: &[u8]) -> Result<QuantizedFragment, PrecomputedError> {
    if bytes.is_empty() {
        return Ok(QuantizedFragment::default());
    }
    let bad = |why: String| PrecomputedError::Draco(format!("decoding a fragment: {why}"));
    let mut mesh = Mesh::new();
    MeshDecoder::new()
        .decode(&mut DecoderBuffer::new(bytes), &mut mesh)
        .map_err(|e| bad(e.to_string()))?;
    let attribute = mesh
        .named_attribute(GeometryAttributeType::Position)
        .ok_or_else(|| bad("no position attribute".into()))?;
    if attribute.num_components() != 3 || attribute.data_type() != DataType::Int32 {
        return Err(bad(format!(
            "positions are {} × {:?}, not 3 × Int32",
            attribute.num_components(),
            attribute.data_type()
        )));
    }
    let data = attribute.buffer().data();
    let stride = attribute.byte_stride() as usize;
    let mut positions = Vec::with_capacity(mesh.num_points());
    for p in 0..mesh.num_points() {
        let value = attribute.mapped_index(PointIndex(p as u32)).0 as usize;
        let at = value * stride;
        let component = |c: usize| -> Result<u32, PrecomputedError> {
            let raw = data
                .get(at + 4 * c..at + 4 * c + 4)
                .ok_or_else(|| bad("position data shorter than its points".into()))?;
            let v = i32::from_le_bytes([raw[0], raw[1], raw[2], raw[3]]);
            u32::try_from(v).map_err(|_| bad(format!("negative coordinate {v}")))
        };
        positions.push([component(0)?, component(1)?, component(2)?]);
    }
    let triangles = mesh
        .faces()
        .iter()
        .map(|f| [f[0].0, f[1].0, f[2].0])
        .collect();
    Ok(QuantizedFragment {
        positions,
        triangles,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tetrahedron_round_trips() {
        let fragment = QuantizedFragment {
            positions: vec![[0, 0, 0], [1023, 0, 0], [0, 1023, 0], [0, 0, 1023]],
            triangles: vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        };
        let back = decode(&encode(&fragment).unwrap()).unwrap();
        // Draco may renumber the points: compare the triangles as position triples.
        let corners = |f: &QuantizedFragment| {
            let mut t: Vec<Vec<[u32; 3]>> = f
                .triangles
                .iter()
                .map(|t| {
                    let p = t.map(|v| f.positions[v as usize]);
                    let r = (0..3).min_by_key(|&i| p[i]).unwrap();
                    (0..3).map(|i| p[(r + i) % 3]).collect()
                })
                .collect();
            t.sort();
            t
        };
        assert_eq!(corners(&back), corners(&fragment));
        assert!(encode(&QuantizedFragment::default()).unwrap().is_empty());
    }
}
