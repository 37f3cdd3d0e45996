//! Wavefront OBJ: reads `v`, `vn`, `f`, `l` and `p`; writes `v`, `vn`, `f`, `l` and `p`.
//!
//! We parse OBJ ourselves rather than through `tobj`. tobj splits the file into one model per
//! group and renumbers each model's vertices, dropping the ones no face uses, so a scan with
//! unreferenced vertices (the Stanford bunny has 1,113) would not come back with the vertex
//! count its file states; and its triangulation is a fan, wrong for non-convex faces. The format
//! is line-based and small, so a direct parser keeps every vertex in file order, reports errors
//! by line number, and hands every polygon to [`crate::ear_clipping`].
//!
//! - Faces accept `v`, `v/vt`, `v//vn` and `v/vt/vn` corners, with 1-based or negative
//!   (relative to the vertices read so far) indices; texture coordinates are ignored.
//! - Normals are given per corner in OBJ but per vertex in [`TriangleMesh`]: they are kept when
//!   every vertex used by a face gets one consistent normal (unused vertices get zero), and
//!   dropped otherwise (the pipeline recomputes them).
//! - Groups, objects, materials, smoothing groups, free-form geometry are ignored; a trailing
//!   `\` continues a line.
//!
//! An MNI polygon file, which shares the extension (its first token is `P`), is read by
//! [`crate::mni_obj`] instead.
//!
//! Cost: one pass over the file, O(file size) time; memory the mesh plus the lines' polygon
//! lists while they are triangulated (ear clipping, see [`crate::ear_clipping`]).

use std::io::Write;
use std::path::Path;

use glam::{DVec3, Vec3};
use voxlod_core::{PolyMesh, TriangleMesh};

use crate::atomic::{stage, TempFile};
use crate::{budget, ear_clipping, IoError, IoErrorKind, PolyView};

/// What the OBJ reader found, before the common checks.
pub(crate) struct ObjContent {
    pub mesh: PolyMesh,
    pub polygons_triangulated: usize,
}

pub(crate) fn read(path: &Path) -> Result<ObjContent, IoError> {
    let bytes = crate::read_file(path)?;
    // OBJ declares no counts; a line of at least 8 bytes ("v 0 0 0\n", "f 1 2 3\n") becomes
    // up to 36 bytes of vertices, triangles and corner normals.
    budget::check_bytes(
        path,
        "the mesh of the OBJ file",
        (bytes.len() as u64).saturating_mul(5),
    )?;
    if crate::mni_obj::is_mni(&bytes) {
        let (mesh, polygons_triangulated) = crate::mni_obj::parse(path, &bytes)?;
        return Ok(ObjContent {
            mesh,
            polygons_triangulated,
        });
    }
    parse(path, &bytes)
}

/// One corner of a face: position index and, if given, normal index (both resolved, 0-based).
#[derive(Clone, Copy)]
struct Corner {
    v: u32,
    vn: Option<u32>,
}

/// What has been read so far.
#[derive(Default)]
struct Builder {
    positions: Vec<Vec3>,
    file_normals: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    /// For each triangle corner, the normal index the file gave it (if any).
    corner_normals: Vec<Option<u32>>,
    lines: Vec<[u32; 2]>,
    points: Vec<u32>,
    polygons_triangulated: usize,
    face: Vec<Corner>,
    polygon: Vec<DVec3>,
}

