//! Stanford PLY through `ply-rs-bw`: ASCII and binary (either byte order) in, binary
//! little-endian out.
//!
//! Reading: the `vertex` element gives positions (`x`, `y`, `z`, any scalar type), normals
//! (`nx`, `ny`, `nz`) and, for [`read_poly_mesh`](crate::read_poly_mesh), every other scalar
//! property as a vertex attribute; `face` lists (`vertex_indices` or `vertex_index`, any
//! integer types) become triangles, polygons ear-clipped; `tristrips` lists (`vertex_indices`,
//! as the Stanford scanning tools and VCG write them: strips separated by -1, each triangle's
//! winding alternating along its strip, repeated corners joining strips) become triangles too;
//! `edge` (`vertex1`, `vertex2`, other
//! scalars as line attributes) and `point` (`vertex_index`) as voxlod writes them. Other
//! elements are read past and ignored. Vertex colours (`red`, `green`, `blue`, `alpha`, or
//! `diffuse_*`) are attributes like any other; [`PlyColors`] says which they are and how to
//! scale them, and [`PlyLooks`] which are texture coordinates and what texture the header's
//! comments name, for [`read_asset`](crate::read_asset). Each element is parsed straight into a small record
//! type rather than ply-rs-bw's map-per-element default, which would cost a hash map per vertex.
//!
//! Writing: `vertex` (x, y, z as float, nx, ny, nz when the mesh has normals, then one float
//! property per vertex attribute), `face` (`list uchar int vertex_indices`), then `edge`
//! (`int vertex1`, `int vertex2`, one float per line attribute) and `point`
//! (`int vertex_index`) when there are lines or points. Vertices and faces are encoded directly
//! a block at a time ([`body`]), edges and points streamed one at a time through
//! ply-rs-bw's writer, so no second copy of the mesh is built.

mod body;
mod header;

use std::fs::File;
use std::io::{BufRead, BufReader, Write};
use std::path::Path;

use glam::{DVec3, Vec3};
use ply_rs_bw::parser::{Parser, Reader};
use ply_rs_bw::ply::{
    Addable, ElementDef, Encoding, Header, Property, PropertyAccess, PropertyAccessResult,
    PropertyDef, PropertyType, ScalarType,
};
use ply_rs_bw::writer::Writer;
use voxlod_core::{Attribute, PolyMesh, TriangleMesh};

use crate::atomic::{stage, TempFile};
use crate::{budget, ear_clipping, guard, IoError, PolyView};

/// What the PLY reader found, before the common checks.
pub(crate) struct PlyContent {
    pub mesh: PolyMesh,
    pub polygons_triangulated: usize,
    /// Which vertex attributes are colour channels, when the vertices have colours.
    pub colors: Option<PlyColors>,
    /// The looks the header and the vertices carry besides colours.
    pub looks: PlyLooks,
}

/// What a PLY file says about its texture: which vertex attributes hold per-vertex texture
/// coordinates (`u`/`v`, `s`/`t`, `texture_u`/`texture_v` or `texture_s`/`texture_t`; as
/// stored, v up the image), the file its `comment TextureFile` line names (as MeshLab writes
/// it), and whether faces carry per-corner texture coordinates (a `texcoord` list, not read).
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct PlyLooks {
    pub uv: Option<[usize; 2]>,
    pub texture_file: Option<String>,
    pub face_texcoords: bool,
}

/// The property name pairs of per-vertex texture coordinates.
const UV_NAMES: [[&str; 2]; 4] = [
    ["u", "v"],
    ["s", "t"],
    ["texture_u", "texture_v"],
    ["texture_s", "texture_t"],
];

/// The [`PlyLooks`] of a header whose vertex extras are `names`. Cost: O(properties + comments).
fn looks_of(header: &Header, names: &[&str]) -> PlyLooks {
    let position = |name: &str| names.iter().position(|n| *n == name);
    let uv = UV_NAMES
        .iter()
        .find_map(|[u, v]| Some([position(u)?, position(v)?]));
    let texture_file = header.comments.iter().find_map(|c| {
        let (key, file) = c.trim().split_once(char::is_whitespace)?;
        (key.eq_ignore_ascii_case("texturefile") && !file.trim().is_empty())
            .then(|| file.trim().to_string())
    });
    let face_texcoords = header
        .elements
        .get("face")
        .is_some_and(|f| f.properties.contains_key("texcoord"));
    PlyLooks {
        uv,
        texture_file,
        face_texcoords,
    }
}

