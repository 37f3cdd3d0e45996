//! Undoing `EXT_meshopt_compression` and `KHR_draco_mesh_compression`: a `.glb` whose buffer
//! views are meshopt-encoded or whose primitives are Draco streams becomes one with plain views
//! in a single buffer, so that a reader without their decoders (the viewer page) can take it;
//! GPU instances (`EXT_mesh_gpu_instancing`) become child nodes.
//! The decoding is the scene reader's (module `scene`: meshopt filters included). Quantized
//! attributes stay quantized (`KHR_mesh_quantization` is core WebGL work). Every count read
//! from the file goes through the memory limit and is checked against the view it fills; a
//! broken file is an error, never a panic.
//!
//! Cost: linear in the decoded size.

use serde_json::{json, Value};

use crate::scene::buffers::{decode_meshopt_views, load_buffers, MESHOPT};
use crate::scene::draco::{decode_draco_primitives, DRACO};
use crate::scene::nodes::{instances, INSTANCING};
use crate::scene::typed_document;
use crate::GltfError;

/// The file with plain buffer views in one buffer (the input itself when nothing is
/// compressed): meshopt views and Draco primitives decoded as the scene reader decodes them
/// (module `scene`), the extensions dropped from the lists.
pub fn decompress_glb(bytes: &[u8]) -> Result<Vec<u8>, GltfError> {
    let glb = gltf::binary::Glb::from_slice(bytes)
        .map_err(|e| GltfError::Invalid(format!("not a GLB file: {e}")))?;
    let mut doc: Value = serde_json::from_slice(&glb.json)
        .map_err(|e| GltfError::Invalid(format!("bad JSON chunk: {e}")))?;
    let uses = |doc: &Value, ext: &str| {
        doc["extensionsUsed"]
            .as_array()
            .is_some_and(|a| a.iter().any(|x| x == ext))
    };
    if ![MESHOPT, DRACO, INSTANCING].iter().any(|e| uses(&doc, e)) {
        return Ok(bytes.to_vec());
    }
    let mut buffers = load_buffers(&doc, glb.bin.as_deref(), None)?;
    decode_meshopt_views(&mut doc, &mut buffers)?;
    decode_draco_primitives(&mut doc, &mut buffers)?;
    let out = one_buffer(&mut doc, &buffers)?;
    if uses(&doc, INSTANCING) {
        instances_as_nodes(&mut doc, std::slice::from_ref(&out))?;
    }
    for key in ["extensionsUsed", "extensionsRequired"] {
        if let Some(list) = doc.get_mut(key).and_then(Value::as_array_mut) {
            list.retain(|x| x != MESHOPT && x != DRACO && x != INSTANCING);
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

/// `buffers` laid end to end (each 4-byte aligned) as the document's one buffer, every view
/// re-pointed into it.
fn one_buffer(doc: &mut Value, buffers: &[Vec<u8>]) -> Result<Vec<u8>, GltfError> {
    let mut starts = Vec::with_capacity(buffers.len());
    let mut out = Vec::new();
    for b in buffers {
        starts.push(out.len());
        out.extend_from_slice(b);
        out.resize(out.len().next_multiple_of(4), 0);
    }
    for (i, view) in (doc["bufferViews"].as_array_mut().into_iter().flatten()).enumerate() {
        let buffer = view["buffer"].as_u64().unwrap_or(0) as usize;
        let start = starts.get(buffer).ok_or_else(|| {
            GltfError::Invalid(format!("buffer view {i}: buffer {buffer} does not exist"))
        })?;
        let offset = view["byteOffset"].as_u64().unwrap_or(0) as usize;
        view["buffer"] = Value::from(0);
        view["byteOffset"] = Value::from(start + offset);
    }
    doc["buffers"] = json!([{"byteLength": out.len()}]);
    Ok(out)
}

/// Every node drawing its mesh under `EXT_mesh_gpu_instancing` made a node with a child per
/// instance (the instance's transform as the child's matrix, the mesh on the child), read as
/// the scene reader reads them (module `scene::nodes`); `buffers` holds the document's one
/// buffer.
fn instances_as_nodes(doc: &mut Value, buffers: &[Vec<u8>]) -> Result<(), GltfError> {
    let document = typed_document(doc)?;
    let mut added = Vec::new();
    for node in document.nodes() {
        let json = &doc["nodes"][node.index()];
        if json["extensions"][INSTANCING].is_null() {
            continue;
        }
        let mesh = json["mesh"].clone();
        let mut children: Vec<Value> = json["children"].as_array().cloned().unwrap_or_default();
        for m in instances(&node, &document, doc, buffers)? {
            let first = doc["nodes"].as_array().map_or(0, Vec::len) + added.len();
            children.push(Value::from(first));
            added.push(json!({"mesh": mesh, "matrix": m.to_cols_array()}));
        }
        let n = &mut doc["nodes"][node.index()];
        n["children"] = Value::Array(children);
        if let Some(o) = n.as_object_mut() {
            o.remove("mesh");
        }
        if let Some(e) = n["extensions"].as_object_mut() {
            e.remove(INSTANCING);
        }
    }
    if let Some(nodes) = doc["nodes"].as_array_mut() {
        nodes.extend(added);
    }
    Ok(())
}
