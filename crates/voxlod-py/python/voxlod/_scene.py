"""Assets with their looks: a glTF scene as NumPy arrays and its materials, and levels written
back as one ``.glb``."""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import _voxlod
from .errors import UsageError


@dataclass
class Scene:
    """An asset as one world-space mesh with its looks (node transforms applied, instances
    repeated): ``vertices`` (n, 3) float32, ``faces`` (m, 3), ``normals`` (n, 3), and where the
    asset has them ``tangents`` (n, 4), ``uv0`` and ``uv1`` (n, 2; v pointing down the image,
    as glTF has it), ``colors`` (n, 4, linear RGBA); ``material`` (m,) the material of each
    face, an index into ``materials`` (dicts of glTF's metallic-roughness fields:
    ``base_color``, ``base_color_texture`` with its ``image``, ``tex_coord``, ``transform`` and
    ``sampler``, ``metallic``, ``roughness``, ``normal_texture``, ``emissive``,
    ``alpha_mode``, …); ``images`` as ``(name, mime, bytes)``; ``parts`` where each node's
    primitive went; ``warnings`` what the reader ignored; ``origin`` the world point the
    vertices are relative to (zeros, but for a scene far from the origin, such as one placed at
    map coordinates, a point near its centre: float32 vertices there would lose its detail;
    ``write_scene`` puts it back as the level nodes' translation)."""

    vertices: np.ndarray
    faces: np.ndarray
    normals: Optional[np.ndarray] = None
    tangents: Optional[np.ndarray] = None
    uv0: Optional[np.ndarray] = None
    uv1: Optional[np.ndarray] = None
    colors: Optional[np.ndarray] = None
    material: Optional[np.ndarray] = None
    materials: List[Dict[str, Any]] = field(default_factory=list)
    images: List[Tuple[str, str, bytes]] = field(default_factory=list)
    parts: List[Dict[str, Any]] = field(default_factory=list)
    warnings: List[str] = field(default_factory=list)
    origin: Tuple[float, float, float] = (0.0, 0.0, 0.0)


def read_scene(path: "os.PathLike[str] | str") -> Scene:
    """Reads a glTF 2.0 asset (``.gltf`` with its files, or ``.glb``; quantized, meshopt- and
    Draco-compressed and GPU-instanced files too), a mesh with its looks (``.obj`` with its
    ``.mtl``, ``.ply`` or ``.off`` with vertex colours, ``.stl``), or a folder of them (joined in
    the order of their names, one part each) as a :class:`Scene`. A file that requires an
    extension voxlod does not read raises :class:`voxlod.InputError` naming it, and so does a
    folder without meshes."""
    d = _voxlod.read_scene(os.fspath(path))
    return Scene(
        vertices=d["vertices"],
        faces=d["faces"],
        normals=d["normals"],
        tangents=d["tangents"],
        uv0=d["uv0"],
        uv1=d["uv1"],
        colors=d["colors"],
        material=d["material"],
        materials=json.loads(d["materials_json"]),
        images=[(n, m, bytes(b)) for n, m, b in d["images"]],
        parts=json.loads(d["parts_json"]),
        warnings=list(d["warnings"]),
        origin=tuple(float(x) for x in d["origin"]),
    )


def _floats(a: Optional[np.ndarray], width: int) -> Optional[np.ndarray]:
    if a is None:
        return None
    a = np.asarray(a, dtype=np.float32)
    return np.ascontiguousarray(a if a.ndim == 2 else a.reshape(-1, width))


def write_scene(
    path: "os.PathLike[str] | str",
    levels: Union[Scene, Sequence[Scene]],
    *,
    layout: str = "msft-lod",
    compress: bool = False,
) -> None:
    """Writes one or more levels (finest first) with their looks as one ``.glb``: ``layout``
    ``"msft-lod"`` (one node, the coarser levels listed by ``MSFT_lod``) or ``"lod-nodes"`` (one
    node per level named ``LOD0``, ``LOD1``, …). Images are embedded as given. With
    ``compress=True`` the geometry and attributes are quantized and meshopt-encoded
    (``EXT_meshopt_compression`` with ``KHR_mesh_quantization``, as gltfpack writes): positions
    on a 14-bit grid (within half a step of the box's longest side / 16383), normals and
    tangents as 8-bit, texture coordinates in 0..1 and colours as 16-bit; texture coordinates
    outside 0..1 stay float. ``read_scene`` and viewers with a meshopt decoder read it. The
    levels share one ``origin`` (their level nodes' translation); levels with different ones
    raise :class:`voxlod.UsageError`."""
    if isinstance(levels, Scene):
        levels = [levels]
    origins = {tuple(float(x) for x in s.origin) for s in levels}
    if len(origins) > 1:
        raise UsageError(f"the levels have different origins: {sorted(origins)}")
    origin = origins.pop() if origins else (0.0, 0.0, 0.0)
    given = []
    for s in levels:
        material = None if s.material is None else np.ascontiguousarray(s.material, dtype=np.uint32)
        given.append(
            (
                _floats(s.vertices, 3),
                np.ascontiguousarray(np.asarray(s.faces).astype(np.uint32)),
                _floats(s.normals, 3),
                _floats(s.tangents, 4),
                _floats(s.uv0, 2),
                _floats(s.uv1, 2),
                _floats(s.colors, 4),
                material,
                json.dumps(s.materials),
                [(n, m, bytes(b)) for n, m, b in s.images],
            )
        )
    _voxlod.write_scene(os.fspath(path), given, layout, compress, origin)
