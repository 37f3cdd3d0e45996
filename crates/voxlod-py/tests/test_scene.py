"""Assets with their looks from Python: a textured, vertex-coloured quad pair written with
``voxlod.write_scene`` reads back with ``voxlod.read_scene`` exactly (arrays, materials,
image bytes), in both layouts; trimesh, an independent reader, sees the same geometry and
texture coordinates; a file requiring Draco is refused by name."""

import json
import struct
import zlib

import numpy as np
import pytest

import voxlod


def png(width, height, rgb):
    """A PNG of one colour, written by hand (no imaging library needed)."""
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
    rows = b"".join(b"\x00" + bytes(rgb) * width for _ in range(height))
    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b"")


def two_quads():
    """Two unit squares side by side in z = 0 (the left textured, the right coloured), split at
    x = 1 so each has its own vertices."""
    v = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
                  [1, 0, 0], [2, 0, 0], [2, 1, 0], [1, 1, 0]], dtype=np.float32)
    f = np.array([[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]])
    uv = np.array([[0, 1], [1, 1], [1, 0], [0, 0], [0, 1], [1, 1], [1, 0], [0, 0]], dtype=np.float32)
    colors = np.ones((8, 4), dtype=np.float32)
    colors[4:, :3] = [0.25, 0.5, 0.75]
    materials = [
        {"name": "textured", "base_color_texture": {"image": 0, "tex_coord": 0}, "metallic": 0.0},
        {"name": "coloured", "roughness": 0.25, "double_sided": True},
    ]
    return voxlod.Scene(
        vertices=v, faces=f, normals=np.tile([0, 0, 1], (8, 1)).astype(np.float32), uv0=uv,
        colors=colors, material=np.array([0, 0, 1, 1], dtype=np.uint32), materials=materials,
        images=[("red.png", "image/png", png(2, 2, (255, 0, 0)))],
    )


def corners(scene):
    """Every face corner with its position, uv and colour, sorted."""
    out = []
    for face, m in zip(scene.faces, scene.material):
        for v in face:
            out.append((tuple(scene.vertices[v]), tuple(scene.uv0[v]), tuple(scene.colors[v]),
                        scene.materials[m]["name"]))
    return sorted(out)


@pytest.mark.parametrize("layout", ["msft-lod", "lod-nodes"])
def test_a_scene_written_reads_back_the_same(tmp_path, layout):
    scene = two_quads()
    coarse = voxlod.Scene(**{**scene.__dict__, "faces": scene.faces[:2], "material": scene.material[:2]})
    path = tmp_path / "two.glb"
    voxlod.write_scene(path, [scene, coarse], layout=layout)
    back = voxlod.read_scene(path)
    assert back.warnings == []
    assert corners(back) == corners(scene)
    assert back.images[0][2] == scene.images[0][2]
    textured = next(m for m in back.materials if m["name"] == "textured")
    assert textured["base_color_texture"]["image"] == 0 and textured["metallic"] == 0.0
    coloured = next(m for m in back.materials if m["name"] == "coloured")
    assert coloured["roughness"] == 0.25 and coloured["double_sided"]
    assert back.normals.shape == (8, 3) and back.tangents is None and back.uv1 is None


def test_trimesh_reads_what_voxlod_writes(tmp_path):
    trimesh = pytest.importorskip("trimesh")
    path = tmp_path / "two.glb"
    voxlod.write_scene(path, two_quads(), layout="lod-nodes")
    loaded = trimesh.load(str(path), force="scene")
    meshes = list(loaded.geometry.values())
    assert sum(len(m.faces) for m in meshes) == 4
    vertices = np.concatenate([m.vertices for m in meshes])
    assert np.allclose(vertices.min(axis=0), [0, 0, 0]) and np.allclose(vertices.max(axis=0), [2, 1, 0])
    textured = [m for m in meshes if getattr(m.visual, "uv", None) is not None and len(m.visual.uv)]
    assert textured, "trimesh sees texture coordinates"
    # trimesh flips v to OpenGL's convention: glTF's (0, 1) corner is its (0, 0).
    uv = textured[0].visual.uv
    assert np.allclose(sorted(map(tuple, uv)), sorted([(0, 0), (1, 0), (1, 1), (0, 1)]))


def test_a_file_requiring_draco_is_refused_by_name(tmp_path):
    doc = {"asset": {"version": "2.0"}, "extensionsUsed": ["KHR_draco_mesh_compression"],
           "extensionsRequired": ["KHR_draco_mesh_compression"], "meshes": [], "nodes": []}
    path = tmp_path / "draco.gltf"
    path.write_text(json.dumps(doc))
    with pytest.raises(voxlod.InputError, match="KHR_draco_mesh_compression"):
        voxlod.read_scene(path)


def test_bad_arrays_are_usage_errors(tmp_path):
    scene = two_quads()
    scene.uv0 = scene.uv0[:, :1]
    with pytest.raises(voxlod.UsageError, match="uv0 must have 2 columns"):
        voxlod.write_scene(tmp_path / "bad.glb", scene)
    with pytest.raises(voxlod.UsageError, match="layout"):
        voxlod.write_scene(tmp_path / "bad.glb", two_quads(), layout="nodes")
