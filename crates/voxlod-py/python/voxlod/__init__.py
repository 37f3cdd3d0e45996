"""voxlod: levels of detail from meshes and scanned volumes by voxel filtering and marching
cubes (He, Hong, Kaufman, Varshney, Wang 1995), with NumPy in and out.

Drop-ins for the functions Python users already call, in parallel Rust:

- :func:`marching_cubes` for ``skimage.measure.marching_cubes``;
- :func:`gaussian_filter` for ``scipy.ndimage.gaussian_filter`` on 3-D float arrays.

The library's own calls: :func:`lod` and :func:`lod_volume` (levels of detail of a mesh or a
scan, paper §2 and §4), :func:`labels` (one mesh per structure of a label map),
:func:`read_mesh`, :func:`write_mesh`, :func:`read_volume`, :func:`write_volume`,
:func:`inspect`, :func:`compare`, :func:`layers` (translucent shells, §3), and the baselines
:func:`cluster` and :func:`envelope`. On a Dask cluster, block by block and with the same
results, :mod:`voxlod.dask` has :func:`voxlod.dask.lod_volume` (either route of §4),
:func:`voxlod.dask.labels` and :func:`voxlod.dask.marching_cubes`. Every function releases the
GIL while it works; every failure is a :class:`voxlod.Error` (see :mod:`voxlod.errors`).

>>> import numpy as np, voxlod
>>> z, y, x = np.mgrid[-8:9, -8:9, -8:9]
>>> ball = (6.0 - np.sqrt(x**2 + y**2 + z**2)).astype(np.float32)
>>> verts, faces, normals, values = voxlod.marching_cubes(ball, level=0.0)
>>> verts.shape[1], faces.dtype.name
(3, 'int32')
"""

from __future__ import annotations

from typing import Any, Optional, Sequence, Tuple, Union

import numpy as np

from . import _voxlod
from ._arrays import check_fits, spacing_triple, triple, volume_array
from ._labels import LabelMesh, Mesher, labels, precomputed
from ._scene import Scene, read_scene, write_scene
from ._facade import (
    Level,
    cluster,
    compare,
    envelope,
    inspect,
    layers,
    lod,
    lod_volume,
    read_mesh,
    read_volume,
    write_mesh,
    write_volume,
)
from .errors import Cancelled, Error, FileError, InputError, NoSurfaceError, TooLargeError, UsageError

__version__: str = _voxlod.__version__

__all__ = [
    "marching_cubes",
    "gaussian_filter",
    "lod",
    "lod_volume",
    "Level",
    "read_mesh",
    "read_scene",
    "write_scene",
    "Scene",
    "write_mesh",
    "read_volume",
    "write_volume",
    "inspect",
    "compare",
    "layers",
    "labels",
    "Mesher",
    "precomputed",
    "LabelMesh",
    "cluster",
    "envelope",
    "Error",
    "UsageError",
    "InputError",
    "NoSurfaceError",
    "TooLargeError",
    "FileError",
    "Cancelled",
]

ArrayLike = Any


