#!/usr/bin/env python3
"""Writes the VTK test files of crates/voxlod-io/tests/data/vtk with VTK's own writers.

Every file holds the same two data sets, so that the tests can check them against values
computed from first principles rather than against a second copy of the data:

- `cube-*.vtp` / `cube-*.vtk`: the unit cube [0,1]^3 as 8 points and 6 quads (outward), with
  point data `Normals` (3 components, the corner's position minus the centre, not unit) and
  `height` (= z); no verts, lines or strips, so VTK writes those sections empty. The legacy
  files `cube-legacy-*-int32.vtk` and `cube-legacy-*-idtype.vtk` hold the same cube from a
  cell array with 32-bit storage (`OFFSETS int`) and one built on `vtkIdTypeArray`s
  (`OFFSETS vtkIdType`, as `vtkAppendPolyData` makes them), both written as 32-bit integers.
- `cells-*.vtp`: 6 points on the x axis at x = 0..5 with one cell of every kind: a vertex {0},
  a poly-line {0,1,2}, a strip {1,2,3,4} (coordinates lifted to make it non-degenerate) and a
  triangle {3,4,5}; cell data `width` = 10 * (cell number).
- `grid-*.vtu` / `grid-*-legacy-ascii.vtk`: the unit cube as an unstructured grid, one
  hexahedron, five tetrahedra, or five tetrahedra with their 12 boundary triangles as cells too;
  point data `height` (= z), cell data `part`.
- `image-*.vti` / `image-*.vtk`: a 4x3x5 Int16 image with extent 2..5 x 0..2 x 1..5, spacing
  0.5 1 2, origin 1 2 3, and value(i, j, k) = i + 10 j + 100 k - 50 for extent indices i, j, k.

Run with a Python that has VTK 9 (pip install vtk):  python3 scripts/vtk-fixtures.py
"""
import os
import sys

import vtk

OUT = os.path.join(os.path.dirname(__file__), "..", "crates", "voxlod-io", "tests", "data", "vtk")


def cube(storage="default"):
    points = vtk.vtkPoints()
    points.SetDataTypeToFloat()
    for z in (0, 1):
        for y in (0, 1):
            for x in (0, 1):
                points.InsertNextPoint(x, y, z)
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    polys = vtk.vtkCellArray()
    if storage == "int32":
        polys.Use32BitStorage()
    for q in quads:
        polys.InsertNextCell(4, q)
    if storage == "idtype":
        offsets, connectivity = vtk.vtkIdTypeArray(), vtk.vtkIdTypeArray()
        offsets.InsertNextValue(0)
        for q in quads:
            for v in q:
                connectivity.InsertNextValue(v)
            offsets.InsertNextValue(connectivity.GetNumberOfTuples())
        polys.SetData(offsets, connectivity)
    mesh = vtk.vtkPolyData()
    mesh.SetPoints(points)
    mesh.SetPolys(polys)
    normals = vtk.vtkFloatArray()
    normals.SetName("Normals")
    normals.SetNumberOfComponents(3)
    height = vtk.vtkFloatArray()
    height.SetName("height")
    for i in range(8):
        p = points.GetPoint(i)
        normals.InsertNextTuple3(p[0] - 0.5, p[1] - 0.5, p[2] - 0.5)
        height.InsertNextValue(p[2])
    mesh.GetPointData().SetNormals(normals)
    mesh.GetPointData().AddArray(height)
    return mesh


def cells():
    points = vtk.vtkPoints()
    for x in range(6):
        points.InsertNextPoint(x, 0.0, float(x % 2))
    mesh = vtk.vtkPolyData()
    mesh.SetPoints(points)
    verts, lines, strips, polys = (vtk.vtkCellArray() for _ in range(4))
    verts.InsertNextCell(1, (0,))
    lines.InsertNextCell(3, (0, 1, 2))
    strips.InsertNextCell(4, (1, 2, 3, 4))
    polys.InsertNextCell(3, (3, 4, 5))
    mesh.SetVerts(verts)
    mesh.SetLines(lines)
    mesh.SetStrips(strips)
    mesh.SetPolys(polys)
    width = vtk.vtkFloatArray()
    width.SetName("width")
    # VTK orders cell data as verts, lines, polys, strips.
    for c in range(4):
        width.InsertNextValue(10.0 * c)
    mesh.GetCellData().AddArray(width)
    return mesh


def image():
    img = vtk.vtkImageData()
    img.SetExtent(2, 5, 0, 2, 1, 5)
    img.SetSpacing(0.5, 1, 2)
    img.SetOrigin(1, 2, 3)
    img.AllocateScalars(vtk.VTK_SHORT, 1)
    for k in range(1, 6):
        for j in range(0, 3):
            for i in range(2, 6):
                img.SetScalarComponentFromFloat(i, j, k, 0, i + 10 * j + 100 * k - 50)
    return img


# name suffix -> writer settings: (data mode, encode appended, compressor, header type, block size, byte order)
MODES = {
    "default": None,  # VTK's defaults: appended, base64-encoded, zlib, UInt32 headers
    "raw-zlib": ("appended", False, "zlib", 32, None, "little"),
    "raw-plain": ("appended", False, None, 32, None, "little"),
    "raw-zlib-u64": ("appended", False, "zlib", 64, None, "little"),
    "raw-plain-u64": ("appended", False, None, 64, None, "little"),
    "raw-zlib-blocks": ("appended", False, "zlib", 64, 40, "little"),
    "raw-lz4": ("appended", False, "lz4", 64, None, "little"),
    "raw-lzma": ("appended", False, "lzma", 32, None, "little"),
    "raw-zlib-big": ("appended", False, "zlib", 64, None, "big"),
    "base64-plain-u64": ("appended", True, None, 64, None, "little"),
    "inline-zlib": ("binary", None, "zlib", 64, None, "little"),
    "inline-plain": ("binary", None, None, 32, None, "little"),
    "ascii": ("ascii", None, None, 32, None, "little"),
}


