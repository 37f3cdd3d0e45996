#!/usr/bin/env python3
"""`voxlod labels` beside zmesh (PyPI) on the same label volume: wall time, triangles and the
volume of each label's mesh against its voxel count.

Run with the peers' Python, which has numpy and zmesh:

    ~/.cache/voxlod-peers/bin/python scripts/labels-vs-zmesh.py [VOXLOD_BINARY] [--size N]

The label map is made here: N^3 voxels (default 192) of spacing 1 x 1 x 1.5 mm holding eight
ellipsoids, labels 1..8, two pairs touching, written as a NRRD (uint16). zmesh meshes every label
at once (its `close=True` so meshes at the border are closed, no simplification, then again with
`reduction_factor=10`); voxlod makes one level per label at the map's resolution (one filtered
marching-cubes surface each, `--levels 1`). Both run on all cores the machine gives them.
"""

import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np
import zmesh


def label_map(n):
    z, y, x = np.mgrid[0:n, 0:n, 0:n].astype(np.float32) / n
    labels = np.zeros((n, n, n), dtype=np.uint16)
    blobs = [
        ((0.30, 0.30, 0.30), (0.12, 0.10, 0.08)),
        ((0.30, 0.30, 0.46), (0.12, 0.10, 0.08)),  # touches label 1
        ((0.70, 0.30, 0.30), (0.08, 0.15, 0.10)),
        ((0.30, 0.70, 0.30), (0.15, 0.08, 0.10)),
        ((0.70, 0.70, 0.70), (0.10, 0.10, 0.10)),
        ((0.70, 0.70, 0.50), (0.10, 0.10, 0.10)),  # touches label 5
        ((0.50, 0.50, 0.50), (0.05, 0.05, 0.05)),
        ((0.20, 0.80, 0.80), (0.06, 0.12, 0.06)),
    ]
    for value, (c, r) in enumerate(blobs, start=1):
        inside = ((x - c[0]) / r[0]) ** 2 + ((y - c[1]) / r[1]) ** 2 + ((z - c[2]) / r[2]) ** 2 <= 1
        labels[inside & (labels == 0)] = value
    return labels


def write_nrrd(path, labels, spacing):
    nz, ny, nx = labels.shape
    header = (
        "NRRD0004\ntype: uint16\ndimension: 3\n"
        f"sizes: {nx} {ny} {nz}\nspace: left-posterior-superior\n"
        f"space directions: ({spacing[0]},0,0) (0,{spacing[1]},0) (0,0,{spacing[2]})\n"
        "space origin: (0,0,0)\nendian: little\nencoding: raw\n\n"
    )
    with open(path, "wb") as f:
        f.write(header.encode())
        f.write(labels.astype("<u2").tobytes())


def run_zmesh(labels, spacing, reduction):
    start = time.perf_counter()
    mesher = zmesh.Mesher(spacing)
    # zmesh takes x-fastest Fortran order as (x, y, z)
    mesher.mesh(np.asfortranarray(labels.transpose(2, 1, 0)), close=True)
    out = {}
    for label in mesher.ids():
        mesh = mesher.get(label, normals=False, reduction_factor=reduction)
        v, f = mesh.vertices, mesh.faces
        a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
        volume = float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)
        out[int(label)] = (len(f), volume)
    return time.perf_counter() - start, out


def main():
    args = sys.argv[1:]
    binary = "target/release/voxlod"
    n = 192
    while args:
        a = args.pop(0)
        if a == "--size":
            n = int(args.pop(0))
        else:
            binary = a
    spacing = (1.0, 1.0, 1.5)
    labels = label_map(n)
    voxel = spacing[0] * spacing[1] * spacing[2]
    counts = {int(v): int((labels == v).sum()) for v in np.unique(labels) if v != 0}
    with tempfile.TemporaryDirectory() as tmp:
        seg = os.path.join(tmp, "seg.nrrd")
        write_nrrd(seg, labels, spacing)
        start = time.perf_counter()
        done = subprocess.run(
            [binary, "labels", seg, "-o", os.path.join(tmp, "out"), "--json"],
            capture_output=True, text=True,
        )
        ours_seconds = time.perf_counter() - start
        if done.returncode != 0:
            sys.exit(f"voxlod failed: {done.stderr.strip()}")
        ours = {l["label"]: (l["levels"][0]["triangles"], l["levels"][0]["volume"])
                for l in json.loads(done.stdout)["labels"]}
    z_seconds, z = run_zmesh(labels, spacing, 0)
    zr_seconds, zr = run_zmesh(labels, spacing, 10)
    print(f"label map {n}^3, spacing {spacing}, {len(counts)} labels")
    print(f"voxlod labels: {ours_seconds:.2f} s (whole command: read, filter, contour, write)")
    print(f"zmesh:         {z_seconds:.2f} s (mesh + get, no simplification); "
          f"{zr_seconds:.2f} s with reduction_factor=10")
    print("label  voxels*dV   voxlod tris  vol err   zmesh tris  vol err   zmesh/10 tris  vol err")
    for label, count in counts.items():
        exact = count * voxel
        row = [f"{label:5d}", f"{exact:10.0f}"]
        for result in (ours, z, zr):
            tris, vol = result.get(label, (0, 0.0))
            row += [f"{tris:12d}", f"{100 * (vol / exact - 1):+7.2f}%"]
        print("  ".join(row))


if __name__ == "__main__":
    main()
