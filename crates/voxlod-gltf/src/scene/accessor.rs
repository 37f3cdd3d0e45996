//! An accessor's elements as floats, whatever their stored type: 32-bit floats, and the
//! integer types `KHR_mesh_quantization` allows for positions, normals, tangents, texture
//! coordinates and colours, normalized (mapped to 0..1 or -1..1 as glTF 2.0 §3.11 says) or not
//! (taken as they are); sparse accessors applied over their base. The `gltf` crate's reader
//! takes floats only, hence this one.
//!
//! Every range is checked against its buffer, and the element count meets the memory limit,
//! so a broken file is an error naming the accessor, never a panic. Cost: linear.

use gltf::accessor::{DataType, Dimensions};
use gltf::Accessor;
use voxlod_core::memory::check_allocation;

use crate::GltfError;

fn invalid(a: &Accessor, m: impl std::fmt::Display) -> GltfError {
    GltfError::Invalid(format!("accessor {}: {m}", a.index()))
}

/// The accessor's elements, `N` floats each; refuses an accessor whose elements have another
/// number of components.
pub(crate) fn floats<const N: usize>(
    a: &Accessor,
    buffers: &[Vec<u8>],
) -> Result<Vec<[f32; N]>, GltfError> {
    if a.dimensions().multiplicity() != N {
        return Err(invalid(
            a,
            format!("{:?} where {N} components are read", a.dimensions()),
        ));
    }
    let n = a.count();
    check_allocation(
        &format!("accessor {}", a.index()),
        (n as u64).saturating_mul(4 * N as u64),
    )?;
    let mut out = vec![[0.0f32; N]; n];
    if let Some(view) = a.view() {
        let bytes = element_bytes(a, &view, buffers, a.offset(), n)?;
        for (k, e) in out.iter_mut().enumerate() {
            *e = element(a, bytes.element(k));
        }
    }
    if let Some(sparse) = a.sparse() {
        let indices = sparse.indices();
        let values = sparse.values();
        let count = sparse.count();
        let index_size = match indices.index_type() {
            gltf::accessor::sparse::IndexType::U8 => 1,
            gltf::accessor::sparse::IndexType::U16 => 2,
            gltf::accessor::sparse::IndexType::U32 => 4,
        };
        let at = range(
            a,
            buffers,
            &indices.view(),
            indices.offset(),
            count * index_size,
        )?;
        let size = a.data_type().size() * N;
        let vals = range(a, buffers, &values.view(), values.offset(), count * size)?;
        for k in 0..count {
            let i = le_uint(&at[k * index_size..(k + 1) * index_size]) as usize;
            let slot = out
                .get_mut(i)
                .ok_or_else(|| invalid(a, format!("sparse index {i} beyond its {n} elements")))?;
            *slot = element(a, &vals[k * size..(k + 1) * size]);
        }
    }
    Ok(out)
}

/// The accessor's elements as vertex indices (unsigned integers).
pub(crate) fn indices(a: &Accessor, buffers: &[Vec<u8>]) -> Result<Vec<u32>, GltfError> {
    if a.dimensions() != Dimensions::Scalar
        || !matches!(a.data_type(), DataType::U8 | DataType::U16 | DataType::U32)
    {
        return Err(invalid(a, "indices that are not unsigned integers"));
    }
    if a.sparse().is_some() {
        return Err(invalid(a, "sparse indices are not read"));
    }
    let n = a.count();
    check_allocation(
        &format!("accessor {}", a.index()),
        (n as u64).saturating_mul(4),
    )?;
    let view = a.view().ok_or_else(|| invalid(a, "indices without data"))?;
    let bytes = element_bytes(a, &view, buffers, a.offset(), n)?;
    Ok((0..n).map(|k| le_uint(bytes.element(k)) as u32).collect())
}

/// The strided elements of a view.
struct Elements<'a> {
    bytes: &'a [u8],
    stride: usize,
    size: usize,
}

impl<'a> Elements<'a> {
    fn element(&self, k: usize) -> &'a [u8] {
        &self.bytes[k * self.stride..k * self.stride + self.size]
    }
}

fn element_bytes<'a>(
    a: &Accessor,
    view: &gltf::buffer::View,
    buffers: &'a [Vec<u8>],
    offset: usize,
    n: usize,
) -> Result<Elements<'a>, GltfError> {
    let size = a.data_type().size() * a.dimensions().multiplicity();
    let stride = view.stride().unwrap_or(size);
    if stride < size {
        return Err(invalid(
            a,
            format!("a byte stride of {stride} for {size}-byte elements"),
        ));
    }
    let span = if n == 0 {
        0
    } else {
        (n - 1)
            .checked_mul(stride)
            .and_then(|s| s.checked_add(size))
            .ok_or_else(|| invalid(a, "its size overflows"))?
    };
    let bytes = range(a, buffers, view, offset, span)?;
    Ok(Elements {
        bytes,
        stride,
        size,
    })
}

/// `len` bytes from `offset` into a view, checked against the view and its buffer.
fn range<'a>(
    a: &Accessor,
    buffers: &'a [Vec<u8>],
    view: &gltf::buffer::View,
    offset: usize,
    len: usize,
) -> Result<&'a [u8], GltfError> {
    let end = offset.checked_add(len).filter(|&e| e <= view.length());
    let Some(end) = end else {
        return Err(invalid(
            a,
            format!(
                "bytes {offset}..+{len} reach beyond its {}-byte view",
                view.length()
            ),
        ));
    };
    let buffer = &buffers[view.buffer().index()];
    let (from, to) = (view.offset() + offset, view.offset() + end);
    buffer.get(from..to).ok_or_else(|| {
        invalid(
            a,
            format!(
                "bytes {from}..{to} reach beyond buffer {} of {} bytes",
                view.buffer().index(),
                buffer.len()
            ),
        )
    })
}

/// One element's components as floats.
fn element<const N: usize>(a: &Accessor, bytes: &[u8]) -> [f32; N] {
    let size = a.data_type().size();
    let norm = a.normalized();
    std::array::from_fn(|k| component(a.data_type(), &bytes[k * size..(k + 1) * size], norm))
}

/// One component: floats as stored, integers normalized (glTF 2.0 §3.11) or as they are.
fn component(t: DataType, b: &[u8], normalized: bool) -> f32 {
    let (value, unit) = match t {
        DataType::F32 => return f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        DataType::I8 => ((b[0] as i8) as f32, 127.0),
        DataType::U8 => (b[0] as f32, 255.0),
        DataType::I16 => (i16::from_le_bytes([b[0], b[1]]) as f32, 32767.0),
        DataType::U16 => (u16::from_le_bytes([b[0], b[1]]) as f32, 65535.0),
        DataType::U32 => (
            u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32,
            u32::MAX as f32,
        ),
    };
    if normalized {
        (value / unit).max(-1.0)
    } else {
        value
    }
}

fn le_uint(b: &[u8]) -> u64 {
    b.iter().rev().fold(0u64, |acc, &x| (acc << 8) | x as u64)
}
