"""The library's levels of detail, files and measurements (``voxlod::lod``, ``read_mesh``,
``inspect``, ``compare``, …) for Python. Meshes are ``(vertices, faces)`` arrays in world
(x, y, z) coordinates, as the command line writes them; volumes are C-ordered arrays of shape
``(nz, ny, nx)`` with spacing and origin given in array-axis order (as for
:func:`voxlod.marching_cubes`)."""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import _voxlod
from ._arrays import check_fits, triple, volume_array
from .errors import UsageError

Progress = Callable[[int, int, str], Optional[bool]]


@dataclass
class Level:
    """One level of detail: a closed, consistently oriented mesh (empty when the filter
    removed the object) and its figures."""

    vertices: np.ndarray
    """(V, 3) float32, world (x, y, z) coordinates."""
    faces: np.ndarray
    """(F, 3) int32, wound counter-clockwise seen from outside."""
    normals: np.ndarray
    """(V, 3) float32 unit normals from the filtered density's gradient, pointing outwards."""
    resolution: int
    """Samples across the longest side of the source's box."""
    genus: Optional[int]
    """The genus of the surface (None where undefined, e.g. an empty level)."""
    plan: Dict[str, Any] = field(default_factory=dict)
    """The level's grid, voxel size and filter radius (world units)."""
    topology: Dict[str, Any] = field(default_factory=dict)
    """Vertices, triangles, edges, components, boundary loops, Euler characteristic, …"""
    seconds: float = 0.0
    """Sampling and contouring time."""
    budget: Optional[Dict[str, Any]] = None
    """With ``triangles`` or ``error``: the budget pipeline's report of the level (the budget,
    the chosen resolution and isodensity, the final stage and its error bound, the measured
    two-sided Hausdorff and mean distance to the input, genus, components, handles removed,
    ``simplified_from``, …), as ``voxlod lod --triangles … --json`` gives it."""


def _levels(result: Tuple[List[dict], List[str]]) -> List[Level]:
    import warnings

    levels, notes = result
    for note in notes:
        warnings.warn(note, stacklevel=3)
    return [
        Level(vertices=d["vertices"], faces=d["faces"], normals=d["normals"],
              resolution=d["resolution"], genus=d["genus"], plan=d["plan"],
              topology=d["topology"], seconds=d["sample_seconds"] + d["contour_seconds"],
              budget=d.get("budget"))
        for d in levels
    ]


def _mesh(vertices: Any, faces: Any, name: str = "mesh") -> Tuple[np.ndarray, np.ndarray]:
    """``(vertices, faces)`` as C-ordered float32 (V, 3) and uint32 (F, 3) arrays."""
    v = np.asarray(vertices)
    f = np.asarray(faces)
    if v.ndim != 2 or v.shape[1] != 3 or f.ndim != 2 or f.shape[1] != 3:
        raise UsageError(f"{name}: vertices and faces must be (n, 3) arrays, not shapes "
                         f"{v.shape} and {f.shape}")
    if not np.issubdtype(f.dtype, np.integer) and f.size:
        raise UsageError(f"{name}: faces must be integers, not {f.dtype}")
    if f.size and (f.min() < 0 or f.max() >= len(v)):
        raise UsageError(f"{name}: a face refers to vertex {int(f.min()) if f.min() < 0 else int(f.max())}"
                         f" of {len(v)}")
    check_fits(v.size * 4 + f.size * 4, f"{name}'s arrays")
    return np.ascontiguousarray(v, np.float32), np.ascontiguousarray(f, np.uint32)


def _resolutions(resolution: int, levels: int, resolutions: Optional[Sequence[int]]) -> List[int]:
    if resolutions is not None:
        return [int(r) for r in resolutions]
    if levels < 1 or resolution < 1:
        raise UsageError(f"resolution ({resolution}) and levels ({levels}) must be at least 1")
    return [max(int(resolution) >> k, 2) for k in range(int(levels))]


