"""voxlod on a Dask cluster: the levels of :func:`voxlod.lod_volume` (either route of the
paper's §4) and the meshes of :func:`voxlod.labels`, each made block by block on the cluster
and identical to the single-process result; and :func:`marching_cubes`, marching cubes block
by block, stitched into the one mesh :func:`voxlod.marching_cubes` gives for the whole volume.

:func:`lod_volume`: the client plans the levels and, per level, sends one task per block of
the level's grid; each task reads the block's window of the scan once (the block grown by the
filter's reach: from a Zarr path the worker reads it itself; from a dask array it is assembled
from the chunks that overlap it, each chunk computed once per level). With ``threshold=T`` a
window without a crossing of the threshold is answered with one value, and otherwise the task
returns the block's bricks of filtered density; with ``direct=True`` the task returns the
block's samples of the data filtered directly. The client gathers them and contours, cleans
and places the level as :func:`voxlod.lod_volume` does.

:func:`labels`: one task per chunk lists the chunk's labels and their boxes; then one task
per label assembles the label's box grown by one voxel from the chunks that hold that label
only, and meshes it as :func:`voxlod.labels` does; with ``shared=True`` the box is grown by a
halo of ``2 * smooth + 7`` voxels and holds every label there, and the volume restoring's
pressures are solved first from every chunk's share of its sums (:func:`labels`).

:func:`marching_cubes`:
Each task reads one chunk of the volume and a one-sample halo around it, assembled from the
chunks that overlap it (so that the gradient normals on the chunk's faces see the same
neighbours as in one piece), skips it when no sample crosses the level, and otherwise contours
the chunk's own cells in Rust, returning its piece of mesh with *global edge keys* on every
vertex and global cell keys on every triangle. The client then stitches the pieces: one vertex
per edge key, in key order, and the triangles in cell order. The result is
:func:`voxlod.marching_cubes`'s mesh index for index, with the same vertices to ``float32``
rounding.

Each call builds one task graph per pass (per level, per labels' pass), whose tasks name the
chunks they need: a dask collection per task would cost tens of milliseconds of graph building
each, which thousands of tasks turn into minutes.

Any ``dask.distributed`` cluster runs it unchanged, local or remote (see the package README):

>>> from dask.distributed import Client, LocalCluster            # doctest: +SKIP
>>> client = Client(LocalCluster(n_workers=2, processes=True))  # doctest: +SKIP
>>> verts, faces, normals = voxlod.dask.marching_cubes("ct.zarr", 500.0, client=client)  # doctest: +SKIP
>>> levels = voxlod.dask.lod_volume("ct.zarr", client=client, threshold=500, levels=4)  # doctest: +SKIP
>>> levels = voxlod.dask.lod_volume("ct.zarr", client=client, direct=True, iso=500)  # doctest: +SKIP
>>> meshes = voxlod.dask.labels("segmentation.zarr", client=client, levels=3)  # doctest: +SKIP

Needs ``dask[array]`` and ``distributed`` (``pip install voxlod[dask]``), and ``zarr`` for
Zarr paths.
"""

from __future__ import annotations

import functools
import itertools
import uuid
from typing import Any, List, Optional, Sequence, Tuple

import numpy as np

from . import _facade, _voxlod
from ._facade import Level
from ._arrays import spacing_triple, triple
from ._labels import (LabelMesh, check_label_dtype, check_surface_options, label_mesh,
                      label_options, label_values, quiet_empty_levels, warn_empty_levels)
from .errors import InputError, NoSurfaceError, UsageError

__all__ = ["marching_cubes", "lod_volume", "labels", "as_dask_array"]

WINDOW_SIDE = 256
"""Scan samples per side that a task's window of the scan aims at on the direct route of
:func:`lod_volume` (64 MiB of float32 per task in flight): smaller windows make more tasks and
read more of the scan twice (the halos of the filter's reach)."""


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


def _piece_from_chunks(parts, corners, read_start, read_stop, level, own_start, own_stop, shape):
    """:func:`_piece` of the samples ``read_start .. read_stop`` assembled from the chunks that
    overlap them."""
    block = _assemble(parts, corners, read_start, read_stop, np.float32)
    return _piece(block, level, read_start, own_start, own_stop, shape)


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
    spacing = spacing_triple(spacing)
    if gradient_direction not in ("descent", "ascent"):
        raise UsageError(f"gradient_direction must be 'descent' or 'ascent', not {gradient_direction!r}")
    shape = tuple(int(n) for n in array.shape)
    keys, bounds = _chunk_keys(array)
    tasks = []
    for read_start, read_stop, own_start, own_stop in _blocks(array):
        parts, corners = _window_chunks(keys, bounds, read_start, read_stop)
        tasks.append((_piece_from_chunks, parts, corners, read_start, read_stop, level,
                      own_start, own_stop, shape))
    pieces = [p for p in _graph_results("voxlod-pieces", tasks, array, client)
              if p is not None and len(p[1])]
    if not pieces:
        raise NoSurfaceError("No surface found at the given iso value.")
    verts, faces, normals = _voxlod.stitch(pieces)
    if gradient_direction == "ascent":
        faces = faces[:, [0, 2, 1]]
    if spacing != (1.0, 1.0, 1.0):
        verts = verts * np.asarray(spacing)
    return verts, faces, normals


