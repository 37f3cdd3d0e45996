"""voxlod.dask on a LocalCluster of two worker processes: the stitched mesh is the
single-process voxlod.marching_cubes mesh, index for index."""

from __future__ import annotations

import numpy as np
import pytest

da = pytest.importorskip("dask.array")
distributed = pytest.importorskip("distributed")

import voxlod
import voxlod.dask
from conftest import gyroid
from meshes import as_trimesh


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                       dashboard_address=None)
    with distributed.Client(cluster) as c:
        yield c
    cluster.close()


def assert_same_mesh(blockwise, whole):
    verts, faces, normals = blockwise
    np.testing.assert_array_equal(faces, whole[1])
    assert verts.shape == whole[0].shape
    np.testing.assert_allclose(verts, whole[0], rtol=0, atol=1e-5)
    np.testing.assert_allclose(normals, whole[2], rtol=0, atol=1e-5)


def test_blockwise_mesh_is_the_single_process_mesh(client):
    volume = gyroid(90)
    whole = voxlod.marching_cubes(volume, 0.0)
    blockwise = voxlod.dask.marching_cubes(da.from_array(volume, chunks=(32, 25, 40)), 0.0,
                                           client=client)
    assert_same_mesh(blockwise, whole)
    assert as_trimesh(blockwise[0], blockwise[1]).is_watertight


def test_zarr_paths_spacing_and_ascent(client, tmp_path):
    pytest.importorskip("zarr")
    volume = -gyroid(64)
    path = tmp_path / "gyroid.zarr"
    da.from_array(volume, chunks=24).to_zarr(str(path))
    spacing = (1.5, 1.0, 0.5)
    whole = voxlod.marching_cubes(volume, 0.0, spacing=spacing, gradient_direction="ascent")
    blockwise = voxlod.dask.marching_cubes(path, 0.0, spacing=spacing,
                                           gradient_direction="ascent", client=client)
    assert_same_mesh(blockwise, whole)


def test_chunks_without_surface_are_skipped():
    volume = np.zeros((40, 40, 40), np.float32)
    volume[5:12, 6:14, 4:9] = 1.0
    array = da.from_array(volume, chunks=20)
    pieces = [voxlod.dask._piece(volume[tuple(slice(s, e) for s, e in zip(rs, re))], 0.5, rs,
                                 os_, oe, volume.shape)
              for rs, re, os_, oe in voxlod.dask._blocks(array)]
    assert len(pieces) == 8 and sum(p is None for p in pieces) == 7
    whole = voxlod.marching_cubes(volume, 0.5)
    assert_same_mesh(voxlod.dask.marching_cubes(array, 0.5), whole)


def test_lod_volume_contours_on_the_cluster_then_builds_the_chain(client):
    z, y, x = np.mgrid[-20:21, -20:21, -20:21]
    ct = np.where(x**2 + y**2 + z**2 < 15**2, 1000, 0).astype(np.int16)
    ct[18:23, 18:23, :] = 0  # a tunnel through the ball: genus 1
    levels = voxlod.dask.lod_volume(da.from_array(ct, chunks=16), client=client, threshold=500,
                                    spacing=(2.0, 1.0, 1.0), resolution=32, levels=3)
    finest = levels[0]
    whole = voxlod.marching_cubes(ct, float(np.nextafter(np.float32(500), np.float32(0))),
                                  spacing=(2.0, 1.0, 1.0))
    np.testing.assert_array_equal(finest.faces, whole[1])
    np.testing.assert_allclose(finest.vertices, whole[0][:, ::-1], atol=1e-4)
    mesh = as_trimesh(finest.vertices, finest.faces)
    assert mesh.is_watertight and mesh.volume > 0 and finest.genus == 1
    counts = [len(level.faces) for level in levels]
    assert all(a > b for a, b in zip(counts, counts[1:])), counts
    assert [level.resolution for level in levels[1:]] == [32, 16, 8]
