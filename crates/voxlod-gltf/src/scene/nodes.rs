//! A glTF scene's node hierarchy flattened into one world-space mesh: every triangle primitive
//! of every node that holds a mesh, under each of its instances (a mesh that several nodes
//! name is repeated), with the node's world transform applied to positions, normals (by the
//! inverse transpose) and tangents, and the winding reversed under a mirroring transform so
//! that triangles keep facing out. Triangle strips and fans become lists; points and lines are
//! left out with a warning. An attribute that some primitives have and others lack is filled
//! for the others (normals computed from their triangles, texture coordinates 0, colours
//! white, tangents +x), so the mesh has one column per attribute.
//!
//! A node with `EXT_mesh_gpu_instancing` places its mesh once per instance, the instance's
//! transform under the node's (as a child node's would be).
//!
//! Of a level chain only the finest level is read: the nodes an `MSFT_lod` extension lists
//! are not roots of the scene, and of sibling nodes named `LOD0`, `LOD1`, … only `LOD0`.
//!
//! **Far from the origin** (a georeferenced scene whose nodes sit at map coordinates, 10⁶ and
//! more): transforms are composed and positions placed in `f64`, and where the scene's box lies
//! farther from the origin than [`FAR`] times its diagonal, positions are kept relative to an
//! origin near the box's centre ([`Flattened::origin`]), so that the `f32` mesh keeps the
//! detail that `f32` world coordinates would round away (half a unit at 4·10⁶).
//!
//! Cost: linear in the vertices and triangles of all instances; their total meets the memory
//! budget as it grows.

use gltf::mesh::Mode;
use gltf::{Document, Node, Primitive, Semantic};
use voxlod_asset::{AssetMesh, Part};
use voxlod_core::glam::{DMat4, DQuat, DVec3, Mat3, Vec2, Vec3, Vec4};
use voxlod_core::memory::check_allocation;
use voxlod_core::Bounds;

use super::accessor::{floats, indices};
use crate::GltfError;

/// The flattened mesh, where each primitive went, and the material index each primitive named
/// (`None` for the default material).
pub(crate) struct Flattened {
    pub mesh: AssetMesh,
    pub parts: Vec<Part>,
    /// One per triangle: the glTF material index, or `None`.
    pub material: Vec<Option<usize>>,
    /// The world point the mesh's positions are relative to (module docs): zero but for a scene
    /// far from the origin.
    pub origin: DVec3,
    /// World positions while primitives are placed; moved into the mesh at the end.
    world: Vec<DVec3>,
}

/// A scene whose box lies farther from the origin than this many times its diagonal is read
/// relative to an origin near its centre: `f32` world coordinates would keep its detail to
/// about `FAR · 2⁻²⁴` of its size or worse.
pub const FAR: f64 = 1024.0;

