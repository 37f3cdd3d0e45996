//! Object File Format (OFF), the format of the CGAL and Princeton shape data: read and written
//! by hand, it is a header and two lists.
//!
//! ```text
//! OFF                # or COFF, NOFF, CNOFF, STOFF, ... ; the counts may follow on this line
//! V F E              # vertex, face and edge counts (E is ignored)
//! x y z [nx ny nz] [colour] [texture]      × V
//! n i1 ... in [colour]                     × F
//! ```
//!
//! Comments (`#` to the end of the line) and blank lines are skipped anywhere. Vertices and
//! faces are one per line; values after the ones we need (texture coordinates, face colours)
//! are ignored, and so are normals unless the header says `N`. Vertex colours are read only
//! when the header says `C` (COFF): three or four values after the position (and normal),
//! integers in 0..=255 when every colour value of the file is an integer, else floats in 0..=1
//! (so a file whose float colours are all written as `0` and `1` reads as nearly black: the
//! format does not say which it is). A COFF file with a vertex lacking its colour comes back
//! without colours. Polygons are ear-clipped. Not
//! supported: binary OFF, `4OFF` and `nOFF` (other dimensions). The writer emits plain `OFF`.
//!
//! Cost: one pass over the file, O(file size) time; memory the mesh, with counts from the
//! header checked against the budget before allocating.

use std::io::Write;
use std::path::Path;

use glam::{DVec3, Vec3};
use voxlod_core::TriangleMesh;

use crate::atomic::{stage, TempFile};
use crate::{budget, ear_clipping, IoError, IoErrorKind};

pub(crate) struct OffContent {
    pub mesh: TriangleMesh,
    pub polygons_triangulated: usize,
    /// RGBA vertex colours in 0..=1 as stored (sRGB by convention): one per vertex, or none.
    pub colors: Vec<[f32; 4]>,
}

pub(crate) fn read(path: &Path) -> Result<OffContent, IoError> {
    let bytes = crate::read_file(path)?;
    parse(path, &bytes)
}

/// The lines that carry content, with their 1-based numbers and comments removed.
fn content_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.lines().enumerate().filter_map(|(i, line)| {
        let line = line.split('#').next().unwrap_or("").trim();
        (!line.is_empty()).then_some((i + 1, line))
    })
}

fn malformed(path: &Path, line: usize, what: String) -> IoError {
    IoError::malformed(path, format!("line {line}: {what}"))
}

/// What the header says: normals or not, and the counts (checked against the file's size and
/// the memory budget).
struct Header {
    has_normals: bool,
    has_colors: bool,
    vertices: usize,
    faces: usize,
}

fn parse_header<'a>(
    path: &Path,
    lines: &mut impl Iterator<Item = (usize, &'a str)>,
    file_bytes: usize,
) -> Result<Header, IoError> {
    // Header keyword, with the counts on the same line or the next.
    let (line_no, header) = lines
        .next()
        .ok_or_else(|| IoError::new(path, IoErrorKind::Empty, "no content (only comments)"))?;
    let mut header_tokens = header.split_whitespace();
    let keyword = header_tokens.next().unwrap_or("");
    let Some(prefix) = keyword.strip_suffix("OFF") else {
        return Err(malformed(
            path,
            line_no,
            format!("expected an OFF header keyword, found '{keyword}'"),
        ));
    };
    if prefix.contains('4') || prefix.contains('n') {
        return Err(IoError::unsupported(
            path,
            format!("'{keyword}' files (not 3-D) are not supported"),
        ));
    }
    if header_tokens.clone().next() == Some("BINARY") {
        return Err(IoError::unsupported(path, "binary OFF is not supported"));
    }
    let mut counts: Vec<&str> = header_tokens.collect();
    let mut counts_line = line_no;
    if counts.is_empty() {
        let (n, line) = lines.next().ok_or_else(|| {
            IoError::truncated(path, "the file ends before the vertex and face counts")
        })?;
        counts = line.split_whitespace().collect();
        counts_line = n;
    }
    let count = |k: usize, what: &str| -> Result<usize, IoError> {
        counts
            .get(k)
            .and_then(|t| t.parse().ok())
            .ok_or_else(|| malformed(path, counts_line, format!("expected the {what} count")))
    };
    let (vertices, faces) = (count(0, "vertex")?, count(1, "face")?);
    // Each vertex and face takes at least a couple of bytes: larger counts are lies.
    if vertices.saturating_add(faces) > file_bytes / 2 {
        return Err(IoError::truncated(
            path,
            format!(
                "the header declares {vertices} vertices and {faces} faces, more than the {file_bytes} bytes of the file can hold"
            ),
        ));
    }
    budget::check_count(path, "the vertices of the OFF file", vertices as u64, 24)?;
    budget::check_count(path, "the faces of the OFF file", faces as u64, 24)?;
    Ok(Header {
        has_normals: prefix.contains('N'),
        has_colors: prefix.contains('C'),
        vertices,
        faces,
    })
}

