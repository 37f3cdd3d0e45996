#!/usr/bin/env python3
"""Times the voxlod Python package against its peers, side by side in one run:

- voxlod.marching_cubes vs skimage.measure.marching_cubes on the peers' 256³ gyroid and
  512³ sphereflake fields (../shared/peers/peers.py; a local gyroid if that is absent);
- voxlod.gaussian_filter vs scipy.ndimage.gaussian_filter at σ = 2 on 256³ float32;
- voxlod.dask.marching_cubes on a chunked volume with a LocalCluster of 2 workers, against the
  single-process voxlod.marching_cubes (``--dask N``, N³ samples; 0 skips).

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


def best_of(repeat, fn):
    times = []
    result = None
    for _ in range(repeat):
        start = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - start)
    return min(times), result


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


def row(name, ours, theirs, detail=""):
    print(f"| {name} | {ours:.3f} | {theirs:.3f} | {theirs / ours:.1f}x | {detail} |", flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--sphereflake", type=int, default=512, help="0 skips it")
    parser.add_argument("--dask", type=int, default=0, help="N for an N³ Dask run; 0 skips it")
    args = parser.parse_args()

    import scipy.ndimage
    import skimage.measure

    import voxlod

    field = peers_field()
    print(f"voxlod {voxlod.__version__}, {os.cpu_count()} cores, "
          f"fields from {'../shared/peers' if field else 'a local gyroid'}\n")
    print("| task | voxlod s | peer s | speed-up | detail |")
    print("|---|---|---|---|---|")
    cases = [("gyroid", 256)] + ([("sphereflake", args.sphereflake)] if args.sphereflake else [])
    for kind, n in cases:
        if field is None and kind != "gyroid":
            continue
        volume = np.ascontiguousarray(field(kind, n) if field else gyroid(n), dtype=np.float32)
        ours, (v, f, _, _) = best_of(args.repeat, lambda: voxlod.marching_cubes(volume, 0.0))
        theirs, (sv, sf, _, _) = best_of(args.repeat, lambda: skimage.measure.marching_cubes(volume, 0.0))
        row(f"marching cubes, {kind} {n}³", ours, theirs,
            f"{len(f):,} vs {len(sf):,} triangles")

    volume = np.random.default_rng(1).random((256, 256, 256), dtype=np.float32)
    ours, a = best_of(args.repeat, lambda: voxlod.gaussian_filter(volume, 2.0))
    theirs, b = best_of(args.repeat, lambda: scipy.ndimage.gaussian_filter(volume, 2.0))
    row("gaussian_filter σ=2, 256³ float32", ours, theirs, f"max |Δ| {np.abs(a - b).max():.1e}")

    if args.dask:
        import dask.array as da
        from distributed import Client, LocalCluster

        import voxlod.dask

        n = args.dask
        volume = gyroid(n)
        single, whole = best_of(1, lambda: voxlod.marching_cubes(volume, 0.0))
        with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                          dashboard_address=None) as cluster, Client(cluster) as client:
            array = da.from_array(volume, chunks=256)
            blockwise, parts = best_of(1, lambda: voxlod.dask.marching_cubes(array, 0.0, client=client))
        same = np.array_equal(parts[1], whole[1]) and np.allclose(parts[0], whole[0], atol=1e-5)
        print(f"| Dask marching cubes, gyroid {n}³, 2 workers | {blockwise:.3f} | {single:.3f} "
              f"(single process) | overhead {blockwise / single:.2f}x | identical mesh: {same} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
