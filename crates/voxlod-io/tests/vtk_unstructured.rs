//! Unstructured grids written by VTK 9.7 itself (`scripts/vtk-fixtures.py`, committed under
//! `tests/data/vtk`): the unit cube as five tetrahedra (in every mode of
//! `vtkXMLUnstructuredGridWriter`), as one hexahedron, and as the tetrahedra with their 12
//! boundary triangles as cells too, in `.vtu` and legacy `.vtk`. Each reads as the cube's
//! closed, outward surface of 12 triangles and volume 1, its `height` point data kept, with
//! notes saying that the volume cells were read as their boundary and the cell data left out.
//! Cells the reader does not take are refused naming the cell.

mod common;

use std::path::Path;

use common::{vtk_data, VTK_MODES};

use voxlod_core::mesh_topology;
use voxlod_io::{read_mesh, read_poly_mesh, IoErrorKind, MeshFormat};

/// The cube's surface: 12 triangles, closed, outward, volume 1, `height` = z; `volume_cells`
/// named in the notes, and the cell data left out.
fn check_cube(path: &Path, volume_cells: usize) {
    let name = path.file_name().unwrap().to_string_lossy().into_owned();
    let loaded = read_mesh(path).unwrap_or_else(|e| panic!("{e}"));
    let mesh = &loaded.mesh;
    assert_eq!(mesh.triangles.len(), 12, "{name}");
    let t = mesh_topology(mesh);
    assert!(
        t.is_closed_manifold() && t.is_consistently_oriented(),
        "{name}: {t:?}"
    );
    assert!(
        (mesh.signed_volume() - 1.0).abs() < 1e-6,
        "{name}: {}",
        mesh.signed_volume()
    );
    let notes = loaded.notes.join("; ");
    let faces = if volume_cells == 1 { 6 } else { 12 };
    let said = format!("{volume_cells} volume cells read as the {faces} faces");
    assert!(notes.contains(&said), "{name}: {notes}");
    assert!(notes.contains("1 cell data arrays"), "{name}: {notes}");
    let poly = read_poly_mesh(path).unwrap();
    let height = (poly.vertex_attributes.iter())
        .find(|a| a.name == "height")
        .unwrap_or_else(|| panic!("{name}: no height attribute"));
    let z: Vec<f32> = poly.mesh.positions.iter().map(|p| p.z).collect();
    assert_eq!(height.values, z, "{name}");
}

#[test]
fn tetrahedra_of_every_writer_mode_read_as_the_cube_s_surface() {
    for mode in VTK_MODES {
        check_cube(&vtk_data(&format!("grid-tets-{mode}.vtu")), 5);
    }
    assert_eq!(
        read_mesh(&vtk_data("grid-tets-default.vtu"))
            .unwrap()
            .format,
        MeshFormat::Vtu
    );
}

#[test]
fn a_hexahedron_and_legacy_grids_read_as_the_cube_s_surface() {
    check_cube(&vtk_data("grid-hexa-default.vtu"), 1);
    check_cube(&vtk_data("grid-hexa-legacy-ascii.vtk"), 1);
    check_cube(&vtk_data("grid-tets-legacy-ascii.vtk"), 5);
}

#[test]
fn boundary_triangles_given_as_cells_too_are_read_once() {
    check_cube(&vtk_data("grid-tets-and-faces-default.vtu"), 5);
    check_cube(&vtk_data("grid-tets-and-faces-legacy-ascii.vtk"), 5);
}

#[test]
fn a_higher_order_cell_is_refused_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("quadratic.vtk");
    let file = "# vtk DataFile Version 3.0\nq\nASCII\nDATASET UNSTRUCTURED_GRID\n\
                POINTS 6 float\n0 0 0 1 0 0 0 1 0 0.5 0 0 0.5 0.5 0 0 0.5 0\n\
                CELLS 1 7\n6 0 1 2 3 4 5\nCELL_TYPES 1\n22\n";
    std::fs::write(&path, file).unwrap();
    let e = read_mesh(&path).unwrap_err();
    assert_eq!(e.kind, IoErrorKind::Unsupported, "{e}");
    let said = e.to_string();
    assert!(
        said.contains("cell 0 is a quadratic cell (VTK cell type 22)"),
        "{said}"
    );
    // A tetrahedron naming a point beyond the points is malformed, naming the cell.
    let path = dir.path().join("beyond.vtk");
    let file = "# vtk DataFile Version 3.0\nq\nASCII\nDATASET UNSTRUCTURED_GRID\n\
                POINTS 4 float\n0 0 0 1 0 0 0 1 0 0 0 1\n\
                CELLS 1 5\n4 0 1 2 9\nCELL_TYPES 1\n10\n";
    std::fs::write(&path, file).unwrap();
    let e = read_mesh(&path).unwrap_err();
    assert_eq!(e.kind, IoErrorKind::Malformed, "{e}");
    assert!(e.to_string().contains("cell 0 names point 9"), "{e}");
}