def _compute(tasks: List[Any], client: Any, each: bool = False) -> List[Any]:
    """The results of ``tasks`` (dask.delayed or dask collections), on ``client`` or Dask's
    current scheduler, with every array result (or array of a tuple result) aligned: arrays
    that distributed deserializes from a message's frames can start at any byte, which the
    Rust side cannot borrow. With ``each``, ``tasks`` is one collection whose result is the
    list of results."""
    import dask

    if client is not None:
        results = client.gather(client.compute(tasks))
    else:
        results = dask.compute(*tasks)
    if each:
        (results,) = results

    return [tuple(_aligned(a) for a in r) if isinstance(r, tuple) else _aligned(r)
            for r in results]


def _aligned(a: Any) -> Any:
    """An array ``a`` C-ordered and aligned (copied only when it is not): a chunk that
    distributed deserializes from a message's frames can start at any byte, which the Rust
    side cannot borrow."""
    return np.require(a, requirements=["C", "A"]) if isinstance(a, np.ndarray) else a


def _chunk_keys(array: Any) -> Tuple[np.ndarray, List[np.ndarray]]:
    """The graph keys of ``array``'s chunks (an object array indexed like ``array.blocks``)
    and, per axis, the chunks' boundaries (``bounds[a][i]`` the first index of chunk ``i``)."""
    keys = np.empty(array.numblocks, dtype=object)
    for index in np.ndindex(*array.numblocks):
        keys[index] = (array.name,) + index
    return keys, [np.cumsum((0,) + tuple(c)) for c in array.chunks]


def _window_chunks(keys: np.ndarray, bounds: List[np.ndarray], start: Sequence[int],
                   stop: Sequence[int]) -> Tuple[List[Any], List[Tuple[int, ...]]]:
    """The keys and first indices of the chunks that overlap samples ``start .. stop``."""
    ranges = [range(int(np.searchsorted(b, s, side="right")) - 1,
                    int(np.searchsorted(b, e, side="left")))
              for b, s, e in zip(bounds, start, stop)]
    chosen = list(itertools.product(*ranges))
    return ([keys[i] for i in chosen],
            [tuple(int(b[i]) for b, i in zip(bounds, index)) for index in chosen])


def _assemble(parts: List[np.ndarray], corners: List[Sequence[int]], start: Sequence[int],
              stop: Sequence[int], dtype: Any) -> np.ndarray:
    """Samples ``start .. stop`` as one ``dtype`` array, from the chunks ``parts`` (each
    starting at its ``corners``) that cover them; on a worker."""
    window = np.empty(tuple(e - s for s, e in zip(start, stop)), dtype)
    for part, corner in zip(parts, corners):
        low = [max(s, c) for s, c in zip(start, corner)]
        high = [min(e, c + n) for e, c, n in zip(stop, corner, part.shape)]
        if all(a < b for a, b in zip(low, high)):
            window[tuple(slice(a - s, b - s) for a, b, s in zip(low, high, start))] = \
                part[tuple(slice(a - c, b - c) for a, b, c in zip(low, high, corner))]
    return window


def _graph_results(name: str, tasks: List[Tuple[Any, ...]], array: Any, client: Any) -> List[Any]:
    """The results of ``tasks`` (graph tasks: a function and its arguments, in which chunk
    keys of ``array`` stand for the chunks; arguments shared by every task are best bound in a
    ``functools.partial``, which the graph does not search for keys), computed as one graph on
    ``client`` or Dask's current scheduler. One graph for all the tasks, not one collection
    per task: a dask collection per task costs tens of milliseconds of graph building each
    (dask.delayed over a slice of an array), which thousands of tasks turn into minutes."""
    from dask.delayed import Delayed
    from dask.highlevelgraph import HighLevelGraph

    name = f"{name}-{uuid.uuid4().hex}"
    layer = {(name, n): task for n, task in enumerate(tasks)}
    layer[name] = (list, list(layer))
    dependencies = [array] if array is not None else []
    graph = HighLevelGraph.from_collections(name, layer, dependencies=dependencies)
    return _compute([Delayed(name, graph)], client, each=True)


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