/// Every triangle primitive of the document's scene (the default one, or the first, or every
/// root node when it has no scene) in world space.
pub(crate) fn flatten(
    doc: &Document,
    json: &serde_json::Value,
    buffers: &[Vec<u8>],
    warnings: &mut Vec<String>,
) -> Result<Flattened, GltfError> {
    let roots: Vec<Node> = match doc.default_scene().or_else(|| doc.scenes().next()) {
        Some(scene) => scene.nodes().collect(),
        None => {
            let mut child = vec![false; doc.nodes().len()];
            for n in doc.nodes() {
                for c in n.children() {
                    child[c.index()] = true;
                }
            }
            doc.nodes().filter(|n| !child[n.index()]).collect()
        }
    };
    let mut out = Flattened {
        mesh: AssetMesh::default(),
        parts: Vec::new(),
        material: Vec::new(),
        origin: DVec3::ZERO,
        world: Vec::new(),
    };
    let mut stack: Vec<(Node, DMat4, usize)> = only_finest(roots)
        .into_iter()
        .map(|n| (n, DMat4::IDENTITY, 0))
        .collect();
    stack.reverse();
    let limit = doc.nodes().len();
    while let Some((node, parent, depth)) = stack.pop() {
        if depth > limit {
            return Err(GltfError::Invalid(format!(
                "node {} is its own ancestor",
                node.index()
            )));
        }
        let world = parent * local_matrix(&node, json);
        if !world.is_finite() {
            return Err(GltfError::Invalid(format!(
                "node {}'s transform is not finite",
                node.index()
            )));
        }
        if let Some(mesh) = node.mesh() {
            let name = node
                .name()
                .or(mesh.name())
                .map_or_else(|| format!("node {}", node.index()), str::to_string);
            let instances = instances(&node, doc, json, buffers)?;
            for (k, instance) in instances.iter().enumerate() {
                let placed = world * *instance;
                let name = match instances.len() {
                    1 => name.clone(),
                    _ => format!("{name}, instance {k}"),
                };
                if !placed.is_finite() {
                    return Err(GltfError::Invalid(format!("{name}: transform not finite")));
                }
                for p in mesh.primitives() {
                    add_primitive(&mut out, &p, &placed, &name, buffers, warnings)?;
                }
            }
        }
        let children = only_finest(node.children().collect());
        stack.extend(children.into_iter().rev().map(|c| (c, world, depth + 1)));
    }
    out.origin = origin_of(&out.world);
    let origin = out.origin;
    out.mesh.positions = (out.world.drain(..))
        .map(|p| (p - origin).as_vec3())
        .collect();
    Ok(out)
}

/// The origin a scene's `world` positions are kept relative to: zero, or for a scene farther
/// from the origin than [`FAR`] times its diagonal, its box's centre rounded to a power of two
/// no larger than the diagonal (a round figure for the reports).
fn origin_of(world: &[DVec3]) -> DVec3 {
    let mut bounds = Bounds::EMPTY;
    world.iter().for_each(|&p| bounds.grow(p));
    let diagonal = bounds.diagonal();
    let far = bounds.min.abs().max(bounds.max.abs()).max_element();
    if bounds.is_empty() || diagonal <= 0.0 || far <= FAR * diagonal {
        return DVec3::ZERO;
    }
    let step = 2f64.powi(diagonal.log2().floor() as i32);
    (bounds.center() / step).round() * step
}

/// `node`'s transform in `f64`, from the file's JSON numbers (the `gltf` crate keeps them as
/// `f32`, which moves a node at 4·10⁶ by up to a quarter of a unit): its `matrix`, else its
/// translation, rotation and scale composed; the crate's `f32` transform where the JSON has
/// neither in the expected shape.
fn local_matrix(node: &Node, json: &serde_json::Value) -> DMat4 {
    let n = &json["nodes"][node.index()];
    let numbers = |key: &str, len: usize| -> Option<Vec<f64>> {
        let list = n.get(key)?.as_array()?;
        let v: Vec<f64> = list.iter().filter_map(serde_json::Value::as_f64).collect();
        (v.len() == len && list.len() == len).then_some(v)
    };
    if n.get("matrix").is_some() {
        if let Some(m) = numbers("matrix", 16) {
            return DMat4::from_cols_slice(&m);
        }
    } else {
        let t = numbers("translation", 3).unwrap_or_else(|| vec![0.0; 3]);
        let r = numbers("rotation", 4).unwrap_or_else(|| vec![0.0, 0.0, 0.0, 1.0]);
        let s = numbers("scale", 3).unwrap_or_else(|| vec![1.0; 3]);
        let rotation = DQuat::from_xyzw(r[0], r[1], r[2], r[3]).normalize();
        return DMat4::from_scale_rotation_translation(
            DVec3::from_slice(&s),
            rotation,
            DVec3::from_slice(&t),
        );
    }
    let m = node.transform().matrix();
    DMat4::from_cols_array_2d(&m.map(|c| c.map(f64::from)))
}

/// The extension that draws a node's mesh once per instance.
pub(crate) const INSTANCING: &str = "EXT_mesh_gpu_instancing";

