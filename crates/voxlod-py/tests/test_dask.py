"""voxlod.dask on a LocalCluster of two worker processes: the stitched mesh is the
single-process voxlod.marching_cubes mesh, index for index; the levels of lod_volume are the
single-process voxlod.lod_volume levels."""

from __future__ import annotations

import collections
import faulthandler
import re
import signal

import numpy as np
import pytest

da = pytest.importorskip("dask.array")
distributed = pytest.importorskip("distributed")

import voxlod
import voxlod.dask
from conftest import gyroid, touching_balls
from meshes import as_trimesh


STALL_SECONDS = 90
"""A test of this module that runs longer has stalled: it fails (with every thread's stack
on stderr) instead of hanging the suite. Each takes a few seconds in a release build."""


@pytest.fixture(autouse=True)
def fail_on_stall():
    """SIGALRM after STALL_SECONDS raises in the main thread, which a client waiting on its
    futures (a lock wait, interruptible by signals) then reports as the test's failure."""

    def stalled(signum, frame):
        faulthandler.dump_traceback(all_threads=True)
        raise TimeoutError(f"the test stalled for {STALL_SECONDS} s (stacks above)")

    previous = signal.signal(signal.SIGALRM, stalled)
    signal.alarm(STALL_SECONDS)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)


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


def chunk_reads(source, chunk):
    """How often each chunk of ``source`` was read, asserting that every read is a chunk
    (dask's empty probe of the array's type aside)."""
    counts = collections.Counter(r for r in source.reads if all(a < b for a, b in r))
    for region in counts:
        assert all(a % chunk == 0 and (b % chunk == 0 or b == n)
                   for (a, b), n in zip(region, source.shape)), region
    return counts


def test_lod_volume_reads_each_chunk_once_per_level_and_skips_blocks_without_surface(
        monkeypatch):
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
    # The windows overlap (halos), but each chunk is read once per level and shared by the
    # windows that need it; a pass of its own for the windows' min and max would read it again.
    reads = chunk_reads(source, 100)
    assert len(reads) == 8 and max(reads.values()) == 2, reads
    assert sum(window_samples) > 2 * ct.size  # the halos: windows add up to more than that


def test_lod_volume_asks_for_one_route():
    with pytest.raises(ValueError, match=r"threshold=T .* or direct=True"):
        voxlod.dask.lod_volume(np.zeros((8, 8, 8), np.float32))
    with pytest.raises(ValueError, match=r"threshold=T .* or direct=True"):
        voxlod.dask.lod_volume(np.zeros((8, 8, 8), np.float32), threshold=0.5, direct=True)


def assert_identical_levels(blockwise, whole):
    """The same levels bit for bit: resolutions, faces, vertices, normals and genus."""
    assert [l.resolution for l in blockwise] == [l.resolution for l in whole]
    for mine, theirs in zip(blockwise, whole):
        assert len(theirs.faces) > 0, theirs.resolution
        np.testing.assert_array_equal(mine.faces, theirs.faces)
        np.testing.assert_array_equal(mine.vertices, theirs.vertices)
        np.testing.assert_array_equal(mine.normals, theirs.normals)
        assert mine.genus == theirs.genus, mine.resolution


@pytest.fixture
def small_windows(monkeypatch):
    """Windows of about 48 scan samples a side, so that small test scans have several blocks
    per level, with halos, in every direction (coarse levels, whose halos exceed that, have
    blocks of two samples or more: hundreds of tasks)."""
    monkeypatch.setattr(voxlod.dask, "WINDOW_SIDE", 48)


def test_direct_levels_are_the_single_process_levels(client, small_windows):
    # A closed gyroid in the data's own units (a CT-like int16 scan), filtered directly.
    ct = (gyroid(72, periods=2.0) * 1000).astype(np.int16)
    keywords = dict(direct=True, iso=-200.0, spacing=(1.5, 1.0, 0.75), origin=(-3.0, 2.0, 10.0),
                    resolutions=[40, 20, 10])
    whole = voxlod.lod_volume(ct, **keywords)
    array = da.from_array(ct, chunks=((20, 30, 22), (41, 31), (15, 15, 42)))
    blockwise = voxlod.dask.lod_volume(array, client=client, **keywords)
    assert_identical_levels(blockwise, whole)
    assert_same_levels(blockwise, whole)  # closed, too