def marching_cubes(
    volume: ArrayLike,
    level: Optional[float] = None,
    *,
    spacing: Sequence[float] = (1.0, 1.0, 1.0),
    gradient_direction: str = "descent",
    step_size: int = 1,
    allow_degenerate: bool = True,
    method: str = "lewiner",
    mask: Optional[ArrayLike] = None,
) -> Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The isosurface of a 3-D volume by marching cubes: a drop-in for
    ``skimage.measure.marching_cubes``, with the same arguments, defaults and results.

    Parameters
    ----------
    volume : (M, N, P) array
        Any real dtype; converted to C-ordered ``float32`` as scikit-image does (no copy when
        it already is). NaN samples are refused (:class:`voxlod.InputError`).
    level : float, optional
        The iso value; samples above it are inside. Default: halfway between the volume's
        minimum and maximum. Must lie within the data's range.
    spacing : three floats
        Voxel size along axes 0, 1, 2, each finite and positive; vertices are multiplied by it
        (normals are not, as in scikit-image).
    gradient_direction : {'descent', 'ascent'}
        ``'descent'``: the object is above the level (triangles wind outward in a right-handed
        (x, y, z) = (axis 2, 1, 0) frame); ``'ascent'``: below, the winding reversed.
    step_size : int
        Only 1 is supported.
    allow_degenerate : bool
        ``False`` drops triangles with two coincident vertices (voxlod keeps vertices off the
        samples, so there are normally none).
    method : {'lewiner', 'lorensen'}
        Accepted for compatibility; both run voxlod's tables, which resolve ambiguous faces so
        that the surface is always closed and manifold.
    mask : (M, N, P) bool array, optional
        Contour only the cells whose corner of highest indices is ``True`` (scikit-image's rule).

    Returns
    -------
    verts : (V, 3) float32 array (float64 when ``spacing`` is not all ones)
        Vertices along axes 0, 1, 2, in spacing units.
    faces : (F, 3) int32 array
        Triangles as indices into ``verts``.
    normals : (V, 3) float32 array
        Unit normals pointing down the data's gradient (in index space).
    values : (V,) float32 array
        Per vertex, the largest range of the data over the cells that use it (scikit-image's
        measure for colour maps).

    Examples
    --------
    >>> import numpy as np, voxlod
    >>> z, y, x = np.mgrid[-10:11, -10:11, -10:11]
    >>> ball = 8.0 - np.sqrt(x**2 + y**2 + z**2)
    >>> verts, faces, normals, values = voxlod.marching_cubes(ball, 0.0, spacing=(2.0, 1.0, 1.0))
    >>> bool(np.ptp(verts[:, 0]) > 30)   # axis 0 is stretched by its spacing
    True
    """
    array = volume_array(volume, np.float32, "volume", min_side=2)
    # None: the middle of the data's range; a level outside the range is refused (in Rust, in
    # the same pass that looks for NaN).
    level = None if level is None else float(level)
    spacing = spacing_triple(spacing)
    if gradient_direction not in ("descent", "ascent"):
        raise UsageError(f"Incorrect input {gradient_direction!r} in `gradient_direction`: "
                         "use 'descent' or 'ascent'")
    if step_size != 1:
        raise UsageError("voxlod.marching_cubes supports step_size=1 only")
    if method not in ("lewiner", "lorensen"):
        raise UsageError(f"method must be 'lewiner' or 'lorensen', not {method!r}")
    mask_array = None
    if mask is not None:
        mask_array = volume_array(mask, np.bool_, "mask")
        if mask_array.shape != array.shape:
            raise UsageError("volume and mask must have the same shape: "
                             f"{array.shape} and {mask_array.shape}")
    verts, faces, normals, values = _voxlod.marching_cubes(
        array, level, gradient_direction == "descent", mask_array)
    if len(verts) == 0:
        raise NoSurfaceError("No surface found at the given iso value.")
    if not allow_degenerate:
        verts, faces, normals, values = _drop_degenerate(verts, faces, normals, values)
    if spacing != (1.0, 1.0, 1.0):
        verts = verts * np.asarray(spacing)
    return verts, faces, normals, values


def _drop_degenerate(verts, faces, normals, values):
    """Triangles with two coincident vertices removed, and the vertices no triangle uses."""
    a, b, c = (verts[faces[:, i]] for i in range(3))
    degenerate = (a == b).all(1) | (b == c).all(1) | (a == c).all(1)
    faces = faces[~degenerate]
    used = np.zeros(len(verts), dtype=bool)
    used[faces.ravel()] = True
    new_index = np.cumsum(used, dtype=np.int64) - 1
    return verts[used], new_index[faces].astype(np.int32), normals[used], values[used]


def gaussian_filter(
    input: ArrayLike,
    sigma: Union[float, Sequence[float]],
    order: int = 0,
    output: Any = None,
    mode: str = "reflect",
    cval: float = 0.0,
    truncate: float = 4.0,
    *,
    radius: Any = None,
    axes: Any = None,
) -> np.ndarray:
    """A Gaussian filter of a 3-D float array: a drop-in for ``scipy.ndimage.gaussian_filter``
    (same taps, truncation and border modes), separable and parallel.

    Parameters
    ----------
    input : (M, N, P) float32 or float64 array
        The result has the same dtype (in the machine's byte order); the filter runs in it.
        NaN spreads as in SciPy.
    sigma : float or three floats
        Standard deviation in samples, per axis 0, 1, 2 if three; 0 leaves an axis alone.
    order : int
        Only 0 (smoothing) is supported.
    output : None
        Only ``None`` is supported: the result is a new array.
    mode : {'reflect', 'mirror', 'nearest', 'wrap', 'constant'}
        How samples past the borders are made up, as in SciPy (also the ``grid-`` spellings).
    cval : float
        The value outside for ``'constant'``.
    truncate : float
        The taps reach ``int(truncate * sigma + 0.5)`` samples each way.

    Examples
    --------
    >>> import numpy as np, voxlod
    >>> impulse = np.zeros((9, 9, 9), np.float32); impulse[4, 4, 4] = 1
    >>> blurred = voxlod.gaussian_filter(impulse, sigma=1.0)
    >>> round(float(blurred.sum()), 5), blurred.dtype.name
    (1.0, 'float32')
    """
    if order != 0 or output is not None or radius is not None or axes is not None:
        raise UsageError("voxlod.gaussian_filter supports order=0, output=None, radius=None "
                         "and axes=None only")
    dtype = np.asarray(input).dtype
    if dtype.kind != "f" or dtype.itemsize not in (4, 8):
        raise UsageError(f"voxlod.gaussian_filter filters float32 and float64 arrays, not {dtype}")
    # Either byte order (a big-endian scan read with np.fromfile): filtered in the machine's.
    array = volume_array(input, dtype.newbyteorder("="), "input")
    check_fits(array.nbytes, "the filtered volume")
    sigmas = triple(sigma, "sigma")
    return _voxlod.gaussian_filter(array, sigmas, float(truncate), str(mode), float(cval))
