#!/usr/bin/env python3
"""`voxlod labels` beside zmesh (PyPI) on the same label volume: wall time, triangles and the
volume of each label's mesh against its voxel count.

Run with the peers' Python, which has numpy and zmesh:

    ~/.cache/voxlod-peers/bin/python scripts/labels-vs-zmesh.py [VOXLOD_BINARY] [--size N]

The label map is made here: N^3 voxels (default 256) of spacing 1 x 1 x 1.5 mm holding L
ellipsoids (default 50, `--labels L`), random but fixed by a seed, later ones drawn over earlier
ones where they overlap, so many touch; written as a NRRD (uint16). `--map FILE.nrrd` runs on an
existing uint8/uint16 label map instead (raw or gzip NRRD with axis-aligned `space directions`).
zmesh meshes every label at once (`close=True` so meshes at the border are closed, no
simplification, then again with `reduction_factor=10`); voxlod makes one level per label at the
map's resolution (one filtered marching-cubes surface each, `--levels 1`, cleaned of slivers by
default, then again plain with `--no-clean`) and writes it, plus labels.vtp, labels.glb and
report.json. voxlod runs on all cores (rayon, labels in parallel); zmesh on one. The load
average before the runs is printed, and voxlod's CPU time (all threads) beside its wall time:
on a shared machine the wall times are only indicative.
"""

import json
import os
import resource
import subprocess
import sys
import tempfile
import time

import numpy as np
import zmesh


def label_map(n, count, seed=1):
    rng = np.random.default_rng(seed)
    z, y, x = np.mgrid[0:n, 0:n, 0:n].astype(np.float32) / n
    labels = np.zeros((n, n, n), dtype=np.uint16)
    for value in range(1, count + 1):
        c = rng.uniform(0.15, 0.85, 3)
        r = rng.uniform(0.03, 0.12, 3)
        inside = ((x - c[0]) / r[0]) ** 2 + ((y - c[1]) / r[1]) ** 2 + ((z - c[2]) / r[2]) ** 2 <= 1
        labels[inside] = value
    return labels


def read_nrrd(path):
    """A uint8/uint16 NRRD label map (raw or gzip) with axis-aligned space directions."""
    import gzip
    import re
    with open(path, "rb") as f:
        data = f.read()
    head, _, body = data.partition(b"\n\n")
    fields = dict(l.split(": ", 1) for l in head.decode().splitlines()[1:] if ": " in l)
    sizes = [int(v) for v in fields["sizes"].split()]
    dtype = {"uint8": "u1", "unsigned char": "u1", "uint16": "<u2", "unsigned short": "<u2"}[fields["type"]]
    if fields.get("encoding") in ("gzip", "gz"):
        body = gzip.decompress(body)
    vectors = re.findall(r"\(([^)]*)\)", fields["space directions"])
    spacing = tuple(float(np.linalg.norm([float(c) for c in v.split(",")])) for v in vectors)
    labels = np.frombuffer(body[: np.prod(sizes) * np.dtype(dtype).itemsize], dtype=dtype)
    return labels.reshape(sizes[::-1]).astype(np.uint16), spacing


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


def run_voxlod(binary, seg, out, flags):
    """`voxlod labels` on `seg`: wall time, CPU time (user + system, all threads) and per label
    (triangles, volume) of level 0."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    done = subprocess.run([binary, "labels", seg, "-o", out, "--json", *flags],
                          capture_output=True, text=True)
    seconds = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode != 0:
        sys.exit(f"voxlod failed: {done.stderr.strip()}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return (seconds, cpu), {l["label"]: (l["levels"][0]["triangles"], l["levels"][0]["volume"])
                     for l in json.loads(done.stdout)["labels"]}


def run_zmesh(labels, spacing, reduction):
    """zmesh on `labels`: wall time (one thread, so also its CPU time) and per label (triangles,
    volume)."""
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
    n, count, given = 256, 50, None
    while args:
        a = args.pop(0)
        if a == "--size":
            n = int(args.pop(0))
        elif a == "--labels":
            count = int(args.pop(0))
        elif a == "--map":
            given = args.pop(0)
        else:
            binary = a
    if given:
        labels, spacing = read_nrrd(given)
    else:
        spacing = (1.0, 1.0, 1.5)
        labels = label_map(n, count)
    voxel = spacing[0] * spacing[1] * spacing[2]
    values, sizes = np.unique(labels, return_counts=True)
    counts = {int(v): int(c) for v, c in zip(values, sizes) if v != 0}
    load = os.getloadavg()[0]
    with tempfile.TemporaryDirectory() as tmp:
        seg = given or os.path.join(tmp, "seg.nrrd")
        if not given:
            write_nrrd(seg, labels, spacing)
        ours_seconds, ours = run_voxlod(binary, seg, os.path.join(tmp, "out"), [])
        plain_seconds, plain = run_voxlod(binary, seg, os.path.join(tmp, "plain"), ["--no-clean"])
    z_seconds, z = run_zmesh(labels, spacing, 0)
    zr_seconds, zr = run_zmesh(labels, spacing, 10)
    shape = "x".join(str(s) for s in labels.shape[::-1])
    print(f"label map {given or 'generated'} {shape}, spacing {spacing}, {len(counts)} labels; "
          f"load average {load:.1f} on {os.cpu_count()} cores before the runs")
    print(f"voxlod labels: {ours_seconds[0]:.2f} s wall, {ours_seconds[1]:.2f} s CPU (whole "
          f"command: read, filter, contour, clean, write); {plain_seconds[0]:.2f} s wall, "
          f"{plain_seconds[1]:.2f} s CPU with --no-clean (plain marching cubes)")
    print(f"zmesh:         {z_seconds:.2f} s (mesh + get, no simplification); "
          f"{zr_seconds:.2f} s with reduction_factor=10")
    print("label  voxels*dV   voxlod tris  vol err   no-clean tris  vol err   zmesh tris  vol err"
          "   zmesh/10 tris  vol err")
    totals = [0, 0, 0, 0]
    errors = [[], [], [], []]
    for label, count in counts.items():
        exact = count * voxel
        row = [f"{label:5d}", f"{exact:10.0f}"]
        for i, result in enumerate((ours, plain, z, zr)):
            tris, vol = result.get(label, (0, 0.0))
            totals[i] += tris
            errors[i].append(abs(vol / exact - 1))
            row += [f"{tris:12d}", f"{100 * (vol / exact - 1):+7.2f}%"]
        print("  ".join(row))
    print("total  " + " " * 10 + "  ".join(
        f"{t:12d}  median |err| {100 * float(np.median(e)):.2f}%" for t, e in zip(totals, errors)))


if __name__ == "__main__":
    main()