impl Builder {
    /// An `f` line (`at` is its number): a triangle, or a polygon ear-clipped.
    fn face<'a>(
        &mut self,
        path: &Path,
        at: usize,
        tokens: impl Iterator<Item = &'a str>,
    ) -> Result<(), IoError> {
        self.face.clear();
        for token in tokens {
            let corner = parse_corner(
                path,
                at,
                token,
                self.positions.len(),
                self.file_normals.len(),
            )?;
            self.face.push(corner);
        }
        if self.face.len() < 3 {
            return Err(IoError::malformed(
                path,
                format!(
                    "line {at}: a face needs at least 3 corners, this one has {}",
                    self.face.len()
                ),
            ));
        }
        let face = std::mem::take(&mut self.face);
        if face.len() == 3 {
            self.add([face[0], face[1], face[2]]);
        } else {
            self.polygon.clear();
            let positions = &self.positions;
            self.polygon
                .extend(face.iter().map(|c| positions[c.v as usize].as_dvec3()));
            for [a, b, c] in ear_clipping::triangulate(&self.polygon) {
                self.add([face[a], face[b], face[c]]);
            }
            self.polygons_triangulated += 1;
        }
        self.face = face;
        Ok(())
    }

    fn add(&mut self, corners: [Corner; 3]) {
        self.triangles.push(corners.map(|c| c.v));
        self.corner_normals.extend(corners.map(|c| c.vn));
    }

    /// An `l` line: a poly-line, as segments.
    fn line<'a>(
        &mut self,
        path: &Path,
        at: usize,
        tokens: impl Iterator<Item = &'a str>,
    ) -> Result<(), IoError> {
        let vs: Vec<u32> = tokens
            .map(|t| parse_corner(path, at, t, self.positions.len(), 0).map(|c| c.v))
            .collect::<Result<_, _>>()?;
        if vs.len() < 2 {
            return Err(IoError::malformed(
                path,
                format!("line {at}: a line element needs at least 2 vertices"),
            ));
        }
        self.lines.extend(vs.windows(2).map(|w| [w[0], w[1]]));
        Ok(())
    }

    fn finish(self) -> ObjContent {
        let normals = per_vertex_normals(
            self.positions.len(),
            &self.triangles,
            &self.corner_normals,
            &self.file_normals,
        );
        ObjContent {
            mesh: PolyMesh {
                mesh: TriangleMesh {
                    positions: self.positions,
                    normals,
                    triangles: self.triangles,
                },
                lines: self.lines,
                points: self.points,
                ..Default::default()
            },
            polygons_triangulated: self.polygons_triangulated,
        }
    }
}

fn parse(path: &Path, bytes: &[u8]) -> Result<ObjContent, IoError> {
    let mut built = Builder::default();
    let mut logical = String::new();
    let mut line_no = 0usize;
    let mut first_line_no = 0usize;
    for raw_line in bytes.split(|&b| b == b'\n') {
        line_no += 1;
        let text = String::from_utf8_lossy(raw_line);
        let text = text.trim_end_matches('\r');
        if logical.is_empty() {
            first_line_no = line_no;
        }
        if let Some(stripped) = text.strip_suffix('\\') {
            logical.push_str(stripped);
            logical.push(' ');
            continue;
        }
        logical.push_str(text);
        let line = std::mem::take(&mut logical);
        let at = first_line_no;
        let content = line.split('#').next().unwrap_or("");
        let mut tokens = content.split_whitespace();
        let Some(keyword) = tokens.next() else {
            continue;
        };
        match keyword {
            "v" => {
                let p = parse_vec3(path, at, &mut tokens, "vertex")?;
                built.positions.push(p);
            }
            "vn" => {
                let n = parse_vec3(path, at, &mut tokens, "normal")?;
                built.file_normals.push(n);
            }
            "f" | "fo" => built.face(path, at, tokens)?,
            "l" => built.line(path, at, tokens)?,
            "p" => {
                for t in tokens {
                    let corner = parse_corner(path, at, t, built.positions.len(), 0)?;
                    built.points.push(corner.v);
                }
            }
            _ => {}
        }
    }
    Ok(built.finish())
}

