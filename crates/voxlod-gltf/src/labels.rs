//! Every label's mesh of a label map in one binary glTF: one node and mesh per label, named by
//! its value (and its segment name when the map names it), coloured by the map's table (grey
//! without one), each vertex carrying its label value in the application-specific attribute
//! `_LABEL` (glTF 2.0 §3.7.2.1: such attribute names start with an underscore; a float scalar,
//! exact for labels up to 2^24). Positions, normals and indices are laid out as [`plain_streams`]
//! lays them out and the container is [`to_glb`]'s; the document is plain glTF with no
//! extension, and the file reads back with [`crate::read_glb`] (one part per label).
//!
//! Cost: linear in the meshes, one copy of them in the binary chunk (checked against the memory
//! budget before it is made).

use serde_json::{json, Value};
use voxlod_core::TriangleMesh;

use crate::chain::to_glb;
use crate::streams::{plain_streams, Component, Stream, StreamKind};
use crate::GltfError;

/// One label's mesh for [`labels_glb`].
#[derive(Clone, Copy, Debug)]
pub struct LabelMesh<'a> {
    /// The label value, stored per vertex as `_LABEL`.
    pub value: i64,
    /// Its segment name, in the node's name and the mesh's `extras`.
    pub name: Option<&'a str>,
    /// Its colour (linear RGB in 0–1), the material's base colour; grey when `None`.
    pub color: Option<[f32; 3]>,
    /// The mesh; a mesh without triangles gets no node.
    pub mesh: &'a TriangleMesh,
}

/// The glTF code of a component type.
fn component_code(c: Component) -> u32 {
    match c {
        Component::I8 => 5120,
        Component::U16 => 5123,
        Component::U32 => 5125,
        Component::F32 => 5126,
    }
}

/// The document's buffer views and accessors, and the binary chunk they point into.
#[derive(Default)]
struct Buffers {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Buffers {
    /// Appends `bytes` (4-byte aligned) as a view and an accessor; returns the accessor index.
    fn push(&mut self, bytes: &[u8], stride: Option<usize>, target: u32, accessor: Value) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let mut view = json!({
            "buffer": 0,
            "byteOffset": self.bin.len(),
            "byteLength": bytes.len(),
            "target": target,
        });
        if let Some(stride) = stride {
            view["byteStride"] = json!(stride);
        }
        self.bin.extend_from_slice(bytes);
        let mut accessor = accessor;
        accessor["bufferView"] = json!(self.views.len());
        self.views.push(view);
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }

    /// A stream of `voxlod-gltf`'s plain layout.
    fn stream(&mut self, s: &Stream) -> usize {
        let (kind, target, stride) = match s.kind {
            StreamKind::Indices => ("SCALAR", 34963, None),
            _ => ("VEC3", 34962, Some(s.stride)),
        };
        let mut accessor = json!({
            "componentType": component_code(s.component),
            "count": s.count,
            "type": kind,
        });
        if let Some((lo, hi)) = s.bounds {
            accessor["min"] = json!(lo);
            accessor["max"] = json!(hi);
        }
        self.push(&s.bytes, stride, target, accessor)
    }

    /// The `_LABEL` attribute: `value` for each of `count` vertices.
    fn label(&mut self, value: i64, count: usize) -> usize {
        let v = value as f32;
        let bytes: Vec<u8> = std::iter::repeat_n(v.to_le_bytes(), count)
            .flatten()
            .collect();
        let accessor = json!({
            "componentType": 5126,
            "count": count,
            "type": "SCALAR",
            "min": [v],
            "max": [v],
        });
        self.push(&bytes, Some(4), 34962, accessor)
    }
}

/// The node name of a label: `label 4` or `label 4 (liver)`.
fn node_name(value: i64, name: Option<&str>) -> String {
    match name.filter(|n| !n.is_empty()) {
        Some(n) => format!("label {value} ({n})"),
        None => format!("label {value}"),
    }
}

/// The `.glb` bytes of the labels' meshes (those with triangles), one node each in the order
/// given. Fails when the binary chunk would not fit in the memory limit
/// ([`GltfError::Core`]).
pub fn labels_glb(labels: &[LabelMesh]) -> Result<Vec<u8>, GltfError> {
    let size: usize = labels
        .iter()
        .map(|l| l.mesh.positions.len() * 28 + l.mesh.triangles.len() * 12)
        .sum();
    voxlod_core::memory::check_allocation("the labels' glTF buffer", size as u64)?;
    let mut buffers = Buffers::default();
    let (mut meshes, mut nodes, mut materials) = (Vec::new(), Vec::new(), Vec::new());
    for l in labels.iter().filter(|l| !l.mesh.triangles.is_empty()) {
        let mut attributes = serde_json::Map::new();
        let mut indices = None;
        // Plain streams of a triangle mesh: positions, normals, indices (no thick-edge widths).
        let streams = plain_streams(l.mesh);
        for s in streams.iter().filter(|s| s.kind != StreamKind::Widths) {
            let accessor = buffers.stream(s);
            let semantic = match s.kind {
                StreamKind::Positions => "POSITION",
                StreamKind::Normals => "NORMAL",
                _ => {
                    indices = Some(accessor);
                    continue;
                }
            };
            attributes.insert(semantic.into(), json!(accessor));
        }
        let label = buffers.label(l.value, l.mesh.positions.len());
        attributes.insert("_LABEL".into(), json!(label));
        let color = l.color.unwrap_or([0.8, 0.8, 0.8]);
        let name = node_name(l.value, l.name);
        materials.push(json!({
            "name": name,
            "pbrMetallicRoughness": {
                "baseColorFactor": [color[0], color[1], color[2], 1.0],
                "metallicFactor": 0.0,
                "roughnessFactor": 1.0,
            },
        }));
        let extras = json!({"label": l.value, "name": l.name});
        meshes.push(json!({
            "name": name,
            "primitives": [{
                "attributes": attributes,
                "indices": indices,
                "material": materials.len() - 1,
                "mode": 4,
            }],
            "extras": extras,
        }));
        nodes.push(json!({"name": name, "mesh": meshes.len() - 1, "extras": extras}));
    }
    let root = json!({
        "asset": {"version": "2.0", "generator": format!("voxlod {}", env!("CARGO_PKG_VERSION"))},
        "scene": 0,
        "scenes": [{"name": "labels", "nodes": (0..nodes.len()).collect::<Vec<_>>()}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "accessors": buffers.accessors,
        "bufferViews": buffers.views,
        "buffers": [{"byteLength": buffers.bin.len()}],
    });
    to_glb(&root, buffers.bin)
}