def lod(
    vertices: Any,
    faces: Any,
    resolution: Optional[int] = None,
    levels: int = 6,
    filter: str = "hypercone",
    *,
    resolutions: Optional[Sequence[int]] = None,
    radius: float = 1.0,
    iso: Optional[float] = None,
    normals: bool = True,
    triangles: Optional[Sequence[int]] = None,
    error: Union[None, float, str] = None,
    then: str = "auto",
    closed: bool = False,
    time_cap: float = 1.0,
    progress: Optional[Progress] = None,
) -> List[Level]:
    """Levels of detail of a triangle mesh (He et al. 1995, §2): the mesh's solid is sampled,
    filtered with the hyper-cone (equation 3) or the Gaussian, and contoured, each level from
    the original with a filter of one voxel of its own grid. With ``triangles`` (or
    ``error``), one level per budget instead, by the budget pipeline of ``voxlod lod
    --triangles`` (§5: the voxel level that filters away what the budget cannot afford, then a
    geometric simplifier).

    Parameters
    ----------
    vertices, faces : (V, 3) and (F, 3) arrays
        The mesh, ideally closed; holes are closed with fans and soups welded first.
    resolution, levels : int
        ``levels`` levels from ``resolution`` samples across the longest side, halving. Without
        ``resolution`` (and ``resolutions``), the finest level is chosen from the mesh's own
        triangle count, at most 256 (the library's default, as ``voxlod lod`` without
        ``--resolution``).
    filter : {'hypercone', 'gaussian'}
    resolutions : sequence of int, optional
        The resolutions themselves, instead of ``resolution`` and ``levels``.
    radius : float
        Filter support radius in voxels of each level.
    iso : float, optional
        The isodensity, strictly between 0 and 1 (default 0.5).
    triangles : sequence of int, optional
        Triangle budgets, one level each, in the order given, each within 10 % (or its
        ``budget["note"]`` says why not); the genus never rises from a larger budget's level to
        a smaller one's. Excludes ``resolution``, ``levels`` and ``resolutions``.
    error : float or str, optional
        An error target: a distance (``0.02``) or a percentage of the bounding box's diagonal
        (``"0.5%"``); alone, one level within it; with ``triangles``, the bound of every level's
        geometric stage.
    then : {'auto', 'quadric', 'envelope', 'none'}
        The geometric stage after the voxel level (``auto``: the quadric collapse, and the
        simplification envelopes where it stalls above the budget).
    closed : bool
        Keep the caps that sampling puts over an open mesh's holes (watertight levels); by
        default the openings are kept.
    time_cap : float
        CPU seconds (all threads) each budget's search may spend per isodensity trying
        neighbouring resolutions (``float('inf')``: all of them); CPU time, so that a busy
        machine gives the same levels as a quiet one.
    progress : callable(done, total, what) -> bool or None, optional
        Called after each step; return False to stop (raises :class:`voxlod.Cancelled`).
        Ctrl-C stops the work too (``KeyboardInterrupt``).

    Returns
    -------
    list of :class:`Level`, finest first.

    Examples
    --------
    >>> import numpy as np, voxlod
    >>> v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], np.float32)
    >>> f = np.array([[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]])
    >>> levels = voxlod.lod(v, f, resolution=24, levels=3)
    >>> [level.resolution for level in levels], levels[0].genus
    ([24, 12, 6], 0)
    """
    v, f = _mesh(vertices, faces)
    given = resolution is not None or resolutions is not None
    if triangles is None and error is None:
        options = (_resolutions(256 if resolution is None else resolution, levels, resolutions),
                   str(filter), float(radius), iso, bool(normals), given)
        return _levels(_voxlod.lod_mesh((v, f), options, progress))
    if given:
        raise UsageError("triangles and error choose each level's resolution: give neither "
                         "resolution nor resolutions with them")
    budgets = None if triangles is None else [_budget(t) for t in triangles]
    options = ([256], str(filter), float(radius), iso, bool(normals), False)
    asked = (budgets, None if error is None else str(error), str(then), bool(closed),
             float(time_cap))
    return _levels(_voxlod.lod_budgets((v, f), options, asked, progress))


