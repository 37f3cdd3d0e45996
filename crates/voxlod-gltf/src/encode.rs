//! meshoptimizer's codecs over one buffer view (`EXT_meshopt_compression`): vertex streams in
//! `ATTRIBUTES` mode (codec version 0, the one the extension names), index streams in
//! `TRIANGLES` mode (index codec version 1). No filter is applied. Decoding is the inverse, for
//! readers that want the plain layout back ([`crate::decode`]).
//!
//! Cost: linear in the stream.

use serde_json::{json, Value};

use crate::streams::{Stream, StreamKind};
use crate::GltfError;

/// The `EXT_meshopt_compression` object of a buffer view whose stream `s` was encoded into
/// `length` bytes at `offset` of buffer 0: `ATTRIBUTES` mode for vertex streams, `TRIANGLES`
/// for indices, no filter.
pub fn view_extension(s: &Stream, offset: usize, length: usize) -> Value {
    let mode = if s.kind == StreamKind::Indices {
        "TRIANGLES"
    } else {
        "ATTRIBUTES"
    };
    json!({
        "buffer": 0,
        "byteOffset": offset,
        "byteLength": length,
        "byteStride": s.stride,
        "count": s.count,
        "mode": mode,
    })
}

/// The encoded bytes of a stream.
pub fn encode_stream(s: &Stream) -> Result<Vec<u8>, GltfError> {
    let bad = |e: meshopt::Error| GltfError::Meshopt(e.to_string());
    match s.kind {
        StreamKind::Indices => {
            let indices = widen_indices(&s.bytes, s.stride)?;
            if indices.len() % 3 != 0 {
                return Err(GltfError::Meshopt(format!(
                    "{} indices is not a whole number of triangles",
                    indices.len()
                )));
            }
            let vertices = indices.iter().max().map_or(0, |&m| m as usize + 1);
            meshopt::encode_index_buffer(&indices, vertices).map_err(bad)
        }
        _ => match s.stride {
            4 => meshopt::encode_vertex_buffer(&elements::<4>(&s.bytes)).map_err(bad),
            8 => meshopt::encode_vertex_buffer(&elements::<8>(&s.bytes)).map_err(bad),
            12 => meshopt::encode_vertex_buffer(&elements::<12>(&s.bytes)).map_err(bad),
            16 => meshopt::encode_vertex_buffer(&elements::<16>(&s.bytes)).map_err(bad),
            other => Err(GltfError::Meshopt(format!(
                "unsupported vertex stride {other}"
            ))),
        },
    }
}

/// Decodes one `EXT_meshopt_compression` view into `count × stride` bytes.
pub fn decode_view(
    encoded: &[u8],
    mode: &str,
    count: usize,
    stride: usize,
) -> Result<Vec<u8>, GltfError> {
    let bad = |e: meshopt::Error| GltfError::Invalid(format!("meshopt data does not decode: {e}"));
    match (mode, stride) {
        ("TRIANGLES", 2) => {
            let v: Vec<u16> = meshopt::decode_index_buffer(encoded, count).map_err(bad)?;
            Ok(v.iter().flat_map(|x| x.to_le_bytes()).collect())
        }
        ("TRIANGLES", 4) => {
            let v: Vec<u32> = meshopt::decode_index_buffer(encoded, count).map_err(bad)?;
            Ok(v.iter().flat_map(|x| x.to_le_bytes()).collect())
        }
        ("ATTRIBUTES", 4) => Ok(flatten(
            meshopt::decode_vertex_buffer::<[u8; 4]>(encoded, count).map_err(bad)?,
        )),
        ("ATTRIBUTES", 8) => Ok(flatten(
            meshopt::decode_vertex_buffer::<[u8; 8]>(encoded, count).map_err(bad)?,
        )),
        ("ATTRIBUTES", 12) => Ok(flatten(
            meshopt::decode_vertex_buffer::<[u8; 12]>(encoded, count).map_err(bad)?,
        )),
        ("ATTRIBUTES", 16) => Ok(flatten(
            meshopt::decode_vertex_buffer::<[u8; 16]>(encoded, count).map_err(bad)?,
        )),
        _ => Err(GltfError::Invalid(format!(
            "meshopt mode {mode} with stride {stride} is not read"
        ))),
    }
}

fn flatten<const N: usize>(v: Vec<[u8; N]>) -> Vec<u8> {
    v.into_iter().flatten().collect()
}

fn elements<const N: usize>(bytes: &[u8]) -> Vec<[u8; N]> {
    bytes
        .chunks_exact(N)
        .map(|c| c.try_into().expect("chunks_exact gives N bytes"))
        .collect()
}

fn widen_indices(bytes: &[u8], stride: usize) -> Result<Vec<u32>, GltfError> {
    match stride {
        2 => Ok(bytes
            .chunks_exact(2)
            .map(|c| u16::from_le_bytes([c[0], c[1]]) as u32)
            .collect()),
        4 => Ok(bytes
            .chunks_exact(4)
            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect()),
        other => Err(GltfError::Meshopt(format!(
            "unsupported index size {other}"
        ))),
    }
}
