//! A level chain as one glTF 2.0 binary: every level a mesh, chained with `MSFT_lod`.
//!
//! **Layout**:
//! - node 0 draws the finest level and carries `extensions.MSFT_lod.ids = [1, …, n−1]` (the
//!   coarser levels' nodes, finest to coarsest) and `extras.MSFT_screencoverage` (one entry per
//!   level, see [`crate::coverage`]); the scene holds node 0 only, as the MSFT_lod README shows;
//! - node `k` draws mesh `k` = level `k` of the chain; every node's extras hold
//!   `{"voxlod": {"level", "cell_size", "triangles"}}` (the pyramid level, its voxel size in the
//!   input's units, its triangle count); mesh extras the same;
//! - one opaque material (metallic 0, roughness 1); positions in the input's units, unit
//!   normals when the levels have them, `u16` indices where a level has at most 65535 vertices;
//! - scene extras: `{"voxlod": {"kind": "lod chain", "screen_coverage": {"definition",
//!   "viewport_height", "tolerance", "diameter", "center"}}}`.
//!
//! With [`Compression::Meshopt`] the streams are quantized ([`crate::streams`]) and every buffer
//! view is encoded with meshoptimizer (`EXT_meshopt_compression`, vertex codec 0, index codec
//! 1, no filter): the GLB's own buffer holds the encoded bytes, and a second buffer without
//! data (`fallback: true`) gives the decoded layout its place. Every node then carries the
//! shared dequantizing scale and translation. Both extensions are required.
//!
//! Cost: linear in the chain's size; with compression, the encoders are linear too.

use std::path::Path;

use glam::Vec3;
use gltf::json;
use gltf::json::validation::{Checked, USize64};
use serde_json::{json as value, Value};
use voxlod_core::TriangleMesh;

use crate::coverage::{screen_coverages, CoverageOptions};
use crate::streams::{
    float_stream, plain_streams, quantized_streams, scalar_stream, Component, Quantization, Stream,
    StreamKind,
};
use crate::GltfError;

/// One level of the chain.
#[derive(Clone, Copy, Debug)]
pub struct ChainLevel<'a> {
    /// The pyramid level it came from (recorded in the extras).
    pub level: usize,
    pub mesh: &'a TriangleMesh,
    /// The level's cell (voxel) size in the input's units: what the pixel-size rule compares.
    pub cell_size: f64,
    /// Dangling edges (two vertex indices of `mesh` each), written as a `LINES` primitive.
    pub lines: &'a [[u32; 2]],
    /// One width per line in the input's units (Low–Tan's thick edges), written as the lines'
    /// `_WIDTH` attribute; empty for none.
    pub line_widths: &'a [f32],
    /// Isolated points (vertex indices of `mesh`), written as a `POINTS` primitive.
    pub points: &'a [u32],
}

impl<'a> ChainLevel<'a> {
    /// A level of triangles only.
    pub fn new(level: usize, mesh: &'a TriangleMesh, cell_size: f64) -> Self {
        ChainLevel {
            level,
            mesh,
            cell_size,
            lines: &[],
            line_widths: &[],
            points: &[],
        }
    }

    /// This level with dangling edges (and their widths, or none).
    pub fn with_lines(self, lines: &'a [[u32; 2]], line_widths: &'a [f32]) -> Self {
        ChainLevel {
            lines,
            line_widths,
            ..self
        }
    }

    /// This level with isolated points.
    pub fn with_points(self, points: &'a [u32]) -> Self {
        ChainLevel { points, ..self }
    }

    fn is_empty(&self) -> bool {
        self.mesh.triangles.is_empty() && self.lines.is_empty() && self.points.is_empty()
    }
}

/// How the geometry is stored.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Compression {
    /// Float positions and normals, as they are.
    #[default]
    None,
    /// `EXT_meshopt_compression` over `KHR_mesh_quantization` streams, as gltfpack writes.
    Meshopt,
}

/// How the file is written.
#[derive(Clone, Debug, PartialEq)]
pub struct ChainOptions {
    pub coverage: CoverageOptions,
    pub compression: Compression,
    /// Base colour of the material (linear RGB).
    pub color: [f32; 3],
    /// Name of the scene.
    pub name: String,
}