def _budget(count: Any) -> int:
    """A triangle budget as a positive int below 2⁶³ (a bool, a fraction, a string refused)."""
    problem = UsageError(f"triangles: {count!r} is not a positive whole number of triangles")
    if isinstance(count, (bool, str, bytes)):
        raise problem
    try:
        whole = float(count).is_integer() and 1 <= int(count) < 2**63
    except (TypeError, ValueError, OverflowError):
        raise problem from None
    if not whole:
        raise problem
    return int(count)


def lod_volume(
    volume: Any,
    spacing: Sequence[float] = (1.0, 1.0, 1.0),
    *,
    threshold: Optional[float] = None,
    direct: bool = False,
    iso: Optional[float] = None,
    origin: Sequence[float] = (0.0, 0.0, 0.0),
    resolution: int = 256,
    levels: int = 6,
    filter: str = "hypercone",
    resolutions: Optional[Sequence[int]] = None,
    radius: float = 1.0,
    normals: bool = True,
    progress: Optional[Progress] = None,
) -> List[Level]:
    """Levels of detail of a scanned volume, by either route of the paper's §4.

    ``threshold=T``: the solid of the samples ``>= T`` (trilinearly interpolated) is filtered,
    and ``iso`` is a density between 0 and 1 (default 0.5). ``direct=True``: the data itself is
    filtered, and ``iso`` (required) is in its units.

    Parameters
    ----------
    volume : (nz, ny, nx) array
        Any real dtype (converted to float32).
    spacing, origin : three floats
        In array-axis order (axis 0, 1, 2), like :func:`voxlod.marching_cubes`'s ``spacing``.
    Other parameters as for :func:`lod`.

    Returns
    -------
    list of :class:`Level`, finest first, in world (x, y, z) = (axis 2, 1, 0) coordinates.

    Examples
    --------
    >>> import numpy as np, voxlod
    >>> z, y, x = np.mgrid[-10:11, -10:11, -10:11]
    >>> ct = np.where(x**2 + y**2 + z**2 < 64, 1000, 0).astype(np.int16)
    >>> levels = voxlod.lod_volume(ct, spacing=(2.0, 1.0, 1.0), threshold=500, resolution=32, levels=2)
    >>> [level.genus for level in levels]
    [0, 0]
    """
    if (threshold is None) == (not direct):
        raise UsageError("give either threshold=T (the solid of the samples >= T) or direct=True "
                         "(the data filtered itself, with iso in its units)")
    array = volume_array(volume, np.float32, "volume")
    options = (_resolutions(resolution, levels, resolutions), str(filter), float(radius), iso,
               bool(normals), True)
    return _levels(_voxlod.lod_volume(
        array, triple(spacing, "spacing"), triple(origin, "origin"),
        None if threshold is None else float(threshold), options, progress))


def read_mesh(path: "os.PathLike[str] | str") -> Tuple[np.ndarray, np.ndarray]:
    """Reads a mesh (OBJ, PLY, STL, OFF, VTK): ``(vertices, faces)``, polygons ear-clipped, STL
    soups welded.

    >>> import voxlod, tempfile, os                            # doctest: +SKIP
    >>> vertices, faces = voxlod.read_mesh("bunny.obj")        # doctest: +SKIP
    """
    vertices, faces, _ = _voxlod.read_mesh(os.fspath(path))
    return vertices, faces


def write_mesh(path: "os.PathLike[str] | str", vertices: Any, faces: Any) -> None:
    """Writes a mesh by the extension (``.ply`` binary with normals, ``.obj``, ``.stl``,
    ``.vtp``, ``.vtk``), through a temporary file that replaces ``path`` only when complete.

    >>> import numpy as np, voxlod, tempfile, os
    >>> path = os.path.join(tempfile.mkdtemp(), "t.ply")
    >>> voxlod.write_mesh(path, np.eye(3), [[0, 1, 2]])
    >>> voxlod.read_mesh(path)[1].tolist()
    [[0, 1, 2]]
    """
    v, f = _mesh(vertices, faces)
    _voxlod.write_mesh(os.fspath(path), (v, f))


