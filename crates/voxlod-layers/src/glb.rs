//! Layered meshes as binary glTF 2.0 (`.glb`), with the eight back-to-front orders stored.
//!
//! **Layout** (documented for users in the README):
//! - one buffer (the GLB `BIN` chunk) holding, in this order: the positions of every layer
//!   concatenated (layer 0 first), their normals likewise, every layer's own triangle indices,
//!   and the eight orders;
//! - mesh `i` is layer `i`, innermost (opaque) first (a layer without triangles, which a tiny
//!   object can give, has no mesh: the extras name each mesh's layer); its one primitive draws its own vertices
//!   with its own indices and material `i`: base colour with alpha = the layer's blend alpha
//!   (see [`crate::plan::Blending`]: by default the alphas whose back-to-front composite has
//!   translucency `1 − d/m` along every ray), `alphaMode: BLEND`, double sided, metallic 0, roughness 1; node `i`
//!   places mesh `i` untransformed, and the scene holds every node;
//! - mesh extras: `{"layer": i, "isodensity": c, "translucency": t, "alpha": a}`; scene extras:
//!   `{"voxlod": {"grid": {dims, spacing, origin, placement}, "orders": [...],
//!   "in_cell_direction": "octant diagonal"}}`: the volume grid in its axis-aligned grid space,
//!   and, for the layers of an oblique or flipped scan, `placement`: the 4×4 row-major affine
//!   map from that space to the vertices' ([`LayeredMesh::placement`]; absent when it is the
//!   identity), which taking the vertices back to the grid's cells needs;
//! - eight extra `SCALAR` `UNSIGNED_INT` accessors named `order+x+y+z`, `order+x+y-z`,
//!   `order+x-y+z`, `order+x-y-z`, `order-x+y+z`, `order-x+y-z`, `order-x-y+z`, `order-x-y-z`:
//!   each a triangle list (three indices per triangle) of every triangle of every layer, back to
//!   front for view directions (eye to scene) with those signs in the vertices' space (see
//!   [`crate::order`] for a placed volume), whose indices refer to the
//!   vertices of all layer meshes concatenated in mesh order (mesh 0's vertices first; a vertex
//!   of mesh i has index `its index in mesh i + vertices of meshes 0..i`). Since the position
//!   accessors are consecutive slices of one buffer view, that concatenation is exactly the
//!   positions buffer view.
//!
//! Layers with an asset's looks baked on ([`crate::looks`]) add texture coordinates and a base
//! colour texture per layer after the orders ([`crate::glb_looks`] documents the additions);
//! without them the file is as above, with no texture coordinate, image or texture.
//!
//! [`voxlod_gltf::read_glb`] reads such a file back: the layers as its parts, the orders and the
//! grid. Cost: linear in the layers' size.

use std::collections::BTreeMap;
use std::path::Path;

use glam::Vec3;
use gltf::json;
use gltf::json::validation::{Checked, USize64};
use serde::Serialize;

use crate::extract::{Layer, LayeredMesh};
use crate::glb_looks::{push_looks, textured, LookParts};
use crate::glb_parts::{accessor, push_view};
use crate::looks::{BakedLayers, LayerLooks};
use crate::order::ORDER_NAMES;
use crate::LayersError;

/// How the file looks.
#[derive(Clone, Debug, PartialEq)]
pub struct GlbOptions {
    /// Base colour of every layer (linear RGB).
    pub color: [f32; 3],
    /// Name of the scene.
    pub name: String,
    /// The filter's support radius in the input's units, recorded in the scene extras for
    /// viewers (`voxlod view` draws the layers only while it spans at most
    /// [`RADIUS_LIMIT_PIXELS`] on screen); `None`: one voxel of the grid.
    pub radius: Option<f64>,
}

impl Default for GlbOptions {
    /// A light steel grey.
    fn default() -> Self {
        GlbOptions {
            color: [0.72, 0.74, 0.78],
            name: "voxlod layers".into(),
            radius: None,
        }
    }
}

/// The largest filter radius on screen, in pixels, at which the layered shells are closer to a
/// 16×16-supersampled reference than the single surface near silhouettes (measured in
/// BENCHMARKS.md, "Layered shells and rendering"): beyond it the shells, which all lie outside
/// the surface, widen the silhouette and the edges get worse. Viewers switch on it.
pub const RADIUS_LIMIT_PIXELS: f64 = 0.45;

