#!/usr/bin/env python3
"""`voxlod labels` beside zmesh and VTK 9.7 (vtkSurfaceNets3D, vtkDiscreteFlyingEdges3D) on the
same label maps, in one run: wall time, peak memory, triangles, and each label's mesh volume
against its voxel volume.

Run with the peers' Python (numpy, scipy, zmesh, vtk):

    ~/.cache/voxlod-peers/bin/python scripts/labels-bench.py [VOXLOD_BINARY] [--map ellipsoids|voronoi] [--size N] [--labels L] [--no-flying-edges]

Maps are made here and written as uint32 NRRD (raw): `ellipsoids` (default 256^3, 50 random
ellipsoids, spacing 1 x 1 x 1.5, later ones drawn over earlier ones) and `voronoi` (default
512^3, 1000 random sites, every voxel labelled by its nearest site, spacing 1). voxlod runs the
whole command (read, find, mesh, write every label's PLY plus labels.glb and report.json):
`labels SEG -o DIR --no-clean` (marching cubes per label) and `labels SEG -o DIR --shared`
(surface nets, smoothed). zmesh meshes and extracts every label in memory (`close=True`); VTK
runs its filters in memory on the same array (default threads). Peak memory is each process's
maximum resident set (voxlod's from /usr/bin/time; the Python peers' from the interpreter's own
maximum, which includes the map).
"""

import json
import os
import resource
import subprocess
import sys
import tempfile
import time

import numpy as np


def ellipsoids(n, count, seed=1):
    rng = np.random.default_rng(seed)
    z, y, x = np.mgrid[0:n, 0:n, 0:n].astype(np.float32) / n
    labels = np.zeros((n, n, n), dtype=np.uint32)
    for value in range(1, count + 1):
        c = rng.uniform(0.15, 0.85, 3)
        r = rng.uniform(0.03, 0.12, 3)
        inside = ((x - c[0]) / r[0]) ** 2 + ((y - c[1]) / r[1]) ** 2 + ((z - c[2]) / r[2]) ** 2 <= 1
        labels[inside] = value
    return labels, (1.0, 1.0, 1.5)


def voronoi(n, count, seed=2):
    from scipy.spatial import cKDTree
    rng = np.random.default_rng(seed)
    tree = cKDTree(rng.uniform(0, n, (count, 3)))
    labels = np.empty((n, n, n), dtype=np.uint32)
    y, x = np.mgrid[0:n, 0:n].astype(np.float32) + 0.5
    for k in range(n):
        points = np.stack([x.ravel(), y.ravel(), np.full(n * n, k + 0.5, np.float32)], axis=1)
        labels[k] = (tree.query(points, workers=-1)[1] + 1).reshape(n, n)
    return labels, (1.0, 1.0, 1.0)


def write_nrrd(path, labels, spacing):
    nz, ny, nx = labels.shape
    header = (
        "NRRD0004\ntype: uint32\ndimension: 3\n"
        f"sizes: {nx} {ny} {nz}\nspace: left-posterior-superior\n"
        f"space directions: ({spacing[0]},0,0) (0,{spacing[1]},0) (0,0,{spacing[2]})\n"
        "space origin: (0,0,0)\nendian: little\nencoding: raw\n\n"
    )
    with open(path, "wb") as f:
        f.write(header.encode())
        f.write(labels.astype("<u4").tobytes())


def run_voxlod(binary, seg, out, flags):
    """The whole command: wall seconds, peak KiB, per label (triangles, volume)."""
    rss = out + ".rss"
    start = time.perf_counter()
    done = subprocess.run(["/usr/bin/time", "-f", "%M", "-o", rss, binary, "labels", seg,
                           "-o", out, "--json", *flags], capture_output=True, text=True)
    seconds = time.perf_counter() - start
    if done.returncode != 0:
        sys.exit(f"voxlod {' '.join(flags)} failed: {done.stderr.strip()}")
    with open(rss) as f:
        peak = int(f.read().split()[-1])
    report = json.loads(done.stdout)
    return seconds, peak, {l["label"]: (l["levels"][0]["triangles"], l["levels"][0]["volume"])
                           for l in report["labels"]}


def volume_of(v, f):
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)


def run_zmesh(labels, spacing):
    import zmesh
    start = time.perf_counter()
    mesher = zmesh.Mesher(spacing)
    mesher.mesh(np.asfortranarray(labels.transpose(2, 1, 0)), close=True)
    out = {}
    for label in mesher.ids():
        mesh = mesher.get(label, normals=False, reduction_factor=0)
        out[int(label)] = (len(mesh.faces), volume_of(mesh.vertices, mesh.faces))
    return time.perf_counter() - start, out


def vtk_image(labels, spacing):
    import vtk
    from vtk.util import numpy_support
    nz, ny, nx = labels.shape
    image = vtk.vtkImageData()
    image.SetDimensions(nx, ny, nz)
    image.SetSpacing(*spacing)
    scalars = numpy_support.numpy_to_vtk(labels.ravel(), deep=False,
                                         array_type=vtk.VTK_UNSIGNED_INT)
    image.GetPointData().SetScalars(scalars)
    return image, scalars


