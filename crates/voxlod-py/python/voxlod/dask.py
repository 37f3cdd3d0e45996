"""voxlod on a Dask cluster: :func:`lod_volume`, the levels of :func:`voxlod.lod_volume`
(threshold route) with each level sampled block by block on the cluster; and
:func:`marching_cubes`, marching cubes block by block, stitched into the one mesh
:func:`voxlod.marching_cubes` gives for the whole volume.

:func:`lod_volume`: the client plans the levels and, per level, sends one task per block of
the level's grid; each task reads the block's window of the scan once, answers a window
without a crossing of the threshold with one value, and otherwise returns the block's bricks
of filtered density. The client gathers them and contours, cleans and places the level as
:func:`voxlod.lod_volume` does.

:func:`marching_cubes`:
Each task reads one chunk of the volume and a one-sample halo around it (so that the gradient
normals on the chunk's faces see the same neighbours as in one piece), skips it when no sample
crosses the level, and otherwise contours the chunk's own cells in Rust, returning its piece of
mesh with *global edge keys* on every vertex and global cell keys on every triangle. The client
then stitches the pieces: one vertex per edge key, in key order, and the triangles in cell
order. The result is :func:`voxlod.marching_cubes`'s mesh index for index, with the same
vertices to ``float32`` rounding.

Any ``dask.distributed`` cluster runs it unchanged, local or remote (see the package README):

>>> from dask.distributed import Client, LocalCluster            # doctest: +SKIP
>>> client = Client(LocalCluster(n_workers=2, processes=True))  # doctest: +SKIP
>>> verts, faces, normals = voxlod.dask.marching_cubes("ct.zarr", 500.0, client=client)  # doctest: +SKIP
>>> levels = voxlod.dask.lod_volume("ct.zarr", client=client, threshold=500, levels=4)  # doctest: +SKIP

Needs ``dask[array]`` and ``distributed`` (``pip install voxlod[dask]``), and ``zarr`` for
Zarr paths.
"""

from __future__ import annotations

import itertools
from typing import Any, List, Optional, Sequence, Tuple

import numpy as np

from . import _facade, _voxlod
from ._arrays import triple
from .errors import NoSurfaceError, UsageError

__all__ = ["marching_cubes", "lod_volume", "as_dask_array"]


def as_dask_array(source: Any) -> Any:
    """``source`` as a 3-D ``dask.array``: a Zarr path or store (read lazily), a dask array, or
    a NumPy array (one chunk per 128³ samples)."""
    import dask.array as da

    if isinstance(source, da.Array):
        array = source
    elif isinstance(source, (str, bytes)) or hasattr(source, "__fspath__"):
        array = da.from_zarr(str(source))
    elif hasattr(source, "shape") and hasattr(source, "dtype"):
        array = da.from_array(source, chunks=128)
    else:
        raise UsageError(f"source must be a Zarr path, a dask array or an array, not {type(source)}")
    if array.ndim != 3 or min(array.shape) < 2:
        raise UsageError(f"source must be a 3-D volume of at least 2x2x2, not shape {array.shape}")
    return array


def _blocks(array: Any) -> List[Tuple[Tuple[int, ...], Tuple[int, ...], Tuple[int, ...], Tuple[int, ...]]]:
    """Per chunk: the samples to read (start, stop, with the halo) and its own cells (start, stop,
    relative to the read samples). Every cell of the volume belongs to exactly one chunk."""
    shape = array.shape
    bounds = [np.cumsum((0,) + tuple(c)) for c in array.chunks]
    blocks = []
    for index in itertools.product(*(range(len(c)) for c in array.chunks)):
        start = [int(bounds[a][i]) for a, i in enumerate(index)]
        stop = [min(int(bounds[a][i + 1]), shape[a] - 1) for a, i in enumerate(index)]
        if any(s >= e for s, e in zip(start, stop)):
            continue  # the last samples of an axis: their cells belong to the chunk before
        read_start = [max(s - 1, 0) for s in start]
        read_stop = [min(e + 2, n) for e, n in zip(stop, shape)]
        own_start = [s - r for s, r in zip(start, read_start)]
        own_stop = [e - r for e, r in zip(stop, read_start)]
        blocks.append((tuple(read_start), tuple(read_stop), tuple(own_start), tuple(own_stop)))
    return blocks


