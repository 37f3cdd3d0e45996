//! Reading a glTF 2.0 asset (`.gltf` with external or embedded buffers and images, or `.glb`)
//! as a [`voxlod_asset::Asset`]: the scene's node hierarchy flattened into one world-space mesh
//! with its attributes and a material per triangle ([`nodes`]), the metallic-roughness
//! materials and the images' encoded bytes ([`materials`]).
//!
//! Extensions read: `KHR_mesh_quantization` (integer attributes, [`accessor`]),
//! `EXT_meshopt_compression` (decoded with meshoptimizer, filters included, [`buffers`]),
//! `KHR_texture_transform`, `KHR_materials_emissive_strength`, `KHR_texture_basisu` (a KTX2
//! image read as it is, [`materials::basisu_sources`]), `KHR_draco_mesh_compression` (decoded
//! with Draco, [`draco`]), `EXT_mesh_gpu_instancing` (every instance placed, [`nodes`]), and
//! `MSFT_lod` chains (their finest level). A file that requires another extension is refused
//! with its name; one that only uses another gets a warning that it is ignored. The JSON is validated by the `gltf` crate (indices in range, required fields) after
//! the extensions it does not know are handled here.
//!
//! [`write`] writes levels of an asset back, with their looks, in either of two layouts,
//! plain or compressed (`columns`: each primitive's streams).
//!
//! Cost: linear in the file, its buffers and images; every size meets the memory limit first.

mod accessor;
pub(crate) mod buffers;
mod columns;
pub(crate) mod draco;
mod materials;
pub(crate) mod nodes;
pub mod write;

use std::path::Path;

use serde_json::Value;
use voxlod_asset::{Asset, Material};
use voxlod_core::glam::DVec3;

use crate::GltfError;

pub use write::{asset_glb, positions_grid, AssetGlbOptions, Layout};

/// Extensions this reader understands.
const READ: [&str; 9] = [
    "KHR_mesh_quantization",
    "EXT_meshopt_compression",
    draco::DRACO,
    nodes::INSTANCING,
    "KHR_texture_transform",
    "KHR_materials_emissive_strength",
    "KHR_texture_basisu",
    "MSFT_lod",
    "MSFT_screencoverage",
];

/// An asset read from a glTF file, and what was left out of it.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneRead {
    /// The asset.
    pub asset: Asset,
    /// What the reader ignored or left out (unknown extensions, primitives that are not
    /// surfaces), in words.
    pub warnings: Vec<String>,
    /// The world point the asset's positions are relative to: zero, but for a scene far from
    /// the origin (map coordinates), a point near its centre (module `nodes`), which
    /// [`AssetGlbOptions::origin`] puts back.
    pub origin: DVec3,
}

/// Reads a `.gltf` or `.glb` file; relative URIs are read beside it. Errors name the file:
/// one that cannot be read is [`GltfError::Io`] (of kind `Access`), one that is not a usable
/// glTF file [`GltfError::Invalid`].
pub fn read_scene(path: &Path) -> Result<SceneRead, GltfError> {
    let bytes = crate::file::file_bytes(path)?;
    parse_scene(&bytes, path.parent()).map_err(|e| crate::file::named(path, e))
}