def _fill_from_chunks(fill: Any, scan: Tuple[Any, ...], level: int, parts: List[np.ndarray],
                      corners: List[Sequence[int]], start: Sequence[int], stop: Sequence[int],
                      block: Tuple[int, int, int]) -> Any:
    """``fill(window, scan, level, block)`` on the window ``start .. stop`` assembled from the
    chunks that overlap it; on a worker."""
    return fill(_assemble(parts, corners, start, stop, np.float32), scan, level, block)


def _fill_zarr_window(fill_zarr: Any, path: str, scan: Tuple[Any, ...], level: int,
                      start: Sequence[int], stop: Sequence[int],
                      block: Tuple[int, int, int]) -> Any:
    """``fill_zarr(path, start, stop, scan, level, block)``, its shared arguments first."""
    return fill_zarr(path, start, stop, scan, level, block)


def _fill_direct_block(window: Any, scan: Tuple[Any, ...], level: int,
                       block: Tuple[int, int, int]) -> np.ndarray:
    """One task of :func:`lod_volume` with ``direct=True``: the block's filtered samples from
    its window of the scan (read once)."""
    window = np.ascontiguousarray(window, dtype=np.float32)
    return _voxlod.fill_direct_block(window, scan, level, tuple(block))


def _fill_direct_zarr_block(path: str, start, stop, scan, level, block) -> np.ndarray:
    """:func:`_fill_direct_block` reading the window from a Zarr path on the worker."""
    return _fill_direct_block(_read_zarr(path, start, stop), scan, level, block)


def _finite_range(array: Any, client: Any) -> Tuple[float, float]:
    """The smallest and largest finite sample of ``array`` as float32 (one reduction over the
    scan, on the cluster); ``(inf, -inf)`` when there is none."""
    import dask.array as da

    samples = array.astype(np.float32)
    finite = da.isfinite(samples)
    low = da.where(finite, samples, np.float32(np.inf)).min()
    high = da.where(finite, samples, np.float32(-np.inf)).max()
    return tuple(float(np.float32(v)) for v in _compute([low, high], client))


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
    """:func:`voxlod.lod_volume`, each level sampled block by block on a Dask cluster: the same
    levels (same triangles, same vertices to ``float32`` rounding, same genus step and
    cleaning) from a volume that need not fit in one process.

    Per level, one task per block of the level's grid reads the block's window of the scan
    once (the block grown by the filter's reach; from a dask array, assembled from the chunks
    that overlap it, each computed once per level). With ``threshold=T`` a window without a
    crossing of the threshold is answered with one value (no density pass), and otherwise the
    task returns the block's bricks of filtered density. With ``direct=True`` the task filters
    the data itself over the window (paper §2.3 and §4) and returns the block's samples, bit for
    bit those of the single process; one reduction over the scan first finds its smallest and
    largest finite sample (the value outside the scan, and the check of ``iso``). The client
    gathers the answers and contours, cleans and places the level as :func:`voxlod.lod_volume`
    does (see the package README for what runs where).

    Parameters
    ----------
    source : Zarr path, dask array or array, shape (nz, ny, nx)
        The scan. A Zarr path is read by the workers themselves, window by window.
    client : dask.distributed.Client, optional
        Where to run; default: the current client, else Dask's default scheduler.
    threshold, direct, iso, spacing, origin, resolution, levels, filter, resolutions, radius, normals, progress
        As for :func:`voxlod.lod_volume`: either ``threshold=T`` (``iso`` a density between 0
        and 1, default 0.5) or ``direct=True`` with ``iso`` in the data's units. ``progress``
        is called after each level's sampling and contouring.

    Returns
    -------
    list of :class:`voxlod.Level`, finest first, as :func:`voxlod.lod_volume` returns them.

    Examples
    --------
    >>> import numpy as np, dask.array as da, voxlod, voxlod.dask
    >>> z, y, x = np.mgrid[-12:13, -12:13, -12:13]
    >>> ct = np.where(x**2 + y**2 + z**2 < 81, 1000, 0).astype(np.int16)
    >>> chunked = da.from_array(ct, chunks=10)
    >>> levels = voxlod.dask.lod_volume(chunked, direct=True, iso=500, resolution=20, levels=2)
    >>> alone = voxlod.lod_volume(ct, direct=True, iso=500, resolution=20, levels=2)
    >>> [len(l.faces) for l in levels] == [len(l.faces) for l in alone]
    True
    """
    if (threshold is None) == (not direct):
        raise UsageError("give either threshold=T (the solid of the samples >= T) or direct=True "
                         "(the data filtered itself, with iso in its units)")
    array = as_dask_array(source)
    path = str(source) if isinstance(source, (str, bytes)) or hasattr(source, "__fspath__") else None
    shape = tuple(int(n) for n in array.shape)
    options = (_facade._resolutions(resolution, levels, resolutions), str(filter), float(radius),
               iso, bool(normals), True)
    where = (shape, triple(spacing, "spacing"), triple(origin, "origin"))
    if direct:
        scan = where + (_finite_range(array, client), int(WINDOW_SIDE), options)
        run_level = _level_runner(array, path, scan, client, _fill_direct_block,
                                  _fill_direct_zarr_block)
        return _facade._levels(_voxlod.lod_direct_blockwise(*scan, run_level, progress))
    scan = where + (float(threshold), options)
    run_level = _level_runner(array, path, scan, client, _fill_block, _fill_zarr_block)
    return _facade._levels(_voxlod.lod_threshold_blockwise(*scan, run_level, progress))