def read_volume(
    path: "os.PathLike[str] | str",
    *,
    shape: Optional[Sequence[int]] = None,
    dtype: Optional[str] = None,
    endian: str = "little",
    spacing: Sequence[float] = (1.0, 1.0, 1.0),
    origin: Sequence[float] = (0.0, 0.0, 0.0),
) -> Tuple[np.ndarray, Tuple[float, float, float], Tuple[float, float, float]]:
    """Reads a volume (NRRD, VTK ImageData, NIfTI, MetaImage; headerless raw with ``shape``,
    ``dtype`` in u8, i16, u16, i32, f32, ``endian``, ``spacing``, ``origin``, all in array-axis
    order): ``(samples, spacing, origin)``, samples a float32 array of shape (nz, ny, nx).

    >>> import voxlod                                                       # doctest: +SKIP
    >>> ct, spacing, origin = voxlod.read_volume("CThead_256x256x113_uint16be.raw",
    ...     shape=(113, 256, 256), dtype="u16", endian="big", spacing=(2, 1, 1))  # doctest: +SKIP
    """
    raw = None
    if shape is not None or dtype is not None:
        if shape is None or dtype is None or len(shape) != 3:
            raise UsageError("a raw volume needs its shape (three numbers) and dtype")
        raw = (tuple(int(s) for s in shape), str(dtype), str(endian), triple(spacing, "spacing"),
               triple(origin, "origin"))
    samples, spacing_, origin_ = _voxlod.read_volume(os.fspath(path), raw)
    return samples, tuple(spacing_), tuple(origin_)


def write_volume(
    path: "os.PathLike[str] | str",
    volume: Any,
    spacing: Sequence[float] = (1.0, 1.0, 1.0),
    origin: Sequence[float] = (0.0, 0.0, 0.0),
) -> None:
    """Writes a volume by the extension (``.nrrd``, ``.nhdr``, ``.vti``, ``.vtk``, ``.mha``,
    ``.mhd``, ``.raw``) as float32; spacing and origin in array-axis order.

    >>> import numpy as np, voxlod, tempfile, os
    >>> path = os.path.join(tempfile.mkdtemp(), "v.nrrd")
    >>> voxlod.write_volume(path, np.arange(24.0).reshape(2, 3, 4), spacing=(2.0, 1.0, 0.5))
    >>> samples, spacing, origin = voxlod.read_volume(path)
    >>> samples.shape, spacing
    ((2, 3, 4), (2.0, 1.0, 0.5))
    """
    array = volume_array(volume, np.float32, "volume")
    _voxlod.write_volume(os.fspath(path), array, triple(spacing, "spacing"), triple(origin, "origin"))


def inspect(vertices: Any, faces: Any, *, welded: bool = True) -> Dict[str, Any]:
    """A mesh's topology and health, the report of ``voxlod inspect --json``: components,
    boundary loops, non-manifold edges and vertices, orientation, degenerate, duplicate and
    zero-area triangles, Euler characteristic, genus, area, volume (counted after welding
    coincident vertices unless ``welded=False``), and ``notes`` in words.

    >>> import numpy as np, voxlod
    >>> v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], np.float32)
    >>> report = voxlod.inspect(v, [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]])
    >>> report["closed_manifold"], report["genus"], round(report["volume"], 4)
    (True, 0, 0.1667)
    """
    v, f = _mesh(vertices, faces)
    report, notes = _voxlod.inspect((v, f), bool(welded))
    report["notes"] = notes
    return report


