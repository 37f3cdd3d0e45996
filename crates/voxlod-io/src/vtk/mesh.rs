//! VTK PolyData through `vtkio`: XML `.vtp` and legacy `.vtk`, read and written.
//!
//! Reading: points (any numeric type); `Polys` (polygons ear-clipped), `Strips` (split into
//! triangles with alternating winding), `Lines` (poly-lines split into segments) and `Verts`
//! (each vertex a point). Point data: an array tagged as normals (or named `Normals`, three
//! components) becomes the normals, every one-component array a vertex attribute. Cell data:
//! one-component arrays become line attributes, taken from the line cells (every segment of a
//! poly-line gets the poly-line's value). Several pieces are concatenated. An unstructured grid
//! (`.vtu`, legacy `UNSTRUCTURED_GRID`) is read through [`unstructured`]: its surface cells,
//! and its volume cells as the boundary of their union. Other data sets (images, structured
//! grids) are refused with a message saying what the file holds.
//!
//! Writing: one piece with the points, `Verts` (one cell per point), `Lines` (one two-point cell
//! per segment) and `Polys` (triangles); normals and vertex attributes as point data, line
//! attributes as cell data. Cell data in VTK covers every cell (verts, then lines, then polys),
//! so vertex and triangle cells carry NaN in the line attribute arrays.
//!
//! Cost: O(file size) time; memory the vtkio model plus the mesh (two copies at the peak).

use std::path::Path;

use glam::{DVec3, Vec3};
use voxlod_core::{Attribute, PolyMesh, TriangleMesh};
use vtkio::model::{
    Attribute as VtkAttribute, Attributes, DataArray, DataSet, ElementType, IOBuffer, Piece,
    PolyDataPiece, UnstructuredGridPiece, Version, VertexNumbers, Vtk,
};

use crate::atomic::TempFile;
use crate::vtk::unstructured::{self, GridCells};
use crate::vtk::{self, Flavor};
use crate::{ear_clipping, IoError, PolyView};

pub(crate) struct VtkMeshContent {
    pub mesh: PolyMesh,
    pub polygons_triangulated: usize,
    /// What reading changed, in words (an unstructured grid's volume cells, its cell data).
    pub notes: Vec<String>,
}

/// Calls `visit` with the vertex indices of every cell, checking the offsets as it goes.
pub(super) fn for_each_cell(
    path: &Path,
    numbers: &VertexNumbers,
    what: &str,
    mut visit: impl FnMut(usize, &[u64]) -> Result<(), IoError>,
) -> Result<(), IoError> {
    let bad = |detail: String| IoError::malformed(path, format!("{what} cells: {detail}"));
    let mut cell = Vec::new();
    match numbers {
        VertexNumbers::Legacy {
            num_cells,
            vertices,
        } => {
            let mut at = 0usize;
            for c in 0..*num_cells as usize {
                let n = *vertices
                    .get(at)
                    .ok_or_else(|| bad(format!("the list ends before cell {c}")))?
                    as usize;
                let ids = vertices
                    .get(at + 1..at + 1 + n)
                    .ok_or_else(|| bad(format!("cell {c} lists fewer than its {n} vertices")))?;
                cell.clear();
                cell.extend(ids.iter().map(|&v| v as u64));
                visit(c, &cell)?;
                at += 1 + n;
            }
        }
        VertexNumbers::XML {
            connectivity,
            offsets,
        } => {
            // Some writers start the offsets with a zero.
            let offsets = match offsets.first() {
                Some(0) => &offsets[1..],
                _ => &offsets[..],
            };
            let mut start = 0usize;
            for (c, &end) in offsets.iter().enumerate() {
                let end = end as usize;
                let ids = connectivity.get(start..end).ok_or_else(|| {
                    bad(format!(
                        "cell {c} spans {start}..{end} of {} connectivity entries",
                        connectivity.len()
                    ))
                })?;
                visit(c, ids)?;
                start = end;
            }
        }
    }
    Ok(())
}

fn vertex_index(
    path: &Path,
    what: &str,
    cell: usize,
    v: u64,
    count: usize,
) -> Result<u32, IoError> {
    if v >= count as u64 {
        return Err(IoError::malformed(
            path,
            format!("{what} cell {cell} refers to point {v} but there are {count} points"),
        ));
    }
    Ok(v as u32)
}

/// A one-component data array, or the normals, with its name.
enum PointArray {
    Normals(Vec<Vec3>),
    Scalar(Attribute),
    Other,
}

/// The usable arrays of one attribute: a data array, or each array of a legacy `FIELD` (VTK 9's
/// legacy writer stores arrays that are not scalars, vectors or normals as field data).
fn classify(attribute: VtkAttribute, expected: usize) -> Vec<PointArray> {
    match attribute {
        VtkAttribute::DataArray(DataArray { name, elem, data }) => {
            vec![classify_array(name, elem, data, expected)]
        }
        VtkAttribute::Field { data_array, .. } => data_array
            .into_iter()
            .map(|f| {
                let elem = ElementType::Generic(f.elem);
                classify_array(f.name, elem, f.data, expected)
            })
            .collect(),
    }
}