fn parse_vec3<'a>(
    path: &Path,
    line: usize,
    tokens: &mut impl Iterator<Item = &'a str>,
    what: &str,
) -> Result<Vec3, IoError> {
    let mut xyz = [0.0f32; 3];
    for c in &mut xyz {
        let token = tokens.next().ok_or_else(|| {
            IoError::malformed(path, format!("line {line}: a {what} needs 3 coordinates"))
        })?;
        *c = token.parse().map_err(|_| {
            IoError::malformed(
                path,
                format!("line {line}: '{token}' is not a number (in a {what})"),
            )
        })?;
    }
    Ok(Vec3::from(xyz))
}

/// Resolves one OBJ index: 1-based, or negative counting back from the last element read.
fn resolve(path: &Path, line: usize, text: &str, count: usize, what: &str) -> Result<u32, IoError> {
    let index: i64 = text.parse().map_err(|_| {
        IoError::malformed(
            path,
            format!("line {line}: '{text}' is not a valid {what} index"),
        )
    })?;
    let resolved = match index {
        i if i > 0 => i - 1,
        i if i < 0 => count as i64 + i,
        _ => {
            return Err(IoError::malformed(
                path,
                format!("line {line}: {what} index 0 is invalid (OBJ indices start at 1)"),
            ))
        }
    };
    if resolved < 0 || resolved >= count as i64 || resolved > u32::MAX as i64 {
        let so_far = match (count, what) {
            (1, _) => what.to_string(),
            (_, "vertex") => "vertices".to_string(),
            _ => format!("{what}s"),
        };
        return Err(IoError::malformed(
            path,
            format!("line {line}: {what} index {index} is out of range ({count} {so_far} so far)"),
        ));
    }
    Ok(resolved as u32)
}

fn parse_corner(
    path: &Path,
    line: usize,
    token: &str,
    vertex_count: usize,
    normal_count: usize,
) -> Result<Corner, IoError> {
    let mut parts = token.split('/');
    let v = resolve(
        path,
        line,
        parts.next().unwrap_or(""),
        vertex_count,
        "vertex",
    )?;
    let _texture = parts.next();
    let vn = match parts.next() {
        Some(t) if !t.is_empty() => Some(resolve(path, line, t, normal_count, "normal")?),
        _ => None,
    };
    Ok(Corner { v, vn })
}

/// One normal per vertex if the file's per-corner normals agree (see the module documentation).
fn per_vertex_normals(
    vertex_count: usize,
    triangles: &[[u32; 3]],
    corner_normals: &[Option<u32>],
    file_normals: &[Vec3],
) -> Vec<Vec3> {
    if file_normals.is_empty() {
        return Vec::new();
    }
    let mut assigned: Vec<Option<Vec3>> = vec![None; vertex_count];
    for (corner, &normal) in triangles.iter().flatten().zip(corner_normals) {
        let Some(ni) = normal else {
            return Vec::new();
        };
        let n = file_normals[ni as usize];
        match &mut assigned[*corner as usize] {
            slot @ None => *slot = Some(n),
            Some(existing) if *existing == n => {}
            Some(_) => return Vec::new(),
        }
    }
    assigned
        .into_iter()
        .map(|n| n.unwrap_or(Vec3::ZERO))
        .collect()
}

