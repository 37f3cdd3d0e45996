//! The vertex and index streams of one level, as plain floats or quantized for compression.
//!
//! Plain: float positions and unit float normals (stride 12), `u16` or `u32` indices.
//! Quantized (`KHR_mesh_quantization`, as gltfpack does by default): positions as unsigned 14-bit
//! integers in `u16` with one padding component (stride 8) on a grid shared by every level,
//! undone by the node's uniform scale and translation (so positions stay in the input's units);
//! normals as normalized `i8` with padding (stride 4). Before quantizing, triangles and vertices
//! are reordered for the vertex cache and for fetch (meshoptimizer, [`cache_order`]), which
//! changes neither the triangles nor their count and makes the meshopt codec's deltas small.
//! The same pieces ([`quantized_positions`], [`snorm8`], [`unorm16`], [`flat_floats`],
//! [`index_stream`]) make the streams of an asset's primitives (`scene::columns`).
//!
//! Cost: linear in the level's size (the cache optimizer is linear too).

use glam::Vec3;
use voxlod_core::TriangleMesh;

use crate::GltfError;

/// Bits of a quantized position component (gltfpack's default).
pub const POSITION_BITS: u32 = 14;

/// glTF component types used here.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Component {
    I8,
    U16,
    U32,
    F32,
}

impl Component {
    /// glTF's `componentType` code.
    pub fn code(self) -> u32 {
        match self {
            Component::I8 => 5120,
            Component::U16 => 5123,
            Component::U32 => 5125,
            Component::F32 => 5126,
        }
    }
}

/// What a stream holds, for its accessor and for the meshopt mode.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StreamKind {
    Positions,
    Normals,
    /// xyz and the bitangent's sign (glTF's `TANGENT`).
    Tangents,
    /// One texture coordinate set.
    TexCoords,
    /// RGBA colours.
    Colors,
    /// One float per vertex (the `_WIDTH` of thick edges).
    Widths,
    Indices,
}

impl StreamKind {
    /// Components per element, and the glTF accessor type.
    pub fn accessor_type(self) -> (usize, &'static str) {
        match self {
            StreamKind::Positions | StreamKind::Normals => (3, "VEC3"),
            StreamKind::Tangents | StreamKind::Colors => (4, "VEC4"),
            StreamKind::TexCoords => (2, "VEC2"),
            StreamKind::Widths | StreamKind::Indices => (1, "SCALAR"),
        }
    }
}

/// One accessor's data in the uncompressed layout.
#[derive(Clone, Debug)]
pub struct Stream {
    pub kind: StreamKind,
    pub bytes: Vec<u8>,
    /// Bytes per element (the view's stride for vertex streams).
    pub stride: usize,
    pub count: usize,
    pub component: Component,
    pub normalized: bool,
    /// Per-component bounds (positions only), in the stored units.
    pub bounds: Option<([f64; 3], [f64; 3])>,
}

/// Where quantized positions sit: `stored · scale + offset` is the position.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quantization {
    pub offset: Vec3,
    pub scale: f32,
}

impl Quantization {
    /// The grid over a box: uniform steps so that the longest side spans `2^bits − 1`.
    pub fn over(lo: Vec3, hi: Vec3) -> Quantization {
        let extent = (hi - lo).max_element();
        let steps = ((1u32 << POSITION_BITS) - 1) as f32;
        let scale = if extent > 0.0 { extent / steps } else { 1.0 };
        Quantization { offset: lo, scale }
    }

    /// The grid point nearest `p` (clamped to the grid): within `scale / 2` of `p` per
    /// component for a point inside the box.
    pub fn quantize(&self, p: Vec3) -> [u16; 3] {
        let max = ((1u32 << POSITION_BITS) - 1) as f32;
        let q = ((p - self.offset) / self.scale)
            .round()
            .clamp(Vec3::ZERO, Vec3::splat(max));
        [q.x as u16, q.y as u16, q.z as u16]
    }
}

/// The streams of one level: positions, normals (when the mesh has them), indices.
pub fn plain_streams(mesh: &TriangleMesh) -> Vec<Stream> {
    let mut out = vec![float_stream(StreamKind::Positions, &mesh.positions)];
    if !mesh.normals.is_empty() {
        let unit: Vec<Vec3> = mesh.normals.iter().map(|n| unit_normal(*n)).collect();
        out.push(float_stream(StreamKind::Normals, &unit));
    }
    let flat: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
    out.push(index_stream(&flat, mesh.positions.len()));
    out
}

/// The quantized streams of one level, reordered for the cache and for fetch.
pub fn quantized_streams(
    mesh: &TriangleMesh,
    grid: &Quantization,
) -> Result<Vec<Stream>, GltfError> {
    let flat: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
    let (indices, order) = cache_order(&flat, mesh.positions.len())?;
    let mut out = vec![quantized_positions(
        order.iter().map(|&old| mesh.positions[old]),
        grid,
    )];
    if !mesh.normals.is_empty() {
        let mut normals = Vec::with_capacity(order.len() * 4);
        for &old in &order {
            let u = unit_normal(mesh.normals[old]);
            normals.extend(u.to_array().map(snorm8));
            normals.push(0);
        }
        out.push(Stream {
            kind: StreamKind::Normals,
            bytes: normals,
            stride: 4,
            count: order.len(),
            component: Component::I8,
            normalized: true,
            bounds: None,
        });
    }
    out.push(index_stream(&indices, order.len()));
    Ok(out)
}