/// The transforms `node`'s mesh is drawn under, in the node's frame: one identity, or with
/// `EXT_mesh_gpu_instancing` one per instance, composed of its `TRANSLATION`, `ROTATION` and
/// `SCALE` (each optional, all of one count) as a node's are. Errors name the node.
pub(crate) fn instances(
    node: &Node,
    doc: &Document,
    json: &serde_json::Value,
    buffers: &[Vec<u8>],
) -> Result<Vec<DMat4>, GltfError> {
    let attributes = &json["nodes"][node.index()]["extensions"][INSTANCING]["attributes"];
    if attributes.is_null() {
        return Ok(vec![DMat4::IDENTITY]);
    }
    let invalid =
        |m: String| GltfError::Invalid(format!("node {} ({INSTANCING}): {m}", node.index()));
    let accessor = |key: &str| -> Result<Option<gltf::Accessor>, GltfError> {
        match &attributes[key] {
            serde_json::Value::Null => Ok(None),
            v => (v.as_u64())
                .and_then(|i| doc.accessors().nth(i as usize))
                .map(Some)
                .ok_or_else(|| invalid(format!("{key} names no accessor: {v}"))),
        }
    };
    let vec3 = |key: &str| -> Result<Option<Vec<[f32; 3]>>, GltfError> {
        accessor(key)?.map(|a| floats::<3>(&a, buffers)).transpose()
    };
    let (t, s) = (vec3("TRANSLATION")?, vec3("SCALE")?);
    let r = (accessor("ROTATION")?)
        .map(|a| floats::<4>(&a, buffers))
        .transpose()?;
    let counts: Vec<usize> = [
        t.as_ref().map(Vec::len),
        r.as_ref().map(Vec::len),
        s.as_ref().map(Vec::len),
    ]
    .into_iter()
    .flatten()
    .collect();
    let Some(&n) = counts.first() else {
        return Err(invalid("no TRANSLATION, ROTATION or SCALE".into()));
    };
    if counts.iter().any(|&c| c != n) {
        return Err(invalid(format!(
            "attributes of different counts {counts:?}"
        )));
    }
    check_allocation(
        &format!("node {}'s {n} instances", node.index()),
        n as u64 * 128,
    )?;
    let d3 = |v: [f32; 3]| DVec3::from_array(v.map(f64::from));
    Ok((0..n)
        .map(|k| {
            let translation = t.as_ref().map_or(DVec3::ZERO, |t| d3(t[k]));
            let scale = s.as_ref().map_or(DVec3::ONE, |s| d3(s[k]));
            let rotation = r.as_ref().map_or(DQuat::IDENTITY, |r| {
                let [x, y, z, w] = r[k].map(f64::from);
                DQuat::from_xyzw(x, y, z, w).normalize()
            });
            DMat4::from_scale_rotation_translation(scale, rotation, translation)
        })
        .collect())
}

/// Sibling nodes without those named `LOD1`, `LOD2`, … when one is named `LOD0`.
fn only_finest(nodes: Vec<Node>) -> Vec<Node> {
    let level = |n: &Node| {
        n.name()
            .and_then(|s| s.strip_prefix("LOD"))
            .and_then(|k| k.parse::<u32>().ok())
    };
    if !nodes.iter().any(|n| level(n) == Some(0)) {
        return nodes;
    }
    nodes
        .into_iter()
        .filter(|n| level(n).is_none_or(|k| k == 0))
        .collect()
}

/// One primitive's attributes, as read.
struct Read {
    positions: Vec<Vec3>,
    normals: Option<Vec<Vec3>>,
    tangents: Option<Vec<Vec4>>,
    uv: [Option<Vec<Vec2>>; 2],
    colors: Option<Vec<Vec4>>,
    triangles: Vec<[u32; 3]>,
}

