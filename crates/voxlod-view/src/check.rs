//! What the page will draw, checked before it is embedded: the page's script trusts its data,
//! so a broken `.glb` must be refused here with a clear error, not fail in the browser.
//!
//! The file is decoded from `EXT_meshopt_compression` and `KHR_draco_mesh_compression` first
//! ([`voxlod_gltf::decompress_glb`]),
//! then its JSON is validated by the `gltf` crate (every index refers to something), every
//! accessor the page reads is bounds-checked against its view and the binary chunk, every index
//! against its primitive's vertices, the node graph must be a forest (the script walks it),
//! every attribute the page binds has its glTF shape (`TEXCOORD_n` two components, `COLOR_0`
//! three or four, …), and every image is inside the file (a buffer view or a `data:` URI: the
//! page fetches nothing).
//! Cost: linear in the file.

use gltf::json;
use gltf::json::validation::Checked;

use voxlod_gltf::ORDER_NAMES;

/// Required extensions the page handles (quantized attributes are plain WebGL attributes;
/// `EXT_meshopt_compression` and `KHR_draco_mesh_compression` are decoded before the check,
/// so they are never left to require).
const READ_EXTENSIONS: &[&str] = &[
    "KHR_mesh_quantization",
    "KHR_texture_transform",
    "KHR_materials_emissive_strength",
];

/// A checked file: its plain bytes and what it holds.
#[derive(Clone, Debug)]
pub struct CheckedGlb {
    pub bytes: Vec<u8>,
    pub triangles: usize,
    /// Levels of the chain: `MSFT_lod` levels in the scene's first node, else the scene's
    /// nodes named `LOD0`, `LOD1`, … (1 when there is no chain).
    pub levels: usize,
    /// Whether it holds the eight back-to-front orders of layered shells (of every level, in a
    /// chain).
    pub layered: bool,
}

/// Checks `bytes` (a `.glb`); the error says what is wrong, without the file's name.
pub fn check_glb(bytes: &[u8]) -> Result<CheckedGlb, String> {
    let plain = voxlod_gltf::decompress_glb(bytes).map_err(|e| e.to_string())?;
    let glb = gltf::binary::Glb::from_slice(&plain).map_err(|e| format!("not a GLB file: {e}"))?;
    let mut root: json::Root =
        json::deserialize::from_slice(&glb.json).map_err(|e| format!("bad JSON chunk: {e}"))?;
    if let Some(ext) = root
        .extensions_required
        .iter()
        .find(|e| !READ_EXTENSIONS.contains(&e.as_str()))
    {
        return Err(format!(
            "it requires the extension {ext}, which the viewer does not read"
        ));
    }
    root.extensions_required.clear();
    check_position_references(&root)?;
    let document = gltf::Document::from_json(root).map_err(|e| format!("invalid glTF: {e}"))?;
    let root = document.into_json();
    let bin: &[u8] = glb.bin.as_deref().unwrap_or(&[]);
    for (i, view) in root.buffer_views.iter().enumerate() {
        let start = view.byte_offset.map_or(0, |o| o.0) as usize;
        let end = start.checked_add(view.byte_length.0 as usize);
        if view.buffer.value() != 0 || end.is_none_or(|e| e > bin.len()) {
            return Err(format!(
                "buffer view {i} is not inside the file's binary chunk"
            ));
        }
    }
    for i in 0..root.accessors.len() {
        accessor_bytes(&root, i)?;
    }
    let mut triangles = 0;
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            triangles += check_primitive(&root, bin, prim)
                .map_err(|e| format!("mesh {m} primitive {p}: {e}"))?;
        }
    }
    check_forest(&root)?;
    check_images(&root)?;
    if triangles == 0 && root.meshes.is_empty() {
        return Err("it holds no mesh to draw".into());
    }
    let nodes = lod_nodes(&glb.json)?;
    let levels = match nodes.len() {
        0 | 1 => lod_node_names(&root).max(1),
        n => n,
    };
    let single_layered = root
        .accessors
        .iter()
        .filter(|a| a.name.as_deref().is_some_and(|n| ORDER_NAMES.contains(&n)))
        .count()
        == 8;
    let layered = single_layered || (levels > 1 && check_layered_chain(&root, bin, &nodes)?);
    Ok(CheckedGlb {
        bytes: plain,
        triangles,
        levels,
        layered,
    })
}

/// gltf-json 1.4's validation indexes the accessors of POSITION attributes without a bounds
/// check (a panic on a file whose position accessor is missing), so they are checked first.
fn check_position_references(root: &json::Root) -> Result<(), String> {
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            let semantic = Checked::Valid(json::mesh::Semantic::Positions);
            if let Some(a) = prim.attributes.get(&semantic) {
                if a.value() >= root.accessors.len() {
                    return Err(format!(
                        "mesh {m} primitive {p}: positions accessor {} does not exist",
                        a.value()
                    ));
                }
            }
        }
    }
    Ok(())
}