def _piece(block: np.ndarray, level: float, offset, own_start, own_stop, shape):
    """One task: the chunk's piece of the surface, or None when no sample crosses the level."""
    block = np.ascontiguousarray(block, dtype=np.float32)
    above = block > level
    if above.all() or not above.any():
        return None
    return _voxlod.contour_block(block, level, offset, own_start, own_stop, shape)


def marching_cubes(
    source: Any,
    level: Optional[float] = None,
    *,
    spacing: Sequence[float] = (1.0, 1.0, 1.0),
    gradient_direction: str = "descent",
    client: Any = None,
) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`voxlod.marching_cubes` of a volume too large for one machine, chunk by chunk.

    Parameters
    ----------
    source : Zarr path, dask array or array
        The volume; its chunks are the tasks.
    level : float, optional
        The iso value (samples above it are inside). Default: halfway between the minimum and
        maximum, which costs one more read of the volume.
    spacing, gradient_direction
        As for :func:`voxlod.marching_cubes`.
    client : dask.distributed.Client, optional
        Where to run; default: the current client, else Dask's default scheduler.

    Returns
    -------
    verts, faces, normals
        As :func:`voxlod.marching_cubes` returns them for the whole volume (without ``values``).
    """
    import dask

    array = as_dask_array(source)
    if level is None:
        low, high = dask.compute(array.min(), array.max())
        level = float(np.float32(0.5) * (np.float32(low) + np.float32(high)))
    level = float(level)
    spacing = triple(spacing, "spacing")
    if gradient_direction not in ("descent", "ascent"):
        raise UsageError(f"gradient_direction must be 'descent' or 'ascent', not {gradient_direction!r}")
    shape = tuple(int(n) for n in array.shape)
    tasks = []
    for read_start, read_stop, own_start, own_stop in _blocks(array):
        region = array[tuple(slice(s, e) for s, e in zip(read_start, read_stop))]
        tasks.append(dask.delayed(_piece)(region, level, read_start, own_start, own_stop, shape))
    pieces = [p for p in _compute(tasks, client) if p is not None and len(p[1])]
    if not pieces:
        raise NoSurfaceError("No surface found at the given iso value.")
    verts, faces, normals = _voxlod.stitch(pieces)
    if gradient_direction == "ascent":
        faces = faces[:, [0, 2, 1]]
    if spacing != (1.0, 1.0, 1.0):
        verts = verts * np.asarray(spacing)
    return verts, faces, normals


def _compute(tasks: List[Any], client: Any) -> List[Any]:
    """The results of ``tasks`` (dask.delayed), on ``client`` or Dask's current scheduler, with
    every array of a tuple result aligned: arrays that distributed deserializes from a
    message's frames can start at any byte, which the Rust side cannot borrow."""
    import dask

    if client is not None:
        results = client.gather(client.compute(tasks))
    else:
        results = dask.compute(*tasks)
    return [tuple(np.require(a, requirements=["C", "A"]) if isinstance(a, np.ndarray) else a
                  for a in r) if isinstance(r, tuple) else r
            for r in results]


def _read_zarr(path: str, start: Sequence[int], stop: Sequence[int]) -> np.ndarray:
    """Samples ``start .. stop`` (array-axis order) of the Zarr array at ``path``, on a worker."""
    import zarr

    array = zarr.open(path, mode="r")
    return np.asarray(array[tuple(slice(a, b) for a, b in zip(start, stop))])