impl Default for ChainOptions {
    /// Uncompressed, coverages for a 1080-pixel viewport, a light steel grey.
    fn default() -> Self {
        ChainOptions {
            coverage: CoverageOptions::default(),
            compression: Compression::None,
            color: [0.72, 0.74, 0.78],
            name: "voxlod levels".into(),
        }
    }
}

impl ChainOptions {
    /// Compressed with meshopt and quantized.
    pub fn meshopt() -> Self {
        ChainOptions {
            compression: Compression::Meshopt,
            ..Default::default()
        }
    }
}

/// The bytes of the `.glb` of a chain; levels are sorted finest (smallest cell) first.
pub fn chain_glb_bytes(
    levels: &[ChainLevel],
    options: &ChainOptions,
) -> Result<Vec<u8>, GltfError> {
    let (root, bin) = chain_document(levels, options)?;
    to_glb(&root, bin)
}

/// The GLB container of a JSON document and its binary chunk.
pub fn to_glb(root: &Value, bin: Vec<u8>) -> Result<Vec<u8>, GltfError> {
    let json = serde_json::to_vec(root).map_err(|e| GltfError::Encode(e.to_string()))?;
    let glb = gltf::binary::Glb {
        header: gltf::binary::Header {
            magic: *b"glTF",
            version: 2,
            length: 0, // computed by the writer
        },
        json: json.into(),
        bin: Some(bin.into()),
    };
    glb.to_vec().map_err(|e| GltfError::Encode(e.to_string()))
}

/// Writes `path` atomically (nothing is left behind on failure).
pub fn write_chain_glb(
    path: &Path,
    levels: &[ChainLevel],
    options: &ChainOptions,
) -> Result<(), GltfError> {
    let bytes = chain_glb_bytes(levels, options)?;
    Ok(voxlod_io::atomic::write_atomically(path, |w| {
        std::io::Write::write_all(w, &bytes)
    })?)
}

/// The glTF JSON (as a value, extensions included) and the binary chunk.
pub fn chain_document(
    levels: &[ChainLevel],
    options: &ChainOptions,
) -> Result<(Value, Vec<u8>), GltfError> {
    let levels = sorted_levels(levels)?;
    let (lo, hi) = chain_bounds(&levels);
    let diameter = f64::from((hi - lo).length());
    let cells: Vec<f64> = levels.iter().map(|l| l.cell_size).collect();
    let coverages = screen_coverages(&cells, diameter, &options.coverage)?;
    let size: usize = levels
        .iter()
        .map(|l| l.mesh.positions.len() * 24 + l.mesh.triangles.len() * 12)
        .sum();
    voxlod_core::memory::check_allocation("the glTF buffer", size as u64)?;

    if options.compression == Compression::Meshopt
        && levels
            .iter()
            .any(|l| !l.lines.is_empty() || !l.points.is_empty())
    {
        return Err(GltfError::InvalidChain(
            "lines and points are written without compression only".into(),
        ));
    }
    let mut doc = Document::new(options.compression);
    let grid = Quantization::over(lo, hi);
    let material = doc.root.push(material("voxlod surface", options.color));
    for l in &levels {
        let streams = match options.compression {
            Compression::None => plain_streams(l.mesh),
            Compression::Meshopt => quantized_streams(l.mesh, &grid)?,
        };
        doc.add_level(l, &streams, material)?;
    }
    let centre = (lo + hi) * 0.5;
    let extras = value!({"voxlod": {
        "kind": "lod chain",
        "screen_coverage": {
            "definition": "bounding-sphere diameter / viewport height (2 d tan(fov/2))",
            "viewport_height": options.coverage.viewport_height,
            "tolerance": options.coverage.tolerance,
            "diameter": diameter,
            "center": [centre.x, centre.y, centre.z],
        }
    }});
    let scene = doc.root.push(json::Scene {
        extensions: None,
        extras: raw(&extras),
        name: Some(options.name.clone()),
        nodes: vec![json::Index::new(0)],
    });
    doc.root.scene = Some(scene);
    let quantized = (options.compression == Compression::Meshopt).then_some(grid);
    doc.finish(&coverages, quantized)
}

