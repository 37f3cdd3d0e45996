#!/usr/bin/env python3
"""Times the voxlod Python package against its peers, side by side in one run:

- voxlod.marching_cubes vs skimage.measure.marching_cubes on the peers' 256³ gyroid and
  512³ sphereflake fields (../shared/peers/peers.py; a local gyroid if that is absent);
- voxlod.gaussian_filter vs scipy.ndimage.gaussian_filter at σ = 2 on 256³ float32;
- voxlod.dask.lod_volume (threshold route) on an N³ Zarr volume with a LocalCluster of 2
  workers, against the single-process blockwise run of the same data, ``voxlod lod VOL.zarr
  --threshold T --resolution N --levels 1`` (``--dask N``; 0 skips; the binary is
  ``$VOXLOD_BIN`` or target/release/voxlod): wall times and whether the meshes are identical;
- the same with ``direct=True`` (``--dask-direct N``, iso 110, ``--direct-resolution``,
  ``--direct-levels``) against ``voxlod.lod_volume(direct=True)`` in this process on the same
  data read whole: wall and CPU times, and whether every level is identical bit for bit.

Each figure is the best of ``--repeat`` runs (wall time). Run it in the package's virtual
environment (scripts/test-python makes one): ``target/python-venv/bin/python
scripts/bench-python.py``.
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]


CPU = {}


def best_of(repeat, fn):
    """The best wall time of ``repeat`` calls and the last result; the CPU time (all threads
    of this process) of the best call is kept in ``CPU[fn]``, which a shared machine disturbs
    far less than the wall time."""
    best = (float("inf"), 0.0)
    result = None
    for _ in range(repeat):
        start, cpu = time.perf_counter(), time.process_time()
        result = fn()
        best = min(best, (time.perf_counter() - start, time.process_time() - cpu))
    CPU[fn] = best[1]
    return best[0], result


def peers_field():
    """The peers' field generator, when the shared benchmark kit is there."""
    shared = Path(os.environ.get("VOXLOD_SHARED", REPO.parent / "shared"))
    path = shared / "peers" / "peers.py"
    if not path.is_file():
        return None
    spec = importlib.util.spec_from_file_location("voxlod_peers", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.field


def gyroid(n):
    t = np.linspace(-1, 1, n, dtype=np.float32) * 3 * np.pi
    z, y, x = np.meshgrid(t, t, t, indexing="ij")
    return (np.sin(x) * np.cos(y) + np.sin(y) * np.cos(z) + np.sin(z) * np.cos(x)).astype(np.float32)


def ball_zarr(n, path):
    """An N³ uint8 Zarr array (128³ chunks) holding a ball of radius 0.4 N (200 inside, 20
    outside) with a tunnel of radius 0.08 N along axis 2: written chunk by chunk."""
    import dask.array as da

    def chunk(block_info=None):
        (z0, z1), (y0, y1), (x0, x1) = block_info[None]["array-location"]
        z, y, x = np.ogrid[z0:z1, y0:y1, x0:x1]
        c = (n - 1) / 2.0
        ball = (x - c) ** 2 + (y - c) ** 2 + (z - c) ** 2 < (0.4 * n) ** 2
        tunnel = (y - c) ** 2 + (z - c) ** 2 < (0.08 * n) ** 2
        return np.where(ball & ~tunnel, 200, 20).astype(np.uint8)

    da.map_blocks(chunk, chunks=((128,) * (n // 128) + ((n % 128,) if n % 128 else ()),) * 3,
                  dtype=np.uint8).to_zarr(str(path))


def dask_lod_volume(n, folder):
    """voxlod.dask.lod_volume against the single-process blockwise run on an N³ Zarr ball."""
    import shutil
    import subprocess
    import tempfile

    from distributed import Client, LocalCluster

    import voxlod
    import voxlod.dask

    folder = Path(folder) if folder else Path(tempfile.mkdtemp(prefix="voxlod-dask-"))
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"ball-{n}.zarr"
    if not path.exists():
        start = time.perf_counter()
        ball_zarr(n, path)
        print(f"wrote {path} in {time.perf_counter() - start:.1f} s", flush=True)
    binary = os.environ.get("VOXLOD_BIN", str(REPO / "target" / "release" / "voxlod"))
    out = folder / f"single-{n}"
    command = [binary, "lod", str(path), "--threshold", "100", "--resolution", str(n),
               "--levels", "1", "-o", str(out)]
    start = time.perf_counter()
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
    single = time.perf_counter() - start
    vertices, faces = voxlod.read_mesh(out / "level-0.ply")
    print(f"single process: {' '.join(command)}: {single:.1f} s", flush=True)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        start = time.perf_counter()
        levels = voxlod.dask.lod_volume(path, client=client, threshold=100, resolution=n,
                                        levels=1)
        blockwise = time.perf_counter() - start
    mine = levels[0]
    a, b = np.unique(mine.vertices, axis=0), np.unique(vertices, axis=0)
    same = (len(mine.faces) == len(faces) and a.shape == b.shape
            and bool(np.allclose(a, b, rtol=0, atol=4 * np.finfo(np.float32).eps * n)))
    print(f"| Dask lod_volume, ball {n}³ Zarr (128³ chunks), threshold, 1 level at {n}, "
          f"LocalCluster of 2 processes | {blockwise:.1f} s | single-process blockwise "
          f"`voxlod lod` {single:.1f} s | overhead {blockwise / single:.2f}x | "
          f"{len(mine.faces):,} vs {len(faces):,} triangles, identical mesh: {same} |", flush=True)
    if not os.environ.get("VOXLOD_KEEP") and folder.name.startswith("voxlod-dask-"):
        shutil.rmtree(folder)


def dask_lod_direct(n, folder, resolution, levels):
    """voxlod.dask.lod_volume(direct=True) against voxlod.lod_volume(direct=True) in this
    process, on the same N³ Zarr ball (read whole into memory for the single process): wall
    and CPU times (the workers' CPU counted once the cluster has closed) and whether every
    level is identical (faces and vertices bit for bit)."""
    import resource
    import tempfile

    import zarr
    from distributed import Client, LocalCluster

    import voxlod
    import voxlod.dask

    folder = Path(folder) if folder else Path(tempfile.mkdtemp(prefix="voxlod-dask-"))
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"ball-{n}.zarr"
    if not path.exists():
        ball_zarr(n, path)
    keywords = dict(direct=True, iso=110.0, resolution=resolution, levels=levels)
    load = " ".join(f"{v:.1f}" for v in os.getloadavg())
    start, cpu = time.perf_counter(), time.process_time()
    whole = voxlod.lod_volume(np.asarray(zarr.open(str(path), mode="r")[...]), **keywords)
    single, single_cpu = time.perf_counter() - start, time.process_time() - cpu
    print(f"single process: voxlod.lod_volume(ball-{n}.zarr read whole, {keywords}): "
          f"{single:.1f} s wall, {single_cpu:.1f} s CPU (load {load})", flush=True)
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        load = " ".join(f"{v:.1f}" for v in os.getloadavg())
        start, cpu = time.perf_counter(), time.process_time()
        mine = voxlod.dask.lod_volume(path, client=client, **keywords)
        blockwise, client_cpu = time.perf_counter() - start, time.process_time() - cpu
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    workers_cpu = (after.ru_utime + after.ru_stime) - (children.ru_utime + children.ru_stime)
    same = len(mine) == len(whole) and all(
        np.array_equal(a.faces, b.faces) and np.array_equal(a.vertices, b.vertices)
        for a, b in zip(mine, whole))
    triangles = " + ".join(f"{len(level.faces):,}" for level in mine)
    print(f"| Dask lod_volume direct, ball {n}³ uint8 Zarr (128³ chunks), iso 110, "
          f"resolution {resolution}, {levels} level(s), LocalCluster of 2 processes (load "
          f"{load}) | {blockwise:.1f} s (client CPU {client_cpu:.1f} s, workers' CPU "
          f"{workers_cpu:.1f} s incl. start-up) | single process {single:.1f} s (CPU "
          f"{single_cpu:.1f} s) | overhead {blockwise / single:.2f}x | {triangles} "
          f"triangles, identical levels: {same} |", flush=True)


def row(name, ours, theirs, detail=""):
    print(f"| {name} | {ours:.3f} | {theirs:.3f} | {theirs / ours:.1f}x | {detail} |", flush=True)


def cpu_note(ours, theirs):
    """The CPU seconds of the two best calls, as a note for the detail column."""
    return f"CPU {CPU[ours]:.3f} s vs {CPU[theirs]:.3f} s"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--sphereflake", type=int, default=512, help="0 skips it")
    parser.add_argument("--dask", type=int, default=0, help="N for an N³ Dask run; 0 skips it")
    parser.add_argument("--dask-dir", default=None,
                        help="where the N³ Zarr volume is written once and kept (default: a "
                             "temporary folder, removed)")
    parser.add_argument("--dask-direct", type=int, default=0,
                        help="N for an N³ Dask run of the direct route; 0 skips it")
    parser.add_argument("--direct-resolution", type=int, default=512,
                        help="the direct run's finest level (default 512)")
    parser.add_argument("--direct-levels", type=int, default=1,
                        help="the direct run's levels (default 1)")
    parser.add_argument("--skip-peers", action="store_true",
                        help="only the Dask runs (with --dask, --dask-direct)")
    args = parser.parse_args()

    import scipy.ndimage
    import skimage.measure

    import voxlod

    if args.skip_peers:
        if args.dask:
            dask_lod_volume(args.dask, args.dask_dir)
        if args.dask_direct:
            dask_lod_direct(args.dask_direct, args.dask_dir, args.direct_resolution,
                            args.direct_levels)
        return 0
    field = peers_field()
    print(f"voxlod {voxlod.__version__}, {os.cpu_count()} cores, "
          f"fields from {'../shared/peers' if field else 'a local gyroid'}, "
          f"load average {' '.join(f'{v:.2f}' for v in os.getloadavg())}\n")
    print("| task | voxlod s | peer s | speed-up | detail |")
    print("|---|---|---|---|---|")
    cases = [("gyroid", 256)] + ([("sphereflake", args.sphereflake)] if args.sphereflake else [])
    for kind, n in cases:
        if field is None and kind != "gyroid":
            continue
        volume = np.ascontiguousarray(field(kind, n) if field else gyroid(n), dtype=np.float32)
        mine = lambda: voxlod.marching_cubes(volume, 0.0)  # noqa: E731
        peer = lambda: skimage.measure.marching_cubes(volume, 0.0)  # noqa: E731
        ours, (v, f, _, _) = best_of(args.repeat, mine)
        theirs, (sv, sf, _, _) = best_of(args.repeat, peer)
        row(f"marching cubes, {kind} {n}³", ours, theirs,
            f"{len(f):,} vs {len(sf):,} triangles; {cpu_note(mine, peer)}")

    volume = np.random.default_rng(1).random((256, 256, 256), dtype=np.float32)
    mine = lambda: voxlod.gaussian_filter(volume, 2.0)  # noqa: E731
    peer = lambda: scipy.ndimage.gaussian_filter(volume, 2.0)  # noqa: E731
    ours, a = best_of(args.repeat, mine)
    theirs, b = best_of(args.repeat, peer)
    row("gaussian_filter σ=2, 256³ float32", ours, theirs,
        f"max |Δ| {np.abs(a - b).max():.1e}; {cpu_note(mine, peer)}")

    if args.dask:
        dask_lod_volume(args.dask, args.dask_dir)
    if args.dask_direct:
        dask_lod_direct(args.dask_direct, args.dask_dir, args.direct_resolution,
                        args.direct_levels)
    return 0


if __name__ == "__main__":
    sys.exit(main())
