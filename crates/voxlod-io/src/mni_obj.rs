//! MNI polygon files: the `.obj` surfaces of the Montreal Neurological Institute's tools (BIC
//! "obj" format; CIVET's and BrainSuite's cortical surfaces, VTK's `vtkMNIObjectReader`), which
//! share Wavefront OBJ's extension and nothing else. [`is_mni`] tells them apart by their first
//! token, `P` (ASCII polygons); the OBJ reader hands them here.
//!
//! Layout, all numbers separated by white space: `P`, five surface properties (ambient,
//! diffuse, specular reflectance, specular scale, transparency) and the point count `n`; `n`
//! points (x y z); `n` unit normals; the item (polygon) count `m`; a colour flag (0: one colour,
//! 1: one per item, 2: one per point) and that many RGBA colours; `m` end indices (item `i`
//! uses the indices from the previous end to its own); the indices themselves, 0-based.
//! Colours are read past and dropped; the normals are kept per vertex; polygons of more than
//! three corners are ear-clipped ([`crate::ear_clipping`]). The binary form (`p`) is refused by
//! name.
//!
//! Counts come from the file, but nothing is reserved by them: every value is pushed as it is
//! read, so a count larger than the file holds ends in a truncation error, never in an
//! allocation. Cost: one pass over the tokens, O(file size).

use std::path::Path;

use glam::{DVec3, Vec3};
use voxlod_core::{PolyMesh, TriangleMesh};

use crate::{ear_clipping, IoError};

/// Whether `bytes` open as an MNI polygon file (ASCII `P` or binary `p` first token).
pub(crate) fn is_mni(bytes: &[u8]) -> bool {
    let start = bytes.iter().position(|b| !b.is_ascii_whitespace());
    let Some(start) = start else {
        return false;
    };
    let rest = &bytes[start..];
    matches!(rest.first(), Some(b'P' | b'p'))
        && rest.get(1).is_some_and(|b| b.is_ascii_whitespace())
}

/// Whether the file at `path` opens as an MNI polygon file ([`is_mni`] on its first 256 bytes).
pub(crate) fn is_mni_file(path: &Path) -> Result<bool, IoError> {
    use std::io::Read;
    let mut head = Vec::with_capacity(256);
    std::fs::File::open(path)
        .and_then(|f| f.take(256).read_to_end(&mut head))
        .map_err(|e| IoError::access(path, "cannot read", &e))?;
    Ok(is_mni(&head))
}

/// The tokens of the file in order, with what each number is for in an error.
struct Tokens<'a> {
    path: &'a Path,
    words: std::str::SplitAsciiWhitespace<'a>,
}

impl Tokens<'_> {
    /// The next token as a `T`, or an error naming `what` was being read.
    fn next<T: std::str::FromStr>(&mut self, what: &str) -> Result<T, IoError> {
        let word = self.words.next().ok_or_else(|| {
            IoError::truncated(
                self.path,
                format!("MNI polygon file ends early: {what} missing"),
            )
        })?;
        word.parse().map_err(|_| {
            IoError::malformed(
                self.path,
                format!("MNI polygon file: {what} is '{word}', not a number of its kind"),
            )
        })
    }

    /// `count` values of three numbers each.
    fn vectors(&mut self, count: usize, what: &str) -> Result<Vec<Vec3>, IoError> {
        let mut out = Vec::new();
        for k in 0..count {
            let label = format!("{what} {k} of {count}");
            let [x, y, z] = [(); 3].map(|_| self.next::<f32>(&label));
            let v = Vec3::new(x?, y?, z?);
            if !v.is_finite() {
                return Err(IoError::malformed(
                    self.path,
                    format!("MNI polygon file: {label} is not finite"),
                ));
            }
            out.push(v);
        }
        Ok(out)
    }
}

/// Reads an MNI polygon file (module docs): the mesh, and how many of its polygons were
/// ear-clipped.
pub(crate) fn parse(path: &Path, bytes: &[u8]) -> Result<(PolyMesh, usize), IoError> {
    let text = std::str::from_utf8(bytes)
        .map_err(|_| IoError::malformed(path, "MNI polygon file is not ASCII text"))?;
    let mut tokens = Tokens {
        path,
        words: text.split_ascii_whitespace(),
    };
    let kind: String = tokens.next("the object type")?;
    if kind != "P" {
        return Err(IoError::malformed(
            path,
            format!(
                "an MNI object of type '{kind}' (binary polygons or not polygons): only ASCII polygon files ('P') are read"
            ),
        ));
    }
    for what in [
        "ambient",
        "diffuse",
        "specular reflectance",
        "specular scale",
        "transparency",
    ] {
        tokens.next::<f32>(what)?;
    }
    let points: usize = tokens.next("the point count")?;
    let positions = tokens.vectors(points, "point")?;
    let normals = tokens.vectors(points, "normal")?;
    let items: usize = tokens.next("the polygon count")?;
    skip_colours(&mut tokens, items, points)?;
    let mut ends = Vec::new();
    for k in 0..items {
        ends.push(tokens.next::<usize>(&format!("end index {k} of {items}"))?);
    }
    let (triangles, polygons_triangulated) = polygons(&mut tokens, &ends, &positions)?;
    let mesh = PolyMesh {
        mesh: TriangleMesh {
            positions,
            normals,
            triangles,
        },
        ..Default::default()
    };
    Ok((mesh, polygons_triangulated))
}