def compare(a: Tuple[Any, Any], b: Tuple[Any, Any], *, samples: int = 100_000,
            seed: Optional[int] = None) -> Dict[str, Any]:
    """Two-sided distance between two meshes, each ``(vertices, faces)``: the dict of
    ``voxlod compare --json`` (``a``, ``b``, ``a_triangles``, ``b_triangles``, ``hausdorff``,
    ``mean``, ``rms``, their ``_fraction`` of the common diagonal, ``samples``, ``diagonal``,
    ``seconds``, ``first_to_second``, ``second_to_first``, ``read_seconds``, ``total_seconds``,
    ``warnings``); ``a`` and ``b`` name the inputs (``"a"``/``"b"``, or the paths given).

    >>> import numpy as np, voxlod
    >>> v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], np.float32)
    >>> f = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]]
    >>> voxlod.compare((v, f), (v + [0, 0, 0.1], f), samples=1000)["hausdorff"] > 0.05
    True
    """
    import time

    start = time.perf_counter()
    names, meshes = [], []
    for which, mesh in (("a", a), ("b", b)):
        if isinstance(mesh, (str, os.PathLike)):
            names.append(os.fspath(mesh))
            mesh = read_mesh(mesh)
        else:
            names.append(which)
        meshes.append(_mesh(*mesh, name=which))
    read_seconds = time.perf_counter() - start
    report = _voxlod.compare(meshes[0], meshes[1], int(samples), seed)
    result = {"a": names[0], "b": names[1], "a_triangles": len(meshes[0][1]),
              "b_triangles": len(meshes[1][1])}
    warnings = report.pop("warnings")
    result.update(report)
    result.update(read_seconds=read_seconds, total_seconds=time.perf_counter() - start,
                  warnings=warnings)
    return result


def cluster(vertices: Any, faces: Any, cells: int = 64, *, method: str = "rossignac-borrel",
            levels: int = 1) -> List[Dict[str, Any]]:
    """Vertex clustering, the baselines the paper compares with: Rossignac–Borrel (1993) on a
    grid of ``cells`` per side (``levels`` levels by octree merging) or Low–Tan
    (``method="low-tan"``, floating cells). Per level a dict with ``vertices``, ``faces``,
    ``normals``, ``lines`` (dangling edges), ``points`` (isolated points) and ``report``.

    >>> import numpy as np, voxlod, trimesh
    >>> ball = trimesh.creation.icosphere(subdivisions=4)
    >>> level, = voxlod.cluster(ball.vertices, ball.faces, cells=8)
    >>> len(level["faces"]) < len(ball.faces)
    True
    """
    v, f = _mesh(vertices, faces)
    return _voxlod.cluster((v, f), str(method), int(cells), int(levels))


def envelope(vertices: Any, faces: Any, epsilon: Any = 0.01, *, relative: bool = True,
             tight: bool = False, progress: Optional[Progress] = None) -> List[Dict[str, Any]]:
    """Simplification envelopes (Varshney et al. 1995): every point of the result within ε of
    the input and back, same genus. ``epsilon`` is one value or a list (one level each, each
    from the one before), a fraction of the bounding-box diagonal (``relative=True``) or in
    mesh units. Per level a dict with ``vertices``, ``faces``, ``normals``, ``report``.

    >>> import numpy as np, voxlod, trimesh
    >>> ball = trimesh.creation.icosphere(subdivisions=4)
    >>> level, = voxlod.envelope(ball.vertices, ball.faces, 0.02)
    >>> len(level["faces"]) < len(ball.faces) / 4
    True
    """
    v, f = _mesh(vertices, faces)
    epsilons = [float(e) for e in np.atleast_1d(epsilon)]
    return _voxlod.envelope((v, f), epsilons, progress, relative=bool(relative), tight=bool(tight))


def layers(vertices: Any, faces: Any, error: float = 0.025, *, resolution: int = 128,
           filter: str = "hypercone", progress: Optional[Progress] = None) -> List[Dict[str, Any]]:
    """Multi-layer translucent shells (paper §3, equations 4–6): the fewest isosurfaces of one
    filtered volume whose piecewise-constant profile is within ``error`` of the filter's
    half-space profile. Innermost (opaque) first, each a dict with ``vertices``, ``faces``,
    ``normals``, ``isodensity``, ``translucency`` and ``alpha``.

    >>> import numpy as np, voxlod, trimesh
    >>> ball = trimesh.creation.icosphere(subdivisions=3)
    >>> shells = voxlod.layers(ball.vertices, ball.faces, 0.025, resolution=24)
    >>> len(shells), shells[0]["translucency"]
    (5, 0.0)
    """
    v, f = _mesh(vertices, faces)
    return _voxlod.layers((v, f), float(error), int(resolution), str(filter), progress)