/// The bytes of a `.glb` for `layered` and its eight orders (global triangle indices into the
/// layers concatenated, by [`Octant::index`](crate::Octant::index)).
///
/// # Example
///
/// Layered shells read back (with [`voxlod_gltf::parse_glb`]) as one part per layer, with the
/// layer's alpha and blending, all eight orders and the grid.
///
/// ```
/// use voxlod_layers::{glb_bytes, layer_solid, GlbOptions, LayersOptions};
/// use voxlod_sampling::{CsgSolid, Shape};
///
/// let solid = CsgSolid::new(Shape::sphere(glam::DVec3::ZERO, 1.0))?;
/// let layered = layer_solid(&solid, &LayersOptions { resolution: 12, ..Default::default() })?;
/// let bytes = glb_bytes(&layered.mesh, &layered.orders, &GlbOptions::default())?;
/// let scene = voxlod_gltf::parse_glb(&bytes)?;
/// assert!(scene.is_layered());
/// assert_eq!(scene.parts.len(), layered.mesh.layers.len());
/// assert_eq!(scene.mesh.triangles.len(), layered.mesh.triangle_count());
/// assert!(scene.parts.iter().all(|p| p.blend));
/// assert_eq!(scene.parts[0].color[3], 1.0);
/// assert_eq!(scene.grid, Some(layered.mesh.grid));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn glb_bytes(
    layered: &LayeredMesh,
    orders: &[Vec<u32>],
    options: &GlbOptions,
) -> Result<Vec<u8>, LayersError> {
    let (root, bin) = document(layered, orders, options, None)?;
    encode_glb(&root, bin)
}

/// The GLB container of a document (through `voxlod_gltf`, as every voxlod `.glb`).
pub(crate) fn encode_glb(root: &serde_json::Value, bin: Vec<u8>) -> Result<Vec<u8>, LayersError> {
    voxlod_gltf::to_glb(root, bin).map_err(|e| LayersError::Gltf(e.to_string()))
}

/// Writes `path` atomically (nothing is left behind on failure).
pub fn write_glb(
    path: &Path,
    layered: &LayeredMesh,
    orders: &[Vec<u32>],
    options: &GlbOptions,
) -> Result<(), LayersError> {
    write_bytes(path, &glb_bytes(layered, orders, options)?)
}

/// The bytes of a `.glb` of baked layers and their eight orders (global triangle indices into
/// the layers concatenated, by [`Octant::index`](crate::Octant::index): the unbaked layers'
/// orders, which hold for the baked ones). Refuses looks that do not fit the layers (a layer
/// with triangles and no looks, texture coordinates not one per vertex).
pub fn baked_glb_bytes(
    baked: &BakedLayers,
    orders: &[Vec<u32>],
    options: &GlbOptions,
) -> Result<Vec<u8>, LayersError> {
    let (root, bin) = document(&baked.mesh, orders, options, Some(&baked.looks))?;
    encode_glb(&root, bin)
}

/// [`baked_glb_bytes`] written to `path` atomically (nothing is left behind on failure).
pub fn write_baked_glb(
    path: &Path,
    baked: &BakedLayers,
    orders: &[Vec<u32>],
    options: &GlbOptions,
) -> Result<(), LayersError> {
    write_bytes(path, &baked_glb_bytes(baked, orders, options)?)
}

/// Writes `bytes` to `path` atomically.
pub(crate) fn write_bytes(path: &Path, bytes: &[u8]) -> Result<(), LayersError> {
    let write = |w: &mut std::io::BufWriter<std::fs::File>| std::io::Write::write_all(w, bytes);
    Ok(voxlod_io::atomic::write_atomically(path, write)?)
}

pub(crate) fn raw(value: serde_json::Value) -> json::Extras {
    serde_json::value::to_raw_value(&value).ok()
}

/// The grid of a layered mesh as extras, with the placement of its vertices when they do not
/// lie in the grid's space.
#[derive(Serialize)]
pub(crate) struct GridExtras {
    dims: [usize; 3],
    spacing: [f64; 3],
    origin: [f64; 3],
    #[serde(skip_serializing_if = "Option::is_none")]
    placement: Option<[[f64; 4]; 4]>,
}

