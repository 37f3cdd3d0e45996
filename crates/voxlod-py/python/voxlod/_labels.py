"""Label maps (segmentations) to meshes: one closed, outward mesh per structure, each with its
own chain of levels of detail (the library's ``voxlod::labels``; each label's indicator is
thresholded at ½ and filtered as in the paper's §4 thresholding route)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, List, Optional, Sequence

import numpy as np

from . import _voxlod
from ._arrays import triple, volume_array
from ._facade import Level, _levels
from .errors import UsageError


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


def labels(
    volume: Any,
    spacing: Sequence[float] = (1.0, 1.0, 1.0),
    labels: Optional[Sequence[int]] = None,
    levels: int = 1,
    *,
    origin: Sequence[float] = (0.0, 0.0, 0.0),
    filter: str = "hypercone",
    radius: float = 1.0,
    normals: bool = True,
) -> List[LabelMesh]:
    """One closed mesh (or chain of ``levels`` levels) per label of a label map, as
    mesh-n-bone, igneous and zmesh make them.

    The labels are meshed in parallel on every core, a few per core at a time (largest box
    first, within the memory limit); Ctrl-C is honoured between those groups. Each level is
    cleaned of slivers, needles and self-intersections (beyond the paper), as ``voxlod labels``
    does by default.

    Parameters
    ----------
    volume : (nz, ny, nx) array of integer labels
        0 is background. Integer dtypes, or floats holding whole numbers (up to 2**24).
    spacing, origin : three floats
        In array-axis order (axis 0, 1, 2), like :func:`voxlod.marching_cubes`'s ``spacing``.
    labels : sequence of int, optional
        Only these labels (each must be in the map); all non-zero labels by default.
    levels : int
        Levels per label, each at half the resolution of the one before.
    filter, radius, normals
        As for :func:`voxlod.lod_volume`.

    Returns
    -------
    list of :class:`LabelMesh`, by increasing label, meshes in world (x, y, z) = (axis 2, 1, 0)
    coordinates.

    Examples
    --------
    >>> import numpy as np, voxlod
    >>> seg = np.zeros((12, 12, 20), np.uint8)
    >>> seg[2:10, 2:10, 2:9] = 1
    >>> seg[2:10, 2:10, 9:17] = 2
    >>> [(m.label, m.voxels, len(m.levels)) for m in voxlod.labels(seg, levels=2)]
    [(1, 448, 2), (2, 512, 2)]
    """
    options = label_options(levels, filter, radius, normals)
    array = label_samples(volume, "volume")
    chosen = None if labels is None else [int(v) for v in labels]
    found = _voxlod.labels(array, triple(spacing, "spacing"), triple(origin, "origin"), chosen,
                           options)
    return [label_mesh(d) for d in found]


def label_options(levels: int, filter: str, radius: float, normals: bool) -> tuple:
    """The options of :func:`labels` as the Rust side takes them, checked."""
    if int(levels) < 1:
        raise UsageError(f"levels must be at least 1, not {levels}")
    return (int(levels), str(filter), float(radius), bool(normals))


def check_label_dtype(dtype: Any, name: str) -> None:
    """Refuses a dtype that cannot hold labels."""
    if np.dtype(dtype).kind not in "iuf" and np.dtype(dtype) != np.bool_:
        raise UsageError(f"{name}: a label map holds integers, not {np.dtype(dtype)}")


def label_samples(volume: Any, name: str) -> np.ndarray:
    """A label map (or a piece of one) as the C-ordered float32 array the Rust side reads:
    integers up to 2**24 in magnitude, exact in float32."""
    array = np.asarray(volume)
    check_label_dtype(array.dtype, name)
    if array.dtype.kind in "iu" and array.size and (
            int(array.max()) > 2**24 or int(array.min()) < -2**24):
        raise UsageError(f"{name}: labels beyond ±2**24 are not supported (they are not exact "
                         "in float32)")
    return volume_array(array, np.float32, name)


def label_mesh(found: dict) -> LabelMesh:
    """One label's dict from the Rust side as a :class:`LabelMesh`."""
    return LabelMesh(label=found["label"], voxels=found["voxels"],
                     voxel_volume=found["voxel_volume"], levels=_levels((found["levels"], [])))
