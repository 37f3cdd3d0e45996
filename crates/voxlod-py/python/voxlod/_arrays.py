"""Argument checks shared by the voxlod functions: arrays are made 3-D, finite-sized and
C-contiguous of the dtype the Rust side reads, copying only when the layout requires it, and
refused with a :class:`voxlod.UsageError` or :class:`voxlod.TooLargeError` before any large
allocation."""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from . import _voxlod
from .errors import TooLargeError, UsageError


def volume_array(volume: Any, dtype: Any, name: str = "volume", min_side: int = 1) -> np.ndarray:
    """``volume`` as a C-contiguous 3-D array of ``dtype`` (no copy when it already is one)."""
    array = np.asarray(volume)
    if array.ndim != 3:
        raise UsageError(f"`{name}` must be a 3-D array; this one has {array.ndim} dimensions "
                         f"(shape {array.shape})")
    if not (np.issubdtype(array.dtype, np.number) or array.dtype == np.bool_) or \
            np.issubdtype(array.dtype, np.complexfloating):
        raise UsageError(f"`{name}` must hold real numbers, not {array.dtype}")
    if array.size == 0 or min(array.shape) < min_side:
        raise UsageError(f"`{name}` must be at least {min_side}x{min_side}x{min_side}; "
                         f"its shape is {array.shape}")
    target = np.dtype(dtype)
    if array.dtype != target or not array.flags.c_contiguous:
        check_fits(array.size * target.itemsize, f"a C-ordered {target} copy of `{name}`")
    return np.ascontiguousarray(array, dtype=target)


def check_fits(nbytes: int, what: str) -> None:
    """Refuses ``nbytes`` beyond the memory voxlod allows itself, before NumPy allocates."""
    available = _voxlod.memory_available()
    if nbytes > available:
        raise TooLargeError(f"{what} would need {nbytes} bytes but only {available} are available "
                            "(set VOXLOD_MAX_MEMORY to change the limit)")


def spacing_triple(value: Any) -> tuple[float, float, float]:
    """A spacing (one number or three) as three floats, each finite and positive."""
    spacing = triple(value, "spacing")
    if not all(np.isfinite(s) and s > 0 for s in spacing):
        raise UsageError(f"`spacing` must be finite and positive, not {spacing}")
    return spacing


def triple(value: Any, name: str) -> tuple[float, float, float]:
    """A scalar or a sequence of three numbers as three floats."""
    values: Sequence[Any]
    if np.ndim(value) == 0:
        values = [value] * 3
    else:
        values = list(np.asarray(value, dtype=float).ravel())
    if len(values) != 3:
        raise UsageError(f"`{name}` must be one number or three (one per axis), not {value!r}")
    try:
        a, b, c = (float(v) for v in values)
    except (TypeError, ValueError) as e:
        raise UsageError(f"`{name}` must be numbers: {e}") from None
    return a, b, c