impl GridExtras {
    pub(crate) fn of(layered: &LayeredMesh) -> GridExtras {
        let grid = &layered.grid;
        let p = &layered.placement;
        let placement = (!p.is_identity()).then(|| {
            let row = |r: usize| {
                let l = p.linear.row(r);
                [l.x, l.y, l.z, p.translation[r]]
            };
            [row(0), row(1), row(2), [0.0, 0.0, 0.0, 1.0]]
        });
        GridExtras {
            dims: grid.dims,
            spacing: grid.spacing,
            origin: grid.origin,
            placement,
        }
    }
}

/// The filter radius `options` give for `grid` (one voxel unless given).
pub(crate) fn radius_of(grid: &voxlod_core::Grid, options: &GlbOptions) -> f64 {
    options
        .radius
        .unwrap_or_else(|| grid.spacing.iter().copied().fold(0.0, f64::max))
}

/// A new document with voxlod as its generator and one buffer (its length set by the caller).
pub(crate) fn new_root() -> json::Root {
    let mut root = json::Root {
        asset: json::Asset {
            generator: Some(format!("voxlod {}", env!("CARGO_PKG_VERSION"))),
            ..Default::default()
        },
        ..Default::default()
    };
    root.push(json::Buffer {
        byte_length: USize64(0),
        name: None,
        uri: None,
        extensions: None,
        extras: None,
    });
    root
}

/// The glTF document of `layered` and its eight orders, with each layer's `looks` when given,
/// and its binary buffer (see the module documentation for the layout).
pub(crate) fn document(
    layered: &LayeredMesh,
    orders: &[Vec<u32>],
    options: &GlbOptions,
    looks: Option<&[Option<LayerLooks>]>,
) -> Result<(serde_json::Value, Vec<u8>), LayersError> {
    let mut root = new_root();
    let mut bin = Vec::new();
    let looked = (layered, looks);
    let level = push_level(&mut root, &mut bin, looked, orders, options.color, "")?;
    let mut nodes = Vec::new();
    for (i, primitive) in level.primitives {
        let l = &layered.layers[i];
        let mesh = root.push(json::Mesh {
            extensions: None,
            extras: raw(layer_extras(i, l)),
            name: Some(format!("layer {i}")),
            primitives: vec![primitive],
            weights: None,
        });
        nodes.push(root.push(json::Node {
            mesh: Some(mesh),
            name: Some(format!("layer {i}")),
            ..Default::default()
        }));
    }
    root.buffers[0].byte_length = USize64(bin.len() as u64);
    let scene = root.push(json::Scene {
        extensions: None,
        extras: raw(serde_json::json!({
            "voxlod": {
                "grid": GridExtras::of(layered),
                "radius": radius_of(&layered.grid, options),
                "orders": ORDER_NAMES,
                "in_cell_direction": "octant diagonal",
            }
        })),
        name: Some(options.name.clone()),
        nodes,
    });
    root.scene = Some(scene);
    let doc = serde_json::to_value(&root)
        .map_err(|e| LayersError::Gltf(format!("cannot encode the JSON chunk: {e}")))?;
    Ok((doc, bin))
}

/// What a layer's mesh (or primitive, in a chain) says about it.
pub(crate) fn layer_extras(i: usize, l: &Layer) -> serde_json::Value {
    serde_json::json!({
        "layer": i,
        "isodensity": l.isodensity,
        "translucency": l.translucency,
        "alpha": l.alpha,
    })
}

/// One layered mesh in a document: a primitive per layer with triangles, and the eight order
/// accessors.
pub(crate) struct LevelParts {
    /// (layer, its primitive), innermost first.
    pub primitives: Vec<(usize, json::mesh::Primitive)>,
    /// The order accessors by [`Octant::index`](crate::Octant::index).
    pub orders: Vec<json::Index<json::Accessor>>,
}

