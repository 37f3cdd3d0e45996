//! A glTF scene's node hierarchy flattened into one world-space mesh: every triangle primitive
//! of every node that holds a mesh, under each of its instances (a mesh that several nodes
//! name is repeated), with the node's world transform applied to positions, normals (by the
//! inverse transpose) and tangents, and the winding reversed under a mirroring transform so
//! that triangles keep facing out. Triangle strips and fans become lists; points and lines are
//! left out with a warning. An attribute that some primitives have and others lack is filled
//! for the others (normals computed from their triangles, texture coordinates 0, colours
//! white, tangents +x), so the mesh has one column per attribute.
//!
//! Of a level chain only the finest level is read: the nodes an `MSFT_lod` extension lists
//! are not roots of the scene, and of sibling nodes named `LOD0`, `LOD1`, … only `LOD0`.
//!
//! Cost: linear in the vertices and triangles of all instances; their total meets the memory
//! budget as it grows.

use gltf::mesh::Mode;
use gltf::{Document, Node, Primitive, Semantic};
use voxlod_asset::{AssetMesh, Part};
use voxlod_core::glam::{Mat3, Mat4, Vec2, Vec3, Vec4};
use voxlod_core::memory::check_allocation;

use super::accessor::{floats, indices};
use crate::GltfError;

/// The flattened mesh, where each primitive went, and the material index each primitive named
/// (`None` for the default material).
pub(crate) struct Flattened {
    pub mesh: AssetMesh,
    pub parts: Vec<Part>,
    /// One per triangle: the glTF material index, or `None`.
    pub material: Vec<Option<usize>>,
}

/// Every triangle primitive of the document's scene (the default one, or the first, or every
/// root node when it has no scene) in world space.
pub(crate) fn flatten(
    doc: &Document,
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
    };
    let mut stack: Vec<(Node, Mat4, usize)> = only_finest(roots)
        .into_iter()
        .map(|n| (n, Mat4::IDENTITY, 0))
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
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
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
            for p in mesh.primitives() {
                add_primitive(&mut out, &p, &world, &name, buffers, warnings)?;
            }
        }
        let children = only_finest(node.children().collect());
        stack.extend(children.into_iter().rev().map(|c| (c, world, depth + 1)));
    }
    Ok(out)
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
    world: &Mat4,
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
    let (v0, t0) = (out.mesh.positions.len(), out.mesh.triangles.len());
    let (v, t) = (v0 + read.positions.len(), t0 + read.triangles.len());
    check_allocation(
        &format!("the scene's {v} vertices and {t} triangles"),
        (v as u64) * 64 + (t as u64) * 20,
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

/// Appends a primitive in world space, filling the columns one side lacks.
fn place(out: &mut Flattened, read: Read, world: &Mat4, v0: usize) {
    let normal_matrix = Mat3::from_mat4(*world).inverse().transpose();
    let linear = Mat3::from_mat4(*world);
    let mirrored = linear.determinant() < 0.0;
    let m = &mut out.mesh;
    let n = read.positions.len();
    let own_normals = read
        .normals
        .clone()
        .unwrap_or_else(|| computed_normals(&read.positions, &read.triangles));
    m.positions
        .extend(read.positions.iter().map(|&p| world.transform_point3(p)));
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