def _level_runner(array: Any, path: Optional[str], scan: Tuple[Any, ...], client: Any,
                  fill: Any, fill_zarr: Any) -> Any:
    """``run_level(level, blocks)`` for the Rust side: one task per ``(block, window_start,
    window_stop)``, ``fill(window, scan, level, block)`` on the window assembled from the dask
    array's chunks that overlap it (each chunk computed once per level), or ``fill_zarr(path,
    start, stop, scan, level, block)`` reading the window on the worker; one graph per level."""

    keys, bounds = _chunk_keys(array)

    def run_level(level: int, blocks: List[Tuple[Any, Any, Any]]) -> List[Any]:
        tasks = []
        from_zarr = functools.partial(_fill_zarr_window, fill_zarr, path, scan, level)
        from_chunks = functools.partial(_fill_from_chunks, fill, scan, level)
        for block, start, stop in blocks:
            if path is not None:
                tasks.append((from_zarr, start, stop, block))
            else:
                parts, corners = _window_chunks(keys, bounds, start, stop)
                tasks.append((from_chunks, parts, corners, start, stop, block))
        return _graph_results("voxlod-level", tasks, None if path else array, client)

    return run_level


def _chunk_labels(chunk: Any, offset: Tuple[int, int, int]) -> Tuple[Any, ...]:
    """One task of :func:`labels`' first pass: the chunk's labels, voxel counts and boxes (in
    the whole map's indices, array-axis order)."""
    chunk = label_values(_aligned(chunk), "the label map", offset)
    return _voxlod.chunk_labels(chunk, tuple(offset))


def _chunk_bounds(array: Any) -> List[Tuple[Tuple[int, ...], Tuple[int, ...]]]:
    """Each chunk's first sample and end (array-axis order), in ``array.blocks`` order."""
    bounds = [np.cumsum((0,) + tuple(c)) for c in array.chunks]
    return [(tuple(int(bounds[a][i]) for a, i in enumerate(index)),
             tuple(int(bounds[a][i + 1]) for a, i in enumerate(index)))
            for index in itertools.product(*(range(len(c)) for c in array.chunks))]


def _find_labels(array: Any, client: Any) -> dict:
    """Per label of the map: ``[voxels, first index, last index, chunks holding it]`` (indices
    in array-axis order; chunks as positions in :func:`_chunk_bounds`), one task per chunk."""
    keys, _ = _chunk_keys(array)
    tasks = [(_chunk_labels, key, start)
             for key, (start, _) in zip(keys.ravel(), _chunk_bounds(array))]
    found: dict = {}
    for n, (values, voxels, lows, highs) in enumerate(
            _graph_results("voxlod-chunk-labels", tasks, array, client)):
        for value, count, low, high in zip(values, voxels, lows, highs):
            entry = found.setdefault(value, [0, list(low), list(high), []])
            entry[0] += count
            entry[1] = [min(a, b) for a, b in zip(entry[1], low)]
            entry[2] = [max(a, b) for a, b in zip(entry[2], high)]
            entry[3].append(n)
    return found


def _chosen_labels(found: dict, wanted: Optional[Sequence[int]]) -> List[int]:
    """The labels to mesh, as ``voxlod.labels`` chooses them (each asked for must exist)."""
    if not found:
        raise InputError("the map holds no label other than 0")
    present = sorted(found)
    if wanted is None:
        return present
    for value in (int(v) for v in wanted):
        if value not in found:
            raise UsageError(f"the map has no label {value} (it holds "
                             f"{', '.join(str(v) for v in present)})")
    return [int(v) for v in wanted]


def _label_box(value: int, low: Sequence[int], high: Sequence[int], chunks: List[Any],
               corners: List[Sequence[int]], convert: Any, dtype: Any) -> np.ndarray:
    """The box of samples ``low .. high`` holding ``value`` where the map does and 0 elsewhere,
    assembled from the chunks that hold the label (each starting at its ``corners``), each
    piece checked and converted by ``convert`` (to ``dtype``)."""
    label = dtype(value)
    box = np.zeros(tuple(h - l for l, h in zip(low, high)), dtype)
    for chunk, corner in zip(chunks, corners):
        start = [max(l, c) for l, c in zip(low, corner)]
        stop = [min(h, c + n) for h, c, n in zip(high, corner, chunk.shape)]
        part = chunk[tuple(slice(a - c, b - c) for a, b, c in zip(start, stop, corner))]
        part = convert(_aligned(part), "the label map")
        box[tuple(slice(a - l, b - l) for a, b, l in zip(start, stop, low))] = \
            np.where(part == label, label, dtype(0))
    return box