def test_direct_reads_a_zarr_path_on_the_workers(client, tmp_path, small_windows):
    zarr = pytest.importorskip("zarr")
    z, y, x = np.mgrid[-30:31, -30:31, -30:31]
    ct = np.where(x**2 + y**2 + (1.5 * z) ** 2 < 25**2, 1200, 40).astype(np.uint16)
    ct[25:36, 25:36, :] = 40  # a tunnel through the ball along axis 2: genus 1
    path = tmp_path / "ball.zarr"
    store = zarr.open(str(path), mode="w", shape=ct.shape, chunks=(20, 25, 32), dtype=ct.dtype)
    store[...] = ct
    keywords = dict(direct=True, iso=600.0, spacing=(1.5, 1.0, 1.0), resolution=36, levels=3,
                    filter="gaussian")
    whole = voxlod.lod_volume(ct, **keywords)
    blockwise = voxlod.dask.lod_volume(path, client=client, **keywords)
    assert_identical_levels(blockwise, whole)
    assert blockwise[0].genus == 1


def test_direct_reads_each_chunk_once_per_level(monkeypatch, small_windows):
    import dask

    z, y, x = np.mgrid[0:50, 0:50, 0:50]
    ct = np.where((x - 20) ** 2 + (y - 24) ** 2 + (z - 26) ** 2 < 15**2, 900.0, -100.0)
    source = CountingArray(ct.astype(np.float32))
    windows = []

    def fill_block(window, scan, level, block):
        windows.append(window.size)
        return voxlod._voxlod.fill_direct_block(np.ascontiguousarray(window, np.float32), scan,
                                                level, tuple(block))

    monkeypatch.setattr(voxlod.dask, "_fill_direct_block", fill_block)
    keywords = dict(direct=True, iso=400.0, resolutions=[30, 15])
    with dask.config.set(scheduler="synchronous"):  # in this process, to count
        blockwise = voxlod.dask.lod_volume(da.from_array(source, chunks=25, asarray=False),
                                           **keywords)
    assert_identical_levels(blockwise, voxlod.lod_volume(ct, **keywords))
    assert len(windows) > 8  # several blocks per level
    # One pass over the scan for its range, then each chunk once per level.
    reads = chunk_reads(source, 25)
    assert len(reads) == 8 and set(reads.values()) == {3}, reads
    assert sum(windows) > 2 * ct.size  # the halos: windows add up to more than that


def test_direct_bad_input_is_refused_with_the_single_process_errors():
    ct = np.zeros((12, 12, 12), np.float32)
    ct[3:9, 3:9, 3:9] = 10.0
    with pytest.raises(voxlod.UsageError, match="iso"):
        voxlod.dask.lod_volume(ct, direct=True, resolution=8, levels=1)
    for iso in (0.0, 11.0):  # at or below every sample, above every sample
        with pytest.raises(voxlod.InputError) as alone:
            voxlod.lod_volume(ct, direct=True, iso=iso, resolution=8, levels=1)
        with pytest.raises(voxlod.InputError, match=re.escape(str(alone.value))):
            voxlod.dask.lod_volume(ct, direct=True, iso=iso, resolution=8, levels=1)
    ct[5, 6, 7] = np.nan
    with pytest.raises(voxlod.InputError, match=r"NaN at index \[5, 6, 7\]"):
        voxlod.dask.lod_volume(da.from_array(ct, chunks=5), direct=True, iso=5.0, resolution=8,
                               levels=1)
    with pytest.raises(voxlod.InputError, match="no finite samples"):
        voxlod.dask.lod_volume(np.full((4, 4, 4), np.nan, np.float32), direct=True, iso=1.0)


@pytest.fixture(scope="module")
def segmentation() -> np.ndarray:
    """Four structures in a (40, 48, 64) map: balls 1 and 2 touch along a flat face, box 4
    touches ball 2 from below, ball 3 stands apart."""
    seg = touching_balls(1.5)
    seg[4:15, 10:30, 25:45] = 4
    return seg


