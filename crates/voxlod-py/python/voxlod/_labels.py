"""Label maps (segmentations) to meshes: one closed, outward mesh per structure, every label
meshed in one pass without a filter (the library's ``voxlod::label_surfaces``: marching cubes
per label, or surface nets shared between neighbours), or each with its own chain of filtered
levels (``voxlod::labels``; each label's indicator thresholded at ½ and filtered as in the
paper's §4 thresholding route); and :class:`Mesher`, zmesh's interface on the former."""

from __future__ import annotations

import contextlib
from dataclasses import dataclass, field
from typing import Any, Iterator, List, Optional, Sequence, Tuple

import numpy as np

from . import _voxlod
from ._arrays import triple, volume_array
from ._facade import Level, _levels
from .errors import InputError, UsageError


@dataclass
class LabelMesh:
    """The meshes of one label of a map."""

    label: int
    """The label value."""
    voxels: int
    """How many voxels of the map carry it."""
    voxel_volume: float
    """``voxels`` times the volume of one voxel (world units cubed): what the mesh of level 0
    encloses, up to the smoothing of the voxel staircase."""
    levels: List[Level] = field(default_factory=list)
    """Its levels of detail, finest first (level 0 at the map's finest spacing)."""

    @property
    def vertices(self) -> np.ndarray:
        """The finest level's vertices."""
        return self.levels[0].vertices

    @property
    def faces(self) -> np.ndarray:
        """The finest level's faces."""
        return self.levels[0].faces


def check_surface_options(filtered: bool, shared: bool, smooth: Optional[int],
                           triangles: Optional[int]) -> None:
    """Refuses the options that do not go together in :func:`labels` (``filtered``: with
    ``levels``, ``filter`` or ``radius``), shared by :func:`voxlod.dask.labels`."""
    if filtered:
        if shared or smooth is not None:
            raise UsageError("shared and smooth mesh the labels together without a filter: "
                             "they do not go with levels, filter or radius")
        if triangles is not None:
            raise UsageError("triangles reduces the one-pass surfaces: it does not go with "
                             "levels, filter or radius")
        return
    if smooth is not None and not shared:
        raise UsageError("smooth smooths the shared surface: pass shared=True")
    if smooth is not None and int(smooth) < 0:
        raise UsageError(f"smooth must be 0 or more iterations, not {smooth}")
    if triangles is not None and int(triangles) < 4:
        raise UsageError(f"triangles must be at least 4 (a closed surface needs four), "
                         f"not {triangles}")