fn classify_array(name: String, elem: ElementType, data: IOBuffer, expected: usize) -> PointArray {
    let components = elem.num_comp() as usize;
    if data.len() != expected * components {
        return PointArray::Other;
    }
    let is_normals = matches!(elem, ElementType::Normals)
        || (components == 3 && name.eq_ignore_ascii_case("normals"));
    if is_normals {
        let values = vtk::to_f64(&data);
        return PointArray::Normals(
            values
                .chunks_exact(3)
                .map(|c| DVec3::new(c[0], c[1], c[2]).as_vec3())
                .collect(),
        );
    }
    if components == 1 {
        return PointArray::Scalar(Attribute {
            name,
            values: vtk::into_f32(data),
        });
    }
    PointArray::Other
}

pub(crate) fn read(path: &Path, flavor: Flavor) -> Result<VtkMeshContent, IoError> {
    let vtk = vtk::load(path, flavor)?;
    let pieces = match vtk.data {
        DataSet::PolyData { pieces, .. } => pieces,
        DataSet::UnstructuredGrid { pieces, .. } => return read_grid(path, pieces),
        DataSet::ImageData { .. } => {
            return Err(IoError::unsupported(
                path,
                "holds image data, not a polygon mesh: read it as a volume",
            ))
        }
        other => {
            let kind = match other {
                DataSet::StructuredGrid { .. } => "a structured grid",
                DataSet::RectilinearGrid { .. } => "a rectilinear grid",
                _ => "field data",
            };
            return Err(IoError::unsupported(
                path,
                format!("holds {kind}; only PolyData meshes are read"),
            ));
        }
    };

    let mut out = PolyMesh::default();
    let mut polygons_triangulated = 0;
    for piece in pieces {
        let Piece::Inline(piece) = piece else {
            return Err(IoError::unsupported(
                path,
                "pieces stored in other files (parallel VTK) are not supported",
            ));
        };
        polygons_triangulated += append_piece(path, *piece, &mut out)?;
    }
    Ok(VtkMeshContent {
        mesh: out,
        polygons_triangulated,
        notes: Vec::new(),
    })
}

/// An unstructured grid's pieces read as polygon data ([`unstructured`]), with notes on its
/// volume cells and cell data.
fn read_grid(
    path: &Path,
    pieces: Vec<Piece<UnstructuredGridPiece>>,
) -> Result<VtkMeshContent, IoError> {
    let mut out = PolyMesh::default();
    let (mut polygons_triangulated, mut cells) = (0, GridCells::default());
    for piece in pieces {
        let Piece::Inline(piece) = piece else {
            return Err(IoError::unsupported(
                path,
                "pieces stored in other files (parallel VTK) are not supported",
            ));
        };
        let (piece, grid) = unstructured::as_poly_data(path, *piece)?;
        cells.volume += grid.volume;
        cells.boundary_faces += grid.boundary_faces;
        cells.cell_arrays_dropped += grid.cell_arrays_dropped;
        polygons_triangulated += append_piece(path, piece, &mut out)?;
    }
    let mut notes = Vec::new();
    if cells.volume > 0 {
        notes.push(format!(
            "{} volume cells read as the {} faces of their union's boundary",
            cells.volume, cells.boundary_faces
        ));
    }
    if cells.cell_arrays_dropped > 0 {
        notes.push(format!(
            "{} cell data arrays of the unstructured grid left out (its point data is read)",
            cells.cell_arrays_dropped
        ));
    }
    Ok(VtkMeshContent {
        mesh: out,
        polygons_triangulated,
        notes,
    })
}

/// Appends one piece to `out`, returning how many polygons it ear-clipped.
fn append_piece(path: &Path, piece: PolyDataPiece, out: &mut PolyMesh) -> Result<usize, IoError> {
    let coords = vtk::to_f64(&piece.points);
    if !coords.len().is_multiple_of(3) {
        return Err(IoError::malformed(
            path,
            format!("{} point coordinates is not a multiple of 3", coords.len()),
        ));
    }
    let positions: Vec<Vec3> = coords
        .chunks_exact(3)
        .map(|c| DVec3::new(c[0], c[1], c[2]).as_vec3())
        .collect();
    let cells = Cells {
        path,
        base: out.mesh.positions.len() as u32,
        positions: &positions,
    };
    let segment_cells = cells.points_and_lines(&piece, out)?;
    let triangulated = cells.polygons_and_strips(&piece, out)?;
    append_data(piece, cells.base, positions.len(), &segment_cells, out);
    out.mesh.positions.extend(positions);
    Ok(triangulated)
}