def assert_same_label_meshes(blockwise, whole):
    assert [(m.label, m.voxels, m.voxel_volume, len(m.levels)) for m in blockwise] == \
        [(m.label, m.voxels, m.voxel_volume, len(m.levels)) for m in whole]
    for mine, theirs in zip(blockwise, whole):
        assert_identical_levels(mine.levels, theirs.levels)


def test_labels_are_the_single_process_meshes(client, segmentation):
    keywords = dict(spacing=(1.5, 1.0, 1.0), origin=(2.0, -3.0, 0.5), levels=2)
    whole = voxlod.labels(segmentation, **keywords)
    assert [m.label for m in whole] == [1, 2, 3, 4]
    # Chunks that cut every structure, unevenly.
    array = da.from_array(segmentation, chunks=((16, 14, 10), (20, 28), (24, 24, 16)))
    blockwise = voxlod.dask.labels(array, client=client, **keywords)
    assert_same_label_meshes(blockwise, whole)
    for mesh in blockwise:
        assert as_trimesh(mesh.vertices, mesh.faces).is_watertight, mesh.label
    chosen = voxlod.dask.labels(array, client=client, labels=[4, 2], filter="gaussian")
    assert_same_label_meshes(chosen, voxlod.labels(segmentation, labels=[4, 2],
                                                   filter="gaussian"))