/// Non-empty levels, finest first; refuses an empty chain, equal cell sizes, or a level whose
/// normals, lines, widths or points do not fit its vertices.
fn sorted_levels<'a>(levels: &[ChainLevel<'a>]) -> Result<Vec<ChainLevel<'a>>, GltfError> {
    let mut out: Vec<ChainLevel> = levels.iter().copied().filter(|l| !l.is_empty()).collect();
    if out.is_empty() {
        return Err(GltfError::InvalidChain(
            "no level has a triangle, line or point".into(),
        ));
    }
    out.sort_by(|a, b| a.cell_size.total_cmp(&b.cell_size));
    for l in &out {
        check_level(l)?;
    }
    // Levels of lines and points only draw no shaded triangles: their normals do not count.
    let shaded = || out.iter().filter(|l| !l.mesh.triangles.is_empty());
    if shaded().any(|l| l.mesh.normals.is_empty()) && shaded().any(|l| !l.mesh.normals.is_empty()) {
        return Err(GltfError::InvalidChain(
            "some levels have normals and some do not".into(),
        ));
    }
    Ok(out)
}

/// One level's sizes and values.
fn check_level(l: &ChainLevel) -> Result<(), GltfError> {
    let m = l.mesh;
    let bad = |what: String| {
        Err(GltfError::InvalidChain(format!(
            "level {}: {what}",
            l.level
        )))
    };
    if !m.normals.is_empty() && m.normals.len() != m.positions.len() {
        return bad(format!(
            "{} normals for {} vertices",
            m.normals.len(),
            m.positions.len()
        ));
    }
    if let Some(p) = m.positions.iter().find(|p| !p.is_finite()) {
        return bad(format!("a vertex is not finite ({p})"));
    }
    let n = m.positions.len() as u64;
    if l.lines
        .iter()
        .flatten()
        .chain(l.points)
        .any(|&v| v as u64 >= n)
    {
        return bad(format!("a line or point refers to a vertex beyond its {n}"));
    }
    if !l.line_widths.is_empty() && l.line_widths.len() != l.lines.len() {
        let (w, e) = (l.line_widths.len(), l.lines.len());
        return bad(format!("{w} line widths for {e} lines"));
    }
    if let Some(w) = l.line_widths.iter().find(|w| !w.is_finite()) {
        return bad(format!("a line width is not finite ({w})"));
    }
    Ok(())
}

fn chain_bounds(levels: &[ChainLevel]) -> (Vec3, Vec3) {
    levels.iter().flat_map(|l| l.mesh.positions.iter()).fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    )
}

fn material(name: &str, color: [f32; 3]) -> json::Material {
    json::Material {
        name: Some(name.into()),
        pbr_metallic_roughness: json::material::PbrMetallicRoughness {
            base_color_factor: json::material::PbrBaseColorFactor([
                color[0], color[1], color[2], 1.0,
            ]),
            metallic_factor: json::material::StrengthFactor(0.0),
            roughness_factor: json::material::StrengthFactor(1.0),
            ..Default::default()
        },
        ..Default::default()
    }
}

/// Chains nodes `0..levels` of `doc` with `MSFT_lod` on node 0 (when there are two or more)
/// and puts `coverages` in node 0's extras as `MSFT_screencoverage`. The caller lists
/// `MSFT_lod` in `extensionsUsed` (gltf-json keeps that list, not the node extension).
pub fn declare_lod(doc: &mut Value, levels: usize, coverages: &[f64]) {
    if levels >= 2 {
        doc["nodes"][0]["extensions"] =
            value!({"MSFT_lod": {"ids": (1..levels).collect::<Vec<_>>()}});
    }
    doc["nodes"][0]["extras"]["MSFT_screencoverage"] = value!(coverages);
}

pub(crate) fn raw(value: &Value) -> json::Extras {
    serde_json::value::to_raw_value(value).ok()
}

/// The document under construction.
struct Document {
    root: json::Root,
    bin: Vec<u8>,
    compression: Compression,
    /// Length of the decoded layout (the fallback buffer) when compressed.
    fallback_len: usize,
    /// `EXT_meshopt_compression` objects by buffer view index.
    view_extensions: Vec<(usize, Value)>,
    /// The material of lines and points, once a level has some.
    edge_material: Option<json::Index<json::Material>>,
}

impl Document {
    fn new(compression: Compression) -> Document {
        let mut root = json::Root {
            asset: json::Asset {
                generator: Some(format!("voxlod {}", env!("CARGO_PKG_VERSION"))),
                ..Default::default()
            },
            ..Default::default()
        };
        let buffers = if compression == Compression::Meshopt {
            2
        } else {
            1
        };
        for _ in 0..buffers {
            root.push(json::Buffer {
                byte_length: USize64(0), // set by finish
                name: None,
                uri: None,
                extensions: None,
                extras: None,
            });
        }
        Document {
            root,
            bin: Vec::new(),
            compression,
            fallback_len: 0,
            view_extensions: Vec::new(),
            edge_material: None,
        }
    }

