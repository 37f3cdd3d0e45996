//! The bytes a glTF file's JSON points at: its buffers (the GLB's binary chunk, data URIs,
//! files beside it) and its images' encoded bytes, and `EXT_meshopt_compression` undone view by
//! view (meshoptimizer's decoders and filters, through the `meshopt` crate) so that every
//! buffer view is plain afterwards. Works on the JSON as a `serde_json::Value`, before the
//! `gltf` crate types it, because the crate refuses the compression extension it cannot read.
//!
//! Every declared length meets the memory limit before it is allocated, every range is
//! checked against the bytes it reads from, and a file named by a URI must lie beside the
//! glTF file (no absolute paths, no `..`). Cost: linear in the bytes read and decoded.

use std::path::Path;

use base64::Engine;
use serde_json::Value;
use voxlod_core::memory::check_allocation;

use crate::encode::decode_view;
use crate::GltfError;

pub(crate) const MESHOPT: &str = "EXT_meshopt_compression";

fn invalid(m: impl Into<String>) -> GltfError {
    GltfError::Invalid(m.into())
}

/// A count read from the JSON (absent is 0).
pub(crate) fn count(v: &Value, key: &str) -> Result<usize, GltfError> {
    match &v[key] {
        Value::Null => Ok(0),
        x => x
            .as_u64()
            .map(|n| n as usize)
            .ok_or_else(|| invalid(format!("{key} is not a count: {x}"))),
    }
}

/// The bytes of every buffer, in order. `bin` is the GLB's binary chunk (buffer 0 when it has
/// no URI); `base` the folder relative URIs are read from. A buffer without data (the fallback
/// of a meshopt-compressed file) is empty.
pub(crate) fn load_buffers(
    doc: &Value,
    bin: Option<&[u8]>,
    base: Option<&Path>,
) -> Result<Vec<Vec<u8>>, GltfError> {
    let empty = Vec::new();
    let buffers = doc["buffers"].as_array().unwrap_or(&empty);
    let mut out = Vec::with_capacity(buffers.len());
    for (i, buffer) in buffers.iter().enumerate() {
        let length =
            count(buffer, "byteLength").map_err(|e| invalid(format!("buffer {i}: {e}")))?;
        let data = match buffer["uri"].as_str() {
            Some(uri) => {
                check_allocation(&format!("buffer {i} ({length} bytes)"), length as u64)?;
                uri_bytes(uri, base).map_err(|e| invalid(format!("buffer {i}: {e}")))?
            }
            None if i == 0 && bin.is_some() => bin.unwrap_or_default().to_vec(),
            None => Vec::new(),
        };
        let fallback = buffer["extensions"][MESHOPT]["fallback"].as_bool() == Some(true);
        if data.len() < length && !fallback {
            return Err(invalid(format!(
                "buffer {i} holds {} bytes but declares {length}",
                data.len()
            )));
        }
        out.push(data);
    }
    Ok(out)
}

/// The bytes a URI names: a base64 data URI, or a file relative to `base`.
pub(crate) fn uri_bytes(uri: &str, base: Option<&Path>) -> Result<Vec<u8>, GltfError> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (_, data) = rest
            .split_once(";base64,")
            .ok_or_else(|| invalid("a data URI that is not base64"))?;
        check_allocation("a data URI", (data.len() as u64 / 4 + 1) * 3)?;
        return base64::engine::general_purpose::STANDARD
            .decode(data)
            .map_err(|e| invalid(format!("its data URI is not base64: {e}")));
    }
    let name = percent_decode(uri);
    let relative = Path::new(&name);
    let escapes = relative.is_absolute()
        || relative
            .components()
            .any(|c| matches!(c, std::path::Component::ParentDir))
        || name.contains("://");
    if escapes {
        return Err(invalid(format!(
            "'{uri}' is not a file beside the glTF file"
        )));
    }
    let base = base.ok_or_else(|| {
        invalid(format!(
            "'{uri}' names a file, and a .glb read from memory has no folder"
        ))
    })?;
    let path = base.join(relative);
    let cannot = |e: std::io::Error| invalid(format!("cannot read {}: {e}", path.display()));
    let len = std::fs::metadata(&path).map_err(cannot)?.len();
    check_allocation(&format!("reading {}", path.display()), len)?;
    std::fs::read(&path).map_err(cannot)
}