def run_vtk_nets(labels, spacing, smoothing):
    """vtkSurfaceNets3D over every label: seconds, triangles of the shared mesh (quads
    triangulated: VTK writes quads, two triangles each)."""
    import vtk
    image, keep = vtk_image(labels, spacing)
    start = time.perf_counter()
    nets = vtk.vtkSurfaceNets3D()
    nets.SetInputData(image)
    nets.SetOutputMeshTypeToTriangles()
    values = np.unique(labels)
    nets.SetNumberOfLabels(int((values != 0).sum()))
    for n, v in enumerate(values[values != 0]):
        nets.SetLabel(n, float(v))
    nets.SetSmoothing(smoothing)
    nets.Update()
    seconds = time.perf_counter() - start
    return seconds, nets.GetOutput().GetNumberOfCells()


def run_vtk_flying_edges(labels, spacing):
    import vtk
    image, keep = vtk_image(labels, spacing)
    start = time.perf_counter()
    fe = vtk.vtkDiscreteFlyingEdges3D()
    fe.SetInputData(image)
    values = np.unique(labels)
    values = values[values != 0]
    fe.SetNumberOfContours(len(values))
    for n, v in enumerate(values):
        fe.SetValue(n, float(v))
    fe.ComputeNormalsOff()
    fe.ComputeGradientsOff()
    fe.Update()
    return time.perf_counter() - start, fe.GetOutput().GetNumberOfCells()


def main():
    args = sys.argv[1:]
    binary, kind, n, count, flying_edges = "target/release/voxlod", "ellipsoids", None, None, True
    while args:
        a = args.pop(0)
        if a == "--map":
            kind = args.pop(0)
        elif a == "--size":
            n = int(args.pop(0))
        elif a == "--labels":
            count = int(args.pop(0))
        elif a == "--no-flying-edges":
            flying_edges = False
        else:
            binary = a
    load = os.getloadavg()[0]
    start = time.perf_counter()
    if kind == "voronoi":
        labels, spacing = voronoi(n or 512, count or 1000)
    else:
        labels, spacing = ellipsoids(n or 256, count or 50)
    made = time.perf_counter() - start
    voxel = spacing[0] * spacing[1] * spacing[2]
    values, sizes = np.unique(labels, return_counts=True)
    counts = {int(v): int(c) for v, c in zip(values, sizes) if v != 0}
    print(f"{kind} map {'x'.join(map(str, labels.shape[::-1]))} uint32 ({labels.nbytes >> 20} MiB), "
          f"spacing {spacing}, {len(counts)} labels, made in {made:.1f} s; load average "
          f"{load:.1f} on {os.cpu_count()} cores before the runs")
    with tempfile.TemporaryDirectory() as tmp:
        seg = os.path.join(tmp, "seg.nrrd")
        write_nrrd(seg, labels, spacing)
        results = {}
        for name, flags in (("voxlod --no-clean", ["--no-clean"]), ("voxlod --shared", ["--shared"])):
            seconds, peak, meshes = run_voxlod(binary, seg, os.path.join(tmp, name[-5:]), flags)
            results[name] = meshes
            tris = sum(t for t, _ in meshes.values())
            print(f"{name:22s} {seconds:6.2f} s  peak {peak / 1024:7.0f} MiB  {tris:10d} triangles "
                  "(whole command)")
    seconds, z = run_zmesh(labels, spacing)
    results["zmesh"] = z
    print(f"{'zmesh':22s} {seconds:6.2f} s  {sum(t for t, _ in z.values()):29d} triangles "
          "(mesh + get every label)")
    for smoothing in (False, True):
        seconds, tris = run_vtk_nets(labels, spacing, smoothing)
        print(f"{'vtkSurfaceNets3D' + (' smoothed' if smoothing else ''):22s} {seconds:6.2f} s "
              f"{tris:29d} triangles (shared)")
    if flying_edges:
        seconds, tris = run_vtk_flying_edges(labels, spacing)
        print(f"{'vtkDiscreteFlyingEdges3D':22s} {seconds:6.2f} s {tris:29d} triangles")
    print(f"peak memory of this Python (map, zmesh, VTK): "
          f"{resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MiB")
    for name, meshes in results.items():
        errors = [abs(meshes.get(l, (0, 0.0))[1] / (c * voxel) - 1) for l, c in counts.items()]
        big = [e for (l, c), e in zip(counts.items(), errors) if c >= 1000]
        print(f"{name:22s} volume vs voxels: median |error| {100 * np.median(errors):.2f} %, "
              f"worst {100 * max(errors):.2f} %, worst of labels >= 1000 voxels "
              f"{100 * max(big, default=0):.2f} %")


if __name__ == "__main__":
    main()
