"""voxlod.dask on a LocalCluster of two worker processes: the stitched mesh is the
single-process voxlod.marching_cubes mesh, index for index; the levels of lod_volume are the
single-process voxlod.lod_volume levels."""

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


def assert_same_levels(blockwise, whole):
    """The levels of voxlod.dask.lod_volume are those of voxlod.lod_volume: same resolutions,
    triangle counts and genus, the same vertex set to float32 rounding, each level closed."""
    assert [l.resolution for l in blockwise] == [l.resolution for l in whole]
    for mine, theirs in zip(blockwise, whole):
        assert len(mine.faces) == len(theirs.faces) > 0, mine.resolution
        assert mine.genus == theirs.genus, mine.resolution
        a, b = np.unique(mine.vertices, axis=0), np.unique(theirs.vertices, axis=0)
        assert a.shape == b.shape, mine.resolution
        scale = float(np.abs(b).max())
        np.testing.assert_allclose(a, b, rtol=0, atol=4 * np.finfo(np.float32).eps * scale)
        assert as_trimesh(mine.vertices, mine.faces).is_watertight, mine.resolution


def test_lod_volume_levels_are_the_single_process_levels(client):
    # A closed gyroid of two periods: a high genus, which the coarse levels' genus step lowers.
    ct = (gyroid(150, periods=2.0) * 1000).astype(np.int16)
    keywords = dict(threshold=0, spacing=(1.5, 1.0, 0.75), origin=(-3.0, 2.0, 10.0),
                    resolutions=[64, 32, 16])
    whole = voxlod.lod_volume(ct, **keywords)
    # Uneven chunks; the levels' blocks (2 to 3 per axis here) do not follow them.
    array = da.from_array(ct, chunks=((50, 60, 40), (61, 89), (40, 40, 70)))
    blockwise = voxlod.dask.lod_volume(array, client=client, **keywords)
    assert_same_levels(blockwise, whole)
    assert whole[0].genus > whole[-1].genus


def test_lod_volume_reads_a_zarr_path_on_the_workers(client, tmp_path):
    zarr = pytest.importorskip("zarr")
    z, y, x = np.mgrid[-60:61, -60:61, -60:61]
    ct = np.where(x**2 + y**2 + (1.5 * z) ** 2 < 50**2, 1200, 40).astype(np.uint16)
    ct[50:71, 50:71, :] = 40  # a tunnel through the ball along axis 2: genus 1
    path = tmp_path / "ball.zarr"
    store = zarr.open(str(path), mode="w", shape=ct.shape, chunks=(40, 50, 64), dtype=ct.dtype)
    store[...] = ct
    keywords = dict(threshold=600, spacing=(1.5, 1.0, 1.0), resolution=48, levels=3,
                    filter="gaussian")
    whole = voxlod.lod_volume(ct, **keywords)
    blockwise = voxlod.dask.lod_volume(path, client=client, **keywords)
    assert_same_levels(blockwise, whole)
    assert blockwise[0].genus == 1


class CountingArray:
    """A NumPy array that counts the regions read from it."""

    def __init__(self, array):
        self.array, self.reads = array, []
        self.shape, self.dtype, self.ndim = array.shape, array.dtype, array.ndim

    def __getitem__(self, index):
        self.reads.append(tuple((s.start, s.stop) for s in index))
        return self.array[index]


def test_lod_volume_reads_each_window_once_and_skips_blocks_without_surface(monkeypatch):
    import dask

    # A small ball in one corner of a large volume: most blocks hold no surface.
    z, y, x = np.mgrid[0:200, 0:200, 0:200]
    ct = np.where((x - 40) ** 2 + (y - 40) ** 2 + (z - 40) ** 2 < 25**2, 1.0, 0.0)
    source = CountingArray(ct.astype(np.float32))
    answers, window_samples = [], []

    def fill_block(window, scan, level, block):
        window_samples.append(window.size)
        answers.append(voxlod._voxlod.fill_threshold_block(
            np.ascontiguousarray(window, np.float32), scan, level, tuple(block)))
        return answers[-1]

    monkeypatch.setattr(voxlod.dask, "_fill_block", fill_block)
    keywords = dict(threshold=0.5, resolutions=[48, 24])
    with dask.config.set(scheduler="synchronous"):  # in this process, to count
        blockwise = voxlod.dask.lod_volume(da.from_array(source, chunks=100, asarray=False),
                                           **keywords)
    assert_same_levels(blockwise, voxlod.lod_volume(ct, **keywords))
    skipped = sum(isinstance(a, float) for a in answers)
    assert 0 < skipped < len(answers), (skipped, len(answers))
    # Every window is read once, the blocks without surface included: the samples read (in
    # pieces, one per chunk a window overlaps) are the windows' samples, once each; a pass of
    # its own for the windows' min and max would double them.
    read = sum(int(np.prod([b - a for a, b in region])) for region in source.reads)
    assert read == sum(window_samples), (read, sum(window_samples))


def test_lod_volume_refuses_the_direct_route_naming_the_single_process_one():
    with pytest.raises(ValueError, match=r"voxlod\.lod_volume\(.*direct=True"):
        voxlod.dask.lod_volume(np.zeros((8, 8, 8), np.float32), direct=True, iso=0.5)
    with pytest.raises(ValueError, match="threshold"):
        voxlod.dask.lod_volume(np.zeros((8, 8, 8), np.float32))