def _fill_block(window: Any, scan: Tuple[Any, ...], level: int, block: Tuple[int, int, int]) -> Any:
    """One task of :func:`lod_volume`: a block's answer from its window of the scan (read once):
    its one value when the window holds no surface, else its bricks."""
    window = np.ascontiguousarray(window, dtype=np.float32)
    return _voxlod.fill_threshold_block(window, scan, level, tuple(block))


def _fill_zarr_block(path: str, start, stop, scan, level, block) -> Any:
    """:func:`_fill_block` reading the window from a Zarr path on the worker."""
    return _fill_block(_read_zarr(path, start, stop), scan, level, block)


def lod_volume(
    source: Any,
    *,
    client: Any = None,
    threshold: Optional[float] = None,
    direct: bool = False,
    iso: Optional[float] = None,
    spacing: Sequence[float] = (1.0, 1.0, 1.0),
    origin: Sequence[float] = (0.0, 0.0, 0.0),
    resolution: int = 256,
    levels: int = 6,
    filter: str = "hypercone",
    resolutions: Optional[Sequence[int]] = None,
    radius: float = 1.0,
    normals: bool = True,
    progress: Optional[_facade.Progress] = None,
) -> List[_facade.Level]:
    """:func:`voxlod.lod_volume` with ``threshold=T``, each level sampled block by block on a
    Dask cluster: the same levels (same triangles, same vertices to ``float32`` rounding, same
    genus step and cleaning) from a volume that need not fit in one process.

    Per level, one task per block of the level's grid reads the block's window of the scan
    (the block grown by the filter's reach), answers a window without a crossing of the
    threshold with one value (no density pass), and otherwise returns the block's bricks of
    filtered density. The client gathers the bricks and contours, cleans and places the level
    as :func:`voxlod.lod_volume` does (see the package README for what runs where).

    Parameters
    ----------
    source : Zarr path, dask array or array, shape (nz, ny, nx)
        The scan. A Zarr path is read by the workers themselves, window by window.
    client : dask.distributed.Client, optional
        Where to run; default: the current client, else Dask's default scheduler.
    threshold, iso, spacing, origin, resolution, levels, filter, resolutions, radius, normals, progress
        As for :func:`voxlod.lod_volume`. ``progress`` is called after each level's sampling
        and contouring.
    direct : bool
        Refused: filtering the data itself needs halos as wide as the coarsest filter; use
        :func:`voxlod.lod_volume` with ``direct=True`` in one process.

    Returns
    -------
    list of :class:`voxlod.Level`, finest first, as :func:`voxlod.lod_volume` returns them.
    """
    if direct:
        raise UsageError("voxlod.dask.lod_volume runs the threshold route only; for direct=True "
                         "use voxlod.lod_volume(volume, spacing, direct=True, iso=...) in one process")
    if threshold is None:
        raise UsageError("give threshold=T (the solid of the samples >= T)")
    array = as_dask_array(source)
    path = str(source) if isinstance(source, (str, bytes)) or hasattr(source, "__fspath__") else None
    shape = tuple(int(n) for n in array.shape)
    options = (_facade._resolutions(resolution, levels, resolutions), str(filter), float(radius),
               iso, bool(normals), True)
    scan = (shape, triple(spacing, "spacing"), triple(origin, "origin"), float(threshold), options)

    def run_level(level: int, blocks: List[Tuple[Any, Any, Any]]) -> List[Any]:
        import dask

        tasks = []
        for block, start, stop in blocks:
            if path is not None:
                tasks.append(dask.delayed(_fill_zarr_block)(path, start, stop, scan, level, block))
            else:
                region = array[tuple(slice(a, b) for a, b in zip(start, stop))]
                tasks.append(dask.delayed(_fill_block)(region, scan, level, block))
        return _compute(tasks, client)

    return _facade._levels(_voxlod.lod_threshold_blockwise(*scan, run_level, progress))