def _mesh_label(value: int, low: Sequence[int], high: Sequence[int], chunks: List[Any],
                corners: List[Sequence[int]], spacing, origin, options) -> dict:
    """One task of :func:`labels`' second pass: the label's meshes from its box (samples
    ``low .. high``, :func:`_label_box`). Samples of other labels are 0 in the box: the
    label's indicator is the same."""
    box = _label_box(value, low, high, chunks, corners, label_values, np.uint32)
    found = _voxlod.labels(box, spacing, origin, [int(value)], options)
    return found[0]


def _surface_label(value: int, low: Sequence[int], high: Sequence[int], chunks: List[Any],
                   corners: List[Sequence[int]], spacing, origin, normals: bool,
                   triangles: Optional[int]) -> dict:
    """One task of :func:`labels`' second pass without a filter: the label's marching-cubes
    mesh from its box (samples ``low .. high``, :func:`_label_box`), as uint32, reduced to
    about ``triangles`` when given. The label's cells all lie in its box grown by one voxel
    and are visited in the same order as in the whole map, so the mesh is the one-process mesh
    (positions equal up to the rounding of ``origin + index * spacing`` to float32), and so is
    its reduction, made from that mesh alone."""
    box = _label_box(value, low, high, chunks, corners, label_values, np.uint32)
    found, _ = _voxlod.label_surfaces(box, spacing, origin, [int(value)], False, None, normals,
                                      triangles)
    return found[0]


SMOOTH_ITERATIONS = 8
"""The λ|μ iterations of the shared surface when ``smooth`` is not given (the Rust
``SmoothingOptions::default().iterations``)."""


def shared_halo(smooth: Optional[int]) -> int:
    """The voxels by which :func:`labels` grows a block or a label's box for the shared
    surface: ``2 * smooth + 3 + R`` (``smooth`` defaulting to :data:`SMOOTH_ITERATIONS`, ``R``
    the restoring's most rounds, ``_voxlod.RESTORE_ROUNDS``: 23 by default).

    Each of the ``smooth`` λ|μ iterations is two passes (λ then μ), each pass moving a vertex
    towards the mean of the vertices its quad edges lead to, read from the pass before (the
    fused sweeps of ``smoothing/relax.rs`` are a Jacobi scheme): after ``2 * smooth`` passes a
    vertex depends on the vertices within ``2 * smooth`` rings, and a ring is one cell. A
    vertex's kind (interface, junction curve, fixed, border) comes from the eight voxels around
    its corner, one more voxel; one more keeps the box's own border (background outside, whose
    vertices are locked) off every vertex that counts. Each restoring round moves a vertex
    along its volume gradient, which its ring of triangles gives, one ring further per round;
    and a volume counts the triangles beside the vertex, one more."""
    return 2 * (SMOOTH_ITERATIONS if smooth is None else int(smooth)) + 3 + \
        _voxlod.RESTORE_ROUNDS


NEIGHBOUR_MARGIN = 3
"""Voxels around a neighbouring label's box that :func:`labels` takes in with ``shared`` and
``triangles``: its patches' vertices lie on the corners of its box grown by one, their kinds
(and so the locked junctions, the floors of its shares) depend on the voxels one further, and
the ring of vertices next to a locked one one further still."""


def _map_box(low: Sequence[int], high: Sequence[int], chunks: List[Any],
             corners: List[Sequence[int]]) -> np.ndarray:
    """The box of samples ``low .. high`` of the map with every label's value (uint32),
    assembled from the chunks that overlap it (each starting at its ``corners``), each piece
    checked as :func:`voxlod.labels` checks the map; on a worker."""
    box = np.zeros(tuple(h - l for l, h in zip(low, high)), np.uint32)
    for chunk, corner in zip(chunks, corners):
        start = [max(l, c) for l, c in zip(low, corner)]
        stop = [min(h, c + n) for h, c, n in zip(high, corner, chunk.shape)]
        if any(a >= b for a, b in zip(start, stop)):
            continue
        part = chunk[tuple(slice(a - c, b - c) for a, b, c in zip(start, stop, corner))]
        box[tuple(slice(a - l, b - l) for a, b, l in zip(start, stop, low))] = \
            label_values(_aligned(part), "the label map", start)
    return box


