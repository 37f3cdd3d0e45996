//! `KHR_draco_mesh_compression` undone primitive by primitive, so that the rest of the reader
//! sees plain primitives: each compressed primitive's buffer view is decoded by Draco, its
//! attributes and triangles are written as float and `u32` accessors in a new buffer, and the
//! extension is removed. Works on the JSON as a `serde_json::Value`, before the `gltf` crate
//! types it, as the meshopt views are undone (module `buffers`).
//!
//! The decoder is the `draco-core` crate (pure Rust), which reads what C++ Draco 1.x writes:
//! Blender's exporter, gltf-transform and glTF-Pipeline use it. Each attribute the extension
//! names is looked up by its Draco unique id and read as floats (Draco has already undone its
//! own quantization and octahedral normals); an integer attribute is normalized (glTF 2.0
//! §3.11) where its glTF accessor or its Draco attribute says so. New accessors are made for
//! the decoded data, so an accessor that several primitives name is never rewritten under one
//! of them; `POSITION` keeps its accessor's `min` and `max`.
//!
//! Every decode is capped by the memory limit (Draco's own ceilings on decoded bytes, points
//! and faces, set from what the limit still allows) and its result checked: a triangle with an
//! index beyond the decoded points, an attribute the stream lacks or with fewer components than
//! its accessor declares, is an error naming the mesh and primitive. Cost: linear in the
//! decoded points and triangles.

use draco_core::{DataType, DecodeLimits, DecoderBuffer, Mesh, MeshDecoder, PointAttribute};
use serde_json::{json, Value};
use voxlod_core::memory::{available_bytes, check_allocation};

use super::buffers::count;
use crate::GltfError;

/// The extension's name.
pub(crate) const DRACO: &str = "KHR_draco_mesh_compression";

/// glTF's component type for 32-bit floats and unsigned ints.
const FLOAT: u32 = 5126;
const UNSIGNED_INT: u32 = 5125;

/// Every Draco-compressed primitive of `doc` decoded into a new buffer (appended to `buffers`
/// and declared in the JSON) and made plain. Errors name the mesh and primitive.
pub(crate) fn decode_draco_primitives(
    doc: &mut Value,
    buffers: &mut Vec<Vec<u8>>,
) -> Result<(), GltfError> {
    let meshes = doc["meshes"].as_array().map_or(0, Vec::len);
    let mut out = Decoded::new(buffers.len());
    for m in 0..meshes {
        let primitives = doc["meshes"][m]["primitives"]
            .as_array()
            .map_or(0, Vec::len);
        for p in 0..primitives {
            let ext = doc["meshes"][m]["primitives"][p]["extensions"][DRACO].clone();
            if ext.is_null() {
                continue;
            }
            let here = |e: GltfError| match e {
                GltfError::Invalid(w) => {
                    GltfError::Invalid(format!("mesh {m}, primitive {p} ({DRACO}): {w}"))
                }
                other => other,
            };
            let primitive = decode_primitive(doc, &ext, buffers, (m, p), &mut out).map_err(here)?;
            doc["meshes"][m]["primitives"][p] = primitive;
        }
    }
    out.declare(doc, buffers);
    Ok(())
}

/// The new buffer and the views and accessors that point into it.
struct Decoded {
    /// Index the new buffer will have.
    buffer: usize,
    bytes: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
    /// (the file's accessor, the new one made for it): the file's, which have no data, are
    /// given the new one's, since the `gltf` crate refuses an accessor without data.
    aliases: Vec<(usize, usize)>,
}

impl Decoded {
    fn new(buffer: usize) -> Decoded {
        Decoded {
            buffer,
            bytes: Vec::new(),
            views: Vec::new(),
            accessors: Vec::new(),
            aliases: Vec::new(),
        }
    }