/// The vertices' positions, normals (when the header says `N`) and colours (when it says `C`
/// and every vertex has one; see the module's documentation for their scale).
struct Vertices {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    colors: Vec<[f32; 4]>,
}

/// The colour values after a vertex's position and normal: `Some` for three or four numbers
/// (alpha NaN when absent, to be made opaque once the file's scale is known), with whether
/// they are all integers.
fn vertex_color<'a>(mut tokens: impl Iterator<Item = &'a str>) -> Option<([f32; 4], bool)> {
    let mut color = [f32::NAN; 4];
    let mut integers = true;
    let mut k = 0;
    for token in tokens.by_ref().take(4) {
        let Ok(value) = token.parse::<f32>() else {
            break;
        };
        integers &= token.parse::<u32>().is_ok();
        color[k] = value;
        k += 1;
    }
    (k >= 3).then_some((color, integers))
}

fn read_vertices<'a>(
    path: &Path,
    lines: &mut impl Iterator<Item = (usize, &'a str)>,
    header: &Header,
) -> Result<Vertices, IoError> {
    let count = header.vertices;
    let needed = if header.has_normals { 6 } else { 3 };
    let mut positions = Vec::with_capacity(count);
    let mut normals = Vec::with_capacity(if header.has_normals { count } else { 0 });
    let mut colors = Vec::with_capacity(if header.has_colors { count } else { 0 });
    let (mut read_colors, mut integer_colors) = (header.has_colors, true);
    for v in 0..count {
        let (n, line) = lines.next().ok_or_else(|| {
            IoError::truncated(path, format!("the file ends after {v} of {count} vertices"))
        })?;
        let mut tokens = line.split_whitespace();
        let values: Vec<f32> = tokens
            .by_ref()
            .take(needed)
            .map(|t| t.parse::<f32>())
            .collect::<Result<_, _>>()
            .map_err(|_| {
                malformed(
                    path,
                    n,
                    format!("vertex {v} has a coordinate that is not a number"),
                )
            })?;
        if values.len() < needed {
            return Err(malformed(
                path,
                n,
                format!("vertex {v} has {} values, expected {needed}", values.len()),
            ));
        }
        positions.push(Vec3::new(values[0], values[1], values[2]));
        if header.has_normals {
            normals.push(Vec3::new(values[3], values[4], values[5]));
        }
        if read_colors {
            match vertex_color(tokens) {
                Some((color, integers)) => {
                    colors.push(color);
                    integer_colors &= integers;
                }
                None => read_colors = false,
            }
        }
    }
    if !read_colors {
        colors = Vec::new();
    }
    let divisor = if integer_colors { 255.0 } else { 1.0 };
    for c in &mut colors {
        *c = c.map(|x| if x.is_nan() { 1.0 } else { x / divisor });
    }
    Ok(Vertices {
        positions,
        normals,
        colors,
    })
}