/// The vertex colour properties of a PLY file: for red, green, blue and alpha (in that order),
/// the index of its attribute in [`PolyMesh::vertex_attributes`] and the factor that takes the
/// stored value to 0..=1 (1/255 for `uchar`, `char` and the 32-bit integers, 1/65535 for the
/// 16-bit ones, 1 for `float` and `double`). Values are as stored: sRGB by convention.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct PlyColors {
    pub channels: [Option<(usize, f32)>; 4],
}

/// The property names each colour channel goes by, the common one first.
const COLOR_NAMES: [[&str; 2]; 4] = [
    ["red", "diffuse_red"],
    ["green", "diffuse_green"],
    ["blue", "diffuse_blue"],
    ["alpha", "diffuse_alpha"],
];

/// The colour channels among the vertex's extra properties (`names`, in attribute order):
/// `None` unless red, green and blue are all there. Cost: O(properties).
fn color_channels(header: &Header, names: &[&str]) -> Option<PlyColors> {
    let vertex = header.elements.get("vertex")?;
    let channel = |candidates: &[&str; 2]| {
        candidates.iter().find_map(|name| {
            let k = names.iter().position(|n| n == name)?;
            let PropertyType::Scalar(t) = &vertex.properties.get(*name)?.data_type else {
                return None;
            };
            let scale = match t {
                ScalarType::Float | ScalarType::Double => 1.0,
                ScalarType::Short | ScalarType::UShort => 1.0 / 65535.0,
                _ => 1.0 / 255.0,
            };
            Some((k, scale))
        })
    };
    let channels = COLOR_NAMES.map(|c| channel(&c));
    channels[..3]
        .iter()
        .all(Option::is_some)
        .then_some(PlyColors { channels })
}

// ---------------------------------------------------------------------------------------------
// Records: one per element kind, filled by the parser through `PropertyAccess`.

/// A scalar of any PLY type, widened.
fn scalar(property: &Property) -> Option<f64> {
    Some(match *property {
        Property::Char(v) => v as f64,
        Property::UChar(v) => v as f64,
        Property::Short(v) => v as f64,
        Property::UShort(v) => v as f64,
        Property::Int(v) => v as f64,
        Property::UInt(v) => v as f64,
        Property::Float(v) => v as f64,
        Property::Double(v) => v,
        _ => return None,
    })
}

/// An integer list of any PLY type, widened; `None` for float lists.
fn int_list(property: Property) -> Option<Vec<i64>> {
    Some(match property {
        Property::ListChar(v) => v.into_iter().map(i64::from).collect(),
        Property::ListUChar(v) => v.into_iter().map(i64::from).collect(),
        Property::ListShort(v) => v.into_iter().map(i64::from).collect(),
        Property::ListUShort(v) => v.into_iter().map(i64::from).collect(),
        Property::ListInt(v) => v.into_iter().map(i64::from).collect(),
        Property::ListUInt(v) => v.into_iter().map(i64::from).collect(),
        _ => return None,
    })
}

/// A `vertex`: position, normal and the remaining scalars in header order.
#[derive(Default)]
struct VertexRecord {
    position: [f64; 3],
    normal: [f32; 3],
    extra: Vec<f32>,
}

impl PropertyAccess for VertexRecord {
    fn new() -> Self {
        VertexRecord::default()
    }

    fn set_property(&mut self, name: &str, property: Property) -> PropertyAccessResult {
        let Some(value) = scalar(&property) else {
            return PropertyAccessResult::Ignored;
        };
        match name {
            "x" => self.position[0] = value,
            "y" => self.position[1] = value,
            "z" => self.position[2] = value,
            "nx" => self.normal[0] = value as f32,
            "ny" => self.normal[1] = value as f32,
            "nz" => self.normal[2] = value as f32,
            _ => self.extra.push(value as f32),
        }
        PropertyAccessResult::Set
    }
}

/// Whether a vertex property is one of the [`VertexRecord::extra`] values.
fn is_vertex_extra(def: &PropertyDef) -> bool {
    matches!(def.data_type, PropertyType::Scalar(_))
        && !matches!(def.name.as_str(), "x" | "y" | "z" | "nx" | "ny" | "nz")
}

