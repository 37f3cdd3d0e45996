"""Assets with their looks from Python: a textured, vertex-coloured quad pair written with
``voxlod.write_scene`` reads back with ``voxlod.read_scene`` exactly (arrays, materials,
image bytes), in both layouts; trimesh, an independent reader, sees the same geometry and
texture coordinates; a file C++ Draco compressed reads as its meshes; a file requiring an
extension voxlod does not read is refused by name."""

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


@pytest.mark.parametrize("layout", ["msft-lod", "lod-nodes"])
def test_a_compressed_scene_reads_back_within_its_quantization(tmp_path, layout):
    scene = two_quads()
    plain, packed = tmp_path / "plain.glb", tmp_path / "packed.glb"
    voxlod.write_scene(plain, scene, layout=layout)
    voxlod.write_scene(packed, scene, layout=layout, compress=True)
    back = voxlod.read_scene(packed)
    assert back.warnings == []
    assert len(back.faces) == len(scene.faces) and len(back.vertices) == len(scene.vertices)
    # Every corner is an input corner within the stated error: half a 14-bit step of the
    # 2-unit box for positions, half a 16-bit step for texture coordinates and colours.
    step = 2.0 / 16383
    for face, m in zip(back.faces, back.material):
        for v in face:
            p, t, c = back.vertices[v], back.uv0[v], back.colors[v]
            name = back.materials[m]["name"]
            ok = [
                i for i, (q, u, k, mi) in enumerate(
                    zip(scene.vertices, scene.uv0, scene.colors, [0, 0, 0, 0, 1, 1, 1, 1]))
                if np.all(np.abs(q - p) <= step / 2 + 1e-6)
                and np.all(np.abs(u - t) <= 0.5 / 65535 + 1e-7)
                and np.all(np.abs(k - c) <= 0.5 / 65535 + 1e-7)
                and scene.materials[mi]["name"] == name
            ]
            assert ok, f"corner {p} {t} {c} of {name} is no input corner"
    raw = packed.read_bytes()
    assert b"EXT_meshopt_compression" in raw and b"KHR_mesh_quantization" in raw


def test_compression_makes_a_larger_scene_smaller(tmp_path):
    """A 64 × 64 quad grid (a few kilobytes of attributes; on two quads the extensions' JSON
    costs more than the encoding saves)."""
    n = 65
    x, y = np.meshgrid(np.arange(n, dtype=np.float32), np.arange(n, dtype=np.float32))
    v = np.stack([x.ravel(), y.ravel(), np.sin(x.ravel() / 9) * 3], axis=1).astype(np.float32)
    k = np.arange(n * n).reshape(n, n)[:-1, :-1].ravel()
    f = np.concatenate([np.stack([k, k + 1, k + n + 1], 1), np.stack([k, k + n + 1, k + n], 1)])
    scene = voxlod.Scene(
        vertices=v, faces=f, uv0=(v[:, :2] / (n - 1)).astype(np.float32),
        colors=np.tile([0.2, 0.4, 0.6, 1.0], (n * n, 1)).astype(np.float32),
        material=np.zeros(len(f), dtype=np.uint32), materials=[{"name": "grid"}], images=[],
    )
    plain, packed = tmp_path / "plain.glb", tmp_path / "packed.glb"
    voxlod.write_scene(plain, scene)
    voxlod.write_scene(packed, scene, compress=True)
    assert packed.stat().st_size < 0.5 * plain.stat().st_size
    back = voxlod.read_scene(packed)
    assert len(back.faces) == len(f) and len(back.vertices) == n * n


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


def draco_tetrahedra_glb(path):
    """A GLB of two tetrahedra, the second moved by (3, 0, 0), whose one primitive C++ Draco
    compressed (DracoPy, positions at 16 bits), drawn by two nodes."""
    import DracoPy

    points = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=np.float32)
    faces = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]], dtype=np.uint32)
    stream = DracoPy.encode(points, faces, quantization_bits=16)
    stream += b"\0" * (-len(stream) % 4)
    doc = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 1]}],
           "nodes": [{"mesh": 0}, {"mesh": 0, "translation": [3.0, 0.0, 0.0]}],
           "extensionsUsed": ["KHR_draco_mesh_compression"],
           "extensionsRequired": ["KHR_draco_mesh_compression"],
           "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "extensions": {
               "KHR_draco_mesh_compression": {"bufferView": 0, "attributes": {"POSITION": 0}}}}]}],
           "accessors": [{"componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 1]},
                         {"componentType": 5125, "count": 12, "type": "SCALAR"}],
           "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": len(stream)}],
           "buffers": [{"byteLength": len(stream)}]}
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    glb = struct.pack("<4sII", b"glTF", 2, 28 + len(text) + len(stream))
    glb += struct.pack("<I4s", len(text), b"JSON") + text
    glb += struct.pack("<I4s", len(stream), b"BIN\0") + stream
    path.write_bytes(glb)