/// Reads past the colour flag and its colours (one, one per polygon, or one per point).
fn skip_colours(tokens: &mut Tokens, items: usize, points: usize) -> Result<(), IoError> {
    let flag: u32 = tokens.next("the colour flag")?;
    let colours = match flag {
        0 => 1,
        1 => items,
        2 => points,
        _ => {
            return Err(IoError::malformed(
                tokens.path,
                format!("MNI polygon file: colour flag {flag}, expected 0, 1 or 2"),
            ))
        }
    };
    for k in 0..colours.saturating_mul(4) {
        tokens.next::<f32>(&format!("colour value {k}"))?;
    }
    Ok(())
}

/// The polygons ending at `ends`, their corners read from `tokens`, as triangles (ear-clipped
/// where larger), and how many were larger.
fn polygons(
    tokens: &mut Tokens,
    ends: &[usize],
    positions: &[Vec3],
) -> Result<(Vec<[u32; 3]>, usize), IoError> {
    let path = tokens.path;
    let (mut triangles, mut clipped, mut start) = (Vec::new(), 0, 0);
    let mut corners: Vec<u32> = Vec::new();
    for (k, &end) in ends.iter().enumerate() {
        if end < start + 3 {
            return Err(IoError::malformed(
                path,
                format!("MNI polygon file: polygon {k} ends at index {end}, fewer than 3 corners after {start}"),
            ));
        }
        corners.clear();
        for c in start..end {
            let v: usize = tokens.next(&format!("corner {c} (polygon {k})"))?;
            if v >= positions.len() {
                return Err(IoError::malformed(
                    path,
                    format!(
                        "MNI polygon file: polygon {k} uses point {v}, beyond the {} points",
                        positions.len()
                    ),
                ));
            }
            corners.push(v as u32);
        }
        if corners.len() == 3 {
            triangles.push([corners[0], corners[1], corners[2]]);
        } else {
            let polygon: Vec<DVec3> = corners
                .iter()
                .map(|&v| positions[v as usize].as_dvec3())
                .collect();
            for [a, b, c] in ear_clipping::triangulate(&polygon) {
                triangles.push([corners[a], corners[b], corners[c]]);
            }
            clipped += 1;
        }
        start = end;
    }
    Ok((triangles, clipped))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tetrahedron as an MNI polygon file: four points, their normals, four triangles, one
    /// colour.
    const TETRAHEDRON: &str = "P 0.3 0.3 0.4 10 1 4
 0 0 0
 1 0 0
 0 1 0
 0 0 1
 -0.57 -0.57 -0.57
 1 0 0
 0 1 0
 0 0 1

 4
 0 1 1 1 1

 3 6 9 12

 0 2 1 0 1 3 0 3 2 1 2 3
";

    #[test]
    fn is_mni_knows_polygon_files_from_wavefront_ones() {
        assert!(is_mni(TETRAHEDRON.as_bytes()));
        assert!(is_mni(b"\n  p 0.3 0.3"));
        assert!(!is_mni(b"# Wavefront\nv 0 0 0\n"));
        assert!(!is_mni(b"Pv 0 0 0"));
        assert!(!is_mni(b""));
    }

    #[test]
    fn parse_reads_points_normals_and_triangles() {
        let (read, clipped) = parse(Path::new("t.obj"), TETRAHEDRON.as_bytes()).unwrap();
        let mesh = &read.mesh;
        assert_eq!(mesh.positions.len(), 4);
        assert_eq!(mesh.positions[3], Vec3::Z);
        assert_eq!(mesh.normals[1], Vec3::X);
        assert_eq!(mesh.triangles, [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]);
        assert_eq!(clipped, 0);
    }

    #[test]
    fn parse_clips_a_quad_and_skips_per_vertex_colours() {
        let square = "P 0 0 0 0 1 4\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n\
                      0 0 1\n0 0 1\n0 0 1\n0 0 1\n1\n2\n\
                      1 0 0 1\n0 1 0 1\n0 0 1 1\n1 1 1 1\n4\n0 1 2 3\n";
        let (read, clipped) = parse(Path::new("q.obj"), square.as_bytes()).unwrap();
        assert_eq!(read.mesh.triangles.len(), 2);
        assert_eq!(clipped, 1);
    }

    #[test]
    fn parse_refuses_truncated_and_inconsistent_files_naming_what_is_wrong() {
        let cases = [
            (&TETRAHEDRON[..60], "ends early"),
            ("P 0.3 0.3 0.4 10 1 99999999999\n0 0 0\n", "ends early"),
            ("p 0.3 0.3 0.4 10 1 4\n", "only ASCII polygon files"),
            (
                "P 0.3 0.3 0.4 10 1 1\n0 0 0\n0 0 1\n1\n7\n",
                "colour flag 7",
            ),
        ];
        for (text, expected) in cases {
            let err = parse(Path::new("bad.obj"), text.as_bytes()).err().unwrap();
            assert!(err.to_string().contains(expected), "{err}");
            assert!(err.to_string().contains("bad.obj"), "{err}");
        }
        let out_of_range = TETRAHEDRON.replace(" 1 2 3\n", " 1 2 9\n");
        let err = parse(Path::new("bad.obj"), out_of_range.as_bytes())
            .err()
            .unwrap();
        assert!(err.to_string().contains("beyond the 4 points"), "{err}");
    }
}