def test_labels_read_chunks_without_labels_once(segmentation):
    import dask

    source = CountingArray(segmentation)
    chunks = (10, 12, 16)  # 4 x 4 x 4 chunks, many of them background only
    with dask.config.set(scheduler="synchronous"):
        blockwise = voxlod.dask.labels(da.from_array(source, chunks=chunks, asarray=False))
    assert_same_label_meshes(blockwise, voxlod.labels(segmentation))
    reads = np.zeros([n // c for n, c in zip(segmentation.shape, chunks)], int)
    for region in source.reads:
        reads[tuple(slice(a // c, (b - 1) // c + 1) for (a, b), c in zip(region, chunks))] += 1
    holding = np.array([[[segmentation[i * 10:(i + 1) * 10, j * 12:(j + 1) * 12,
                                       k * 16:(k + 1) * 16].any()
                          for k in range(4)] for j in range(4)] for i in range(4)])
    assert (~holding).sum() > 10
    assert (reads[~holding] == 1).all(), reads
    assert (reads[holding] >= 2).all(), reads


def test_bad_label_maps_raise():
    seg = np.zeros((20, 20, 20), np.float32)
    with pytest.raises(voxlod.InputError, match="no label other than 0"):
        voxlod.dask.labels(da.from_array(seg, chunks=10))
    seg[2:5, 2:5, 2:5] = 1
    with pytest.raises(voxlod.UsageError, match=r"no label 7 \(it holds 1\)"):
        voxlod.dask.labels(da.from_array(seg, chunks=10), labels=[7])
    seg[13, 14, 15] = 2.5
    with pytest.raises(voxlod.InputError, match=r"2.5 at index \(13, 14, 15\) is not a label"):
        voxlod.dask.labels(da.from_array(seg, chunks=10))
    with pytest.raises(voxlod.UsageError, match="integers"):
        voxlod.dask.labels(da.from_array(seg.astype(np.complex64), chunks=10))
    with pytest.raises(voxlod.UsageError, match="levels"):
        voxlod.dask.labels(da.from_array(seg, chunks=10), levels=0)


@pytest.mark.parametrize("shared,filter", [(False, None), (True, None), (False, "hypercone")])
def test_a_precomputed_layer_from_dask_is_the_one_process_layer(client, segmentation, tmp_path,
                                                                shared, filter):
    keywords = dict(spacing=(1.5, 1.0, 1.0), origin=(2.0, -3.0, 0.5), levels=2, sharding="always",
                    shared=shared, filter=filter)
    voxlod.precomputed(tmp_path / "whole", segmentation, **keywords)
    array = da.from_array(segmentation, chunks=((16, 14, 10), (20, 28), (24, 24, 16)))
    voxlod.dask.precomputed(tmp_path / "dask", array, client=client, **keywords)
    files = sorted(p.relative_to(tmp_path / "whole") for p in (tmp_path / "whole").rglob("*")
                   if p.is_file())
    assert len(files) >= 4  # info, a volume chunk, mesh/info and the shard
    assert files == sorted(p.relative_to(tmp_path / "dask") for p in (tmp_path / "dask").rglob("*")
                           if p.is_file())
    for f in files:
        assert (tmp_path / "whole" / f).read_bytes() == (tmp_path / "dask" / f).read_bytes(), f


@pytest.fixture(scope="module")
def cells() -> np.ndarray:
    """A 40³ Voronoi-like map of 12 labels that touch one another, the chunk borders (chunks of
    16) and the map's faces, in a ball of radius 22 (background in the corners)."""
    n = 40
    seeds = np.random.default_rng(1).uniform(0, n, (12, 3))
    z, y, x = np.mgrid[:n, :n, :n]
    points = np.stack([z, y, x], -1).reshape(-1, 1, 3)
    cells = (((points - seeds[None]) ** 2).sum(-1).argmin(1) + 1).reshape(n, n, n)
    cells[(z - n / 2) ** 2 + (y - n / 2) ** 2 + (x - n / 2) ** 2 > (0.55 * n) ** 2] = 0
    return cells.astype(np.uint16)


def sorted_triangles(mesh) -> np.ndarray:
    """The mesh's triangles as (F, 3, 3) positions, each turned to start at its smallest
    vertex (rounded positions, lexicographic), sorted by their rounded positions."""
    t = mesh.vertices[mesh.faces].astype(np.float64)
    key = np.round(t * 1000).astype(np.int64)
    first = np.lexsort(key.transpose(2, 0, 1)[::-1].reshape(3, -1)).reshape(-1)
    rank = np.empty(key.shape[0] * 3, np.int64)
    rank[first] = np.arange(len(first))
    start = rank.reshape(-1, 3).argmin(1)
    turn = (start[:, None] + np.arange(3)[None]) % 3
    rows = np.arange(len(t))[:, None]
    t, key = t[rows, turn], key[rows, turn]
    return t[np.lexsort(key.reshape(len(t), 9).T[::-1])]


def assert_same_surfaces(blockwise, whole, tolerance=1e-4):
    """Per label the same voxels and triangle count, and the same triangles (sorted by their
    rounded positions) within ``tolerance`` voxel."""
    assert [(m.label, m.voxels) for m in blockwise] == [(m.label, m.voxels) for m in whole]
    for mine, theirs in zip(blockwise, whole):
        assert len(mine.faces) == len(theirs.faces), mine.label
        np.testing.assert_allclose(sorted_triangles(mine), sorted_triangles(theirs), rtol=0,
                                   atol=tolerance, err_msg=f"label {mine.label}")


def vertex_distance(mine, theirs) -> float:
    """The largest distance from a vertex of either mesh to the other's nearest vertex."""
    from scipy.spatial import cKDTree

    return max(float(cKDTree(b).query(a)[0].max())
               for a, b in ((mine.vertices, theirs.vertices), (theirs.vertices, mine.vertices)))


def assert_identical(blockwise, whole):
    """Per label the same voxels and the same arrays, bit for bit."""
    assert [(m.label, m.voxels) for m in blockwise] == [(m.label, m.voxels) for m in whole]
    for mine, theirs in zip(blockwise, whole):
        for name in ("vertices", "faces", "normals"):
            a, b = getattr(mine.levels[0], name), getattr(theirs.levels[0], name)
            assert a.dtype == b.dtype and np.array_equal(a, b), (mine.label, name)


def test_shared_labels_are_the_single_process_meshes_bit_for_bit(client, cells):
    array = da.from_array(cells, chunks=16)
    for keywords in (dict(smooth=0), dict(smooth=3), dict(), dict(smooth=0, triangles=200),
                     dict(smooth=3, triangles=200),
                     dict(smooth=0, triangles=1000)):  # 1000: a neighbour's share limits
        whole = voxlod.labels(cells, shared=True, **keywords)
        assert len(whole) == 12
        assert_identical(voxlod.dask.labels(array, client=client, shared=True, **keywords),
                         whole)
    keywords = dict(spacing=(1.5, 1.0, 0.5), origin=(2.0, -3.0, 0.5), labels=[9, 3], smooth=2)
    assert_identical(voxlod.dask.labels(da.from_array(cells, chunks=(16, 11, 20)),
                                        client=client, shared=True, **keywords),
                     voxlod.labels(cells, shared=True, **keywords))


def test_shared_labels_far_from_most_of_the_map_are_still_bit_for_bit(client):
    # 64³ and 40 labels, one iteration (halo 2 + 3 + 4 = 9): each block's and label's box
    # holds a fraction of the map, so the restoring's pressures come from the blocks' sums.
    n = 64
    seeds = np.random.default_rng(5).uniform(0, n, (40, 3))
    z, y, x = np.mgrid[:n, :n, :n]
    points = np.stack([z, y, x], -1).reshape(-1, 1, 3)
    many = (((points - seeds[None]) ** 2).sum(-1).argmin(1) + 1).reshape(n, n, n)
    many[(z - n / 2) ** 2 + (y - n / 2) ** 2 + (x - n / 2) ** 2 > (0.52 * n) ** 2] = 0
    many = many.astype(np.uint32)
    whole = voxlod.labels(many, shared=True, smooth=1)
    blockwise = voxlod.dask.labels(da.from_array(many, chunks=16), client=client, shared=True,
                                   smooth=1)
    assert_identical(blockwise, whole)
    halo = voxlod.dask.shared_halo(1)
    assert halo == 9
    # Most labels' tasks see a box smaller than the map along some axis.
    boxes = [_box(many == m.label) for m in whole]
    assert sum(any(h - l + 1 + 2 * halo < n for l, h in zip(*b)) for b in boxes) > 30


def _box(mask: np.ndarray):
    """The first and last index of ``mask``'s true samples, per axis."""
    where = np.nonzero(mask)
    return [w.min() for w in where], [w.max() for w in where]


def test_smoothed_shared_labels_keep_their_volumes_and_close(client, cells):
    for mine in voxlod.dask.labels(da.from_array(cells, chunks=16), client=client, shared=True,
                                   smooth=3):
        mesh = as_trimesh(mine.vertices, mine.faces)
        assert mesh.is_watertight, mine.label
        assert abs(mesh.volume / mine.voxel_volume - 1) < 1e-3, mine.label


def test_the_shared_halo_matters(cells, monkeypatch):
    import dask

    array = da.from_array(cells, chunks=16)
    whole = voxlod.labels(cells, shared=True, smooth=3)
    monkeypatch.setattr(voxlod.dask, "shared_halo", lambda smooth: 1)
    with dask.config.set(scheduler="synchronous"):
        blockwise = voxlod.dask.labels(array, shared=True, smooth=3)
    # A halo of one voxel: the boxes' borders move vertices the whole map does not (by more
    # than 0.05 voxel somewhere).
    assert max(vertex_distance(mine, theirs) if len(mine.vertices) == len(theirs.vertices)
               else np.inf for mine, theirs in zip(blockwise, whole)) > 0.05


def test_labels_triangles_are_the_single_process_meshes(client, cells, segmentation):
    for seg in (cells, segmentation):
        array = da.from_array(seg, chunks=16)
        for triangles in (200, 1000):
            assert_same_surfaces(voxlod.dask.labels(array, client=client, triangles=triangles),
                                 voxlod.labels(seg, triangles=triangles))


def test_bad_surface_options_raise_as_in_one_process(cells):
    array = da.from_array(cells, chunks=16)
    for keywords, message in ((dict(smooth=2), "pass shared=True"),
                              (dict(shared=True, smooth=-1), "0 or more iterations"),
                              (dict(shared=True, levels=2), "do not go with levels"),
                              (dict(smooth=2, filter="gaussian"), "do not go with levels"),
                              (dict(triangles=100, radius=2.0), "triangles reduces"),
                              (dict(shared=True, triangles=3), "at least 4")):
        with pytest.raises(voxlod.UsageError, match=message):
            voxlod.labels(cells, **keywords)
        with pytest.raises(voxlod.UsageError, match=message):
            voxlod.dask.labels(array, **keywords)