def labels(
    volume: Any,
    spacing: Sequence[float] = (1.0, 1.0, 1.0),
    labels: Optional[Sequence[int]] = None,
    levels: Optional[int] = None,
    *,
    origin: Sequence[float] = (0.0, 0.0, 0.0),
    shared: bool = False,
    smooth: Optional[int] = None,
    filter: Optional[str] = None,
    radius: Optional[float] = None,
    normals: bool = True,
    triangles: Optional[int] = None,
) -> List[LabelMesh]:
    """One closed, outward mesh per label of a label map, as zmesh, igneous and mesh-n-bone
    make them; or a chain of filtered levels per label.

    By default every label is meshed in one pass over the map, on every core, by marching
    cubes of its voxels (the isosurface ½ of the label's indicator, the surface zmesh makes).
    With ``shared=True`` the labels are meshed together by surface nets (Frisken 2022, as
    VTK's ``vtkSurfaceNets3D``): every interface between two labels is meshed once and used by
    both, so neighbours meet without gap or overlap, then smoothed by ``smooth`` λ|μ iterations
    (default 8; 0 keeps the voxels' faces) with each vertex kept within half a voxel of its
    corner and each label's volume kept. With ``levels``, ``filter`` or ``radius``, each
    label's indicator is filtered and contoured instead (the paper's §4 thresholding route),
    ``levels`` levels at halving resolution, each cleaned of slivers.

    Parameters
    ----------
    volume : (nz, ny, nx) array of labels
        0 is background; labels are whole numbers from 0 to 4294967295 (any integer or float
        dtype holding such values).
    spacing, origin : three floats
        In array-axis order (axis 0, 1, 2), like :func:`voxlod.marching_cubes`'s ``spacing``.
    labels : sequence of int, optional
        Only these labels (each must be in the map), in this order; all non-zero labels, in
        increasing order, by default.
    levels : int, optional
        Filtered levels per label, each at half the resolution of the one before.
    shared, smooth
        The shared surface and its smoothing iterations (not with the filtered levels).
    triangles : int, optional
        Each label's mesh reduced to at most about this many triangles (at least 4; not with
        the filtered levels). With ``shared`` the shared surface is simplified patch by patch
        with the junctions between three labels locked, so neighbours still share their
        triangles; a label whose locked junctions hold more stays above.
    filter, radius
        The filtered levels' filter (``hypercone`` or ``gaussian``) and radius in voxels.
    normals : bool
        Per-vertex normals (the surface's area-weighted, or the filtered density's gradient).

    Returns
    -------
    list of :class:`LabelMesh`, meshes in world (x, y, z) = (axis 2, 1, 0) coordinates.

    Examples
    --------
    >>> import numpy as np, voxlod
    >>> seg = np.zeros((12, 12, 20), np.uint32)
    >>> seg[2:10, 2:10, 2:9] = 1
    >>> seg[2:10, 2:10, 9:17] = 4000000000
    >>> [(m.label, m.voxels, len(m.faces) > 0) for m in voxlod.labels(seg, shared=True)]
    [(1, 448, True), (4000000000, 512, True)]
    >>> [(m.label, len(m.levels)) for m in voxlod.labels(seg % 7, levels=2)]
    [(1, 2), (3, 2)]
    """
    chosen = None if labels is None else [int(v) for v in labels]
    filtered = levels is not None or filter is not None or radius is not None
    check_surface_options(filtered, bool(shared), smooth, triangles)
    if filtered:
        options = label_options(1 if levels is None else levels, filter or "hypercone",
                                1.0 if radius is None else radius, normals)
        found = _voxlod.labels(label_values(volume, "volume"), triple(spacing, "spacing"),
                               triple(origin, "origin"), chosen, options)
        meshes = [label_mesh(d) for d in found]
        warn_empty_levels(meshes)
        return meshes
    if chosen is not None and any(not 0 < v <= 2**32 - 1 for v in chosen):
        raise UsageError(f"labels are whole numbers from 1 to 4294967295, not {chosen}")
    array = label_values(volume, "volume")
    found, _ = _voxlod.label_surfaces(array, triple(spacing, "spacing"), triple(origin, "origin"),
                                      chosen, bool(shared),
                                      None if smooth is None else int(smooth), bool(normals),
                                      None if triangles is None else int(triangles))
    resolution = max(array.shape)
    return [LabelMesh(label=d["label"], voxels=d["voxels"], voxel_volume=d["voxel_volume"],
                      levels=[Level(vertices=d["vertices"], faces=d["faces"], normals=d["normals"],
                                    resolution=resolution, genus=None)])
            for d in found]


def label_values(volume: Any, name: str, offset: Sequence[int] = (0, 0, 0)) -> np.ndarray:
    """A label map (or a piece of one whose first sample is at ``offset`` in the whole map) as
    the C-ordered uint32 array the Rust side reads; values that are not labels (negative,
    fractional, not finite, above 2**32 - 1) are refused naming the first by its index in the
    whole map."""
    array = np.asarray(volume)
    check_label_dtype(array.dtype, name)
    unbounded = array.dtype.kind in "if" or (array.dtype.kind == "u" and array.dtype.itemsize > 4)
    if unbounded and array.size:
        valid = (array >= 0) & (array <= 2**32 - 1)
        if array.dtype.kind == "f":
            valid &= np.isfinite(array) & (np.floor(array) == array)
        if not valid.all():
            at = tuple(int(i) for i in np.argwhere(~valid)[0])
            where = tuple(a + int(o) for a, o in zip(at, offset))
            raise InputError(f"{name}: {array[at]} at index {where} is not a label (labels are "
                             "whole numbers from 0 to 4294967295)")
    return volume_array(array, np.uint32, name)


class MesherMesh:
    """One label's mesh as zmesh's :class:`Mesh` gives it: ``vertices`` (V, 3) float32 in
    (x, y, z) physical units, ``faces`` (F, 3) uint32, ``normals`` (V, 3) float32 or None."""

    def __init__(self, vertices: np.ndarray, faces: np.ndarray, normals: Optional[np.ndarray]):
        self.vertices = vertices
        self.faces = faces
        self.normals = normals