/// Appends `layered` and its `orders` to buffer 0 of `root` (bytes in `bin`): views, accessors
/// and materials, names prefixed by `prefix`, and each layer's looks when given; checks the
/// mesh, the orders, the looks and the memory budget first.
pub(crate) fn push_level(
    root: &mut json::Root,
    bin: &mut Vec<u8>,
    (layered, looks): (&LayeredMesh, Option<&[Option<LayerLooks>]>),
    orders: &[Vec<u32>],
    color: [f32; 3],
    prefix: &str,
) -> Result<LevelParts, LayersError> {
    layered.validate()?;
    let total_triangles = layered.triangle_count();
    if orders.len() != 8 || orders.iter().any(|o| o.len() != total_triangles) {
        return Err(LayersError::Invalid(format!(
            "expected eight orders of {total_triangles} triangles"
        )));
    }
    let vertex_count = layered.vertex_count();
    let with_normals = layered.layers.iter().all(|l| !l.mesh.normals.is_empty());
    let bytes = vertex_count * 12 * (1 + with_normals as usize) + total_triangles * 12 * 9;
    voxlod_core::memory::check_allocation("the glTF buffer", (bin.len() + bytes) as u64)?;
    bin.reserve(bytes);
    let views = write_buffer(root, bin, layered, orders, with_normals, prefix);
    let looks = match looks {
        Some(looks) => push_looks(root, bin, layered, looks, prefix)?,
        None => vec![None; layered.layers.len()],
    };
    let primitives = layer_primitives(root, layered, &views, (color, &looks), prefix);
    let orders = ORDER_NAMES
        .iter()
        .enumerate()
        .map(|(o, name)| {
            root.push(accessor(
                views.orders,
                o * total_triangles * 12,
                total_triangles * 3,
                json::accessor::ComponentType::U32,
                json::accessor::Type::Scalar,
                None,
                format!("{prefix}{name}"),
            ))
        })
        .collect();
    Ok(LevelParts { primitives, orders })
}

/// The four buffer views of one layered mesh.
struct BufferViews {
    positions: json::Index<json::buffer::View>,
    normals: Option<json::Index<json::buffer::View>>,
    indices: json::Index<json::buffer::View>,
    orders: json::Index<json::buffer::View>,
}

/// Appends to `bin` the positions, normals (when every layer has them), each layer's own
/// indices and the orders (as triangles of concatenated vertex indices), and adds a view of
/// buffer 0 over each part to `root`.
fn write_buffer(
    root: &mut json::Root,
    bin: &mut Vec<u8>,
    layered: &LayeredMesh,
    orders: &[Vec<u32>],
    with_normals: bool,
    prefix: &str,
) -> BufferViews {
    use json::buffer::Target::{ArrayBuffer, ElementArrayBuffer};
    let view = |root: &mut json::Root, at: usize, end: usize, stride, target, name: &str| {
        push_view(
            root,
            at..end,
            stride,
            Some(target),
            &format!("{prefix}{name}"),
        )
    };
    let at = bin.len();
    for l in &layered.layers {
        for p in &l.mesh.positions {
            push_vec3(bin, *p);
        }
    }
    let positions = view(root, at, bin.len(), Some(12), ArrayBuffer, "positions");
    let normals = with_normals.then(|| {
        let at = bin.len();
        for l in &layered.layers {
            for n in &l.mesh.normals {
                push_vec3(bin, voxlod_gltf::streams::unit_normal(*n));
            }
        }
        view(root, at, bin.len(), Some(12), ArrayBuffer, "normals")
    });
    let at = bin.len();
    for l in &layered.layers {
        for t in &l.mesh.triangles {
            for &v in t {
                bin.extend_from_slice(&v.to_le_bytes());
            }
        }
    }
    let indices = view(
        root,
        at,
        bin.len(),
        None,
        ElementArrayBuffer,
        "layer indices",
    );
    let concatenated = layered.concatenated();
    let at = bin.len();
    for order in orders {
        for &t in order {
            for &v in &concatenated.mesh.triangles[t as usize] {
                bin.extend_from_slice(&v.to_le_bytes());
            }
        }
    }
    let orders = view(
        root,
        at,
        bin.len(),
        None,
        ElementArrayBuffer,
        "back-to-front orders",
    );
    debug_assert_eq!(bin.len() % 4, 0);
    BufferViews {
        positions,
        normals,
        indices,
        orders,
    }
}