def _shared_label(value: int, chosen: List[int], low: Sequence[int], high: Sequence[int],
                  chunks: List[Any], corners: List[Sequence[int]], spacing, origin,
                  smooth: Optional[int], normals: bool, triangles: Optional[int],
                  pressures: Optional[List[Tuple[Any, Any]]] = None) -> dict:
    """One task of :func:`labels` with ``shared``: the shared surface of the box of samples
    ``low .. high`` holding every label (:func:`_map_box`), placed in the whole map (``origin``
    the whole map's), smoothed with the whole map's restoring ``pressures`` and reduced as in
    one process, and the mesh of ``value`` (the first of ``chosen``; the others are the labels
    whose shares limit its patches under a budget)."""
    box = _map_box(low, high, chunks, corners)
    found, _ = _voxlod.label_surfaces(box, spacing, origin, [int(v) for v in chosen], True,
                                      smooth, normals, triangles, tuple(low), pressures or [])
    return found[0]


def _shared_block_sums(low: Sequence[int], high: Sequence[int], owned_lo: Sequence[int],
                       owned_hi: Sequence[int], chunks: List[Any], corners: List[Sequence[int]],
                       spacing=None, origin=None, smooth: Optional[int] = None,
                       pressures: Optional[List[Tuple[Any, Any]]] = None) -> Tuple[Any, ...]:
    """One task of a restoring round of :func:`labels` with ``shared``: the restoring's sums of
    the corners ``owned_lo .. owned_hi`` (a chunk's) from the samples ``low .. high`` around
    them (:func:`_map_box`), smoothed with the rounds' ``pressures`` so far."""
    box = _map_box(low, high, chunks, corners)
    return _voxlod.shared_sums(box, spacing, origin, tuple(low), tuple(owned_lo),
                               tuple(owned_hi), smooth, pressures or [])


def _shared_pressures(array: Any, client: Any, spacing, origin,
                      smooth: Optional[int]) -> List[Tuple[Any, Any]]:
    """The volume restoring's pressures of the whole map's shared surface, round by round, as
    one process solves them: per round one task per chunk (its corners owned, its samples
    grown by :func:`shared_halo`) gives its sums, and the sums of all give the round's
    pressure, until the volumes are within the tolerance or ``_voxlod.RESTORE_ROUNDS`` rounds
    have run. Nothing to restore without smoothing."""
    if smooth == 0:
        return []
    halo = shared_halo(smooth)
    shape = tuple(int(n) for n in array.shape)
    grid_keys, bounds = _chunk_keys(array)
    blocks = []
    for start, stop in _chunk_bounds(array):
        low = [max(a - halo, 0) for a in start]
        high = [min(b + halo, n) for b, n in zip(stop, shape)]
        # The last chunk along an axis owns the map's last corner plane too.
        owned_hi = [b + (b == n) for b, n in zip(stop, shape)]
        parts, corners = _window_chunks(grid_keys, bounds, low, high)
        blocks.append((low, high, list(start), owned_hi, parts, corners))
    pressures: List[Tuple[Any, Any]] = []
    for _ in range(_voxlod.RESTORE_ROUNDS):
        task = functools.partial(_shared_block_sums, spacing=spacing, origin=origin,
                                 smooth=smooth, pressures=list(pressures))
        sums = _graph_results("voxlod-shared-sums", [(task,) + b for b in blocks], array,
                              client)
        pressure = _voxlod.shared_pressure(sums, smooth)
        if pressure is None:
            break
        pressures.append(pressure)
    return pressures