/// The cells of one piece, whose points are `positions`, numbered from `base` in the mesh.
struct Cells<'a> {
    path: &'a Path,
    base: u32,
    positions: &'a [Vec3],
}

impl Cells<'_> {
    fn index(&self, what: &str, cell: usize, v: u64) -> Result<u32, IoError> {
        Ok(self.base + vertex_index(self.path, what, cell, v, self.positions.len())?)
    }

    /// Appends the vertex cells as points and the poly-lines as segments; returns the cell
    /// number (among all the piece's cells) of each segment.
    fn points_and_lines(
        &self,
        piece: &PolyDataPiece,
        out: &mut PolyMesh,
    ) -> Result<Vec<usize>, IoError> {
        if let Some(verts) = &piece.verts {
            for_each_cell(self.path, verts, "vertex", |c, ids| {
                for &v in ids {
                    out.points.push(self.index("vertex", c, v)?);
                }
                Ok(())
            })?;
        }
        let vert_cells = piece.verts.as_ref().map_or(0, |v| v.num_cells());
        let mut segment_cells = Vec::new();
        if let Some(lines) = &piece.lines {
            for_each_cell(self.path, lines, "line", |c, ids| {
                for pair in ids.windows(2) {
                    out.lines.push([
                        self.index("line", c, pair[0])?,
                        self.index("line", c, pair[1])?,
                    ]);
                    segment_cells.push(vert_cells + c);
                }
                Ok(())
            })?;
        }
        Ok(segment_cells)
    }

    /// Appends the polygons (ear-clipped) and strips as triangles; returns how many polygons
    /// were ear-clipped.
    fn polygons_and_strips(
        &self,
        piece: &PolyDataPiece,
        out: &mut PolyMesh,
    ) -> Result<usize, IoError> {
        let mut triangulated = 0;
        let mut polygon = Vec::new();
        let mut corners = Vec::new();
        if let Some(polys) = &piece.polys {
            for_each_cell(self.path, polys, "polygon", |c, ids| {
                corners.clear();
                for &v in ids {
                    corners.push(self.index("polygon", c, v)?);
                }
                if corners.len() < 3 {
                    return Err(IoError::malformed(
                        self.path,
                        format!(
                            "polygon cell {c} has {} corners; at least 3 are needed",
                            corners.len()
                        ),
                    ));
                }
                if corners.len() == 3 {
                    out.mesh
                        .triangles
                        .push([corners[0], corners[1], corners[2]]);
                    return Ok(());
                }
                polygon.clear();
                polygon.extend(
                    corners
                        .iter()
                        .map(|&v| self.positions[(v - self.base) as usize].as_dvec3()),
                );
                out.mesh.triangles.extend(
                    ear_clipping::triangulate(&polygon)
                        .into_iter()
                        .map(|t| t.map(|i| corners[i])),
                );
                triangulated += 1;
                Ok(())
            })?;
        }
        if let Some(strips) = &piece.strips {
            for_each_cell(self.path, strips, "strip", |c, ids| {
                for (k, w) in ids.windows(3).enumerate() {
                    let [a, b, d] = [w[0], w[1], w[2]].map(|v| self.index("strip", c, v));
                    let (a, b, d) = (a?, b?, d?);
                    // Every other triangle of a strip is reversed to keep the winding.
                    out.mesh
                        .triangles
                        .push(if k % 2 == 0 { [a, b, d] } else { [b, a, d] });
                }
                Ok(())
            })?;
        }
        Ok(triangulated)
    }
}

/// Appends a piece's point data (normals, scalars) and the cell data of its line cells
/// (`segment_cells`: the cell of each segment it added).
fn append_data(
    piece: PolyDataPiece,
    base: u32,
    count: usize,
    segment_cells: &[usize],
    out: &mut PolyMesh,
) {
    let total_cells = piece.num_cells();
    let had_vertices = base > 0;
    let mut normals = None;
    let mut scalars = Vec::new();
    for attribute in piece
        .data
        .point
        .into_iter()
        .flat_map(|a| classify(a, count))
    {
        match attribute {
            PointArray::Normals(n) if normals.is_none() => normals = Some(n),
            PointArray::Scalar(a) => scalars.push(a),
            _ => {}
        }
    }
    match normals {
        // Normals are kept only if every piece has them.
        Some(n) if !had_vertices || out.mesh.normals.len() == base as usize => {
            out.mesh.normals.extend(n)
        }
        _ => out.mesh.normals.clear(),
    }
    merge_attributes(&mut out.vertex_attributes, scalars, base as usize, count);

    let line_before = out.lines.len() - segment_cells.len();
    let mut line_scalars = Vec::new();
    for attribute in piece
        .data
        .cell
        .into_iter()
        .flat_map(|a| classify(a, total_cells))
    {
        if let PointArray::Scalar(a) = attribute {
            line_scalars.push(Attribute {
                name: a.name,
                values: segment_cells.iter().map(|&c| a.values[c]).collect(),
            });
        }
    }
    merge_attributes(
        &mut out.line_attributes,
        line_scalars,
        line_before,
        segment_cells.len(),
    );
}

