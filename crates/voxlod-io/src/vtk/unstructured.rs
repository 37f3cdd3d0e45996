//! A VTK unstructured grid (XML `.vtu`, legacy `DATASET UNSTRUCTURED_GRID`) as the polygon
//! data the mesh reader takes: its surface cells as they are (triangles, quads, pixels and
//! polygons as polygons, triangle strips as strips, lines and vertices as lines and
//! vertices), its volume cells (tetrahedra, hexahedra, voxels, wedges, pyramids) as the
//! boundary of their union: each cell's faces, those that two cells share dropped, each kept
//! face turned to face away from its cell's centroid (so a tetrahedral or hexahedral model
//! reads as its closed, outward surface). A surface cell that is also a face of the volume's
//! boundary (a finite element model's boundary elements) is read once. Point data is kept;
//! cell data, whose order is the grid's and not that of polygon data, is left out, and the
//! result says so. Higher-order and polyhedral cells are refused, naming the cell type.
//!
//! Cost: O(cells) with a hash of each volume cell's faces.

use std::collections::HashMap;
use std::path::Path;

use glam::DVec3;
use vtkio::model::{Attributes, CellType, PolyDataPiece, UnstructuredGridPiece, VertexNumbers};

use super::mesh::for_each_cell;
use crate::IoError;

/// What became of an unstructured grid's cells.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct GridCells {
    /// Volume cells, read as the boundary of their union.
    pub volume: usize,
    /// Faces of that boundary.
    pub boundary_faces: usize,
    /// Cell data arrays left out.
    pub cell_arrays_dropped: usize,
}

/// Cell lists being built, as (connectivity, offsets).
#[derive(Default)]
struct Lists {
    verts: Vec<u64>,
    vert_offsets: Vec<u64>,
    lines: Vec<u64>,
    line_offsets: Vec<u64>,
    polys: Vec<u64>,
    poly_offsets: Vec<u64>,
    strips: Vec<u64>,
    strip_offsets: Vec<u64>,
}

fn push(list: &mut Vec<u64>, offsets: &mut Vec<u64>, cell: &[u64]) {
    list.extend_from_slice(cell);
    offsets.push(list.len() as u64);
}

fn numbers(connectivity: Vec<u64>, offsets: Vec<u64>) -> Option<VertexNumbers> {
    (!offsets.is_empty()).then_some(VertexNumbers::XML {
        connectivity,
        offsets,
    })
}

/// The faces of a linear volume cell, as corner positions in the cell (`None`: not a volume
/// cell). Orientation does not matter: faces are turned outward from the centroid.
fn faces_of(kind: CellType) -> Option<&'static [&'static [usize]]> {
    Some(match kind {
        CellType::Tetra => &[&[0, 1, 3], &[1, 2, 3], &[2, 0, 3], &[0, 2, 1]],
        CellType::Hexahedron => &[
            &[0, 3, 2, 1],
            &[4, 5, 6, 7],
            &[0, 1, 5, 4],
            &[1, 2, 6, 5],
            &[2, 3, 7, 6],
            &[3, 0, 4, 7],
        ],
        // VTK's voxel numbers its corners x fastest, then y, then z.
        CellType::Voxel => &[
            &[0, 2, 3, 1],
            &[4, 5, 7, 6],
            &[0, 1, 5, 4],
            &[2, 6, 7, 3],
            &[0, 4, 6, 2],
            &[1, 3, 7, 5],
        ],
        CellType::Wedge => &[
            &[0, 1, 2],
            &[3, 5, 4],
            &[0, 3, 4, 1],
            &[1, 4, 5, 2],
            &[2, 5, 3, 0],
        ],
        CellType::Pyramid => &[
            &[0, 3, 2, 1],
            &[0, 1, 4],
            &[1, 2, 4],
            &[2, 3, 4],
            &[3, 0, 4],
        ],
        _ => return None,
    })
}

/// Corners each linear volume cell type has.
fn corners_of(kind: CellType) -> usize {
    match kind {
        CellType::Tetra => 4,
        CellType::Pyramid => 5,
        CellType::Wedge => 6,
        _ => 8,
    }
}