def test_a_draco_compressed_file_reads_as_its_meshes(tmp_path):
    pytest.importorskip("DracoPy")
    path = tmp_path / "draco.glb"
    draco_tetrahedra_glb(path)
    scene = voxlod.read_scene(path)
    assert scene.faces.shape == (8, 3)
    v = scene.vertices[scene.faces]
    volume = np.einsum("ij,ij->i", v[:, 0], np.cross(v[:, 1], v[:, 2])).sum() / 6
    assert abs(volume - 2 / 6) < 1e-4
    assert np.allclose(scene.vertices.min(axis=0), [0, 0, 0], atol=1e-4)
    assert np.allclose(scene.vertices.max(axis=0), [4, 1, 1], atol=1e-4)


def test_a_file_requiring_an_extension_voxlod_does_not_read_is_refused_by_name(tmp_path):
    doc = {"asset": {"version": "2.0"}, "extensionsUsed": ["KHR_materials_pbrSpecularGlossiness"],
           "extensionsRequired": ["KHR_materials_pbrSpecularGlossiness"], "meshes": [], "nodes": []}
    path = tmp_path / "old.gltf"
    path.write_text(json.dumps(doc))
    with pytest.raises(voxlod.InputError, match="KHR_materials_pbrSpecularGlossiness"):
        voxlod.read_scene(path)


def test_bad_arrays_are_usage_errors(tmp_path):
    scene = two_quads()
    scene.uv0 = scene.uv0[:, :1]
    with pytest.raises(voxlod.UsageError, match="uv0 must have 2 columns"):
        voxlod.write_scene(tmp_path / "bad.glb", scene)
    with pytest.raises(voxlod.UsageError, match="layout"):
        voxlod.write_scene(tmp_path / "bad.glb", two_quads(), layout="nodes")


def test_a_scene_at_map_coordinates_reads_relative_to_its_origin_and_writes_it_back(tmp_path):
    # Written with an origin at map coordinates, the quads' nodes sit at 4e6, where float32 world
    # coordinates step by half a unit; read back, the vertices keep their unit squares.
    scene = two_quads()
    scene.origin = (4_000_000.3, 5_500_000.7, 250.1)
    path = tmp_path / "far.glb"
    voxlod.write_scene(path, scene)
    back = voxlod.read_scene(path)
    assert back.origin != (0.0, 0.0, 0.0)
    assert any("far from the origin" in w for w in back.warnings)
    world = back.vertices.astype(np.float64) + back.origin
    assert np.allclose(world - scene.origin, [[x, y, 0] for x, y in [
        (0, 0), (1, 0), (1, 1), (0, 1), (1, 0), (2, 0), (2, 1), (1, 1)]], atol=1e-5)
    # Levels with different origins cannot share a file.
    other = voxlod.Scene(**{**back.__dict__, "origin": (0.0, 0.0, 0.0)})
    with pytest.raises(voxlod.UsageError, match="origins"):
        voxlod.write_scene(tmp_path / "two.glb", [back, other])


def test_a_folder_of_meshes_reads_as_one_scene(tmp_path):
    (tmp_path / "a.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    (tmp_path / "b.obj").write_text("mtllib b.mtl\nusemtl red\nv 5 0 0\nv 6 0 0\nv 5 1 0\nf 1 2 3\n")
    (tmp_path / "b.mtl").write_text("newmtl red\nKd 1 0 0\n")
    (tmp_path / "notes.txt").write_text("not a mesh")
    scene = voxlod.read_scene(tmp_path)
    assert scene.faces.tolist() == [[0, 1, 2], [3, 4, 5]]
    assert scene.vertices[3].tolist() == [5.0, 0.0, 0.0]
    assert [p["name"] for p in scene.parts] == ["a", "b"]
    red = scene.materials[scene.material[1]]
    assert red["name"] == "red" and red["base_color"][:3] == [1.0, 0.0, 0.0]
    assert any("notes.txt" in w for w in scene.warnings)
    (tmp_path / "a.obj").unlink()
    (tmp_path / "b.obj").unlink()
    with pytest.raises(voxlod.InputError, match="holds no mesh"):
        voxlod.read_scene(tmp_path)