/// Appends a piece's attributes to the ones gathered so far, by name; an attribute missing on
/// either side is filled with NaN so that every attribute keeps one value per element.
fn merge_attributes(into: &mut Vec<Attribute>, new: Vec<Attribute>, before: usize, added: usize) {
    for a in into.iter_mut() {
        if let Some(n) = new.iter().find(|n| n.name == a.name) {
            a.values.extend_from_slice(&n.values);
        } else {
            a.values.resize(before + added, f32::NAN);
        }
    }
    for n in new {
        if !into.iter().any(|a| a.name == n.name) {
            let mut values = vec![f32::NAN; before];
            values.extend(n.values);
            into.push(Attribute {
                name: n.name,
                values,
            });
        }
    }
}

/// Legacy VTK separates tokens by spaces: array names must be single words there.
fn check_legacy_names(path: &Path, view: &PolyView<'_>) -> Result<(), IoError> {
    let all = view.vertex_attributes.iter().chain(view.line_attributes);
    for a in all {
        if a.name.is_empty() || a.name.chars().any(char::is_whitespace) {
            return Err(IoError::unsupported(
                path,
                format!(
                    "attribute name '{}' is not a single word, as legacy VTK requires",
                    a.name
                ),
            ));
        }
    }
    Ok(())
}

/// Cells in the layout of the flavour: `n i1 .. in` runs for legacy, offsets and connectivity
/// for XML. No cells, no section.
fn cell_numbers<'a>(
    flavor: Flavor,
    cells: impl Iterator<Item = &'a [u32]> + Clone,
) -> Option<VertexNumbers> {
    let count = cells.clone().count();
    if count == 0 {
        return None;
    }
    Some(match flavor {
        Flavor::Legacy => VertexNumbers::Legacy {
            num_cells: count as u32,
            vertices: cells
                .flat_map(|c| std::iter::once(c.len() as u32).chain(c.iter().copied()))
                .collect(),
        },
        Flavor::Xml => {
            let mut end = 0u64;
            VertexNumbers::XML {
                offsets: cells
                    .clone()
                    .map(|c| {
                        end += c.len() as u64;
                        end
                    })
                    .collect(),
                connectivity: cells.flatten().map(|&v| v as u64).collect(),
            }
        }
    })
}

pub(crate) fn write(path: &Path, view: PolyView<'_>, flavor: Flavor) -> Result<TempFile, IoError> {
    if flavor == Flavor::Legacy {
        check_legacy_names(path, &view)?;
    }
    let m: &TriangleMesh = view.mesh;
    let points: Vec<f32> = m.positions.iter().flat_map(|p| p.to_array()).collect();
    let verts = cell_numbers(flavor, view.points.chunks(1));
    let lines = cell_numbers(flavor, view.lines.iter().map(|l| &l[..]));
    let polys = cell_numbers(flavor, m.triangles.iter().map(|t| &t[..]));

    let mut data = Attributes::new();
    if !m.normals.is_empty() {
        data.point.push(VtkAttribute::DataArray(DataArray {
            name: "Normals".to_string(),
            elem: ElementType::Normals,
            data: IOBuffer::F32(m.normals.iter().flat_map(|n| n.to_array()).collect()),
        }));
    }
    for a in view.vertex_attributes {
        data.point
            .push(VtkAttribute::scalars(a.name.clone(), 1).with_data(a.values.clone()));
    }
    for a in view.line_attributes {
        let mut values = vec![f32::NAN; view.points.len()];
        values.extend_from_slice(&a.values);
        values.resize(values.len() + m.triangles.len(), f32::NAN);
        data.cell
            .push(VtkAttribute::scalars(a.name.clone(), 1).with_data(values));
    }

    let piece = PolyDataPiece {
        points: IOBuffer::F32(points),
        verts,
        lines,
        polys,
        strips: None,
        data,
    };
    let vtk = Vtk {
        version: match flavor {
            Flavor::Legacy => Version::new_legacy(4, 2),
            Flavor::Xml => Version::new_xml(1, 0),
        },
        title: "written by voxlod".to_string(),
        // Legacy binary data is big-endian by definition; XML says which it uses.
        byte_order: match flavor {
            Flavor::Legacy => vtkio::model::ByteOrder::BigEndian,
            Flavor::Xml => vtkio::model::ByteOrder::LittleEndian,
        },
        file_path: None,
        data: DataSet::inline(piece),
    };
    vtk::save(path, vtk, flavor, false)
}