/// `%20` and the like decoded (URIs in glTF are percent-encoded); a malformed escape is kept.
fn percent_decode(uri: &str) -> String {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = bytes
            .get(i + 1..i + 3)
            .and_then(|h| std::str::from_utf8(h).ok());
        match (bytes[i], hex.and_then(|h| u8::from_str_radix(h, 16).ok())) {
            (b'%', Some(b)) => {
                out.push(b);
                i += 3;
            }
            (b, _) => {
                out.push(b);
                i += 1;
            }
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Every meshopt-compressed view decoded into a buffer of its own (appended to `buffers`), the
/// view pointed at it and the extension dropped from the JSON. A file without the extension is
/// left as it is.
pub(crate) fn decode_meshopt_views(
    doc: &mut Value,
    buffers: &mut Vec<Vec<u8>>,
) -> Result<(), GltfError> {
    let Some(views) = doc["bufferViews"].as_array_mut() else {
        return Ok(());
    };
    for (i, view) in views.iter_mut().enumerate() {
        let Some(ext) = view["extensions"].get(MESHOPT).cloned() else {
            continue;
        };
        let data = decode_one(view, &ext, buffers)
            .map_err(|e| invalid(format!("buffer view {i}: {e}")))?;
        view["buffer"] = Value::from(buffers.len());
        view["byteOffset"] = Value::from(0);
        view["byteLength"] = Value::from(data.len());
        if let Some(e) = view["extensions"].as_object_mut() {
            e.remove(MESHOPT);
        }
        buffers.push(data);
    }
    // The decoded views are new buffers: declare them so the document's indices hold.
    let lengths: Vec<usize> = buffers.iter().map(Vec::len).collect();
    let declared = doc["buffers"].as_array().map_or(0, Vec::len);
    if let Some(list) = doc["buffers"].as_array_mut() {
        for &len in &lengths[declared..] {
            list.push(serde_json::json!({ "byteLength": len.max(1) }));
        }
    }
    Ok(())
}

/// One compressed view decoded and unfiltered, padded to its declared length.
fn decode_one(view: &Value, ext: &Value, buffers: &[Vec<u8>]) -> Result<Vec<u8>, GltfError> {
    let length = count(view, "byteLength")?;
    let (source, offset, size) = (
        count(ext, "buffer")?,
        count(ext, "byteOffset")?,
        count(ext, "byteLength")?,
    );
    let (n, stride) = (count(ext, "count")?, count(ext, "byteStride")?);
    let decoded = n
        .checked_mul(stride)
        .ok_or_else(|| invalid("its size overflows"))?;
    if decoded > length {
        return Err(invalid(format!(
            "{n} × {stride} bytes do not fit its {length} bytes"
        )));
    }
    check_allocation("a decoded meshopt view", decoded as u64)?;
    let bytes = buffers
        .get(source)
        .ok_or_else(|| invalid(format!("buffer {source} does not exist")))?;
    let encoded = offset
        .checked_add(size)
        .and_then(|end| bytes.get(offset..end))
        .ok_or_else(|| {
            invalid(format!(
                "bytes {offset}..+{size} reach beyond buffer {source}"
            ))
        })?;
    let mode = ext["mode"].as_str().unwrap_or("");
    let mut data = match mode {
        "INDICES" => decode_sequence(encoded, n, stride)?,
        _ => decode_view(encoded, mode, n, stride)?,
    };
    unfilter(&mut data, ext["filter"].as_str().unwrap_or("NONE"), stride)?;
    data.resize(length, 0);
    Ok(data)
}

/// An index sequence (mode `INDICES`, for non-triangle primitives and the like).
fn decode_sequence(encoded: &[u8], n: usize, stride: usize) -> Result<Vec<u8>, GltfError> {
    let bad = |e: meshopt::Error| invalid(format!("meshopt data does not decode: {e}"));
    match stride {
        2 => Ok(meshopt::decode_index_sequence::<u16>(encoded, n)
            .map_err(bad)?
            .iter()
            .flat_map(|x| x.to_le_bytes())
            .collect()),
        4 => Ok(meshopt::decode_index_sequence::<u32>(encoded, n)
            .map_err(bad)?
            .iter()
            .flat_map(|x| x.to_le_bytes())
            .collect()),
        _ => Err(invalid(format!(
            "an index sequence of {stride}-byte indices"
        ))),
    }
}

/// meshoptimizer's filters undone in place: octahedral normals, quaternions, exponential
/// floats, YCoCg colours.
fn unfilter(data: &mut [u8], filter: &str, stride: usize) -> Result<(), GltfError> {
    match (filter, stride) {
        ("NONE", _) => {}
        ("OCTAHEDRAL", 4) => {
            let mut v: Vec<[i8; 4]> = data.chunks_exact(4).map(|c| c.map_i8()).collect();
            meshopt::decode_filter_oct(&mut v);
            put(data, v.iter().flat_map(|e| e.map(|x| x as u8)));
        }
        ("OCTAHEDRAL", 8) | ("QUATERNION", 8) => {
            let mut v: Vec<[i16; 4]> = data
                .chunks_exact(8)
                .map(|c| words(c).map(|w| w as i16))
                .collect();
            if filter == "QUATERNION" {
                meshopt::decode_filter_quat(&mut v);
            } else {
                meshopt::decode_filter_oct(&mut v);
            }
            put(
                data,
                v.iter()
                    .flat_map(|e| e.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<_>>()),
            );
        }
        ("EXPONENTIAL", s) if s % 4 == 0 => exponential(data, s)?,
        ("COLOR", 4) => {
            let mut v: Vec<[u8; 4]> = data
                .chunks_exact(4)
                .map(|c| [c[0], c[1], c[2], c[3]])
                .collect();
            meshopt::decode_filter_color(&mut v);
            put(data, v.into_iter().flatten());
        }
        ("COLOR", 8) => {
            let mut v: Vec<[u16; 4]> = data.chunks_exact(8).map(words).collect();
            meshopt::decode_filter_color(&mut v);
            put(
                data,
                v.iter()
                    .flat_map(|e| e.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<_>>()),
            );
        }
        (f, s) => {
            return Err(invalid(format!(
                "meshopt filter {f} on {s}-byte elements is not read"
            )))
        }
    }
    Ok(())
}

/// Four signed bytes.
trait MapI8 {
    fn map_i8(&self) -> [i8; 4];
}

impl MapI8 for [u8] {
    fn map_i8(&self) -> [i8; 4] {
        [self[0] as i8, self[1] as i8, self[2] as i8, self[3] as i8]
    }
}

/// Four little-endian 16-bit words of an 8-byte element.
fn words(c: &[u8]) -> [u16; 4] {
    std::array::from_fn(|k| u16::from_le_bytes([c[2 * k], c[2 * k + 1]]))
}

/// The bytes written back over `data` from the start.
fn put(data: &mut [u8], bytes: impl Iterator<Item = u8>) {
    for (d, b) in data.iter_mut().zip(bytes) {
        *d = b;
    }
}

/// The exponential filter for any number of 32-bit components per element.
fn exponential(data: &mut [u8], stride: usize) -> Result<(), GltfError> {
    macro_rules! run {
        ($n:literal) => {{
            let mut v: Vec<[u32; $n]> = data
                .chunks_exact(4 * $n)
                .map(|c| {
                    std::array::from_fn(|k| {
                        u32::from_le_bytes(c[4 * k..4 * k + 4].try_into().unwrap())
                    })
                })
                .collect();
            meshopt::decode_filter_exp(&mut v);
            for (c, e) in data.chunks_exact_mut(4 * $n).zip(&v) {
                for k in 0..$n {
                    c[4 * k..4 * k + 4].copy_from_slice(&e[k].to_le_bytes());
                }
            }
        }};
    }
    match stride / 4 {
        1 => run!(1),
        2 => run!(2),
        3 => run!(3),
        4 => run!(4),
        n => {
            return Err(invalid(format!(
                "the exponential filter on {n} components is not read"
            )))
        }
    }
    Ok(())
}
