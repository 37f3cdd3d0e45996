"""Marching cubes block by block on a Dask cluster, stitched into the one mesh
:func:`voxlod.marching_cubes` gives for the whole volume.

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

Needs ``dask[array]`` and ``distributed`` (``pip install voxlod[dask]``), and ``zarr`` for
Zarr paths.
"""

from __future__ import annotations

import itertools
from typing import Any, List, Optional, Sequence, Tuple

import numpy as np

from . import _voxlod
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
    if client is not None:
        pieces = client.gather(client.compute(tasks))
    else:
        pieces = dask.compute(*tasks)
    pieces = [p for p in pieces if p is not None and len(p[1])]
    if not pieces:
        raise NoSurfaceError("No surface found at the given iso value.")
    verts, faces, normals = _voxlod.stitch(pieces)
    if gradient_direction == "ascent":
        faces = faces[:, [0, 2, 1]]
    if spacing != (1.0, 1.0, 1.0):
        verts = verts * np.asarray(spacing)
    return verts, faces, normals


def lod_volume(
    source: Any,
    *,
    client: Any = None,
    threshold: Optional[float] = None,
    direct: bool = False,
    iso: Optional[float] = None,
    spacing: Sequence[float] = (1.0, 1.0, 1.0),
    origin: Sequence[float] = (0.0, 0.0, 0.0),
    **chain: Any,
) -> List[Any]:
    """Levels of detail of a volume too large for one machine: its full-resolution surface
    contoured chunk by chunk on the cluster (:func:`marching_cubes`), then the chain of coarser
    levels of that closed surface in this process (:func:`voxlod.lod`, the mesh route).

    ``threshold=T`` takes the surface of the samples ``>= T``; ``direct=True`` the isosurface
    at ``iso`` of the data itself. ``spacing`` and ``origin`` are in array-axis order; the
    remaining keywords (``resolution``, ``levels``, ``filter``, ``resolutions``, ``radius``,
    ``normals``, ``progress``) go to :func:`voxlod.lod`.

    Returns
    -------
    list of :class:`voxlod.Level`
        First the full-resolution surface (its ``resolution`` the longest side in samples), in
        world (x, y, z) coordinates, then the levels of :func:`voxlod.lod`, finest first.

    This is not :func:`voxlod.lod_volume` run blockwise: the coarser levels filter the
    contoured surface's solid rather than the scan; the full-resolution surface is the mesh
    :func:`voxlod.marching_cubes` gives for the whole volume.
    """
    from . import _facade

    if (threshold is None) == (not direct):
        raise UsageError("give either threshold=T or direct=True with iso")
    if direct and iso is None:
        raise UsageError("direct=True needs iso, in the data's units")
    # Inside is `>= threshold` in the library, `> level` in marching cubes: the level just below.
    level = float(np.nextafter(np.float32(threshold), np.float32(-np.inf))) if threshold is not None else float(iso)
    verts, faces, normals = marching_cubes(source, level, spacing=spacing, client=client)
    # Array-axis order to world (x, y, z): reversing the axes also turns the winding outward.
    vertices = (verts[:, ::-1] + np.asarray(triple(origin, "origin"))[::-1]).astype(np.float32)
    report = _facade.inspect(vertices, faces, welded=False)
    finest = _facade.Level(vertices=vertices, faces=faces, normals=normals[:, ::-1].copy(),
                           resolution=int(max(as_dask_array(source).shape)),
                           genus=report["genus"], topology=report)
    return [finest] + _facade.lod(vertices, faces, **chain)