def configure(writer, mode):
    if mode is None:
        return
    data_mode, encode, compressor, header, block, order = mode
    {"appended": writer.SetDataModeToAppended, "binary": writer.SetDataModeToBinary,
     "ascii": writer.SetDataModeToAscii}[data_mode]()
    if encode is not None:
        writer.SetEncodeAppendedData(encode)
    if compressor is None:
        writer.SetCompressorTypeToNone()
    else:
        {"zlib": writer.SetCompressorTypeToZLib, "lz4": writer.SetCompressorTypeToLZ4,
         "lzma": writer.SetCompressorTypeToLZMA}[compressor]()
    {32: writer.SetHeaderTypeToUInt32, 64: writer.SetHeaderTypeToUInt64}[header]()
    if block is not None:
        writer.SetBlockSize(block)
    {"little": writer.SetByteOrderToLittleEndian, "big": writer.SetByteOrderToBigEndian}[order]()


def write(writer, data, name):
    writer.SetFileName(os.path.join(OUT, name))
    writer.SetInputData(data)
    if not writer.Write():
        sys.exit(f"VTK could not write {name}")


def cube_grid(kind):
    """The unit cube as an unstructured grid: one hexahedron ("hexa"), five tetrahedra
    ("tets"), or the five tetrahedra with the 12 triangles of their boundary as surface cells
    too ("tets-and-faces", as finite element models carry boundary elements); point data
    `height` (= z) and cell data `part` (= cell number)."""
    points = vtk.vtkPoints()
    for z in (0, 1):
        for y in (0, 1):
            for x in (0, 1):
                points.InsertNextPoint(x, y, z)
    grid = vtk.vtkUnstructuredGrid()
    grid.SetPoints(points)
    tets = [(0, 1, 3, 5), (0, 3, 2, 6), (0, 5, 4, 6), (3, 5, 6, 7), (0, 3, 5, 6)]
    if kind == "hexa":
        grid.InsertNextCell(vtk.VTK_HEXAHEDRON, 8, (0, 1, 3, 2, 4, 5, 7, 6))
    else:
        for t in tets:
            grid.InsertNextCell(vtk.VTK_TETRA, 4, t)
    if kind == "tets-and-faces":
        # The tetrahedra's own boundary: each face split along the tetrahedra's diagonal.
        faces = [(0, 2, 3), (0, 3, 1), (4, 5, 6), (5, 7, 6), (0, 1, 5), (0, 5, 4),
                 (2, 6, 3), (3, 6, 7), (0, 4, 6), (0, 6, 2), (1, 3, 5), (3, 7, 5)]
        for f in faces:
            grid.InsertNextCell(vtk.VTK_TRIANGLE, 3, f)
    height = vtk.vtkFloatArray()
    height.SetName("height")
    for i in range(8):
        height.InsertNextValue(points.GetPoint(i)[2])
    grid.GetPointData().AddArray(height)
    part = vtk.vtkIntArray()
    part.SetName("part")
    for c in range(grid.GetNumberOfCells()):
        part.InsertNextValue(c)
    grid.GetCellData().AddArray(part)
    return grid


def main():
    os.makedirs(OUT, exist_ok=True)
    for kind in ("hexa", "tets", "tets-and-faces"):
        # The tetrahedra in every encoding, the others in VTK's default one.
        for suffix, mode in MODES.items() if kind == "tets" else [("default", None)]:
            w = vtk.vtkXMLUnstructuredGridWriter()
            configure(w, mode)
            write(w, cube_grid(kind), f"grid-{kind}-{suffix}.vtu")
        w = vtk.vtkUnstructuredGridWriter()
        w.SetFileTypeToASCII()
        write(w, cube_grid(kind), f"grid-{kind}-legacy-ascii.vtk")
    for suffix, mode in MODES.items():
        for data, stem in ((cube(), "cube"), (cells(), "cells")):
            w = vtk.vtkXMLPolyDataWriter()
            configure(w, mode)
            write(w, data, f"{stem}-{suffix}.vtp")
        w = vtk.vtkXMLImageDataWriter()
        configure(w, mode)
        write(w, image(), f"image-{suffix}.vti")
    for binary in (False, True):
        kind = "binary" if binary else "ascii"
        w = vtk.vtkPolyDataWriter()
        w.SetFileTypeToBinary() if binary else w.SetFileTypeToASCII()
        write(w, cube(), f"cube-legacy-{kind}.vtk")
        for storage in ("int32", "idtype"):
            w = vtk.vtkPolyDataWriter()
            w.SetFileTypeToBinary() if binary else w.SetFileTypeToASCII()
            write(w, cube(storage), f"cube-legacy-{kind}-{storage}.vtk")
        w = vtk.vtkStructuredPointsWriter()
        w.SetFileTypeToBinary() if binary else w.SetFileTypeToASCII()
        write(w, image(), f"image-legacy-{kind}.vtk")
    print(f"VTK {vtk.vtkVersion.GetVTKVersion()} wrote {len(os.listdir(OUT))} files to {OUT}")


if __name__ == "__main__":
    main()