    /// The accessors, mesh and node of one level: its triangles (from `streams`), then its
    /// lines and its points as primitives of their own with their own float positions.
    fn add_level(
        &mut self,
        level: &ChainLevel,
        streams: &[Stream],
        material: json::Index<json::Material>,
    ) -> Result<(), GltfError> {
        use json::mesh::Mode;
        let mut primitives = Vec::new();
        if !level.mesh.triangles.is_empty() {
            primitives.push(self.primitive(streams, level.level, Mode::Triangles, material)?);
        }
        let at = |v: &u32| level.mesh.positions[*v as usize];
        if !level.lines.is_empty() {
            let ends: Vec<Vec3> = level.lines.iter().flatten().map(at).collect();
            let mut s = vec![float_stream(StreamKind::Positions, &ends)];
            if !level.line_widths.is_empty() {
                let twice: Vec<f32> = level.line_widths.iter().flat_map(|&w| [w, w]).collect();
                s.push(scalar_stream(&twice));
            }
            let m = self.edge_material();
            primitives.push(self.primitive(&s, level.level, Mode::Lines, m)?);
        }
        if !level.points.is_empty() {
            let points: Vec<Vec3> = level.points.iter().map(at).collect();
            let s = [float_stream(StreamKind::Positions, &points)];
            let m = self.edge_material();
            primitives.push(self.primitive(&s, level.level, Mode::Points, m)?);
        }
        let extras = value!({"voxlod": {
            "level": level.level,
            "cell_size": level.cell_size,
            "triangles": level.mesh.triangles.len(),
            "lines": level.lines.len(),
            "points": level.points.len(),
        }});
        let mesh = self.root.push(json::Mesh {
            extensions: None,
            extras: raw(&extras),
            name: Some(format!("level {}", level.level)),
            primitives,
            weights: None,
        });
        self.root.push(json::Node {
            mesh: Some(mesh),
            name: Some(format!("level {}", level.level)),
            extras: raw(&extras),
            ..Default::default()
        });
        Ok(())
    }

    /// One primitive drawing `streams` (indexed when they hold indices).
    fn primitive(
        &mut self,
        streams: &[Stream],
        level: usize,
        mode: json::mesh::Mode,
        material: json::Index<json::Material>,
    ) -> Result<json::mesh::Primitive, GltfError> {
        use json::mesh::Semantic;
        let mut attributes = std::collections::BTreeMap::new();
        let mut indices = None;
        for s in streams {
            let accessor = self.add_stream(s, level)?;
            let semantic = match s.kind {
                StreamKind::Positions => Semantic::Positions,
                StreamKind::Normals => Semantic::Normals,
                StreamKind::Tangents => Semantic::Tangents,
                StreamKind::TexCoords => Semantic::TexCoords(0),
                StreamKind::Colors => Semantic::Colors(0),
                StreamKind::Widths => Semantic::Extras("WIDTH".into()),
                StreamKind::Indices => {
                    indices = Some(accessor);
                    continue;
                }
            };
            attributes.insert(Checked::Valid(semantic), accessor);
        }
        Ok(json::mesh::Primitive {
            attributes,
            extensions: None,
            extras: None,
            indices,
            material: Some(material),
            mode: Checked::Valid(mode),
            targets: None,
        })
    }

    /// The material of lines and points: near black, so edges show against the surface.
    fn edge_material(&mut self) -> json::Index<json::Material> {
        if let Some(m) = self.edge_material {
            return m;
        }
        let m = self
            .root
            .push(material("voxlod edges and points", [0.1, 0.1, 0.12]));
        self.edge_material = Some(m);
        m
    }