/// A `face`: its corner indices (negative ones kept, to be reported).
#[derive(Default)]
struct FaceRecord {
    corners: Vec<i64>,
    /// The index list had a float type.
    bad_type: bool,
}

impl PropertyAccess for FaceRecord {
    fn new() -> Self {
        FaceRecord::default()
    }

    fn set_property(&mut self, name: &str, property: Property) -> PropertyAccessResult {
        if name == "vertex_indices" || name == "vertex_index" {
            match int_list(property) {
                Some(list) => self.corners = list,
                None => self.bad_type = true,
            }
            PropertyAccessResult::Set
        } else {
            PropertyAccessResult::Ignored
        }
    }
}

/// An `edge`: two vertex indices and the remaining scalars in header order.
#[derive(Default)]
struct EdgeRecord {
    ends: [i64; 2],
    extra: Vec<f32>,
}

impl PropertyAccess for EdgeRecord {
    fn new() -> Self {
        EdgeRecord::default()
    }

    fn set_property(&mut self, name: &str, property: Property) -> PropertyAccessResult {
        let Some(value) = scalar(&property) else {
            return PropertyAccessResult::Ignored;
        };
        match name {
            "vertex1" => self.ends[0] = value as i64,
            "vertex2" => self.ends[1] = value as i64,
            _ => self.extra.push(value as f32),
        }
        PropertyAccessResult::Set
    }
}

fn is_edge_extra(def: &PropertyDef) -> bool {
    matches!(def.data_type, PropertyType::Scalar(_))
        && !matches!(def.name.as_str(), "vertex1" | "vertex2")
}

/// A `point`: one vertex index.
#[derive(Default)]
struct PointRecord {
    vertex: i64,
}

impl PropertyAccess for PointRecord {
    fn new() -> Self {
        PointRecord::default()
    }

    fn set_property(&mut self, name: &str, property: Property) -> PropertyAccessResult {
        match (name, scalar(&property)) {
            ("vertex_index" | "vertex", Some(v)) => {
                self.vertex = v as i64;
                PropertyAccessResult::Set
            }
            _ => PropertyAccessResult::Ignored,
        }
    }
}

/// Any other element: read past.
struct Skipped;

impl PropertyAccess for Skipped {
    fn new() -> Self {
        Skipped
    }
}

// ---------------------------------------------------------------------------------------------
// Reading.

/// The fewest bytes one element can take, to catch counts the file cannot hold before reading.
fn min_element_bytes(def: &ElementDef, encoding: Encoding) -> u64 {
    if encoding == Encoding::Ascii {
        // At least one digit and a separator per property, or a newline.
        return (2 * def.properties.len() as u64).max(1);
    }
    let size = |t: &ScalarType| match t {
        ScalarType::Char | ScalarType::UChar => 1u64,
        ScalarType::Short | ScalarType::UShort => 2,
        ScalarType::Int | ScalarType::UInt | ScalarType::Float => 4,
        ScalarType::Double => 8,
    };
    // An element without properties takes no bytes; counting it as one keeps a header that
    // declares billions of them from spinning the parser.
    def.properties
        .values()
        .map(|p| match &p.data_type {
            PropertyType::Scalar(t) => size(t),
            PropertyType::List(count, _) => size(count),
        })
        .sum::<u64>()
        .max(1)
}

/// Reading the elements of one kind, through ply-rs-bw under the panic guard.
struct Payload<'a, R: std::io::BufRead> {
    path: &'a Path,
    reader: &'a mut Reader<R>,
    def: &'a ElementDef,
    header: &'a Header,
}

impl<R: std::io::BufRead> Payload<'_, R> {
    fn elements<E: PropertyAccess>(&mut self) -> Result<Vec<E>, IoError> {
        let (path, def) = (self.path, self.def);
        let binary = self.header.encoding != Encoding::Ascii;
        guard::quietly(|| {
            Parser::<E>::new().read_payload_for_element(self.reader, def, self.header)
        })
        .ok_or_else(|| {
            IoError::malformed(
                path,
                format!("the '{}' elements cannot be decoded", def.name),
            )
        })?
        .map_err(|e| IoError::from_ply(path, &def.name, binary, &e))
    }
}