/// (offset in the binary chunk, element stride, element size, count) of accessor `i`.
fn accessor_bytes(root: &json::Root, i: usize) -> Result<(usize, usize, usize, usize), String> {
    let a = &root.accessors[i];
    let bad = |m: &str| format!("accessor {i}: {m}");
    let view_index = a
        .buffer_view
        .ok_or_else(|| bad("has no buffer view (sparse data is not read)"))?;
    let view = &root.buffer_views[view_index.value()];
    let Checked::Valid(ct) = a.component_type else {
        return Err(bad("invalid component type"));
    };
    let Checked::Valid(kind) = a.type_ else {
        return Err(bad("invalid type"));
    };
    let size = ct.0.size() * kind.multiplicity();
    let stride = view.byte_stride.map_or(size, |s| s.0);
    let count = a.count.0 as usize;
    let offset = a.byte_offset.map_or(0, |o| o.0) as usize;
    let needed = match count {
        0 => Some(0),
        n => (n - 1)
            .checked_mul(stride)
            .and_then(|x| x.checked_add(offset + size)),
    };
    if stride < size || needed.is_none_or(|n| n > view.byte_length.0 as usize) {
        return Err(bad("reaches beyond its buffer view"));
    }
    let start = view.byte_offset.map_or(0, |o| o.0) as usize + offset;
    Ok((start, stride, size, count))
}

/// The primitive's triangles, after checking its indices against its vertices.
fn check_primitive(
    root: &json::Root,
    bin: &[u8],
    prim: &json::mesh::Primitive,
) -> Result<usize, String> {
    let Some(pos) = prim
        .attributes
        .get(&Checked::Valid(json::mesh::Semantic::Positions))
    else {
        return Ok(0);
    };
    let vertices = root.accessors[pos.value()].count.0 as usize;
    for (semantic, a) in &prim.attributes {
        let accessor = &root.accessors[a.value()];
        if accessor.count.0 as usize != vertices {
            return Err(format!(
                "attribute {semantic:?} has another count than the positions"
            ));
        }
        check_shape(semantic, accessor)?;
    }
    let mode = match prim.mode {
        Checked::Valid(m) => m,
        Checked::Invalid => return Err("invalid mode".into()),
    };
    let count = match prim.indices {
        Some(i) => check_indices(root, bin, i.value(), vertices)?,
        None => vertices,
    };
    Ok(if mode == json::mesh::Mode::Triangles {
        count / 3
    } else {
        0
    })
}

/// The components an attribute the page binds must have (glTF 2.0 §3.7.2.1): what WebGL would
/// otherwise read as something else.
fn check_shape(
    semantic: &Checked<json::mesh::Semantic>,
    accessor: &json::Accessor,
) -> Result<(), String> {
    use json::accessor::Type;
    use json::mesh::Semantic;
    let allowed: &[Type] = match semantic {
        Checked::Valid(Semantic::Positions | Semantic::Normals) => &[Type::Vec3],
        Checked::Valid(Semantic::Tangents) => &[Type::Vec4],
        Checked::Valid(Semantic::TexCoords(_)) => &[Type::Vec2],
        Checked::Valid(Semantic::Colors(_)) => &[Type::Vec3, Type::Vec4],
        _ => return Ok(()),
    };
    match accessor.type_ {
        Checked::Valid(t) if allowed.contains(&t) => Ok(()),
        _ => Err(format!(
            "attribute {semantic:?} must be of type {}",
            allowed
                .iter()
                .map(|t| format!("{t:?}").to_uppercase())
                .collect::<Vec<_>>()
                .join(" or ")
        )),
    }
}

/// Every image is inside the file: a buffer view, or a `data:` URI.
fn check_images(root: &json::Root) -> Result<(), String> {
    for (i, image) in root.images.iter().enumerate() {
        match (&image.buffer_view, &image.uri) {
            (Some(_), _) => {}
            (None, Some(uri)) if uri.starts_with("data:") => {}
            (None, Some(uri)) => {
                return Err(format!(
                    "image {i} is the file {uri:?} outside the .glb; the page embeds only \
                     images inside it (a buffer view or a data: URI)"
                ))
            }
            (None, None) => return Err(format!("image {i} has neither a buffer view nor a URI")),
        }
    }
    Ok(())
}

/// The count of index accessor `a`, after checking every index is below `vertices`.
fn check_indices(
    root: &json::Root,
    bin: &[u8],
    a: usize,
    vertices: usize,
) -> Result<usize, String> {
    let (start, stride, size, count) = accessor_bytes(root, a)?;
    for e in 0..count {
        let b = &bin[start + e * stride..start + e * stride + size];
        let v = match size {
            1 => b[0] as usize,
            2 => u16::from_le_bytes([b[0], b[1]]) as usize,
            4 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize,
            _ => return Err("indices must be unsigned integers".into()),
        };
        if v >= vertices {
            return Err(format!("index {v} beyond its {vertices} vertices"));
        }
    }
    Ok(count)
}