/// A primitive (with its accessors and material) for each layer with triangles, of `color` or
/// with the layer's looks.
fn layer_primitives(
    root: &mut json::Root,
    layered: &LayeredMesh,
    views: &BufferViews,
    (color, looks): ([f32; 3], &[Option<LookParts>]),
    prefix: &str,
) -> Vec<(usize, json::mesh::Primitive)> {
    let mut first_vertex = 0usize;
    let mut first_index = 0usize;
    let mut out = Vec::new();
    for (i, l) in layered.layers.iter().enumerate() {
        if !l.mesh.triangles.is_empty() {
            // glTF has no empty primitives; an empty layer has no vertices either.
            let at = (first_vertex, first_index);
            let mut p = layer_primitive(root, (i, l), views, at, color, prefix);
            if let Some(look) = &looks[i] {
                look_at(root, &mut p, look);
            }
            out.push((i, p));
        }
        first_vertex += l.mesh.positions.len();
        first_index += l.mesh.triangles.len() * 3;
    }
    out
}

/// Layer `i` (its vertices and indices starting at `first`) as its accessors, material and
/// primitive.
fn layer_primitive(
    root: &mut json::Root,
    (i, l): (usize, &Layer),
    views: &BufferViews,
    (first_vertex, first_index): (usize, usize),
    c: [f32; 3],
    prefix: &str,
) -> json::mesh::Primitive {
    // This layer's slice of a view of float triples (positions or normals).
    let vec3s = |view, bounds, what: &str| {
        accessor(
            view,
            first_vertex * 12,
            l.mesh.positions.len(),
            json::accessor::ComponentType::F32,
            json::accessor::Type::Vec3,
            bounds,
            format!("{prefix}layer {i} {what}"),
        )
    };
    let pos = root.push(vec3s(
        views.positions,
        Some(min_max(&l.mesh.positions)),
        "positions",
    ));
    let mut attributes = BTreeMap::new();
    attributes.insert(Checked::Valid(json::mesh::Semantic::Positions), pos);
    if let Some(nview) = views.normals {
        let nor = root.push(vec3s(nview, None, "normals"));
        attributes.insert(Checked::Valid(json::mesh::Semantic::Normals), nor);
    }
    let count = l.mesh.triangles.len() * 3;
    let indices = root.push(accessor(
        views.indices,
        first_index * 4,
        count,
        json::accessor::ComponentType::U32,
        json::accessor::Type::Scalar,
        None,
        format!("{prefix}layer {i} indices"),
    ));
    let material = root.push(json::Material {
        alpha_mode: Checked::Valid(json::material::AlphaMode::Blend),
        double_sided: true,
        name: Some(format!("{prefix}layer {i} opacity {:.4}", l.alpha)),
        pbr_metallic_roughness: json::material::PbrMetallicRoughness {
            base_color_factor: json::material::PbrBaseColorFactor([c[0], c[1], c[2], l.alpha]),
            metallic_factor: json::material::StrengthFactor(0.0),
            roughness_factor: json::material::StrengthFactor(1.0),
            ..Default::default()
        },
        ..Default::default()
    });
    json::mesh::Primitive {
        attributes,
        extensions: None,
        extras: raw(layer_extras(i, l)),
        indices: Some(indices),
        material: Some(material),
        mode: Checked::Valid(json::mesh::Mode::Triangles),
        targets: None,
    }
}

/// `primitive` given its look: `TEXCOORD_0` and its material's base colour texture.
fn look_at(root: &mut json::Root, primitive: &mut json::mesh::Primitive, look: &LookParts) {
    let semantic = Checked::Valid(json::mesh::Semantic::TexCoords(0));
    primitive.attributes.insert(semantic, look.texcoords);
    if let Some(m) = primitive.material {
        textured(&mut root.materials[m.value()], look);
    }
}

fn push_vec3(bin: &mut Vec<u8>, v: Vec3) {
    for c in v.to_array() {
        bin.extend_from_slice(&c.to_le_bytes());
    }
}

fn min_max(points: &[Vec3]) -> ([f32; 3], [f32; 3]) {
    if points.is_empty() {
        return ([0.0; 3], [0.0; 3]);
    }
    let (lo, hi) = points.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    (lo.to_array(), hi.to_array())
}