fn index(path: &Path, what: &str, i: usize, v: i64, vertex_count: usize) -> Result<u32, IoError> {
    if v < 0 || v >= vertex_count as i64 {
        return Err(IoError::malformed(
            path,
            format!("{what} {i} refers to vertex {v} but there are {vertex_count} vertices"),
        ));
    }
    Ok(v as u32)
}

/// Opens the file and reads its header, checked line by line and then by ply-rs-bw, with every
/// element count checked against the file's size and the memory budget.
fn open_header(path: &Path) -> Result<(Reader<BufReader<File>>, Header), IoError> {
    let file = File::open(path).map_err(|e| IoError::access(path, "cannot open", &e))?;
    let file_len = file
        .metadata()
        .map_err(|e| IoError::access(path, "cannot read", &e))?
        .len();
    let mut reader = BufReader::with_capacity(1 << 20, file);
    let start = reader
        .fill_buf()
        .map_err(|e| IoError::access(path, "cannot read", &e))?;
    header::check(path, start)?;
    let mut reader = Reader::new(reader);
    let header = guard::quietly(|| Parser::<Skipped>::new().read_header(&mut reader))
        .ok_or_else(|| IoError::malformed(path, "the header is not valid PLY"))?
        .map_err(|e| IoError::from_ply(path, "", false, &e))?;

    // Element counts the file cannot possibly hold are errors, not allocations; the others go
    // through the memory budget (a record per element, and the mesh built from them).
    for def in header.elements.values() {
        let what = format!("'{}' elements", def.name);
        let count = def.count as u64;
        let least = min_element_bytes(def, header.encoding);
        budget::check_fits_file(path, &what, count, least, file_len)?;
        let record = 64 + 8 * def.properties.len() as u64;
        budget::check_count(path, &format!("the {what}"), count, record)?;
    }
    let vertex_def = header
        .elements
        .get("vertex")
        .ok_or_else(|| IoError::malformed(path, "no 'vertex' element in the header"))?;
    for axis in ["x", "y", "z"] {
        if !matches!(
            vertex_def.properties.get(axis).map(|p| &p.data_type),
            Some(PropertyType::Scalar(_))
        ) {
            return Err(IoError::malformed(
                path,
                format!("the 'vertex' element has no scalar property '{axis}'"),
            ));
        }
    }
    Ok((reader, header))
}

/// The elements voxlod reads, as parsed.
#[derive(Default)]
struct Records {
    vertices: Vec<VertexRecord>,
    faces: Vec<FaceRecord>,
    strips: Vec<FaceRecord>,
    edges: Vec<EdgeRecord>,
    points: Vec<PointRecord>,
}

fn read_records(
    path: &Path,
    reader: &mut Reader<BufReader<File>>,
    header: &Header,
) -> Result<Records, IoError> {
    let mut records = Records::default();
    for (name, def) in &header.elements {
        let mut read = Payload {
            path,
            reader,
            def,
            header,
        };
        match name.as_str() {
            "vertex" => records.vertices = read.elements()?,
            "face" => records.faces = read.elements()?,
            "tristrips" => records.strips = read.elements()?,
            "edge" => records.edges = read.elements()?,
            "point" => records.points = read.elements()?,
            _ => {
                read.elements::<Skipped>()?;
            }
        }
    }
    Ok(records)
}

/// The faces as triangles, polygons ear-clipped; also how many polygons were.
fn triangulate_faces(
    path: &Path,
    faces: &[FaceRecord],
    positions: &[Vec3],
) -> Result<(Vec<[u32; 3]>, usize), IoError> {
    let mut triangles = Vec::with_capacity(faces.len());
    let mut polygons_triangulated = 0;
    let mut polygon = Vec::new();
    for (f, face) in faces.iter().enumerate() {
        if face.bad_type {
            return Err(IoError::malformed(
                path,
                format!("face {f} has a non-integer index list"),
            ));
        }
        if face.corners.len() < 3 {
            return Err(IoError::malformed(
                path,
                format!(
                    "face {f} has {} corners; a face needs at least 3",
                    face.corners.len()
                ),
            ));
        }
        let corners: Vec<u32> = face
            .corners
            .iter()
            .map(|&v| index(path, "face", f, v, positions.len()))
            .collect::<Result<_, _>>()?;
        if corners.len() == 3 {
            triangles.push([corners[0], corners[1], corners[2]]);
        } else {
            polygon.clear();
            polygon.extend(corners.iter().map(|&v| positions[v as usize].as_dvec3()));
            triangles.extend(
                ear_clipping::triangulate(&polygon)
                    .into_iter()
                    .map(|t| t.map(|i| corners[i])),
            );
            polygons_triangulated += 1;
        }
    }
    Ok((triangles, polygons_triangulated))
}