class Mesher:
    """zmesh's ``Mesher`` on voxlod, so that a zmesh user switches in one line
    (``from voxlod import Mesher``): ``Mesher(voxel_res).mesh(labels)`` meshes every label of a
    ``labels[x, y, z]`` array in one pass (:func:`voxlod.labels`), ``ids()`` lists them and
    ``get(id)`` gives one's vertices and faces, placed as zmesh places them: voxel ``i`` at
    ``i * voxel_res``, everything one voxel further with ``close=True`` (zmesh pads the array
    by a voxel on each side then), half a voxel further with ``voxel_centered=True``.

    Beyond zmesh: ``mesh(..., shared=True, smooth=N)`` gives neighbours that share their
    boundary, smoothed with volumes kept. Unlike zmesh with ``close=False``, every mesh is
    closed at the array's border. zmesh's simplification (``reduction_factor``, ``max_error``)
    is not done here: use :func:`voxlod.lod_mesh`; asking for it raises
    :class:`voxlod.UsageError`.
    """

    def __init__(self, voxel_res: Sequence[float]):
        self.voxel_res = triple(voxel_res, "voxel_res")
        self._meshes: dict = {}
        self._shift = np.zeros(3, np.float32)

    def mesh(self, data: Any, close: bool = False, shared: bool = False,
             smooth: Optional[int] = None) -> None:
        """Meshes every label of ``data`` (indexed ``[x, y, z]``, as zmesh takes it)."""
        array = np.asarray(data)
        if array.ndim != 3:
            raise UsageError(f"data must be a 3-D array indexed [x, y, z], not shape {array.shape}")
        found = labels(array.T, spacing=self.voxel_res[::-1], shared=shared, smooth=smooth)
        self._meshes = {m.label: m for m in found}
        self._shift = np.float32(1.0 if close else 0.0) * np.float32(self.voxel_res)

    def ids(self) -> List[int]:
        """The labels meshed, in increasing order."""
        return list(self._meshes)

    def get(self, label: int, normals: bool = False, reduction_factor: int = 0,
            max_error: Optional[float] = None, voxel_centered: bool = False) -> MesherMesh:
        """One label's mesh (``normals`` per vertex when asked for)."""
        if reduction_factor or max_error is not None:
            raise UsageError("voxlod's Mesher does not simplify (reduction_factor, max_error): "
                             "use voxlod.lod_mesh")
        if label not in self._meshes:
            raise UsageError(f"label {label} was not meshed (ids: {self.ids()[:20]})")
        level = self._meshes[label].levels[0]
        shift = self._shift + np.float32(0.5 if voxel_centered else 0.0) * \
            np.float32(self.voxel_res)
        vertices = level.vertices + shift if shift.any() else level.vertices
        return MesherMesh(vertices, level.faces.astype(np.uint32),
                          level.normals if normals else None)

    def erase(self, label: int) -> None:
        """Forgets one label's mesh."""
        self._meshes.pop(label, None)

    def clear(self) -> None:
        """Forgets every mesh."""
        self._meshes = {}


def label_options(levels: int, filter: str, radius: float, normals: bool) -> tuple:
    """The options of :func:`labels` as the Rust side takes them, checked."""
    if int(levels) < 1:
        raise UsageError(f"levels must be at least 1, not {levels}")
    return (int(levels), str(filter), float(radius), bool(normals))


def check_label_dtype(dtype: Any, name: str) -> None:
    """Refuses a dtype that cannot hold labels."""
    if np.dtype(dtype).kind not in "iuf" and np.dtype(dtype) != np.bool_:
        raise UsageError(f"{name}: a label map holds integers, not {np.dtype(dtype)}")


def label_mesh(found: dict) -> LabelMesh:
    """One label's dict from the Rust side as a :class:`LabelMesh`."""
    return LabelMesh(label=found["label"], voxels=found["voxels"],
                     voxel_volume=found["voxel_volume"], levels=_levels((found["levels"], [])))