fn add_primitive(
    out: &mut Flattened,
    p: &Primitive,
    world: &DMat4,
    name: &str,
    buffers: &[Vec<u8>],
    warnings: &mut Vec<String>,
) -> Result<(), GltfError> {
    let here = |e: GltfError| match e {
        GltfError::Invalid(m) => {
            GltfError::Invalid(format!("{name}, primitive {}: {m}", p.index()))
        }
        other => other,
    };
    let Some(read) = read_primitive(p, buffers, name, warnings).map_err(here)? else {
        return Ok(());
    };
    let (v0, t0) = (out.world.len(), out.mesh.triangles.len());
    let (v, t) = (v0 + read.positions.len(), t0 + read.triangles.len());
    check_allocation(
        &format!("the scene's {v} vertices and {t} triangles"),
        (v as u64) * 88 + (t as u64) * 20,
    )?;
    if v > u32::MAX as usize {
        return Err(GltfError::Invalid(format!(
            "the scene has more than {} vertices",
            u32::MAX
        )));
    }
    place(out, read, world, v0);
    out.material
        .extend(std::iter::repeat_n(p.material().index(), t - t0));
    out.parts.push(Part {
        name: name.to_string(),
        first_triangle: t0 as u32,
        triangle_count: (t - t0) as u32,
    });
    Ok(())
}

/// Reads one primitive, or `None` (with a warning) for one that is not made of triangles or
/// has no positions.
fn read_primitive(
    p: &Primitive,
    buffers: &[Vec<u8>],
    name: &str,
    warnings: &mut Vec<String>,
) -> Result<Option<Read>, GltfError> {
    let Some(pos) = p.get(&Semantic::Positions) else {
        warnings.push(format!(
            "{name}, primitive {}: no positions, left out",
            p.index()
        ));
        return Ok(None);
    };
    let positions: Vec<Vec3> = floats::<3>(&pos, buffers)?
        .into_iter()
        .map(Vec3::from)
        .collect();
    let n = positions.len();
    let list = match p.indices() {
        Some(a) => indices(&a, buffers)?,
        None => (0..n as u32).collect(),
    };
    if let Some(&bad) = list.iter().find(|&&i| i as usize >= n) {
        return Err(GltfError::Invalid(format!(
            "index {bad} beyond its {n} vertices"
        )));
    }
    let triangles = match p.mode() {
        Mode::Triangles => list.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
        Mode::TriangleStrip => (2..list.len())
            .map(|k| {
                if k % 2 == 0 {
                    [list[k - 2], list[k - 1], list[k]]
                } else {
                    [list[k - 1], list[k - 2], list[k]]
                }
            })
            .collect(),
        Mode::TriangleFan => (2..list.len())
            .map(|k| [list[0], list[k - 1], list[k]])
            .collect(),
        other => {
            warnings.push(format!(
                "{name}, primitive {}: {other:?} are not surfaces, left out",
                p.index()
            ));
            return Ok(None);
        }
    };
    let mut read = read_columns(p, buffers)?;
    read.positions = positions;
    read.triangles = triangles;
    read.check_lengths(n)?;
    Ok(Some(read))
}

/// A primitive's attribute columns other than positions (the positions and triangles empty).
fn read_columns(p: &Primitive, buffers: &[Vec<u8>]) -> Result<Read, GltfError> {
    let column = |s: Semantic| p.get(&s);
    let normals = column(Semantic::Normals)
        .map(|a| floats::<3>(&a, buffers))
        .transpose()?
        .map(|v| v.into_iter().map(Vec3::from).collect::<Vec<_>>());
    let tangents = column(Semantic::Tangents)
        .map(|a| floats::<4>(&a, buffers))
        .transpose()?
        .map(|v| v.into_iter().map(Vec4::from).collect::<Vec<_>>());
    let [uv0, uv1] =
        [0, 1].map(|k| column(Semantic::TexCoords(k)).map(|a| floats::<2>(&a, buffers)));
    let uv = [uv0.transpose()?, uv1.transpose()?]
        .map(|o| o.map(|v| v.into_iter().map(Vec2::from).collect::<Vec<_>>()));
    let colors = match column(Semantic::Colors(0)) {
        Some(a) if a.dimensions().multiplicity() == 3 => Some(
            floats::<3>(&a, buffers)?
                .into_iter()
                .map(|c| Vec3::from(c).extend(1.0))
                .collect::<Vec<_>>(),
        ),
        Some(a) => Some(
            floats::<4>(&a, buffers)?
                .into_iter()
                .map(Vec4::from)
                .collect(),
        ),
        None => None,
    };
    Ok(Read {
        positions: Vec::new(),
        normals,
        tangents,
        uv,
        colors,
        triangles: Vec::new(),
    })
}

