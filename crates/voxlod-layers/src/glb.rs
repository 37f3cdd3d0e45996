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
//!   `{"voxlod": {"grid": {dims, spacing, origin}, "orders": [...], "in_cell_direction":
//!   "octant diagonal"}}`;
//! - eight extra `SCALAR` `UNSIGNED_INT` accessors named `order+x+y+z`, `order+x+y-z`,
//!   `order+x-y+z`, `order+x-y-z`, `order-x+y+z`, `order-x+y-z`, `order-x-y+z`, `order-x-y-z`:
//!   each a triangle list (three indices per triangle) of every triangle of every layer, back to
//!   front for view directions (eye to scene) with those signs, whose indices refer to the
//!   vertices of all layer meshes concatenated in mesh order (mesh 0's vertices first; a vertex
//!   of mesh i has index `its index in mesh i + vertices of meshes 0..i`). Since the position
//!   accessors are consecutive slices of one buffer view, that concatenation is exactly the
//!   positions buffer view.
//!
//! The reader ([`read_glb`]) takes any glTF 2.0 binary file whose triangle primitives use float
//! positions, and returns the orders when present. It checks every offset against the buffer
//! (no panic on a broken file). Node transforms are ignored. Cost: linear in the file.

use std::collections::BTreeMap;
use std::path::Path;

use glam::Vec3;
use gltf::json;
use gltf::json::validation::{Checked, USize64};
use serde::Serialize;
use voxlod_core::TriangleMesh;

use crate::extract::{Layer, LayeredMesh};
use crate::order::{Octant, ORDER_NAMES};
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
/// layers concatenated, by [`Octant::index`]).
pub fn glb_bytes(
    layered: &LayeredMesh,
    orders: &[Vec<u32>],
    options: &GlbOptions,
) -> Result<Vec<u8>, LayersError> {
    let (root, bin) = document(layered, orders, options)?;
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
    let bytes = glb_bytes(layered, orders, options)?;
    Ok(voxlod_io::atomic::write_atomically(path, |w| {
        std::io::Write::write_all(w, &bytes)
    })?)
}

pub(crate) fn raw(value: serde_json::Value) -> json::Extras {
    serde_json::value::to_raw_value(&value).ok()
}

/// The grid of a layered mesh as extras.
#[derive(Serialize)]
pub(crate) struct GridExtras {
    dims: [usize; 3],
    spacing: [f64; 3],
    origin: [f64; 3],
}