/// `piece` as polygon data (module documentation), with what became of its cells. Refuses a
/// cell of a type not read, a cell with the wrong number of corners, or an index beyond the
/// points, naming the cell.
pub(crate) fn as_poly_data(
    path: &Path,
    piece: UnstructuredGridPiece,
) -> Result<(PolyDataPiece, GridCells), IoError> {
    let coords = super::to_f64(&piece.points);
    let point = |i: u64| -> Option<DVec3> {
        let k = 3 * usize::try_from(i).ok()?;
        Some(DVec3::new(
            *coords.get(k)?,
            *coords.get(k + 1)?,
            *coords.get(k + 2)?,
        ))
    };
    let mut lists = Lists::default();
    let mut faces: HashMap<Vec<u64>, (Vec<u64>, usize)> = HashMap::new();
    let mut surface: Vec<Vec<u64>> = Vec::new();
    let mut grid = GridCells::default();
    let types = &piece.cells.types;
    for_each_cell(
        path,
        &piece.cells.cell_verts,
        "unstructured grid",
        |cell, corners| {
            let Some(&kind) = types.get(cell) else {
                let problem = format!("cell {cell} has no cell type ({} types)", types.len());
                return Err(IoError::malformed(path, problem));
            };
            if let Some(bad) = corners.iter().find(|&&v| point(v).is_none()) {
                let problem = format!("cell {cell} names point {bad}, beyond the points");
                return Err(IoError::malformed(path, problem));
            }
            match kind {
                CellType::Vertex | CellType::PolyVertex => {
                    for &v in corners {
                        push(&mut lists.verts, &mut lists.vert_offsets, &[v]);
                    }
                }
                CellType::Line | CellType::PolyLine => {
                    push(&mut lists.lines, &mut lists.line_offsets, corners)
                }
                CellType::Triangle | CellType::Quad | CellType::Polygon => {
                    surface.push(corners.to_vec())
                }
                CellType::Pixel if corners.len() == 4 => {
                    surface.push(vec![corners[0], corners[1], corners[3], corners[2]])
                }
                CellType::TriangleStrip => {
                    push(&mut lists.strips, &mut lists.strip_offsets, corners)
                }
                _ => {
                    let cell_faces = volume_faces(path, cell, kind, corners.len())?;
                    grid.volume += 1;
                    add_faces(&mut faces, corners, cell_faces, &point);
                }
            }
            Ok(())
        },
    )?;
    let boundary: Vec<(Vec<u64>, Vec<u64>)> = faces
        .into_iter()
        .filter(|(_, (_, uses))| *uses == 1)
        .map(|(key, (face, _))| (key, face))
        .collect();
    grid.boundary_faces = boundary.len();
    let on_boundary: std::collections::HashSet<&Vec<u64>> = boundary.iter().map(|b| &b.0).collect();
    for polygon in &surface {
        let mut key = polygon.clone();
        key.sort_unstable();
        if !on_boundary.contains(&key) {
            push(&mut lists.polys, &mut lists.poly_offsets, polygon);
        }
    }
    let mut boundary: Vec<Vec<u64>> = boundary.into_iter().map(|b| b.1).collect();
    boundary.sort_unstable();
    for face in &boundary {
        push(&mut lists.polys, &mut lists.poly_offsets, face);
    }
    grid.cell_arrays_dropped = piece.data.cell.len();
    let poly = PolyDataPiece {
        points: piece.points,
        verts: numbers(lists.verts, lists.vert_offsets),
        lines: numbers(lists.lines, lists.line_offsets),
        polys: numbers(lists.polys, lists.poly_offsets),
        strips: numbers(lists.strips, lists.strip_offsets),
        data: Attributes {
            point: piece.data.point,
            cell: Vec::new(),
        },
    };
    Ok((poly, grid))
}

/// The faces of a volume cell of `kind` with `corners` corners; refuses another type or
/// count, naming the cell.
fn volume_faces(
    path: &Path,
    cell: usize,
    kind: CellType,
    corners: usize,
) -> Result<&'static [&'static [usize]], IoError> {
    let Some(faces) = faces_of(kind) else {
        let problem = format!(
            "cell {cell} is {}: only linear cells are read (vertices, lines, triangles, \
             strips, polygons, pixels, quads, tetrahedra, voxels, hexahedra, wedges, pyramids)",
            cell_name(kind)
        );
        return Err(IoError::unsupported(path, problem));
    };
    if corners != corners_of(kind) {
        let want = corners_of(kind);
        let problem = format!(
            "cell {cell} is {} of {corners} corners, not {want}",
            cell_name(kind)
        );
        return Err(IoError::malformed(path, problem));
    }
    Ok(faces)
}

/// A cell type in words, with VTK's number.
fn cell_name(kind: CellType) -> String {
    let name = match kind {
        CellType::Tetra => "a tetrahedron",
        CellType::Voxel => "a voxel",
        CellType::Hexahedron => "a hexahedron",
        CellType::Wedge => "a wedge",
        CellType::Pyramid => "a pyramid",
        CellType::Pixel => "a pixel",
        CellType::QuadraticEdge
        | CellType::QuadraticTriangle
        | CellType::QuadraticQuad
        | CellType::QuadraticTetra
        | CellType::QuadraticHexahedron
        | CellType::QuadraticWedge
        | CellType::QuadraticPyramid => "a quadratic cell",
        CellType::Polyhedron => "a polyhedron",
        _ => "a cell of a type not read",
    };
    format!("{name} (VTK cell type {})", kind as u8)
}

/// Counts the faces of one volume cell (`corners`, its faces `cell_faces` as positions in
/// it), each stored turned away from the cell's centroid, keyed by its sorted corners.
fn add_faces(
    faces: &mut HashMap<Vec<u64>, (Vec<u64>, usize)>,
    corners: &[u64],
    cell_faces: &[&[usize]],
    point: &dyn Fn(u64) -> Option<DVec3>,
) {
    let at = |v: u64| point(v).unwrap_or(DVec3::ZERO);
    let centroid = corners.iter().map(|&v| at(v)).sum::<DVec3>() / corners.len() as f64;
    for face in cell_faces {
        let mut face: Vec<u64> = face.iter().map(|&k| corners[k]).collect();
        let middle = face.iter().map(|&v| at(v)).sum::<DVec3>() / face.len() as f64;
        // Newell's normal of the face's loop.
        let mut normal = DVec3::ZERO;
        for (k, &v) in face.iter().enumerate() {
            let (a, b) = (at(v), at(face[(k + 1) % face.len()]));
            normal += DVec3::new(
                (a.y - b.y) * (a.z + b.z),
                (a.z - b.z) * (a.x + b.x),
                (a.x - b.x) * (a.y + b.y),
            );
        }
        if normal.dot(middle - centroid) < 0.0 {
            face.reverse();
        }
        let mut key = face.clone();
        key.sort_unstable();
        faces.entry(key).or_insert((face, 0)).1 += 1;
    }
}