    /// Appends `data` as a view and an accessor over it (`count` elements of `kind`), and
    /// returns the accessor's index once declared (after the document's own accessors).
    fn push(
        &mut self,
        data: &[u8],
        component: u32,
        kind: &str,
        count: usize,
        doc: &Value,
    ) -> usize {
        while !self.bytes.len().is_multiple_of(4) {
            self.bytes.push(0);
        }
        let views_before = doc["bufferViews"].as_array().map_or(0, Vec::len);
        let accessors_before = doc["accessors"].as_array().map_or(0, Vec::len);
        self.views.push(json!({
            "buffer": self.buffer,
            "byteOffset": self.bytes.len(),
            "byteLength": data.len(),
        }));
        self.bytes.extend_from_slice(data);
        self.accessors.push(json!({
            "bufferView": views_before + self.views.len() - 1,
            "componentType": component,
            "type": kind,
            "count": count,
        }));
        accessors_before + self.accessors.len() - 1
    }

    /// Adds the views, accessors and buffer to the document and the buffer to `buffers`.
    fn declare(self, doc: &mut Value, buffers: &mut Vec<Vec<u8>>) {
        if self.views.is_empty() {
            return;
        }
        let list = |doc: &mut Value, key: &str| {
            if !doc[key].is_array() {
                doc[key] = json!([]);
            }
            doc[key]
                .as_array_mut()
                .map(std::mem::take)
                .unwrap_or_default()
        };
        for (key, items) in [("bufferViews", self.views), ("accessors", self.accessors)] {
            let mut all = list(doc, key);
            all.extend(items);
            doc[key] = Value::Array(all);
        }
        for (old, new) in self.aliases {
            let no_data = doc["accessors"][old].get("bufferView").is_none()
                && doc["accessors"][old].get("sparse").is_none();
            if no_data && doc["accessors"][old].is_object() {
                doc["accessors"][old] = doc["accessors"][new].clone();
            }
        }
        let mut all = list(doc, "buffers");
        while all.len() < self.buffer {
            all.push(json!({"byteLength": 1}));
        }
        all.push(json!({ "byteLength": self.bytes.len().max(1) }));
        doc["buffers"] = Value::Array(all);
        buffers.push(self.bytes);
    }
}

/// One primitive decoded: its JSON with the extension removed and its attributes and indices
/// naming new accessors in `out`.
fn decode_primitive(
    doc: &Value,
    ext: &Value,
    buffers: &[Vec<u8>],
    (m, p): (usize, usize),
    out: &mut Decoded,
) -> Result<Value, GltfError> {
    let invalid = |w: String| GltfError::Invalid(w);
    let mut primitive = doc["meshes"][m]["primitives"][p].clone();
    let mode = primitive["mode"].as_u64().unwrap_or(4);
    if mode != 4 && mode != 5 {
        return Err(invalid(format!("mode {mode}: only triangles are read")));
    }
    let bytes = view_bytes(doc, buffers, count(ext, "bufferView")?)?;
    let mesh = decode(bytes)?;
    let points = mesh.num_points();
    let names = ext["attributes"]
        .as_object()
        .ok_or_else(|| invalid("no attributes".into()))?;
    let mut attributes = primitive["attributes"]
        .as_object()
        .cloned()
        .unwrap_or_default();
    for (name, id) in names {
        let id = id
            .as_u64()
            .and_then(|i| u32::try_from(i).ok())
            .ok_or_else(|| invalid(format!("{name}'s id {id} is not a count")))?;
        let accessor = attributes
            .get(name)
            .and_then(Value::as_u64)
            .map(|a| doc["accessors"][a as usize].clone())
            .ok_or_else(|| invalid(format!("{name} names no accessor of the primitive")))?;
        let attribute = mesh
            .attribute_by_unique_id(id)
            .ok_or_else(|| invalid(format!("{name}: the stream has no attribute {id}")))?;
        let new = add_attribute(name, attribute, &accessor, points, doc, out)?;
        out.aliases
            .push((attributes[name].as_u64().unwrap_or(0) as usize, new));
        attributes.insert(name.clone(), Value::from(new));
    }
    let mut flat = Vec::with_capacity(12 * mesh.num_faces());
    for v in mesh.faces().iter().flat_map(|f| [f[0].0, f[1].0, f[2].0]) {
        if v as usize >= points {
            return Err(invalid(format!("index {v} beyond its {points} points")));
        }
        flat.extend_from_slice(&v.to_le_bytes());
    }
    let indices = out.push(&flat, UNSIGNED_INT, "SCALAR", 3 * mesh.num_faces(), doc);
    if let Some(old) = primitive["indices"].as_u64() {
        out.aliases.push((old as usize, indices));
    }
    primitive["attributes"] = Value::Object(attributes);
    primitive["indices"] = Value::from(indices);
    primitive["mode"] = Value::from(4);
    if let Some(e) = primitive["extensions"].as_object_mut() {
        e.remove(DRACO);
    }
    Ok(primitive)
}