def precomputed(
    directory: Any,
    volume: Any,
    meshes: Optional[List[LabelMesh]] = None,
    *,
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
    """Writes ``directory`` as a neuroglancer precomputed segmentation layer, as
    ``voxlod labels SEG -o DIR --format precomputed`` does: the labels of ``volume`` in raw
    chunks and per label a multi-resolution mesh of ``levels`` levels (Draco fragments on the
    octree's grid), sharded above 512 labels (``sharding``: ``auto``, ``always`` or
    ``never``). ``unit`` is the unit of ``spacing`` (``nm``, ``um`` or ``mm``). cloud-volume
    reads the layer back. Returns the layer's report (per label and level: fragments,
    triangles, bytes; ``carried``: the labels thinner than a coarser level's filter or
    smaller than its simplification's error, whose empty level holds the finer level's
    surface).

    The coarser levels are each simplified from the finer one with the seams locked, so no
    crack opens between levels; ``meshes`` are then the labels' meshes as :func:`labels`
    returns them (made here, ``shared`` or not, when not given), their first level used. With
    ``filter`` or ``radius`` they are the paper's filter pyramid instead: the labels' filtered
    levels (:func:`labels` with ``levels``, ``filter`` and ``radius``; ``meshes``, if given,
    must have ``levels`` levels each), smoother and with fewer handles, whose consecutive
    levels meet on a fragment's face only within about their filters' radii.
    """
    nanometres = {"nm": 1.0, "um": 1e3, "mm": 1e6}.get(unit)
    if nanometres is None:
        raise UsageError(f"unit must be nm, um or mm, not {unit!r}")
    filtered = filter is not None or radius is not None
    if filtered and shared:
        raise UsageError("shared meshes the labels together without a filter: it does not go "
                         "with filter or radius")
    array = label_values(volume, "volume")
    if meshes is None:
        with quiet_empty_levels():
            meshes = labels(array, spacing=spacing, origin=origin, shared=shared, normals=False,
                            **({"levels": levels, "filter": filter, "radius": radius}
                               if filtered else {}))
    pairs = [(int(m.label), layer_levels(m, levels if filtered else None)) for m in meshes]
    report = _voxlod.write_precomputed(str(directory), array, triple(spacing, "spacing"),
                                       triple(origin, "origin"), pairs,
                                       (int(levels), int(quantization_bits), nanometres,
                                        str(sharding)))
    warn_vanished(report)
    return report


@contextlib.contextmanager
def quiet_empty_levels() -> Iterator[None]:
    """A context in which :func:`warn_empty_levels` says nothing: for a layer, whose own
    warnings (:func:`warn_vanished`) say what the empty levels become in it."""
    import warnings

    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=r".* have no surface at some levels")
        yield


def warn_empty_levels(meshes: List[LabelMesh]) -> None:
    """Warns of the labels with levels the filter emptied (thinner than those levels'
    filter)."""
    empty = [m.label for m in meshes if any(len(level.faces) == 0 for level in m.levels)]
    _warn_labels(empty, "no surface at some levels (thinner than those levels' filter): those "
                        "levels are empty")


def warn_vanished(report: dict) -> None:
    """Warns of the labels a layer has no mesh for (no surface at level 0) and of those whose
    coarser levels hold a finer level's surface (thinner than those levels' filter, or smaller
    than their simplification's error)."""
    empty = [label for label, lods in report["labels"] if not lods]
    _warn_labels(empty, "no surface even at level 0 (thinner than the finest filter): the layer "
                        "has no mesh for them")
    _warn_labels(report["carried"], "no surface at some coarser levels of detail (thinner than "
                                    "those levels' filter, or smaller than their "
                                    "simplification's error): each such level holds the finer "
                                    "level's surface")


def _warn_labels(labels: List[int], what: str) -> None:
    """One warning that ``labels`` (if any) have ``what``, the first ten named, at the caller's
    caller's call site."""
    import warnings

    if labels:
        listed = ", ".join(str(v) for v in labels[:10]) + (", …" if len(labels) > 10 else "")
        warnings.warn(f"{len(labels)} label(s) have {what} (labels {listed})", stacklevel=4)


def layer_levels(mesh: LabelMesh, levels: Optional[int]) -> List[Tuple[np.ndarray, np.ndarray]]:
    """A label's meshes for :func:`precomputed`: its first level alone, or its ``levels``
    levels (refusing another count), as the Rust side takes them."""
    chosen = mesh.levels[:1] if levels is None else mesh.levels
    if levels is not None and len(chosen) != int(levels):
        raise UsageError(f"label {mesh.label} has {len(chosen)} levels, the layer {levels}")
    return [(np.ascontiguousarray(level.vertices, np.float32),
             np.ascontiguousarray(level.faces, np.uint32)) for level in chosen]