def labels(
    source: Any,
    *,
    client: Any = None,
    spacing: Sequence[float] = (1.0, 1.0, 1.0),
    labels: Optional[Sequence[int]] = None,
    levels: Optional[int] = None,
    origin: Sequence[float] = (0.0, 0.0, 0.0),
    shared: bool = False,
    smooth: Optional[int] = None,
    filter: Optional[str] = None,
    radius: Optional[float] = None,
    normals: bool = True,
    triangles: Optional[int] = None,
) -> List[LabelMesh]:
    """:func:`voxlod.labels` on a Dask cluster: one closed mesh (or chain of ``levels``
    levels) per label of a label map, the same meshes as in one process, from a map that need
    not fit in one.

    A first pass, one task per chunk, lists each chunk's labels with their voxel counts and
    boxes. Then one task per label meshes it as :func:`voxlod.labels` does:

    - by default (marching cubes of its voxels, reduced to ``triangles`` when given) or with
      ``levels``, ``filter`` or ``radius`` (its filtered levels), from the label's box grown by
      one voxel (cut to the map), assembled from the chunks that hold that label only
      (elsewhere in the box the label's indicator is 0). A chunk that holds no label is read
      once, one that holds some twice (once per pass, shared by its labels).
    - with ``shared=True``, from the label's box grown by a halo of :func:`shared_halo`
      voxels, ``2 * smooth + 3 + 4`` (23 for the default 8 iterations; cut to the map, whose
      outside is background as in one process), holding every label's values there and
      assembled from every chunk that overlaps it: the task makes the box's shared surface
      (surface nets, smoothed) and keeps the label's mesh. Smoothing is local: each λ|μ
      iteration is two passes, each reaching one ring of vertices (one cell) further, so the
      halo holds everything the label's vertices see through the smoothing and the
      restoring's rounds, plus the voxels that decide the vertices' kinds. With ``triangles``, the box also takes in the boxes
      (grown by :data:`NEIGHBOUR_MARGIN`) of the labels asked for whose boxes touch the
      label's: a patch between two labels is reduced towards the smaller of their two shares,
      and a neighbour's share depends on all its patches. The cost: each task meshes its whole
      grown box, so every voxel is meshed by every label whose grown box covers it (about
      ``((side + 2 * halo) / side)³`` times the work of one process for labels ``side``
      voxels wide, more with ``triangles``).

      The volume restoring is not local: one process keeps each label's volume by one
      pressure per label, solved over all the labels that touch, round by round. So before
      the label tasks, each round runs one task per chunk (the chunk's corners owned, its
      samples grown by the same halo), which smooths its box with the rounds so far and gives
      its share of the restoring's sums (each label pair's volume and Gram weight over the
      triangles and vertices it owns, summed exactly in fixed point); the shares added give
      the whole map's sums, and from them the round's pressures, as one process solves them,
      until every volume is within the tolerance (usually one or two rounds: the map is read
      once per round). The label tasks then apply those pressures. Every task places its box
      in the whole map (its corners numbered from the map's first), so the meshes are the
      one-process meshes bit for bit, with and without ``triangles``, and the two meshes of an
      interface share their vertices' positions exactly.

    Parameters
    ----------
    source : Zarr path, dask array or array, shape (nz, ny, nx)
        The label map (integers; 0 is background).
    client : dask.distributed.Client, optional
        Where to run; default: the current client, else Dask's default scheduler.
    spacing, labels, levels, origin, shared, smooth, filter, radius, normals, triangles
        As for :func:`voxlod.labels` (``shared``, ``smooth`` and ``triangles`` not with the
        filtered levels, ``smooth`` only with ``shared``).

    Returns
    -------
    list of :class:`voxlod.LabelMesh`, by increasing label (or in the order of ``labels``), as
    :func:`voxlod.labels` returns them.

    Examples
    --------
    >>> import numpy as np, dask.array as da, voxlod, voxlod.dask
    >>> seg = np.zeros((12, 12, 20), np.uint8)
    >>> seg[2:10, 2:10, 2:9] = 1
    >>> seg[2:10, 2:10, 9:17] = 2
    >>> found = voxlod.dask.labels(da.from_array(seg, chunks=6), levels=2)
    >>> [(m.label, m.voxels, len(m.levels)) for m in found]
    [(1, 448, 2), (2, 512, 2)]
    >>> found = voxlod.dask.labels(da.from_array(seg, chunks=6), shared=True, smooth=0)
    >>> alone = voxlod.labels(seg, shared=True, smooth=0)
    >>> [len(m.faces) for m in found] == [len(m.faces) for m in alone]
    True
    """
    filtered = levels is not None or filter is not None or radius is not None
    check_surface_options(filtered, bool(shared), smooth, triangles)
    options = label_options(1 if levels is None else levels, filter or "hypercone",
                            1.0 if radius is None else radius, normals)
    smooth = None if smooth is None else int(smooth)
    triangles = None if triangles is None else int(triangles)
    array = as_dask_array(source)
    check_label_dtype(array.dtype, "the label map")
    spacing, origin = triple(spacing, "spacing"), triple(origin, "origin")
    found = _find_labels(array, client)
    grid_keys, bounds = _chunk_keys(array)
    keys, chunks = grid_keys.ravel(), _chunk_bounds(array)
    shape = tuple(int(n) for n in array.shape)
    chosen = _chosen_labels(found, labels)
    near = _touching_boxes(found, chosen) if shared and triangles is not None else {}
    if shared:
        # The pressures are the same for every label's task: bound once, not in each task.
        shared_label = functools.partial(
            _shared_label, pressures=_shared_pressures(array, client, spacing, origin, smooth))
    tasks = []
    for value in chosen:
        _, first, last, holding = found[value]
        if shared:
            touching = near[value] if triangles is not None else []
            low, high, limiting = _shared_box(value, found, touching, shape, shared_halo(smooth))
            parts, corners = _window_chunks(grid_keys, bounds, low, high)
            tasks.append((shared_label, value, limiting, low, high, parts, corners, spacing,
                          origin, smooth, bool(normals), triangles))
            continue
        low = [max(f - 1, 0) for f in first]
        high = [min(l + 2, n) for l, n in zip(last, shape)]
        box_origin = tuple(o + l * s for o, l, s in zip(origin, low, spacing))
        holding_keys, corners = [keys[n] for n in holding], [chunks[n][0] for n in holding]
        if filtered:
            tasks.append((_mesh_label, value, low, high, holding_keys, corners, spacing,
                          box_origin, options))
        else:
            tasks.append((_surface_label, value, low, high, holding_keys, corners, spacing,
                          box_origin, bool(normals), triangles))
    results = _graph_results("voxlod-label-meshes", tasks, array, client)
    if filtered:
        meshes = [label_mesh(d) for d in results]
        warn_empty_levels(meshes)
        return meshes
    resolution = max(array.shape)
    return [LabelMesh(label=d["label"], voxels=d["voxels"], voxel_volume=d["voxel_volume"],
                      levels=[Level(vertices=d["vertices"], faces=d["faces"],
                                    normals=d["normals"], resolution=resolution, genus=None)])
            for d in results]