/// The triangles of `tristrips` records: each list is one or more strips separated by -1; the
/// k-th triangle of a strip is (s[k], s[k+1], s[k+2]) with its first two corners swapped when k
/// is odd, so that all wind alike. Triangles with a repeated corner (the joins a stripper puts
/// between strips) are left out. Cost: O(indices).
fn triangulate_strips(
    path: &Path,
    strips: &[FaceRecord],
    vertex_count: usize,
) -> Result<Vec<[u32; 3]>, IoError> {
    let mut triangles = Vec::new();
    for (s, record) in strips.iter().enumerate() {
        if record.bad_type {
            return Err(IoError::malformed(
                path,
                format!("triangle strip {s} has a non-integer index list"),
            ));
        }
        for strip in record.corners.split(|&v| v == -1) {
            let corners: Vec<u32> = strip
                .iter()
                .map(|&v| index(path, "triangle strip", s, v, vertex_count))
                .collect::<Result<_, _>>()?;
            for (k, w) in corners.windows(3).enumerate() {
                let t = if k % 2 == 0 {
                    [w[0], w[1], w[2]]
                } else {
                    [w[1], w[0], w[2]]
                };
                if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
                    triangles.push(t);
                }
            }
        }
    }
    Ok(triangles)
}

/// The names of the extra scalar properties of `element`, in header order.
fn extra_names<'a>(
    header: &'a Header,
    element: &str,
    is_extra: fn(&PropertyDef) -> bool,
) -> Vec<&'a str> {
    header.elements.get(element).map_or_else(Vec::new, |def| {
        def.properties
            .values()
            .filter(|d| is_extra(d))
            .map(|d| d.name.as_str())
            .collect()
    })
}

pub(crate) fn read(path: &Path) -> Result<PlyContent, IoError> {
    let (mut reader, header) = open_header(path)?;
    let records = read_records(path, &mut reader, &header)?;

    // Vertices, normals, attributes.
    let has_normals = ["nx", "ny", "nz"]
        .iter()
        .all(|n| header.elements["vertex"].properties.contains_key(*n));
    let vertices = &records.vertices;
    let vertex_count = vertices.len();
    let positions: Vec<Vec3> = vertices
        .iter()
        .map(|v| DVec3::from(v.position).as_vec3())
        .collect();
    let normals: Vec<Vec3> = if has_normals {
        vertices.iter().map(|v| Vec3::from(v.normal)).collect()
    } else {
        Vec::new()
    };
    let vertex_names = extra_names(&header, "vertex", is_vertex_extra);
    let vertex_attributes = collect_attributes(&vertex_names, vertices.iter().map(|v| &v.extra));
    let colors = color_channels(&header, &vertex_names);
    let looks = looks_of(&header, &vertex_names);

    let (mut triangles, polygons_triangulated) =
        triangulate_faces(path, &records.faces, &positions)?;
    triangles.extend(triangulate_strips(path, &records.strips, vertex_count)?);

    // Edges and points.
    let lines: Vec<[u32; 2]> = records
        .edges
        .iter()
        .enumerate()
        .map(|(e, r)| {
            Ok([
                index(path, "edge", e, r.ends[0], vertex_count)?,
                index(path, "edge", e, r.ends[1], vertex_count)?,
            ])
        })
        .collect::<Result<_, IoError>>()?;
    let edge_names = extra_names(&header, "edge", is_edge_extra);
    let line_attributes = collect_attributes(&edge_names, records.edges.iter().map(|e| &e.extra));
    let points: Vec<u32> = records
        .points
        .iter()
        .enumerate()
        .map(|(p, r)| index(path, "point", p, r.vertex, vertex_count))
        .collect::<Result<_, _>>()?;

    Ok(PlyContent {
        mesh: PolyMesh {
            mesh: TriangleMesh {
                positions,
                normals,
                triangles,
            },
            lines,
            points,
            vertex_attributes,
            line_attributes,
        },
        polygons_triangulated,
        colors,
        looks,
    })
}