/// Parses a `.gltf` (JSON) or `.glb` (binary) file's bytes; `base` is the folder its relative
/// URIs are read from (none for bytes from memory, which then may only embed their data).
pub fn parse_scene(bytes: &[u8], base: Option<&Path>) -> Result<SceneRead, GltfError> {
    let invalid = |m: String| GltfError::Invalid(m);
    let (json, bin) = if bytes.starts_with(b"glTF") {
        let glb = gltf::binary::Glb::from_slice(bytes)
            .map_err(|e| invalid(format!("not a GLB file: {e}")))?;
        (glb.json.into_owned(), glb.bin.map(|b| b.into_owned()))
    } else {
        (bytes.to_vec(), None)
    };
    let mut doc: Value = serde_json::from_slice(&json)
        .map_err(|e| invalid(format!("its JSON does not parse: {e}")))?;
    let mut warnings = check_extensions(&mut doc)?;
    warnings.extend(materials::basisu_sources(&mut doc));
    let mut buffers = buffers::load_buffers(&doc, bin.as_deref(), base)?;
    buffers::decode_meshopt_views(&mut doc, &mut buffers)?;
    draco::decode_draco_primitives(&mut doc, &mut buffers)?;
    check_position_accessors(&doc)?;
    let document = typed_document(&doc)?;
    let mut materials = materials::materials(&document, &doc);
    let images = materials::images(&document, &doc, &buffers, base)?;
    let flat = nodes::flatten(&document, &doc, &buffers, &mut warnings)?;
    if flat.mesh.triangles.is_empty() {
        return Err(GltfError::NoTriangles);
    }
    let origin = flat.origin;
    if origin != DVec3::ZERO {
        let [x, y, z] = origin.to_array();
        warnings.push(format!(
            "the scene lies far from the origin: it is read relative to ({x}, {y}, {z}), which \
             the levels written as glTF carry as their nodes' translation"
        ));
    }
    // Primitives without a material take glTF's default one, added last.
    let default = materials.len() as u32;
    if flat.material.iter().any(Option::is_none) {
        materials.push(Material {
            name: "default".into(),
            ..Material::default()
        });
    }
    let mut mesh = flat.mesh;
    mesh.material = flat
        .material
        .iter()
        .map(|m| m.map_or(default, |k| k as u32))
        .collect();
    let asset = Asset {
        mesh,
        materials,
        images,
        parts: flat.parts,
    };
    asset.validate().map_err(|e| invalid(e.to_string()))?;
    Ok(SceneRead {
        asset,
        warnings,
        origin,
    })
}

/// The document typed and validated by the `gltf` crate, which refuses required extensions
/// it does not know: they are left out of the copy it types (the readers here handle or refuse
/// them first).
pub(crate) fn typed_document(doc: &Value) -> Result<gltf::Document, GltfError> {
    let mut typed = doc.clone();
    if let Some(o) = typed.as_object_mut() {
        o.remove("extensionsRequired");
        // The readers index the document by name, which leaves `null` for an array the file
        // does not have (a scene without buffers); glTF leaves such arrays out.
        o.retain(|_, v| !v.is_null());
    }
    let root: gltf::json::Root = serde_json::from_value(typed)
        .map_err(|e| GltfError::Invalid(format!("not a glTF 2.0 document: {e}")))?;
    gltf::Document::from_json(root)
        .map_err(|e| GltfError::Invalid(format!("not a valid glTF 2.0 document: {e}")))
}

/// Refuses a primitive whose `POSITION` names a missing accessor. gltf-json 1.4.1's validation
/// of primitives reads that accessor before it checks the index (and panics), so the check
/// comes first, here and only here.
fn check_position_accessors(doc: &Value) -> Result<(), GltfError> {
    let accessors = doc["accessors"].as_array().map_or(0, Vec::len);
    for (m, mesh) in doc["meshes"].as_array().into_iter().flatten().enumerate() {
        for (p, primitive) in mesh["primitives"]
            .as_array()
            .into_iter()
            .flatten()
            .enumerate()
        {
            let position = &primitive["attributes"]["POSITION"];
            if position.as_u64().is_some_and(|a| a as usize >= accessors) {
                return Err(GltfError::Invalid(format!(
                    "mesh {m}, primitive {p}: POSITION names accessor {position} of {accessors}"
                )));
            }
        }
    }
    Ok(())
}

/// Refuses a file that requires an extension this reader does not understand (naming it),
/// warns of those it only uses, and drops the ones it handles from `extensionsRequired` so the
/// `gltf` crate's validation takes the file.
fn check_extensions(doc: &mut Value) -> Result<Vec<String>, GltfError> {
    let list = |doc: &Value, key: &str| -> Vec<String> {
        doc[key].as_array().map_or_else(Vec::new, |a| {
            a.iter()
                .filter_map(|x| x.as_str().map(str::to_string))
                .collect()
        })
    };
    let required = list(doc, "extensionsRequired");
    let unknown: Vec<&String> = required
        .iter()
        .filter(|x| !READ.contains(&x.as_str()))
        .collect();
    if !unknown.is_empty() {
        let names: Vec<&str> = unknown.iter().map(|s| s.as_str()).collect();
        return Err(GltfError::Invalid(format!(
            "it requires {}, which voxlod does not read",
            names.join(", ")
        )));
    }
    let warnings = list(doc, "extensionsUsed")
        .into_iter()
        .filter(|x| !READ.contains(&x.as_str()))
        .map(|x| format!("the extension {x} is not read and was ignored"))
        .collect();
    if let Some(a) = doc
        .get_mut("extensionsRequired")
        .and_then(Value::as_array_mut)
    {
        a.clear();
    }
    Ok(warnings)
}
