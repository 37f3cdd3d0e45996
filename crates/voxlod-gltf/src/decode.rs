//! Undoing `EXT_meshopt_compression`: a `.glb` whose buffer views are meshopt-encoded becomes
//! one with the same JSON but plain views in a single buffer, so that a reader without a
//! meshopt decoder (the viewer page) can take it. Quantized attributes stay quantized
//! (`KHR_mesh_quantization` is core WebGL work). Every count read from the file goes through
//! the memory limit and is checked against the view it fills; a broken file is an error,
//! never a panic.
//!
//! Cost: linear in the decoded size.

use serde_json::Value;

use crate::encode::decode_view;
use crate::GltfError;

const EXT: &str = "EXT_meshopt_compression";

/// The file with plain buffer views (the input itself when nothing is compressed).
pub fn decompress_glb(bytes: &[u8]) -> Result<Vec<u8>, GltfError> {
    let glb = gltf::binary::Glb::from_slice(bytes)
        .map_err(|e| GltfError::Invalid(format!("not a GLB file: {e}")))?;
    let mut doc: Value = serde_json::from_slice(&glb.json)
        .map_err(|e| GltfError::Invalid(format!("bad JSON chunk: {e}")))?;
    let uses = |doc: &Value| {
        doc["extensionsUsed"]
            .as_array()
            .is_some_and(|a| a.iter().any(|x| x == EXT))
    };
    if !uses(&doc) {
        return Ok(bytes.to_vec());
    }
    let bin: &[u8] = glb.bin.as_deref().unwrap_or(&[]);
    let views = doc["bufferViews"].as_array().cloned().unwrap_or_default();
    let mut out = Vec::new();
    for (i, view) in views.iter().enumerate() {
        let data = view_bytes(view, bin)
            .map_err(|m| GltfError::Invalid(format!("buffer view {i}: {m}")))?;
        let at = out.len();
        out.extend_from_slice(&data);
        out.resize(out.len().next_multiple_of(4), 0);
        let v = &mut doc["bufferViews"][i];
        v["buffer"] = Value::from(0);
        v["byteOffset"] = Value::from(at);
        v["byteLength"] = Value::from(data.len());
        if let Some(ext) = v.get_mut("extensions").and_then(Value::as_object_mut) {
            ext.remove(EXT);
        }
    }
    doc["buffers"] = serde_json::json!([{"byteLength": out.len()}]);
    for key in ["extensionsUsed", "extensionsRequired"] {
        if let Some(list) = doc.get_mut(key).and_then(Value::as_array_mut) {
            list.retain(|x| x != EXT);
        }
    }
    let json = serde_json::to_vec(&doc).map_err(|e| GltfError::Encode(e.to_string()))?;
    let glb = gltf::binary::Glb {
        header: glb.header,
        json: json.into(),
        bin: Some(out.into()),
    };
    glb.to_vec().map_err(|e| GltfError::Encode(e.to_string()))
}

/// The plain bytes of one view: decoded, or copied from the GLB's own buffer.
fn view_bytes(view: &Value, bin: &[u8]) -> Result<Vec<u8>, String> {
    let num = |v: &Value, key: &str| -> Result<usize, String> {
        match &v[key] {
            Value::Null => Ok(0),
            x => x
                .as_u64()
                .map(|n| n as usize)
                .ok_or_else(|| format!("{key} is not a count")),
        }
    };
    let length = num(view, "byteLength")?;
    if let Some(ext) = view["extensions"].get(EXT) {
        let (offset, size) = (num(ext, "byteOffset")?, num(ext, "byteLength")?);
        let (count, stride) = (num(ext, "count")?, num(ext, "byteStride")?);
        if num(ext, "buffer")? != 0 {
            return Err("compressed data outside the GLB's own buffer".into());
        }
        let decoded = count.checked_mul(stride).ok_or("its size overflows")?;
        if decoded > length {
            return Err(format!(
                "{count} × {stride} bytes do not fit its {length} bytes"
            ));
        }
        voxlod_core::memory::check_allocation("a decoded meshopt view", decoded as u64)
            .map_err(|e| e.to_string())?;
        let encoded = slice(bin, offset, size)?;
        let mode = ext["mode"].as_str().unwrap_or("");
        if ext.get("filter").is_some_and(|f| f != "NONE") {
            return Err("meshopt filters are not read".into());
        }
        let mut data = decode_view(encoded, mode, count, stride).map_err(|e| e.to_string())?;
        data.resize(length, 0);
        return Ok(data);
    }
    if num(view, "buffer")? != 0 {
        return Err("data outside the GLB's own buffer".into());
    }
    Ok(slice(bin, num(view, "byteOffset")?, length)?.to_vec())
}

fn slice(bin: &[u8], offset: usize, len: usize) -> Result<&[u8], String> {
    offset
        .checked_add(len)
        .filter(|&end| end <= bin.len())
        .map(|end| &bin[offset..end])
        .ok_or_else(|| {
            format!(
                "bytes {offset}..+{len} reach beyond the {}-byte buffer",
                bin.len()
            )
        })
}
