"""The exceptions voxlod raises.

Every failure of a voxlod call is a :class:`Error`, and also one of Python's built-in classes,
so that code written for NumPy, SciPy or scikit-image catches it where it expects to::

    >>> import numpy as np, voxlod
    >>> try:
    ...     voxlod.marching_cubes(np.zeros((2, 2)))
    ... except ValueError as e:            # also a voxlod.UsageError
    ...     print(type(e).__name__)
    UsageError
"""

from __future__ import annotations

__all__ = [
    "Error", "UsageError", "InputError", "NoSurfaceError", "TooLargeError", "FileError", "Cancelled",
]


class Error(Exception):
    """Any failure of a voxlod call; the message is the library's own, one line."""


class UsageError(Error, ValueError):
    """The call is wrong: an argument of the wrong shape, type or range."""


class InputError(Error, ValueError):
    """The data cannot be processed as asked: NaN samples, a malformed file, a broken mesh,
    no surface at the requested level."""


class NoSurfaceError(InputError, RuntimeError):
    """The volume has no surface at the level (a ``RuntimeError`` too, as scikit-image raises)."""


class TooLargeError(Error, MemoryError):
    """The work would not fit in the memory voxlod allows itself (``VOXLOD_MAX_MEMORY``) or in
    32-bit mesh indices."""


class FileError(Error, OSError):
    """A file could not be opened, read, written or renamed."""


class Cancelled(Error):
    """The progress callback asked to stop (Ctrl-C raises ``KeyboardInterrupt`` instead)."""