def _shared_box(value: int, found: dict, touching: List[int], shape: Sequence[int],
                halo: int) -> Tuple[List[int], List[int], List[int]]:
    """The box (first sample, end) of ``value``'s task with ``shared``: its box grown by
    ``halo`` and the boxes of the labels ``touching`` it (under a budget, its possible
    neighbours, whose shares limit its patches: :func:`_touching_boxes`) grown by
    :data:`NEIGHBOUR_MARGIN`; cut to the map. Also the labels to ask the task for: ``value``
    first, then those neighbours."""
    _, first, last, _ = found[value]
    low = [f - halo for f in first]
    high = [l + 1 + halo for l in last]
    for other in touching:
        _, o_first, o_last, _ = found[other]
        low = [min(a, of - NEIGHBOUR_MARGIN) for a, of in zip(low, o_first)]
        high = [max(b, ol + 1 + NEIGHBOUR_MARGIN) for b, ol in zip(high, o_last)]
    low = [max(a, 0) for a in low]
    high = [min(b, n) for b, n in zip(high, shape)]
    return low, high, [int(value)] + [int(o) for o in touching]


TOUCH_BUCKET = 64
"""Side, in voxels, of the buckets by which :func:`_touching_boxes` finds boxes that touch."""


def _touching_boxes(found: dict, chosen: List[int]) -> dict:
    """Per label of ``chosen``, the other labels of ``chosen`` whose boxes touch or overlap its
    own (grown by one voxel), in the order of ``chosen``. Each box is entered in the buckets of
    :data:`TOUCH_BUCKET` voxels it covers, so only labels sharing a bucket are compared: about
    linear in the labels for boxes smaller than a bucket, rather than quadratic."""
    buckets: dict = {}
    cells = {}
    for n, value in enumerate(chosen):
        _, first, last, _ = found[value]
        ranges = [range((f - 1) // TOUCH_BUCKET, (l + 1) // TOUCH_BUCKET + 1)
                  for f, l in zip(first, last)]
        cells[value] = list(itertools.product(*ranges))
        for cell in cells[value]:
            buckets.setdefault(cell, []).append(n)
    out = {}
    for value in chosen:
        _, first, last, _ = found[value]
        seen = set()
        for cell in cells[value]:
            seen.update(buckets[cell])
        near = []
        for n in sorted(seen):
            other = chosen[n]
            if other == value:
                continue
            _, o_first, o_last, _ = found[other]
            if all(of <= l + 1 and f <= ol + 1
                   for f, l, of, ol in zip(first, last, o_first, o_last)):
                near.append(other)
        out[value] = near
    return out


def precomputed(
    directory: Any,
    source: Any,
    *,
    client: Any = None,
    spacing: Sequence[float] = (1.0, 1.0, 1.0),
    origin: Sequence[float] = (0.0, 0.0, 0.0),
    levels: int = 3,
    quantization_bits: int = 16,
    unit: str = "nm",
    sharding: str = "auto",
    shared: bool = False,
    filter: Optional[str] = None,
    radius: Optional[float] = None,
) -> dict:
    """:func:`voxlod.precomputed` with the labels meshed on a Dask cluster
    (:func:`labels`, each label's box where its chunks are; with ``shared``, the shared
    surface smoothed with the whole map's restoring; with ``filter`` or ``radius``, each
    label's filtered levels): the same bytes as one process writes, since the meshes are the
    same and the layer's bytes depend only on them and the map. The map itself is gathered
    once to write its chunks."""
    array = as_dask_array(source)
    filtered = filter is not None or radius is not None
    pyramid = {"levels": levels, "filter": filter, "radius": radius} if filtered else {}
    with quiet_empty_levels():
        meshes = labels(array, client=client, spacing=spacing, origin=origin, normals=False,
                        shared=shared, **pyramid)
    from ._labels import precomputed as write
    return write(directory, np.asarray(array), meshes, spacing=spacing, origin=origin,
                 levels=levels, quantization_bits=quantization_bits, unit=unit,
                 sharding=sharding, filter=filter, radius=radius)
