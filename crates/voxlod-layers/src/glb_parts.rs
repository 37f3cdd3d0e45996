//! The glTF pieces every layered `.glb` is built of: buffer views of the one buffer and the
//! accessors over them (modules `glb`, `glb_looks` and `glb_chain`). Cost: constant per piece.

use gltf::json;
use gltf::json::validation::{Checked, USize64};

/// Adds a view of `bytes` of buffer 0 to `root`.
pub(crate) fn push_view(
    root: &mut json::Root,
    bytes: std::ops::Range<usize>,
    stride: Option<usize>,
    target: Option<json::buffer::Target>,
    name: &str,
) -> json::Index<json::buffer::View> {
    root.push(json::buffer::View {
        buffer: json::Index::new(0),
        byte_length: USize64(bytes.len() as u64),
        byte_offset: Some(USize64(bytes.start as u64)),
        byte_stride: stride.map(json::buffer::Stride),
        name: Some(name.into()),
        target: target.map(Checked::Valid),
        extensions: None,
        extras: None,
    })
}

/// An accessor of `count` elements of `view` from byte `offset`.
pub(crate) fn accessor(
    view: json::Index<json::buffer::View>,
    offset: usize,
    count: usize,
    component: json::accessor::ComponentType,
    kind: json::accessor::Type,
    bounds: Option<([f32; 3], [f32; 3])>,
    name: String,
) -> json::Accessor {
    json::Accessor {
        buffer_view: Some(view),
        byte_offset: Some(USize64(offset as u64)),
        count: USize64(count as u64),
        component_type: Checked::Valid(json::accessor::GenericComponentType(component)),
        extensions: None,
        extras: None,
        type_: Checked::Valid(kind),
        min: bounds.map(|b| serde_json::json!(b.0)),
        max: bounds.map(|b| serde_json::json!(b.1)),
        name: Some(name),
        normalized: false,
        sparse: None,
    }
}
