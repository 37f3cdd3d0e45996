//! Reading a binary glTF 2.0 file (`.glb`) as one triangle mesh: every triangle primitive with
//! float positions, concatenated in mesh then primitive order, with where each lies and its
//! material ([`GlbPart`]). Of an `MSFT_lod` chain (as [`crate::chain`] writes it) only the
//! finest level is read. What a voxlod layered file stores beside its meshes comes back too:
//! the eight back-to-front orders (accessors named by [`ORDER_NAMES`]) and the volume grid the
//! layers were cut from with the placement of their vertices (the scene's extras); the layout
//! is documented with the layered writer, `voxlod_layers::glb`.
//!
//! Every offset is checked against the buffer, so a broken file is an error, never a panic;
//! the file's size meets the memory limit before it is read. Node transforms are ignored, and
//! so are sparse accessors and data outside the GLB's own buffer (refused). Cost: linear in
//! the file.

use std::path::Path;

use glam::Vec3;
use gltf::json;
use gltf::json::validation::Checked;
use voxlod_core::{Placement, TriangleMesh};

use crate::file::{file_bytes, named};
use crate::GltfError;

/// The accessor names of the eight back-to-front orders a layered file stores, by octant of the
/// view direction (eye to scene): the signs along x, y and z, the index having bit 4 for
/// x < 0, 2 for y < 0 and 1 for z < 0. A level of a layered chain prefixes them with
/// `level K `.
pub const ORDER_NAMES: [&str; 8] = [
    "order+x+y+z",
    "order+x+y-z",
    "order+x-y+z",
    "order+x-y-z",
    "order-x+y+z",
    "order-x+y-z",
    "order-x-y+z",
    "order-x-y-z",
];

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

/// What [`read_glb`] found: every triangle primitive concatenated, and what a layered file
/// stores beside them.
#[derive(Clone, Debug, PartialEq)]
pub struct GlbScene {
    /// All primitives' vertices and triangles, in mesh then primitive order (global indices).
    pub mesh: TriangleMesh,
    /// Where each primitive lies in `mesh`, and its material.
    pub parts: Vec<GlbPart>,
    /// The accessors named by [`ORDER_NAMES`], in its order, as triangles of global vertex
    /// indices; eight entries, `None` where the file has no such accessor.
    pub orders: Vec<Option<Vec<[u32; 3]>>>,
    /// The volume grid the layers were cut from (scene extras of a voxlod file).
    pub grid: Option<voxlod_core::Grid>,
    /// The map from the grid's space to the vertices' (an oblique or flipped scan's layers);
    /// the identity when the file records none: the vertices lie in the grid's space.
    pub placement: Placement,
}

impl Default for GlbScene {
    /// Nothing read: no mesh, part, order or grid, the identity placement.
    fn default() -> Self {
        GlbScene {
            mesh: TriangleMesh::default(),
            parts: Vec::new(),
            orders: Vec::new(),
            grid: None,
            placement: Placement::IDENTITY,
        }
    }
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

    /// A scene read as an asset ([`crate::read_scene`]: in world space, compressed, quantized
    /// and instanced files included) as a plain, unlayered `GlbScene`: its positions and
    /// triangles, a part per primitive and instance with its material's base colour.
    pub fn from_scene(read: &crate::SceneRead) -> GlbScene {
        let a = &read.asset;
        let mut next_vertex = 0u32;
        let parts = (a.parts.iter())
            .map(|p| {
                let range =
                    p.first_triangle as usize..(p.first_triangle + p.triangle_count) as usize;
                let corners = || a.mesh.triangles[range.clone()].iter().flatten().copied();
                let first = corners().min().unwrap_or(next_vertex);
                let last = corners().max().map_or(first, |v| v + 1);
                next_vertex = last;
                let material =
                    (a.mesh.material.get(range.start)).and_then(|&m| a.materials.get(m as usize));
                GlbPart {
                    name: p.name.clone(),
                    first_vertex: first,
                    vertex_count: last - first,
                    first_triangle: p.first_triangle,
                    triangle_count: p.triangle_count,
                    color: material.map_or([1.0; 4], |m| m.base_color),
                    blend: material.is_some_and(|m| m.alpha_mode == voxlod_asset::AlphaMode::Blend),
                }
            })
            .collect();
        GlbScene {
            mesh: TriangleMesh::new(a.mesh.positions.clone(), a.mesh.triangles.clone()),
            parts,
            ..GlbScene::default()
        }
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
}

/// Reads a `.glb` (see the module documentation). An error names the file: one that cannot be
/// read is [`GltfError::Io`] (of kind `Access`), one that is not a usable glTF binary
/// [`GltfError::Invalid`].
pub fn read_glb(path: &Path) -> Result<GlbScene, GltfError> {
    parse_glb(&file_bytes(path)?).map_err(|e| named(path, e))
}

/// Reads any `.glb`: a layered file as [`read_glb`] reads it, any other as its scene
/// ([`GlbScene::from_scene`] of [`crate::parse_scene`]). The file is read once; errors name it
/// as [`read_glb`]'s do.
pub fn read_any_glb(path: &Path) -> Result<GlbScene, GltfError> {
    let bytes = file_bytes(path)?;
    if let Ok(stored) = parse_glb(&bytes) {
        if stored.is_layered() {
            return Ok(stored);
        }
    }
    let read = crate::parse_scene(&bytes, path.parent()).map_err(|e| named(path, e))?;
    Ok(GlbScene::from_scene(&read))
}

/// Parses the bytes of a `.glb`.
///
/// # Example
///
/// A chain of two levels reads back as its finest level: one part, the level's own triangles.
///
/// ```
/// use voxlod_core::{glam::Vec3, TriangleMesh};
/// use voxlod_gltf::{chain_glb_bytes, parse_glb, ChainLevel, ChainOptions};
///
/// let corners = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
/// let tetrahedron = TriangleMesh::new(corners, vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]);
/// let triangle = TriangleMesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]]);
/// let levels = [ChainLevel::new(0, &tetrahedron, 0.5), ChainLevel::new(1, &triangle, 1.0)];
/// let bytes = chain_glb_bytes(&levels, &ChainOptions::default())?;
/// let scene = parse_glb(&bytes)?;
/// assert_eq!(scene.parts.len(), 1);
/// assert_eq!(scene.mesh.positions, tetrahedron.positions);
/// assert_eq!(scene.mesh.triangles, tetrahedron.triangles);
/// assert!(!scene.is_layered());
/// assert_eq!(scene.grid, None);
///
/// // A file cut short is an error, not a panic.
/// assert!(parse_glb(&bytes[..bytes.len() / 2]).is_err());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn parse_glb(bytes: &[u8]) -> Result<GlbScene, GltfError> {
    let bad = GltfError::Invalid;
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
    (scene.grid, scene.placement) = stored_grid(&root);
    Ok(scene)
}