impl GridExtras {
    pub(crate) fn of(grid: &voxlod_core::Grid) -> GridExtras {
        GridExtras {
            dims: grid.dims,
            spacing: grid.spacing,
            origin: grid.origin,
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

/// The glTF document of `layered` and its eight orders, and its binary buffer (see the module
/// documentation for the layout).
fn document(
    layered: &LayeredMesh,
    orders: &[Vec<u32>],
    options: &GlbOptions,
) -> Result<(serde_json::Value, Vec<u8>), LayersError> {
    let mut root = new_root();
    let mut bin = Vec::new();
    let level = push_level(&mut root, &mut bin, layered, orders, options.color, "")?;
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
                "grid": GridExtras::of(&layered.grid),
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
    /// The order accessors by [`Octant::index`].
    pub orders: Vec<json::Index<json::Accessor>>,
}

/// Appends `layered` and its `orders` to buffer 0 of `root` (bytes in `bin`): views, accessors
/// and materials, names prefixed by `prefix`; checks the mesh, the orders and the memory
/// budget first.
pub(crate) fn push_level(
    root: &mut json::Root,
    bin: &mut Vec<u8>,
    layered: &LayeredMesh,
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
    let primitives = layer_primitives(root, layered, &views, color, prefix);
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
        push_view(root, at..end, stride, target, &format!("{prefix}{name}"))
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

/// Adds a view of `bytes` of buffer 0 to `root`.
fn push_view(
    root: &mut json::Root,
    bytes: std::ops::Range<usize>,
    stride: Option<usize>,
    target: json::buffer::Target,
    name: &str,
) -> json::Index<json::buffer::View> {
    root.push(json::buffer::View {
        buffer: json::Index::new(0),
        byte_length: USize64(bytes.len() as u64),
        byte_offset: Some(USize64(bytes.start as u64)),
        byte_stride: stride.map(json::buffer::Stride),
        name: Some(name.into()),
        target: Some(Checked::Valid(target)),
        extensions: None,
        extras: None,
    })
}

/// A primitive (with its accessors and material) for each layer with triangles.
fn layer_primitives(
    root: &mut json::Root,
    layered: &LayeredMesh,
    views: &BufferViews,
    color: [f32; 3],
    prefix: &str,
) -> Vec<(usize, json::mesh::Primitive)> {
    let mut first_vertex = 0usize;
    let mut first_index = 0usize;
    let mut out = Vec::new();
    for (i, l) in layered.layers.iter().enumerate() {
        if !l.mesh.triangles.is_empty() {
            // glTF has no empty primitives; an empty layer has no vertices either.
            let at = (first_vertex, first_index);
            let p = layer_primitive(root, (i, l), views, at, color, prefix);
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

fn accessor(
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

// -------------------------------------------------------------------------------------------
// Reading.

/// One mesh primitive of a glTF file.
#[derive(Clone, Debug, PartialEq)]
pub struct GlbPart {
    /// The mesh's name, or `mesh M` for an unnamed one.
    pub name: String,
    /// Its vertices are `first_vertex..first_vertex + vertex_count` of [`GlbScene::mesh`].
    pub first_vertex: u32,
    /// How many vertices it has.
    pub vertex_count: u32,
    /// Its triangles are `first_triangle..` of [`GlbScene::mesh`], `triangle_count` of them.
    pub first_triangle: u32,
    /// How many triangles it has.
    pub triangle_count: u32,
    /// Base colour factor (RGBA); alpha is the opacity.
    pub color: [f32; 4],
    /// Whether the material blends.
    pub blend: bool,
}

/// What [`read_glb`] found: every triangle primitive concatenated, and the stored orders.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GlbScene {
    /// All primitives' vertices and triangles, in mesh then primitive order (global indices).
    pub mesh: TriangleMesh,
    /// Where each primitive lies in `mesh`, and its material.
    pub parts: Vec<GlbPart>,
    /// The `order±x±y±z` accessors by [`Octant::index`], as triangles of global vertex indices.
    pub orders: Vec<Option<Vec<[u32; 3]>>>,
    /// The volume grid the layers were cut from (scene extras of a voxlod file).
    pub grid: Option<voxlod_core::Grid>,
}

impl GlbScene {
    /// Whether all eight orders are present: a layered file.
    pub fn is_layered(&self) -> bool {
        self.orders.len() == 8 && self.orders.iter().all(|o| o.is_some())
    }

    /// The part a vertex belongs to.
    pub fn part_of_vertex(&self, v: u32) -> Option<&GlbPart> {
        let i = self
            .parts
            .partition_point(|p| p.first_vertex + p.vertex_count <= v);
        self.parts.get(i).filter(|p| v >= p.first_vertex)
    }

    /// The part of each triangle.
    pub fn triangle_parts(&self) -> Vec<u16> {
        let mut out = vec![0u16; self.mesh.triangles.len()];
        for (i, p) in self.parts.iter().enumerate() {
            let range = p.first_triangle as usize..(p.first_triangle + p.triangle_count) as usize;
            out[range].fill(i.min(u16::MAX as usize) as u16);
        }
        out
    }

    /// The stored order for a view direction.
    pub fn order_for(&self, direction: glam::DVec3) -> Result<Option<&[[u32; 3]]>, LayersError> {
        let o = Octant::of(direction)?;
        Ok(self.orders.get(o.index()).and_then(|x| x.as_deref()))
    }
}

/// Reads a `.glb` (see the module documentation).
pub fn read_glb(path: &Path) -> Result<GlbScene, LayersError> {
    let len = std::fs::metadata(path)
        .map_err(|e| LayersError::Gltf(format!("{}: cannot read: {e}", path.display())))?
        .len();
    voxlod_core::memory::check_allocation(&format!("reading {}", path.display()), len)?;
    let bytes = std::fs::read(path)
        .map_err(|e| LayersError::Gltf(format!("{}: cannot read: {e}", path.display())))?;
    parse_glb(&bytes).map_err(|e| match e {
        LayersError::Gltf(m) => LayersError::Gltf(format!("{}: {m}", path.display())),
        other => other,
    })
}

/// Parses the bytes of a `.glb`.
///
/// # Example
///
/// Layered shells written with [`glb_bytes`] read back as one part per layer, with the
/// layer's alpha and blending, and all eight orders.
///
/// ```
/// use voxlod_layers::{glb_bytes, layer_solid, parse_glb, GlbOptions, LayersOptions};
/// use voxlod_sampling::{CsgSolid, Shape};
///
/// let solid = CsgSolid::new(Shape::sphere(glam::DVec3::ZERO, 1.0))?;
/// let layered = layer_solid(&solid, &LayersOptions { resolution: 12, ..Default::default() })?;
/// let bytes = glb_bytes(&layered.mesh, &layered.orders, &GlbOptions::default())?;
/// let scene = parse_glb(&bytes)?;
/// assert!(scene.is_layered());
/// assert_eq!(scene.parts.len(), layered.mesh.layers.len());
/// assert_eq!(scene.mesh.triangles.len(), layered.mesh.triangle_count());
/// assert!(scene.parts.iter().all(|p| p.blend));
/// assert_eq!(scene.parts[0].color[3], 1.0);
/// assert_eq!(scene.grid, Some(layered.mesh.grid));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn parse_glb(bytes: &[u8]) -> Result<GlbScene, LayersError> {
    let bad = |m: String| LayersError::Gltf(m);
    let glb =
        gltf::binary::Glb::from_slice(bytes).map_err(|e| bad(format!("not a GLB file: {e}")))?;
    let root: json::Root = json::deserialize::from_slice(&glb.json)
        .map_err(|e| bad(format!("bad JSON chunk: {e}")))?;
    let bin: &[u8] = glb.bin.as_deref().unwrap_or(&[]);
    let reader = Reader { root: &root, bin };
    let mut scene = GlbScene {
        orders: vec![None; 8],
        ..Default::default()
    };
    let chain = finest_of_chain(&root, &glb.json);
    for (m, mesh) in root.meshes.iter().enumerate() {
        if chain.is_some_and(|finest| finest != m) {
            continue;
        }
        for (p, prim) in mesh.primitives.iter().enumerate() {
            read_primitive(&reader, (m, mesh), (p, prim), &mut scene)?;
        }
    }
    let prefix = if chain.is_some() { "level 0 " } else { "" };
    read_orders(&reader, &mut scene, prefix)?;
    if scene.mesh.triangles.is_empty() {
        return Err(bad("no triangle primitives".into()));
    }
    scene.grid = stored_grid(&root);
    Ok(scene)
}

/// Appends primitive `p` of mesh `m` to `scene` as a part, when it draws triangles with
/// positions (others are skipped). Normals are kept while every primitive so far has them.
fn read_primitive(
    reader: &Reader,
    (m, mesh): (usize, &json::Mesh),
    (p, prim): (usize, &json::mesh::Primitive),
    scene: &mut GlbScene,
) -> Result<(), LayersError> {
    let bad = |m: String| LayersError::Gltf(m);
    match prim.mode {
        Checked::Valid(json::mesh::Mode::Triangles) => {}
        _ => return Ok(()),
    }
    let Some(pos) = prim
        .attributes
        .get(&Checked::Valid(json::mesh::Semantic::Positions))
    else {
        return Ok(());
    };
    let positions = reader.vec3(pos.value())?;
    let normals = match prim
        .attributes
        .get(&Checked::Valid(json::mesh::Semantic::Normals))
    {
        Some(n) => Some(reader.vec3(n.value())?),
        None => None,
    };
    let n = positions.len() as u32;
    let indices = match prim.indices {
        Some(i) => reader.indices(i.value())?,
        None => (0..n).collect(),
    };
    if indices.len() % 3 != 0 {
        return Err(bad(format!(
            "mesh {m} primitive {p}: {} indices is not a whole number of triangles",
            indices.len()
        )));
    }
    if let Some(&v) = indices.iter().find(|&&v| v >= n) {
        return Err(bad(format!(
            "mesh {m} primitive {p}: index {v} beyond its {n} vertices"
        )));
    }
    let base = scene.mesh.positions.len() as u32;
    let first_triangle = scene.mesh.triangles.len() as u32;
    let had_normals = !scene.mesh.normals.is_empty() || scene.mesh.positions.is_empty();
    match (normals, had_normals) {
        (Some(nr), true) if nr.len() == positions.len() => {
            scene.mesh.normals.extend_from_slice(&nr)
        }
        _ => scene.mesh.normals.clear(),
    }
    scene.mesh.positions.extend_from_slice(&positions);
    scene.mesh.triangles.extend(
        indices
            .chunks_exact(3)
            .map(|c| [c[0] + base, c[1] + base, c[2] + base]),
    );
    let (color, blend) = match prim.material {
        Some(mi) => {
            let mat = reader
                .root
                .materials
                .get(mi.value())
                .ok_or_else(|| bad(format!("mesh {m}: material {} missing", mi.value())))?;
            (
                mat.pbr_metallic_roughness.base_color_factor.0,
                matches!(
                    mat.alpha_mode,
                    Checked::Valid(json::material::AlphaMode::Blend)
                ),
            )
        }
        None => ([1.0; 4], false),
    };
    scene.parts.push(GlbPart {
        name: mesh.name.clone().unwrap_or_else(|| format!("mesh {m}")),
        first_vertex: base,
        vertex_count: n,
        first_triangle,
        triangle_count: (indices.len() / 3) as u32,
        color,
        blend,
    });
    Ok(())
}

/// The mesh of the finest level when the file is an `MSFT_lod` chain (the scene's first node
/// carries the extension): what the scene shows to a reader without the extension, and all
/// that is read of a chain.
fn finest_of_chain(root: &json::Root, json_chunk: &[u8]) -> Option<usize> {
    let scene = root.scene.map_or(0, |s| s.value());
    let node = root.scenes.get(scene)?.nodes.first()?.value();
    // gltf-json drops extensions it has no type for, so the node is looked up in the JSON.
    let doc: serde_json::Value = serde_json::from_slice(json_chunk).ok()?;
    doc["nodes"][node]["extensions"].get("MSFT_lod")?;
    Some(root.nodes.get(node)?.mesh?.value())
}

/// Reads the accessors named `PREFIXorder±x±y±z` into `scene.orders`; each must be a triangle
/// list over the vertices read.
fn read_orders(reader: &Reader, scene: &mut GlbScene, prefix: &str) -> Result<(), LayersError> {
    let total = scene.mesh.positions.len() as u32;
    for (a, acc) in reader.root.accessors.iter().enumerate() {
        let name = acc.name.as_deref().and_then(|n| n.strip_prefix(prefix));
        let Some(o) = name.and_then(Octant::from_name) else {
            continue;
        };
        let idx = reader.indices(a)?;
        if idx.len() % 3 != 0 || idx.iter().any(|&v| v >= total) {
            return Err(LayersError::Gltf(format!(
                "accessor {}: not a triangle list over the {total} vertices",
                o.name()
            )));
        }
        scene.orders[o.index()] = Some(idx.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect());
    }
    Ok(())
}

/// The volume grid of a voxlod file, from the extras of its scene (or its first scene);
/// `None` when absent or not a valid grid.
fn stored_grid(root: &json::Root) -> Option<voxlod_core::Grid> {
    root.scene
        .and_then(|i| root.scenes.get(i.value()))
        .or(root.scenes.first())
        .and_then(|sc| sc.extras.as_ref())
        .and_then(|raw| serde_json::from_str::<serde_json::Value>(raw.get()).ok())
        .and_then(|v| {
            let g = &v["voxlod"]["grid"];
            let triple = |x: &serde_json::Value| -> Option<[f64; 3]> {
                let a = x.as_array()?;
                Some([
                    a.first()?.as_f64()?,
                    a.get(1)?.as_f64()?,
                    a.get(2)?.as_f64()?,
                ])
            };
            let dims = triple(&g["dims"])?.map(|d| d as usize);
            voxlod_core::Grid::new(dims, triple(&g["spacing"])?, triple(&g["origin"])?).ok()
        })
}

/// Bounds-checked accessor reading.
struct Reader<'a> {
    root: &'a json::Root,
    bin: &'a [u8],
}

impl Reader<'_> {
    /// The bytes of accessor `a`: (data from the first element, element stride, count,
    /// component type).
    fn layout(
        &self,
        a: usize,
        elem_size: usize,
    ) -> Result<(&[u8], usize, usize, json::accessor::ComponentType), LayersError> {
        let bad = |m: String| LayersError::Gltf(format!("accessor {a}: {m}"));
        let acc = self
            .root
            .accessors
            .get(a)
            .ok_or_else(|| bad("missing".into()))?;
        let Checked::Valid(json::accessor::GenericComponentType(ct)) = acc.component_type else {
            return Err(bad("invalid component type".into()));
        };
        let view_index = acc
            .buffer_view
            .ok_or_else(|| bad("has no buffer view (sparse accessors are not read)".into()))?;
        let view = self
            .root
            .buffer_views
            .get(view_index.value())
            .ok_or_else(|| bad("its buffer view is missing".into()))?;
        if view.buffer.value() != 0 {
            return Err(bad("data outside the GLB's own buffer".into()));
        }
        let count = acc.count.0 as usize;
        let stride = view.byte_stride.map_or(elem_size, |s| s.0);
        let start = view.byte_offset.map_or(0, |o| o.0 as usize);
        let view_len = view.byte_length.0 as usize;
        let offset = acc.byte_offset.map_or(0, |o| o.0 as usize);
        let needed = if count == 0 {
            0
        } else {
            offset
                .checked_add((count - 1).saturating_mul(stride))
                .and_then(|x| x.checked_add(elem_size))
                .ok_or_else(|| bad("size overflows".into()))?
        };
        if stride < elem_size
            || needed > view_len
            || start
                .checked_add(view_len)
                .is_none_or(|end| end > self.bin.len())
        {
            return Err(bad("reaches beyond its buffer".into()));
        }
        Ok((
            &self.bin[start + offset..start + view_len],
            stride,
            count,
            ct,
        ))
    }

    fn vec3(&self, a: usize) -> Result<Vec<Vec3>, LayersError> {
        let (data, stride, count, ct) = self.layout(a, 12)?;
        if ct != json::accessor::ComponentType::F32 {
            return Err(LayersError::Gltf(format!(
                "accessor {a}: positions and normals must be floats"
            )));
        }
        let f = |b: &[u8]| f32::from_le_bytes([b[0], b[1], b[2], b[3]]);
        let out: Vec<Vec3> = (0..count)
            .map(|i| {
                let e = &data[i * stride..i * stride + 12];
                Vec3::new(f(&e[0..4]), f(&e[4..8]), f(&e[8..12]))
            })
            .collect();
        if let Some(i) = out.iter().position(|p| !p.is_finite()) {
            return Err(LayersError::Gltf(format!(
                "accessor {a}: element {i} is not finite"
            )));
        }
        Ok(out)
    }

    fn indices(&self, a: usize) -> Result<Vec<u32>, LayersError> {
        use json::accessor::ComponentType as C;
        let size = match self.root.accessors.get(a).map(|x| x.component_type) {
            Some(Checked::Valid(json::accessor::GenericComponentType(C::U8))) => 1,
            Some(Checked::Valid(json::accessor::GenericComponentType(C::U16))) => 2,
            Some(Checked::Valid(json::accessor::GenericComponentType(C::U32))) => 4,
            _ => {
                return Err(LayersError::Gltf(format!(
                    "accessor {a}: indices must be unsigned integers"
                )))
            }
        };
        let (data, stride, count, _) = self.layout(a, size)?;
        Ok((0..count)
            .map(|i| {
                let e = &data[i * stride..];
                match size {
                    1 => e[0] as u32,
                    2 => u16::from_le_bytes([e[0], e[1]]) as u32,
                    _ => u32::from_le_bytes([e[0], e[1], e[2], e[3]]),
                }
            })
            .collect())
    }
}