/// A triangle list reordered for the vertex cache, then its vertices for fetch
/// (meshoptimizer's `optimizeVertexCache` and `optimizeVertexFetchRemap`): the new indices, and
/// for each new vertex the old one it is. The triangles stay the same triangles, as many;
/// vertices no triangle uses are dropped. Refuses an index beyond `vertex_count`. Cost: linear.
pub fn cache_order(flat: &[u32], vertex_count: usize) -> Result<(Vec<u32>, Vec<usize>), GltfError> {
    if flat.iter().any(|&v| v as usize >= vertex_count) {
        return Err(GltfError::InvalidChain(
            "a triangle refers to a vertex the mesh does not have".into(),
        ));
    }
    let cached = meshopt::optimize_vertex_cache(flat, vertex_count);
    let remap = meshopt::optimize_vertex_fetch_remap(&cached, vertex_count);
    let used = remap.iter().filter(|&&r| r != u32::MAX).count();
    let mut order = vec![0usize; used];
    for (old, &new) in remap.iter().enumerate() {
        if new != u32::MAX {
            order[new as usize] = old;
        }
    }
    let indices = cached.iter().map(|&v| remap[v as usize]).collect();
    Ok((indices, order))
}

/// Positions on `grid` as unsigned 14-bit integers in `u16` with one padding component
/// (stride 8), with their bounds in grid units.
pub fn quantized_positions(positions: impl Iterator<Item = Vec3>, grid: &Quantization) -> Stream {
    let mut bytes = Vec::new();
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    let mut count = 0;
    for p in positions {
        let q = grid.quantize(p);
        for c in 0..3 {
            lo[c] = lo[c].min(q[c] as f64);
            hi[c] = hi[c].max(q[c] as f64);
            bytes.extend_from_slice(&q[c].to_le_bytes());
        }
        bytes.extend_from_slice(&0u16.to_le_bytes());
        count += 1;
    }
    Stream {
        kind: StreamKind::Positions,
        bytes,
        stride: 8,
        count,
        component: Component::U16,
        normalized: false,
        bounds: (count > 0).then_some((lo, hi)),
    }
}

/// A value in -1..=1 as a normalized `i8` (glTF 2.0 §3.11: read back as `max(c / 127, -1)`),
/// within `0.5 / 127` of it.
pub fn snorm8(x: f32) -> u8 {
    (x.clamp(-1.0, 1.0) * 127.0).round() as i8 as u8
}

/// A value in 0..=1 as a normalized `u16` (read back as `c / 65535`), within `0.5 / 65535`.
pub fn unorm16(x: f32) -> [u8; 2] {
    ((x.clamp(0.0, 1.0) * 65535.0).round() as u16).to_le_bytes()
}

/// Floats, `width` per element (stride `4 · width`), without bounds.
pub fn flat_floats(kind: StreamKind, values: &[f32], width: usize) -> Stream {
    Stream {
        kind,
        bytes: values.iter().flat_map(|v| v.to_le_bytes()).collect(),
        stride: 4 * width,
        count: values.len() / width,
        component: Component::F32,
        normalized: false,
        bounds: None,
    }
}

/// Float triples, with bounds when they are positions.
pub(crate) fn float_stream(kind: StreamKind, values: &[Vec3]) -> Stream {
    let mut bytes = Vec::with_capacity(values.len() * 12);
    for v in values {
        for c in v.to_array() {
            bytes.extend_from_slice(&c.to_le_bytes());
        }
    }
    let bounds = (kind == StreamKind::Positions && !values.is_empty()).then(|| {
        let (lo, hi) = values.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(*p), hi.max(*p)),
        );
        (lo.to_array().map(f64::from), hi.to_array().map(f64::from))
    });
    Stream {
        kind,
        bytes,
        stride: 12,
        count: values.len(),
        component: Component::F32,
        normalized: false,
        bounds,
    }
}

/// One float per vertex.
pub(crate) fn scalar_stream(values: &[f32]) -> Stream {
    flat_floats(StreamKind::Widths, values, 1)
}

/// `u16` indices when every vertex index fits, else `u32`.
pub fn index_stream(indices: &[u32], vertex_count: usize) -> Stream {
    let small = vertex_count <= u16::MAX as usize;
    let mut bytes = Vec::with_capacity(indices.len() * if small { 2 } else { 4 });
    for &v in indices {
        if small {
            bytes.extend_from_slice(&(v as u16).to_le_bytes());
        } else {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
    }
    Stream {
        kind: StreamKind::Indices,
        bytes,
        stride: if small { 2 } else { 4 },
        count: indices.len(),
        component: if small {
            Component::U16
        } else {
            Component::U32
        },
        normalized: false,
        bounds: None,
    }
}

/// A unit normal (glTF requires them): zero or non-finite normals become +z.
pub fn unit_normal(n: Vec3) -> Vec3 {
    let u = n.normalize_or_zero();
    if u == Vec3::ZERO || !u.is_finite() {
        Vec3::Z
    } else {
        u
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantized_positions_come_back_within_half_a_step() {
        let mesh = voxlod_testkit::shapes::unit_cube();
        let grid = Quantization::over(Vec3::splat(-1.0), Vec3::splat(2.0));
        let streams = quantized_streams(&mesh, &grid).unwrap();
        let pos = &streams[0];
        assert_eq!(pos.count, mesh.positions.len());
        let mut back = Vec::new();
        for e in pos.bytes.chunks_exact(8) {
            let q = |i: usize| u16::from_le_bytes([e[2 * i], e[2 * i + 1]]) as f32;
            back.push(Vec3::new(q(0), q(1), q(2)) * grid.scale + grid.offset);
        }
        for p in &mesh.positions {
            let d = back
                .iter()
                .map(|b| (*b - *p).length())
                .fold(f32::MAX, f32::min);
            assert!(d <= grid.scale, "{p} is {d} from every quantized vertex");
        }
        let idx = streams.last().unwrap();
        assert_eq!(idx.count, mesh.triangles.len() * 3);
    }
}