    /// One buffer view (plain or encoded) and its accessor.
    fn add_stream(
        &mut self,
        s: &Stream,
        level: usize,
    ) -> Result<json::Index<json::Accessor>, GltfError> {
        let vertex = s.kind != StreamKind::Indices;
        let (buffer, offset) = match self.compression {
            Compression::None => {
                let at = self.bin.len();
                self.bin.extend_from_slice(&s.bytes);
                pad4(&mut self.bin);
                (0, at)
            }
            Compression::Meshopt => {
                let encoded = crate::encode::encode_stream(s)?;
                let at = self.bin.len();
                self.bin.extend_from_slice(&encoded);
                pad4(&mut self.bin);
                let fallback_at = self.fallback_len;
                self.fallback_len = (fallback_at + s.bytes.len()).next_multiple_of(4);
                let view = self.root.buffer_views.len();
                let extension = crate::encode::view_extension(s, at, encoded.len());
                self.view_extensions.push((view, extension));
                (1, fallback_at)
            }
        };
        let view = self.root.push(json::buffer::View {
            buffer: json::Index::new(buffer),
            byte_length: USize64(s.bytes.len() as u64),
            byte_offset: Some(USize64(offset as u64)),
            byte_stride: vertex.then_some(json::buffer::Stride(s.stride)),
            name: None,
            target: Some(Checked::Valid(if vertex {
                json::buffer::Target::ArrayBuffer
            } else {
                json::buffer::Target::ElementArrayBuffer
            })),
            extensions: None,
            extras: None,
        });
        Ok(self.root.push(accessor(s, view, level)))
    }

    /// Buffer lengths, extensions, and the JSON value.
    fn finish(
        mut self,
        coverages: &[f64],
        quantized: Option<Quantization>,
    ) -> Result<(Value, Vec<u8>), GltfError> {
        self.root.buffers[0].byte_length = USize64(self.bin.len() as u64);
        let mut used = vec!["MSFT_lod".to_string()];
        if self.compression == Compression::Meshopt {
            self.root.buffers[1].byte_length = USize64(self.fallback_len as u64);
            let required = ["EXT_meshopt_compression", "KHR_mesh_quantization"];
            used.extend(required.map(String::from));
            self.root.extensions_required = required.map(String::from).to_vec();
        }
        let levels = self.root.nodes.len();
        if levels < 2 {
            used.clear(); // one level: no chain to declare
        }
        self.root.extensions_used = used;
        let mut doc =
            serde_json::to_value(&self.root).map_err(|e| GltfError::Encode(e.to_string()))?;
        declare_lod(&mut doc, levels, coverages);
        if let Some(q) = quantized {
            for n in 0..levels {
                doc["nodes"][n]["translation"] = value!(q.offset.to_array());
                doc["nodes"][n]["scale"] = value!([q.scale, q.scale, q.scale]);
            }
            doc["buffers"][1]["extensions"] =
                value!({"EXT_meshopt_compression": {"fallback": true}});
            for (view, ext) in self.view_extensions {
                doc["bufferViews"][view]["extensions"] = value!({"EXT_meshopt_compression": ext});
            }
        }
        Ok((doc, self.bin))
    }
}

fn accessor(s: &Stream, view: json::Index<json::buffer::View>, level: usize) -> json::Accessor {
    use json::accessor::ComponentType as C;
    let component = match s.component {
        Component::I8 => C::I8,
        Component::U16 => C::U16,
        Component::U32 => C::U32,
        Component::F32 => C::F32,
    };
    let kind = match s.kind.accessor_type().0 {
        1 => json::accessor::Type::Scalar,
        2 => json::accessor::Type::Vec2,
        3 => json::accessor::Type::Vec3,
        _ => json::accessor::Type::Vec4,
    };
    let name = match s.kind {
        StreamKind::Positions => "positions",
        StreamKind::Normals => "normals",
        StreamKind::Tangents => "tangents",
        StreamKind::TexCoords => "texture coordinates",
        StreamKind::Colors => "colours",
        StreamKind::Widths => "widths",
        StreamKind::Indices => "indices",
    };
    json::Accessor {
        buffer_view: Some(view),
        byte_offset: Some(USize64(0)),
        count: USize64(s.count as u64),
        component_type: Checked::Valid(json::accessor::GenericComponentType(component)),
        extensions: None,
        extras: None,
        type_: Checked::Valid(kind),
        min: s.bounds.map(|b| value!(b.0)),
        max: s.bounds.map(|b| value!(b.1)),
        name: Some(format!("level {level} {name}")),
        normalized: s.normalized,
        sparse: None,
    }
}

fn pad4(bytes: &mut Vec<u8>) {
    bytes.resize(bytes.len().next_multiple_of(4), 0);
}
