#!/usr/bin/env python3
"""VTK 9.7's vtkSurfaceNets3D on a raw label map written by voxlod-labels' `shared_nets`
example, timed as the shared route is timed there: every label, default smoothing
(vtkConstrainedSmoothingFilter, 16 iterations, relaxation 0.5, automatic constraints), default
threads (the STDThread backend; `--sequential` for the wheel's default). Prints seconds, triangles and each label's volume (from the BoundaryLabels cell data)
against its voxel volume.

    cargo run --release -p voxlod-labels --example shared_nets -- voronoi 512 1000 /tmp/v.u32
    ~/.cache/voxlod-peers/bin/python scripts/shared-nets-vtk.py /tmp/v.u32 512,512,512 1,1,1 [--no-smoothing] [--sequential]
"""

import resource
import sys
import time

import numpy as np


def main():
    path, dims, spacing = sys.argv[1], sys.argv[2], sys.argv[3]
    smoothing = "--no-smoothing" not in sys.argv
    nx, ny, nz = (int(v) for v in dims.split(","))
    spacing = tuple(float(v) for v in spacing.split(","))
    labels = np.fromfile(path, dtype="<u4").reshape(nz, ny, nx)
    import vtk
    from vtk.util import numpy_support
    # The wheel defaults to the sequential backend; its threaded one is STDThread.
    vtk.vtkSMPTools.SetBackend("Sequential" if "--sequential" in sys.argv else "STDThread")
    image = vtk.vtkImageData()
    image.SetDimensions(nx, ny, nz)
    image.SetSpacing(*spacing)
    scalars = numpy_support.numpy_to_vtk(labels.ravel(), deep=False,
                                         array_type=vtk.VTK_UNSIGNED_INT)
    image.GetPointData().SetScalars(scalars)
    values, counts = np.unique(labels, return_counts=True)
    keep = values != 0
    values, counts = values[keep], counts[keep]
    print(f"map {nx}x{ny}x{nz}, spacing {spacing}, {len(values)} labels; SMP backend "
          f"{vtk.vtkSMPTools.GetBackend()}, {vtk.vtkSMPTools.GetEstimatedNumberOfThreads()} threads")
    start = time.perf_counter()
    cpu = time.process_time()
    nets = vtk.vtkSurfaceNets3D()
    nets.SetInputData(image)
    nets.SetNumberOfLabels(len(values))
    for n, v in enumerate(values):
        nets.SetLabel(n, float(v))
    nets.SetSmoothing(smoothing)
    nets.Update()
    seconds = time.perf_counter() - start
    cpu = time.process_time() - cpu
    out = nets.GetOutput()
    points = numpy_support.vtk_to_numpy(out.GetPoints().GetData()).astype(np.float64)
    polys = numpy_support.vtk_to_numpy(out.GetPolys().GetConnectivityArray())
    offsets = numpy_support.vtk_to_numpy(out.GetPolys().GetOffsetsArray())
    sides = numpy_support.vtk_to_numpy(out.GetCellData().GetArray("BoundaryLabels"))
    sizes = np.diff(offsets)
    print(f"vtkSurfaceNets3D{' smoothed' if smoothing else ''}: {seconds:.3f} s (CPU time {cpu:.2f} s), "
          f"{out.GetNumberOfPoints()} points, {out.GetNumberOfCells()} cells "
          f"(sizes {sorted(set(sizes.tolist()))}); peak memory of this Python "
          f"{resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MiB")
    # Triangles (quads split on their first corner) for the volumes.
    tris = []
    tri_sides = []
    for size in sorted(set(sizes.tolist())):
        cells = np.nonzero(sizes == size)[0]
        corners = polys[offsets[cells][:, None] + np.arange(size)]
        for k in range(1, size - 1):
            tris.append(corners[:, [0, k, k + 1]])
            tri_sides.append(sides[cells])
    tris, tri_sides = np.concatenate(tris), np.concatenate(tri_sides)
    a, b, c = points[tris[:, 0]], points[tris[:, 1]], points[tris[:, 2]]
    signed = np.einsum("ij,ij->i", a, np.cross(b, c)) / 6.0
    slot = {int(v): n for n, v in enumerate(values)}
    volume = np.zeros(len(values))
    for column, sign in ((0, 1.0), (1, -1.0)):
        idx = np.array([slot.get(int(l), -1) for l in tri_sides[:, column]])
        ok = idx >= 0
        np.add.at(volume, idx[ok], sign * signed[ok])
    voxel = spacing[0] * spacing[1] * spacing[2]
    error = np.abs(volume / (counts * voxel) - 1)
    big = error[counts >= 1000]
    print(f"{len(tris)} triangles; volume vs voxels: median |error| {100 * np.median(error):.3f} %, "
          f"worst {100 * error.max():.3f} %, worst of labels >= 1000 voxels "
          f"{100 * (big.max() if len(big) else 0):.3f} %")


if __name__ == "__main__":
    main()