/// Writes positions, normals when present, triangles, and the lines and points of a
/// [`PolyMesh`] (`l` and `p`). Coordinates use the shortest text that reads back exactly.
pub(crate) fn write(path: &Path, mesh: PolyView<'_>) -> Result<TempFile, IoError> {
    if !mesh.vertex_attributes.is_empty() || !mesh.line_attributes.is_empty() {
        return Err(IoError::new(
            path,
            IoErrorKind::Unsupported,
            "OBJ cannot store vertex or line attributes; write .ply, .vtp or .vtk",
        ));
    }
    let m = mesh.mesh;
    let has_normals = !m.normals.is_empty();
    stage(path, |w| {
        writeln!(w, "# written by voxlod")?;
        writeln!(
            w,
            "# {} vertices, {} triangles",
            m.positions.len(),
            m.triangles.len()
        )?;
        for p in &m.positions {
            writeln!(w, "v {} {} {}", p.x, p.y, p.z)?;
        }
        for n in &m.normals {
            writeln!(w, "vn {} {} {}", n.x, n.y, n.z)?;
        }
        for t in &m.triangles {
            let [a, b, c] = t.map(|i| i + 1);
            if has_normals {
                writeln!(w, "f {a}//{a} {b}//{b} {c}//{c}")?;
            } else {
                writeln!(w, "f {a} {b} {c}")?;
            }
        }
        for [a, b] in mesh.lines {
            writeln!(w, "l {} {}", a + 1, b + 1)?;
        }
        for p in mesh.points {
            writeln!(w, "p {}", p + 1)?;
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse_str(text: &str) -> Result<ObjContent, IoError> {
        parse(Path::new("test.obj"), text.as_bytes())
    }

    #[test]
    fn negative_indices_count_back_from_the_last_vertex() {
        let obj = parse_str("v 0 0 0\nv 1 0 0\nv 1 1 0\nf -3 -2 -1\nv 0 1 0\nf 1 -2 -1\n").unwrap();
        assert_eq!(obj.mesh.mesh.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    }

    #[test]
    fn corner_forms_and_normals() {
        let obj = parse_str(
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n\
             f 1/1/1 2//1 3/1/-1 # comment\n",
        )
        .unwrap();
        let m = &obj.mesh.mesh;
        assert_eq!(m.triangles, vec![[0, 1, 2]]);
        assert_eq!(m.normals, vec![Vec3::Z; 3]);
        // Disagreeing normals at a vertex are dropped.
        let obj = parse_str(
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvn 0 0 1\nvn 0 0 -1\n\
             f 1//1 2//1 3//1\nf 2//2 4//2 3//2\n",
        )
        .unwrap();
        assert!(obj.mesh.mesh.normals.is_empty());
    }

    #[test]
    fn polygons_are_ear_clipped_and_counted() {
        // A non-convex L-shaped hexagon and a quad; continued line.
        let obj = parse_str(
            "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nv 1 3 0\nv 0 3 0\n\
             f 1 2 3 \\\n 4 5 6\nf 1 2 3 4\n",
        )
        .unwrap();
        assert_eq!(obj.polygons_triangulated, 2);
        let m = &obj.mesh.mesh;
        assert_eq!(m.triangles.len(), 4 + 2);
        let l_area: f64 = (0..4)
            .map(|t| {
                let [a, b, c] = m.corners(t);
                (b - a).cross(c - a).z / 2.0
            })
            .sum();
        assert!((l_area - 4.0).abs() < 1e-9, "{l_area}");
    }

    #[test]
    fn lines_and_points() {
        let obj = parse_str("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nl 1 2 3\np 3\n").unwrap();
        assert_eq!(obj.mesh.lines, vec![[0, 1], [1, 2]]);
        assert_eq!(obj.mesh.points, vec![2]);
    }

    #[test]
    fn bad_indices_name_the_line() {
        for (text, needle) in [
            ("v 0 0 0\nf 1 2 3\n", "line 2"),
            ("v 0 0 0\nv 0 0 0\nv 0 0 0\nf 0 1 2\n", "index 0"),
            ("v 0 0 0\nv 0 0 0\nf 1 2\n", "at least 3"),
            ("v 0 0\n", "3 coordinates"),
            ("v 0 x 0\n", "'x' is not a number"),
            ("v 0 0 0\nf 1 -5 1\n", "out of range"),
            ("v 0 0 0\nv 0 0 0\nv 0 0 0\nf 1//4 2 3\n", "normal index"),
        ] {
            let err = parse_str(text)
                .err()
                .unwrap_or_else(|| panic!("{text} was accepted"));
            assert_eq!(err.kind, IoErrorKind::Malformed);
            assert!(err.message.contains(needle), "{needle}: {err}");
        }
    }
}
