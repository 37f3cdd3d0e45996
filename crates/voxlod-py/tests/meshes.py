"""Mesh checks for the tests, written against trimesh and SciPy, not voxlod."""

from __future__ import annotations

import numpy as np
import trimesh
from scipy.spatial import cKDTree


def as_trimesh(verts: np.ndarray, faces: np.ndarray) -> trimesh.Trimesh:
    return trimesh.Trimesh(vertices=np.asarray(verts, float), faces=faces, process=False)


def area(verts: np.ndarray, faces: np.ndarray) -> float:
    a, b, c = (np.asarray(verts, float)[faces[:, i]] for i in range(3))
    return float(0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1).sum())


def signed_volume(verts: np.ndarray, faces: np.ndarray) -> float:
    a, b, c = (np.asarray(verts, float)[faces[:, i]] for i in range(3))
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)


def nearest(points: np.ndarray, reference: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Distance from each point to the nearest reference point, and that point's index."""
    return cKDTree(np.asarray(reference, float)).query(np.asarray(points, float))


def on_grid_edges(verts: np.ndarray, tol: float = 1e-6) -> np.ndarray:
    """Which vertices (in index units) lie on a grid edge: two coordinates whole numbers."""
    whole = np.abs(verts - np.round(verts)) < tol
    return whole.sum(axis=1) >= 2