/// The bytes of buffer view `view`, checked against its buffer.
fn view_bytes<'b>(doc: &Value, buffers: &'b [Vec<u8>], view: usize) -> Result<&'b [u8], GltfError> {
    let v = &doc["bufferViews"][view];
    if v.is_null() {
        return Err(GltfError::Invalid(format!(
            "buffer view {view} does not exist"
        )));
    }
    let (buffer, offset, length) = (
        count(v, "buffer")?,
        count(v, "byteOffset")?,
        count(v, "byteLength")?,
    );
    (buffers.get(buffer))
        .and_then(|b| b.get(offset..offset.checked_add(length)?))
        .ok_or_else(|| {
            GltfError::Invalid(format!(
                "buffer view {view} (bytes {offset}..+{length} of buffer {buffer}) reaches beyond its buffer"
            ))
        })
}

/// A Draco stream decoded, within what the memory limit still allows.
fn decode(bytes: &[u8]) -> Result<Mesh, GltfError> {
    let room = available_bytes()?;
    let limits = DecodeLimits::default()
        .with_max_decoded_bytes(room / 2)
        .with_max_points(room / 24)
        .with_max_faces(room / 24);
    let mut mesh = Mesh::new();
    MeshDecoder::new()
        .decode(
            &mut DecoderBuffer::new(bytes).with_limits(limits),
            &mut mesh,
        )
        .map_err(|e| GltfError::Invalid(format!("Draco cannot decode it: {e}")))?;
    Ok(mesh)
}

/// `attribute` (glTF attribute `name`, declared by `accessor`) for `points` points as floats in
/// a new accessor of `out`; its index.
fn add_attribute(
    name: &str,
    attribute: &PointAttribute,
    accessor: &Value,
    points: usize,
    doc: &Value,
    out: &mut Decoded,
) -> Result<usize, GltfError> {
    let kind = accessor["type"].as_str().unwrap_or("");
    let components = match kind {
        "SCALAR" => 1,
        "VEC2" => 2,
        "VEC3" => 3,
        "VEC4" => 4,
        _ => {
            return Err(GltfError::Invalid(format!(
                "{name}'s accessor has type {kind:?}"
            )))
        }
    };
    let has = attribute.num_components() as usize;
    if has < components {
        return Err(GltfError::Invalid(format!(
            "{name} has {has} components where its accessor declares {kind}"
        )));
    }
    check_allocation(
        &format!("{name}'s {points} decoded values"),
        (points as u64).saturating_mul(4 * components as u64),
    )?;
    let mut values = attribute.read_f32s(points, components);
    let normalized = accessor["normalized"].as_bool() == Some(true) || attribute.normalized();
    if let Some(scale) = normalized
        .then(|| integer_scale(attribute.data_type()))
        .flatten()
    {
        values.iter_mut().for_each(|v| *v = (*v / scale).max(-1.0));
    }
    let data: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    let index = out.push(&data, FLOAT, kind, points, doc);
    let new = out.accessors.last_mut().expect("just pushed");
    for key in ["min", "max"] {
        if name == "POSITION" && !accessor[key].is_null() {
            new[key] = accessor[key].clone();
        }
    }
    Ok(index)
}

/// What a normalized integer of `data` divides by to reach -1..1 or 0..1 (glTF 2.0 §3.11);
/// `None` for floats.
fn integer_scale(data: DataType) -> Option<f32> {
    Some(match data {
        DataType::Int8 => 127.0,
        DataType::Uint8 => 255.0,
        DataType::Int16 => 32767.0,
        DataType::Uint16 => 65535.0,
        DataType::Int32 => 2147483647.0,
        DataType::Uint32 => 4294967295.0,
        _ => return None,
    })
}
