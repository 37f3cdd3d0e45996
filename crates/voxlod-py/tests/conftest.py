"""Shared inputs of the voxlod pytest suite: analytic fields and the shared CT scan."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[3]


def gyroid(n: int, periods: float = 3.0, closed: bool = True, dtype=np.float32) -> np.ndarray:
    """The gyroid sin x cos y + sin y cos z + sin z cos x on an n³ grid; with ``closed``,
    intersected with a ball inside the grid, so that its surface at 0 is closed."""
    t = np.linspace(0.0, 2.0 * np.pi * periods, n)
    z, y, x = np.meshgrid(t, t, t, indexing="ij")
    field = np.sin(x) * np.cos(y) + np.sin(y) * np.cos(z) + np.sin(z) * np.cos(x)
    if closed:
        c = (n - 1) / 2.0
        k = np.arange(n) - c
        kz, ky, kx = np.meshgrid(k, k, k, indexing="ij")
        ball = (0.45 * n - np.sqrt(kx**2 + ky**2 + kz**2)) / (0.1 * n)
        field = np.minimum(field, ball)
    return field.astype(dtype)


def shared_data() -> Path | None:
    """The shared data folder (``VOXLOD_SHARED_DATA`` or ../shared/data beside the checkout)."""
    env = os.environ.get("VOXLOD_SHARED_DATA")
    for candidate in ([Path(env)] if env else []) + [REPO.parent / "shared" / "data"]:
        if candidate.is_dir():
            return candidate
    return None


@pytest.fixture(scope="session")
def ct_head() -> np.ndarray:
    """The CT head (113 slices of 256², big-endian uint16), padded with one sample of air so
    that its surfaces close; skipped when the shared data is absent."""
    data = shared_data()
    path = data / "volumes" / "CThead_256x256x113_uint16be.raw" if data else None
    if path is None or not path.is_file():
        pytest.skip("the CT head CThead_256x256x113_uint16be.raw is not in the shared data "
                    "(set VOXLOD_SHARED_DATA)")
    volume = np.fromfile(path, dtype=">u2").reshape(113, 256, 256).astype(np.float32)
    return np.pad(volume, 1)


def touching_balls(step0: float) -> np.ndarray:
    """A (40, 48, 64) uint16 label map, axis 0 in ``step0``-unit steps: balls 1 and 2 (radius 10
    units) overlap and the overlap goes to the nearer centre, so they touch along a flat face;
    ball 3 (radius 8) stands apart."""
    z, y, x = np.meshgrid(*(np.arange(n, dtype=float) for n in (40, 48, 64)), indexing="ij")
    z = z * step0

    def distance(cz, cy, cx):
        return np.sqrt((z - cz) ** 2 + (y - cy) ** 2 + (x - cx) ** 2)

    d1, d2, d3 = distance(30, 24, 18), distance(30, 24, 34), distance(27, 24, 53)
    seg = np.zeros(z.shape, np.uint16)
    seg[(d1 < 10) & (d1 <= d2)] = 1
    seg[(d2 < 10) & (d2 < d1)] = 2
    seg[d3 < 8] = 3
    return seg