/// The faces as triangles, polygons ear-clipped; also how many polygons were.
fn read_faces<'a>(
    path: &Path,
    lines: &mut impl Iterator<Item = (usize, &'a str)>,
    count: usize,
    positions: &[Vec3],
) -> Result<(Vec<[u32; 3]>, usize), IoError> {
    let mut triangles = Vec::with_capacity(count);
    let mut polygons_triangulated = 0;
    let mut corners: Vec<u32> = Vec::new();
    let mut polygon: Vec<DVec3> = Vec::new();
    for f in 0..count {
        let (n, line) = lines.next().ok_or_else(|| {
            IoError::truncated(path, format!("the file ends after {f} of {count} faces"))
        })?;
        let mut tokens = line.split_whitespace();
        let size: usize = tokens.next().and_then(|t| t.parse().ok()).ok_or_else(|| {
            malformed(
                path,
                n,
                format!("face {f} does not start with its corner count"),
            )
        })?;
        if size < 3 {
            return Err(malformed(
                path,
                n,
                format!("face {f} has {size} corners; a face needs at least 3"),
            ));
        }
        corners.clear();
        for _ in 0..size {
            let token = tokens.next().ok_or_else(|| {
                malformed(
                    path,
                    n,
                    format!("face {f} lists fewer than its {size} corners"),
                )
            })?;
            let index: u32 = token
                .parse()
                .ok()
                .filter(|&i: &u32| (i as usize) < positions.len())
                .ok_or_else(|| {
                    malformed(
                        path,
                        n,
                        format!(
                            "face {f} refers to vertex '{token}' but there are {} vertices",
                            positions.len()
                        ),
                    )
                })?;
            corners.push(index);
        }
        if size == 3 {
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

fn parse(path: &Path, bytes: &[u8]) -> Result<OffContent, IoError> {
    let text = String::from_utf8_lossy(bytes);
    let mut lines = content_lines(&text);
    let header = parse_header(path, &mut lines, bytes.len())?;
    let Vertices {
        positions,
        normals,
        colors,
    } = read_vertices(path, &mut lines, &header)?;
    let (triangles, polygons_triangulated) =
        read_faces(path, &mut lines, header.faces, &positions)?;
    Ok(OffContent {
        mesh: TriangleMesh {
            positions,
            normals,
            triangles,
        },
        polygons_triangulated,
        colors,
    })
}

/// Writes `OFF` (or `NOFF` with normals), one vertex and one triangle per line.
pub(crate) fn write(path: &Path, mesh: &TriangleMesh) -> Result<TempFile, IoError> {
    let has_normals = !mesh.normals.is_empty();
    stage(path, |w| {
        writeln!(w, "{}", if has_normals { "NOFF" } else { "OFF" })?;
        writeln!(w, "# written by voxlod")?;
        writeln!(w, "{} {} 0", mesh.positions.len(), mesh.triangles.len())?;
        for (i, p) in mesh.positions.iter().enumerate() {
            if has_normals {
                let n = mesh.normals[i];
                writeln!(w, "{} {} {} {} {} {}", p.x, p.y, p.z, n.x, n.y, n.z)?;
            } else {
                writeln!(w, "{} {} {}", p.x, p.y, p.z)?;
            }
        }
        for [a, b, c] in &mesh.triangles {
            writeln!(w, "3 {a} {b} {c}")?;
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse_str(text: &str) -> Result<OffContent, IoError> {
        parse(Path::new("t.off"), text.as_bytes())
    }

    #[test]
    fn headers_comments_and_polygons() {
        let off = parse_str(
            "# a comment\nCOFF 4 1 0\n0 0 0 255 0 0 255\n1 0 0 1 1 1 1\n\n\
             1 1 0 # trailing\n0 1 0 0 0 0 0\n4 0 1 2 3 255 0 0\n",
        )
        .unwrap();
        assert_eq!(off.mesh.positions.len(), 4);
        assert_eq!(off.mesh.triangles.len(), 2);
        assert_eq!(off.polygons_triangulated, 1);
        assert!(off.mesh.normals.is_empty());
        // The third vertex has no colour: the file's colours are left out.
        assert!(off.colors.is_empty());

        // Integer colours, with alpha or not, scaled from 0..=255.
        let off =
            parse_str("COFF\n3 1 0\n0 0 0 255 0 0 255\n1 0 0 1 1 1 1\n0 1 0 0 51 255\n3 0 1 2\n")
                .unwrap();
        let expected = [[1.0, 0.0, 0.0, 1.0], [1.0 / 255.0; 4], [0.0, 0.2, 1.0, 1.0]];
        assert_eq!(off.colors, expected);

        // Float colours, three of them (alpha 1); a vertex without one drops them all.
        let off =
            parse_str("COFF\n3 1 0\n0 0 0 1 0.5 0\n1 0 0 0 0 1\n0 1 0 1 1 1\n3 0 1 2\n").unwrap();
        assert_eq!(off.colors[0], [1.0, 0.5, 0.0, 1.0]);
        let off = parse_str("COFF\n3 1 0\n0 0 0 1 0.5 0\n1 0 0\n0 1 0 1 1 1\n3 0 1 2\n").unwrap();
        assert!(off.colors.is_empty());

        let off =
            parse_str("NOFF\n3 1 0\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n").unwrap();
        assert_eq!(off.mesh.normals, vec![Vec3::Z; 3]);
    }

    #[test]
    fn errors_name_the_line() {
        for (text, kind, needle) in [
            ("PLY\n", IoErrorKind::Malformed, "OFF header"),
            (
                "OFF\n3 1 0\n0 0 0\n1 0 0\n",
                IoErrorKind::Truncated,
                "2 of 3 vertices",
            ),
            (
                "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n",
                IoErrorKind::Malformed,
                "line 6",
            ),
            (
                "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n",
                IoErrorKind::Malformed,
                "at least 3",
            ),
            (
                "OFF\n99999999 1 0\n0 0 0\n",
                IoErrorKind::Truncated,
                "99999999",
            ),
            ("4OFF\n", IoErrorKind::Unsupported, "4OFF"),
            ("# nothing\n", IoErrorKind::Empty, "no content"),
        ] {
            let err = parse_str(text)
                .err()
                .unwrap_or_else(|| panic!("accepted {text:?}"));
            assert_eq!(err.kind, kind, "{err}");
            assert!(err.message.contains(needle), "{needle}: {err}");
        }
    }
}