/// Appends primitive `p` of mesh `m` to `scene` as a part, when it draws triangles with
/// positions (others are skipped). Normals are kept while every primitive so far has them.
fn read_primitive(
    reader: &Reader,
    (m, mesh): (usize, &json::Mesh),
    (p, prim): (usize, &json::mesh::Primitive),
    scene: &mut GlbScene,
) -> Result<(), GltfError> {
    let bad = GltfError::Invalid;
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
fn read_orders(reader: &Reader, scene: &mut GlbScene, prefix: &str) -> Result<(), GltfError> {
    let total = scene.mesh.positions.len() as u32;
    for (a, acc) in reader.root.accessors.iter().enumerate() {
        let name = acc.name.as_deref().and_then(|n| n.strip_prefix(prefix));
        let Some(o) = name.and_then(|n| ORDER_NAMES.iter().position(|o| *o == n)) else {
            continue;
        };
        let idx = reader.indices(a)?;
        if idx.len() % 3 != 0 || idx.iter().any(|&v| v >= total) {
            return Err(GltfError::Invalid(format!(
                "accessor {}: not a triangle list over the {total} vertices",
                ORDER_NAMES[o]
            )));
        }
        scene.orders[o] = Some(idx.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect());
    }
    Ok(())
}

/// The volume grid of a voxlod file, from the extras of its scene (or its first scene), and
/// the placement of its vertices: `None` for a grid absent or not valid, the identity for a
/// placement absent, without a grid, or not finite and invertible.
fn stored_grid(root: &json::Root) -> (Option<voxlod_core::Grid>, Placement) {
    let Some(v) = root
        .scene
        .and_then(|i| root.scenes.get(i.value()))
        .or(root.scenes.first())
        .and_then(|sc| sc.extras.as_ref())
        .and_then(|raw| serde_json::from_str::<serde_json::Value>(raw.get()).ok())
    else {
        return (None, Placement::IDENTITY);
    };
    let g = &v["voxlod"]["grid"];
    let triple = |x: &serde_json::Value| -> Option<[f64; 3]> {
        let a = x.as_array()?;
        Some([
            a.first()?.as_f64()?,
            a.get(1)?.as_f64()?,
            a.get(2)?.as_f64()?,
        ])
    };
    let grid = (|| {
        let dims = triple(&g["dims"])?.map(|d| d as usize);
        voxlod_core::Grid::new(dims, triple(&g["spacing"])?, triple(&g["origin"])?).ok()
    })();
    let placement = grid.and_then(|_| {
        let rows = g["placement"].as_array()?;
        let row = |r: usize| -> Option<[f64; 4]> {
            let a = rows.get(r)?.as_array()?;
            let x = |c: usize| a.get(c)?.as_f64();
            Some([x(0)?, x(1)?, x(2)?, x(3)?])
        };
        let [r0, r1, r2] = [row(0)?, row(1)?, row(2)?];
        let linear = glam::DMat3::from_cols_array(&[
            r0[0], r1[0], r2[0], r0[1], r1[1], r2[1], r0[2], r1[2], r2[2],
        ]);
        let translation = glam::DVec3::new(r0[3], r1[3], r2[3]);
        let det = linear.determinant();
        (linear.is_finite() && translation.is_finite() && det.is_normal()).then_some(Placement {
            linear,
            translation,
        })
    });
    (grid, placement.unwrap_or(Placement::IDENTITY))
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
    ) -> Result<(&[u8], usize, usize, json::accessor::ComponentType), GltfError> {
        let bad = |m: String| GltfError::Invalid(format!("accessor {a}: {m}"));
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

    fn vec3(&self, a: usize) -> Result<Vec<Vec3>, GltfError> {
        let (data, stride, count, ct) = self.layout(a, 12)?;
        if ct != json::accessor::ComponentType::F32 {
            return Err(GltfError::Invalid(format!(
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
            return Err(GltfError::Invalid(format!(
                "accessor {a}: element {i} is not finite"
            )));
        }
        Ok(out)
    }

    fn indices(&self, a: usize) -> Result<Vec<u32>, GltfError> {
        use json::accessor::ComponentType as C;
        let size = match self.root.accessors.get(a).map(|x| x.component_type) {
            Some(Checked::Valid(json::accessor::GenericComponentType(C::U8))) => 1,
            Some(Checked::Valid(json::accessor::GenericComponentType(C::U16))) => 2,
            Some(Checked::Valid(json::accessor::GenericComponentType(C::U32))) => 4,
            _ => {
                return Err(GltfError::Invalid(format!(
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
