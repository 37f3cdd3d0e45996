//! STL through `stl_io`: ASCII and binary in, binary out.
//!
//! STL stores every triangle with its own three corners (a "soup"). On reading, the soup is
//! welded with [`voxlod_core::weld::weld_vertices`], so corners with identical coordinates
//! become one vertex and a closed model is watertight; the report says how many vertices it
//! merged. Coordinates within a hundred-millionth of the diagonal of zero are zero first
//! ([`voxlod_core::weld::zero_rounding_noise`]: CAD exporters' rounding noise, which would leave
//! such models open). Facet normals are not kept (they are per face; the mesh holds per-vertex normals).
//!
//! stl_io tells ASCII from binary by the `solid ` prefix alone, which misreads the many binary
//! files whose 80-byte header also starts with `solid`. We decide first: a file whose length is
//! exactly 84 + 50 × (its triangle count) is binary; a file starting with `solid` is ASCII;
//! anything else is a binary file of the wrong size (truncated, named as such). The binary
//! header is then blanked before stl_io sees it. Only the first `solid … endsolid` block of an
//! ASCII file is read.
//!
//! Cost: O(F) expected for F triangles (stl_io's parse, then welding the 3F corners through a
//! hash map); memory the file's bytes, the triangle soup and the welded mesh.

use std::io::Cursor;
use std::path::Path;

use glam::Vec3;
use stl_io::{Normal, Triangle, Vertex};
use voxlod_core::weld::{weld_vertices, zero_rounding_noise, WeldReport};
use voxlod_core::TriangleMesh;

use crate::atomic::{stage, TempFile};
use crate::{budget, guard, IoError, IoErrorKind};

const HEADER: usize = 84;
const RECORD: u64 = 50;

pub(crate) fn read(path: &Path) -> Result<(TriangleMesh, WeldReport), IoError> {
    let mut bytes = crate::read_file(path)?;
    let len = bytes.len() as u64;

    let binary_count = (bytes.len() >= HEADER)
        .then(|| u32::from_le_bytes(bytes[80..84].try_into().expect("four bytes")) as u64);
    let exact_binary = binary_count.is_some_and(|n| HEADER as u64 + RECORD * n == len);
    let ascii = !exact_binary && bytes.trim_ascii_start().starts_with(b"solid");

    let (mut mesh, is_ascii) = if ascii {
        (read_ascii(path, bytes)?, true)
    } else {
        let Some(count) = binary_count else {
            return Err(IoError::truncated(
                path,
                format!(
                    "a binary STL needs an 84-byte header, the file has {} bytes (and it does not start with 'solid' as ASCII STL does)",
                    bytes.len()
                ),
            ));
        };
        let expected = HEADER as u64 + RECORD * count;
        if len < expected {
            return Err(IoError::truncated(
                path,
                format!(
                    "binary STL header promises {count} triangles ({expected} bytes) but the file has {len} bytes"
                ),
            ));
        }
        // Three corners and a triangle, before and while welding.
        budget::check_count(
            path,
            "the triangles of the binary STL",
            count,
            3 * 12 + 12 + 48,
        )?;
        // Keep stl_io from taking a header that starts with "solid" for ASCII, and drop any
        // bytes after the last triangle.
        bytes[..80].fill(0);
        bytes.truncate(expected as usize);
        (soup(path, bytes, false)?, false)
    };
    debug_assert!(is_ascii || mesh.triangles.len() as u64 == binary_count.unwrap_or(0));
    zero_rounding_noise(&mut mesh);
    let report = weld_vertices(&mut mesh);
    Ok((mesh, report))
}

/// An ASCII file, with a nameless `solid` line given a name (stl_io wants `solid <name>`).
fn read_ascii(path: &Path, bytes: Vec<u8>) -> Result<TriangleMesh, IoError> {
    let start = bytes.len() - bytes.trim_ascii_start().len();
    let rest = &bytes[start..];
    let first_line_end = rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
    if rest[..first_line_end].trim_ascii() == b"solid" {
        let mut fixed = b"solid unnamed".to_vec();
        fixed.extend_from_slice(&rest[first_line_end..]);
        soup(path, fixed, true)
    } else if start > 0 {
        soup(path, rest.to_vec(), true)
    } else {
        soup(path, bytes, true)
    }
}

/// Reads the triangles as a soup: three new vertices per triangle.
fn soup(path: &Path, bytes: Vec<u8>, ascii: bool) -> Result<TriangleMesh, IoError> {
    let mut cursor = Cursor::new(bytes);
    let format = if ascii { "an ASCII" } else { "a binary" };
    let not_stl = || IoError::malformed(path, format!("not readable as {format} STL file"));
    let triangles = guard::quietly(|| stl_io::create_stl_reader(&mut cursor))
        .ok_or_else(not_stl)?
        .map_err(|_| not_stl())?;
    let mut triangles = triangles.enumerate();
    let mut mesh = TriangleMesh::default();
    loop {
        let next = guard::quietly(|| triangles.next()).ok_or_else(not_stl)?;
        let Some((t, triangle)) = next else {
            break;
        };
        let triangle = triangle.map_err(|e| IoError::from_stl(path, ascii, t, &e))?;
        let base = mesh.positions.len() as u32;
        for (k, v) in triangle.vertices.iter().enumerate() {
            let p = Vec3::from(v.0);
            if !p.is_finite() {
                return Err(IoError::new(
                    path,
                    IoErrorKind::NonFinite,
                    format!(
                        "vertex {} (corner {k} of triangle {t}) has a non-finite coordinate {p}",
                        3 * t + k
                    ),
                ));
            }
            mesh.positions.push(p);
        }
        mesh.triangles.push([base, base + 1, base + 2]);
    }
    Ok(mesh)
}

/// Writes binary STL: each triangle with its geometric unit normal (zero if it has no area).
pub(crate) fn write(path: &Path, mesh: &TriangleMesh) -> Result<TempFile, IoError> {
    if mesh.triangles.len() > u32::MAX as usize {
        return Err(IoError::unsupported(
            path,
            "binary STL holds at most 2^32 - 1 triangles",
        ));
    }
    let triangle = |t: usize| {
        let [a, b, c] = mesh.triangles[t].map(|v| mesh.positions[v as usize]);
        let n = (b - a).cross(c - a).normalize_or_zero();
        Triangle {
            normal: Normal::new(n.to_array()),
            vertices: [a, b, c].map(|p| Vertex::new(p.to_array())),
        }
    };
    stage(path, |w| {
        stl_io::write_stl(w, (0..mesh.triangles.len()).map(triangle))
    })
}