impl Read {
    /// Refuses a column whose length is not the `n` positions'.
    fn check_lengths(&self, n: usize) -> Result<(), GltfError> {
        for (what, len) in [
            ("normals", self.normals.as_ref().map(Vec::len)),
            ("tangents", self.tangents.as_ref().map(Vec::len)),
            ("texture coordinates 0", self.uv[0].as_ref().map(Vec::len)),
            ("texture coordinates 1", self.uv[1].as_ref().map(Vec::len)),
            ("colours", self.colors.as_ref().map(Vec::len)),
        ] {
            if let Some(len) = len.filter(|&len| len != n) {
                return Err(GltfError::Invalid(format!(
                    "{len} {what} for {n} positions"
                )));
            }
        }
        Ok(())
    }
}

/// Appends a primitive in world space (its positions to [`Flattened::world`]), filling the
/// columns one side lacks.
fn place(out: &mut Flattened, read: Read, world: &DMat4, v0: usize) {
    let linear = Mat3::from_mat4(world.as_mat4());
    let normal_matrix = linear.inverse().transpose();
    let mirrored = linear.determinant() < 0.0;
    let m = &mut out.mesh;
    let n = read.positions.len();
    let own_normals = read
        .normals
        .clone()
        .unwrap_or_else(|| computed_normals(&read.positions, &read.triangles));
    let placed = read.positions.iter();
    (out.world).extend(placed.map(|&p| world.transform_point3(p.as_dvec3())));
    fill(&mut m.normals, Some(own_normals), v0, n, Vec3::Z, |v| {
        (normal_matrix * v).normalize_or_zero()
    });
    let sign = if mirrored { -1.0 } else { 1.0 };
    fill(
        &mut m.tangents,
        read.tangents,
        v0,
        n,
        Vec4::new(1.0, 0.0, 0.0, 1.0),
        |t| {
            (linear * t.truncate())
                .normalize_or_zero()
                .extend(t.w * sign)
        },
    );
    let [uv0, uv1] = read.uv;
    fill(&mut m.uv[0], uv0, v0, n, Vec2::ZERO, |t| t);
    fill(&mut m.uv[1], uv1, v0, n, Vec2::ZERO, |t| t);
    fill(&mut m.colors, read.colors, v0, n, Vec4::ONE, |c| c);
    let base = v0 as u32;
    m.triangles.extend(read.triangles.iter().map(|&[a, b, c]| {
        if mirrored {
            [a + base, c + base, b + base]
        } else {
            [a + base, b + base, c + base]
        }
    }));
}

/// One attribute column: `values` (transformed) appended for `n` new vertices, or the default
/// where the primitive lacks it and the mesh has it; earlier vertices get the default when the
/// column starts here.
fn fill<T: Copy>(
    column: &mut Vec<T>,
    values: Option<Vec<T>>,
    v0: usize,
    n: usize,
    default: T,
    map: impl Fn(T) -> T,
) {
    match values {
        Some(v) => {
            if column.len() < v0 {
                column.resize(v0, default);
            }
            column.extend(v.into_iter().map(map));
        }
        None if !column.is_empty() => column.resize(v0 + n, default),
        None => {}
    }
}

/// Area-weighted vertex normals of a primitive without its own.
fn computed_normals(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    let mut normals = vec![Vec3::ZERO; positions.len()];
    for t in triangles {
        let [a, b, c] = t.map(|v| positions[v as usize]);
        let n = (b - a).cross(c - a);
        for &v in t {
            normals[v as usize] += n;
        }
    }
    normals.iter().map(|n| n.normalize_or_zero()).collect()
}