/// Turns per-element extra values (in header order) into named attributes.
fn collect_attributes<'a>(
    names: &[&str],
    records: impl Iterator<Item = &'a Vec<f32>> + Clone,
) -> Vec<Attribute> {
    names
        .iter()
        .enumerate()
        .map(|(k, name)| Attribute {
            name: name.to_string(),
            values: records
                .clone()
                .map(|extra| extra.get(k).copied().unwrap_or(f32::NAN))
                .collect(),
        })
        .collect()
}

// ---------------------------------------------------------------------------------------------
// Writing: views over the mesh that the writer queries property by property.

/// Vertex `index` of a mesh, as ply-rs-bw's writer sees it (the reference for
/// [`body`]'s bytes).
#[cfg(test)]
#[derive(Default)]
struct VertexOut<'a> {
    mesh: Option<PolyView<'a>>,
    index: usize,
}

#[cfg(test)]
impl PropertyAccess for VertexOut<'_> {
    fn new() -> Self {
        VertexOut::default()
    }

    fn get_float(&self, name: &str) -> Option<f32> {
        let view = self.mesh.as_ref()?;
        let m = view.mesh;
        let i = self.index;
        Some(match name {
            "x" => m.positions[i].x,
            "y" => m.positions[i].y,
            "z" => m.positions[i].z,
            "nx" => m.normals[i].x,
            "ny" => m.normals[i].y,
            "nz" => m.normals[i].z,
            _ => {
                view.vertex_attributes
                    .iter()
                    .find(|a| a.name == name)?
                    .values[i]
            }
        })
    }
}

/// A triangle, an edge or a point, as the writer sees it.
#[derive(Default)]
struct CellOut<'a> {
    corners: [i32; 3],
    mesh: Option<PolyView<'a>>,
    index: usize,
}

impl PropertyAccess for CellOut<'_> {
    fn new() -> Self {
        CellOut::default()
    }

    fn get_list_int(&self, name: &str) -> Option<&[i32]> {
        (name == "vertex_indices").then_some(&self.corners[..])
    }

    fn get_int(&self, name: &str) -> Option<i32> {
        match name {
            "vertex1" | "vertex_index" => Some(self.corners[0]),
            "vertex2" => Some(self.corners[1]),
            _ => None,
        }
    }

    fn get_float(&self, name: &str) -> Option<f32> {
        let view = self.mesh.as_ref()?;
        Some(view.line_attributes.iter().find(|a| a.name == name)?.values[self.index])
    }
}

fn property(name: &str, data_type: PropertyType) -> PropertyDef {
    PropertyDef::new(name.to_string(), data_type)
}

fn element(name: &str, count: usize, properties: Vec<PropertyDef>) -> ElementDef {
    let mut def = ElementDef::new(name.to_string());
    def.count = count;
    for p in properties {
        def.properties.add(p);
    }
    def
}

/// Attribute names become PLY property names: they must be single words, distinct, and not
/// collide with the properties the format already uses.
fn check_names(path: &Path, attributes: &[Attribute], reserved: &[&str]) -> Result<(), IoError> {
    for (k, a) in attributes.iter().enumerate() {
        let bad = a.name.is_empty()
            || a.name.chars().any(|c| c.is_whitespace() || c.is_control())
            || reserved.contains(&a.name.as_str())
            || attributes[..k].iter().any(|b| b.name == a.name);
        if bad {
            return Err(IoError::unsupported(
                path,
                format!(
                    "attribute name '{}' cannot be a PLY property (empty, spaces, repeated, or one of {})",
                    a.name,
                    reserved.join(", ")
                ),
            ));
        }
    }
    Ok(())
}

/// The four elements a written PLY file may hold.
struct Elements {
    vertex: ElementDef,
    face: ElementDef,
    edge: ElementDef,
    point: ElementDef,
}