/// Whether a chain holds layered levels (`voxlod layers --lod`): each level's mesh with its
/// eight orders named `level K order±x±y±z`, every index below the vertices of the level's
/// triangle primitives (which the page concatenates). Either every level has its eight or
/// none does.
fn check_layered_chain(root: &json::Root, bin: &[u8], nodes: &[usize]) -> Result<bool, String> {
    let named = |name: &str| {
        root.accessors
            .iter()
            .position(|a| a.name.as_deref() == Some(name))
    };
    let mut layered = 0;
    for (k, &node) in nodes.iter().enumerate() {
        let orders: Vec<usize> = ORDER_NAMES
            .iter()
            .filter_map(|o| named(&format!("level {k} {o}")))
            .collect();
        if orders.is_empty() {
            continue;
        }
        if orders.len() != 8 {
            return Err(format!(
                "level {k} has {} of the eight orders",
                orders.len()
            ));
        }
        let mesh = root.nodes[node]
            .mesh
            .ok_or_else(|| format!("level {k}'s node has no mesh"))?;
        let vertices: usize = root.meshes[mesh.value()]
            .primitives
            .iter()
            .filter(|p| p.mode == Checked::Valid(json::mesh::Mode::Triangles))
            .filter_map(|p| {
                p.attributes
                    .get(&Checked::Valid(json::mesh::Semantic::Positions))
            })
            .map(|a| root.accessors[a.value()].count.0 as usize)
            .sum();
        for a in orders {
            check_indices(root, bin, a, vertices).map_err(|e| format!("level {k} order: {e}"))?;
        }
        layered += 1;
    }
    match layered {
        0 => Ok(false),
        n if n == nodes.len() => Ok(true),
        n => Err(format!("{n} of the {} levels have orders", nodes.len())),
    }
}

/// Every node has at most one parent and no node is its own ancestor.
fn check_forest(root: &json::Root) -> Result<(), String> {
    let mut parent = vec![None; root.nodes.len()];
    for (i, n) in root.nodes.iter().enumerate() {
        for c in n.children.iter().flatten() {
            if parent[c.value()].replace(i).is_some() {
                return Err(format!("node {} has two parents", c.value()));
            }
        }
    }
    for start in 0..root.nodes.len() {
        let (mut at, mut steps) = (start, 0);
        while let Some(p) = parent[at] {
            at = p;
            steps += 1;
            if steps > root.nodes.len() {
                return Err(format!("node {start} is its own ancestor"));
            }
        }
    }
    Ok(())
}

/// The nodes of the `MSFT_lod` chain on the scene's first node, finest first (that node alone
/// without a chain, none without a scene node); every id must be a node.
fn lod_nodes(json_chunk: &[u8]) -> Result<Vec<usize>, String> {
    let doc: serde_json::Value =
        serde_json::from_slice(json_chunk).map_err(|e| format!("bad JSON chunk: {e}"))?;
    let scene = doc["scene"].as_u64().unwrap_or(0) as usize;
    let nodes = doc["nodes"].as_array().map_or(0, Vec::len) as u64;
    let Some(first) = doc["scenes"][scene]["nodes"][0]
        .as_u64()
        .filter(|&n| n < nodes)
    else {
        return Ok(Vec::new());
    };
    let Some(ids) = doc["nodes"][first as usize]["extensions"]["MSFT_lod"]["ids"].as_array() else {
        return Ok(vec![first as usize]);
    };
    let mut out = vec![first as usize];
    for id in ids {
        match id.as_u64().filter(|&i| i < nodes) {
            Some(i) => out.push(i as usize),
            None => {
                return Err(format!(
                    "MSFT_lod refers to node {id}, which does not exist"
                ))
            }
        }
    }
    Ok(out)
}

/// How many levels the scene's root nodes named `LOD0`, `LOD1`, … `LODn−1` make (each index
/// once, n ≥ 2, as the page's script reads them); 0 when they make no chain.
fn lod_node_names(root: &json::Root) -> usize {
    let scene = root.scene.map_or(0, |s| s.value());
    let Some(roots) = root.scenes.get(scene).map(|s| &s.nodes) else {
        return 0;
    };
    let mut seen = vec![false; roots.len()];
    let mut named = 0;
    for r in roots {
        let level = root.nodes[r.value()]
            .name
            .as_deref()
            .and_then(|n| n.strip_prefix("LOD"))
            .filter(|k| !k.is_empty() && k.bytes().all(|b| b.is_ascii_digit()))
            .and_then(|k| k.parse::<usize>().ok());
        if let Some(k) = level.filter(|&k| k < roots.len()) {
            seen[k] = true;
            named += 1;
        }
    }
    let levels = seen.iter().take_while(|&&s| s).count();
    if levels >= 2 && levels == named && seen[levels..].iter().all(|s| !s) {
        levels
    } else {
        0
    }
}