/// The element definitions of `view`: vertex (position, normal when present, attributes),
/// face (an index list), edge (two indices and the line attributes) and point (one index).
fn element_definitions(view: PolyView<'_>) -> Elements {
    let m = view.mesh;
    let float = || PropertyType::Scalar(ScalarType::Float);
    let int = || PropertyType::Scalar(ScalarType::Int);
    let mut vertex_props = vec![
        property("x", float()),
        property("y", float()),
        property("z", float()),
    ];
    if !m.normals.is_empty() {
        vertex_props.extend(["nx", "ny", "nz"].map(|n| property(n, float())));
    }
    vertex_props.extend(
        view.vertex_attributes
            .iter()
            .map(|a| property(&a.name, float())),
    );
    let vertex_def = element("vertex", m.positions.len(), vertex_props);
    let face_def = element(
        "face",
        m.triangles.len(),
        vec![property(
            "vertex_indices",
            PropertyType::List(ScalarType::UChar, ScalarType::Int),
        )],
    );
    let mut edge_props = vec![property("vertex1", int()), property("vertex2", int())];
    edge_props.extend(
        view.line_attributes
            .iter()
            .map(|a| property(&a.name, float())),
    );
    let edge_def = element("edge", view.lines.len(), edge_props);
    let point_def = element(
        "point",
        view.points.len(),
        vec![property("vertex_index", int())],
    );
    Elements {
        vertex: vertex_def,
        face: face_def,
        edge: edge_def,
        point: point_def,
    }
}

/// The vertex and face elements of `view` as ply-rs-bw's writer encodes them, element by
/// element: the reference for [`body`].
#[cfg(test)]
pub(crate) fn reference_body(view: PolyView<'_>) -> Vec<u8> {
    let defs = element_definitions(view);
    let mut out = Vec::new();
    let vertex_writer = Writer::<VertexOut>::new();
    for index in 0..view.mesh.positions.len() {
        let vertex = VertexOut {
            mesh: Some(view),
            index,
        };
        (vertex_writer.write_little_endian_element(&mut out, &vertex, &defs.vertex)).unwrap();
    }
    let cell_writer = Writer::<CellOut>::new();
    for t in &view.mesh.triangles {
        let cell = CellOut {
            corners: t.map(|v| v as i32),
            mesh: Some(view),
            index: 0,
        };
        (cell_writer.write_little_endian_element(&mut out, &cell, &defs.face)).unwrap();
    }
    out
}

pub(crate) fn write(path: &Path, view: PolyView<'_>) -> Result<TempFile, IoError> {
    let m = view.mesh;
    check_names(
        path,
        view.vertex_attributes,
        &["x", "y", "z", "nx", "ny", "nz"],
    )?;
    check_names(path, view.line_attributes, &["vertex1", "vertex2"])?;
    let mut indices = (m.triangles.iter().flatten())
        .chain(view.lines.iter().flatten())
        .chain(view.points);
    if let Some(&too_big) = indices.find(|&&v| v > i32::MAX as u32) {
        return Err(IoError::unsupported(
            path,
            format!("vertex index {too_big} does not fit PLY's int indices"),
        ));
    }

    let Elements {
        vertex: vertex_def,
        face: face_def,
        edge: edge_def,
        point: point_def,
    } = element_definitions(view);
    let mut header = Header::new();
    header.encoding = Encoding::BinaryLittleEndian;
    header.comments.push("written by voxlod".to_string());
    header.elements.add(vertex_def);
    header.elements.add(face_def);
    if !view.lines.is_empty() {
        header.elements.add(edge_def.clone());
    }
    if !view.points.is_empty() {
        header.elements.add(point_def.clone());
    }

    stage(path, |w| {
        Writer::<Skipped>::new().write_header(w, &header)?;
        body::write_vertices(w, view)?;
        body::write_faces(w, view)?;
        let cell_writer = Writer::<CellOut>::new();
        let mut cell = CellOut {
            corners: [0; 3],
            mesh: Some(view),
            index: 0,
        };
        for (i, [a, b]) in view.lines.iter().enumerate() {
            cell.corners = [*a as i32, *b as i32, 0];
            cell.index = i;
            cell_writer.write_little_endian_element(w, &cell, &edge_def)?;
        }
        for p in view.points {
            cell.corners = [*p as i32, 0, 0];
            cell_writer.write_little_endian_element(w, &cell, &point_def)?;
        }
        w.flush()
    })
}
