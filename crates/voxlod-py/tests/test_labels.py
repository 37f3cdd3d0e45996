"""voxlod.labels: one closed mesh per structure of a label map, checked with trimesh against the
voxel counts, and against zmesh (igneous' mesher) where it is installed."""

from __future__ import annotations

import numpy as np
import pytest

import voxlod
from conftest import touching_balls
from meshes import as_trimesh, nearest

SPACING = (1.5, 1.0, 1.0)  # axis 0 in 1.5-unit steps


@pytest.fixture(scope="module")
def segmentation() -> np.ndarray:
    """Three structures in a (40, 48, 64) map: balls 1 and 2 (radius 10 units) overlap, and the
    overlap goes to the nearer centre, so they touch along a flat face; ball 3 stands apart."""
    return touching_balls(SPACING[0])


def test_three_structures_give_three_closed_meshes_of_their_voxel_volume(segmentation):
    found = voxlod.labels(segmentation, spacing=SPACING)
    assert [m.label for m in found] == [1, 2, 3]
    for m in found:
        assert m.voxels == int((segmentation == m.label).sum())
        assert m.voxel_volume == pytest.approx(m.voxels * 1.5)
        mesh = as_trimesh(m.vertices, m.faces)
        assert mesh.is_watertight and mesh.is_winding_consistent, m.label
        assert mesh.euler_number == 2, m.label  # one sphere-like piece
        # Outward: positive volume, within 3 % of the voxels' volume.
        assert abs(mesh.volume / m.voxel_volume - 1) < 0.03, (m.label, mesh.volume, m.voxel_volume)
    # The touching balls meet at x = 26 (world x is axis 2): 1 ends there, 2 begins there.
    one, two = found[0].vertices, found[1].vertices
    assert one[:, 0].max() == pytest.approx(two[:, 0].min(), abs=1.0)
    assert one[:, 0].max() < 27.5 and two[:, 0].min() > 24.5
    # World (x, y, z): ball 3 is centred at x = 53, y = 24, z = 27 (axis 0 scaled by 1.5).
    centre = found[2].vertices.mean(axis=0)
    assert np.allclose(centre, [53, 24, 27], atol=0.5), centre


def test_chains_coarsen_and_labels_can_be_chosen(segmentation):
    (three,) = voxlod.labels(segmentation, spacing=SPACING, labels=[3], levels=3)
    assert three.label == 3 and len(three.levels) == 3
    counts = [len(level.faces) for level in three.levels]
    assert all(a > b for a, b in zip(counts, counts[1:])), counts
    for level in three.levels[:2]:
        assert as_trimesh(level.vertices, level.faces).is_watertight


def test_bad_label_maps_raise(segmentation):
    with pytest.raises(voxlod.UsageError, match="no label 7"):
        voxlod.labels(segmentation, labels=[7])
    with pytest.raises(voxlod.InputError, match="no label other than 0"):
        voxlod.labels(np.zeros((4, 4, 4), np.uint8))
    with pytest.raises(voxlod.InputError, match=r"0.5 at index \(0, 0, 0\) is not a label"):
        voxlod.labels(np.full((4, 4, 4), 0.5, np.float32), levels=1)
    with pytest.raises(voxlod.InputError, match=r"0.5 at index \(0, 0, 0\) is not a label"):
        voxlod.labels(np.full((4, 4, 4), 0.5, np.float32))
    with pytest.raises(voxlod.InputError, match=r"-3 at index \(1, 2, 3\) is not a label"):
        negative = np.zeros((4, 4, 4), np.int64)
        negative[1, 2, 3] = -3
        voxlod.labels(negative)
    with pytest.raises(voxlod.InputError, match="is not a label"):
        voxlod.labels(np.full((4, 4, 4), 2**32, np.uint64))
    with pytest.raises(voxlod.UsageError, match="3-D"):
        voxlod.labels(np.ones((2, 4, 4, 4), np.uint8))
    with pytest.raises(voxlod.UsageError, match="pass shared=True"):
        voxlod.labels(segmentation, smooth=3)
    with pytest.raises(voxlod.UsageError, match="do not go with levels"):
        voxlod.labels(segmentation, shared=True, levels=2)
    with pytest.raises(voxlod.UsageError, match="levels"):
        voxlod.labels(segmentation, levels=0)
    with pytest.raises(ValueError, match="3-D"):
        voxlod.labels(segmentation[0])


def test_agrees_with_zmesh(segmentation):
    zmesh = pytest.importorskip("zmesh", reason="zmesh is not installed: no comparison with "
                                "igneous' mesher (pip install zmesh)")
    mesher = zmesh.Mesher(SPACING[::-1])
    # zmesh reads Fortran order (x fastest first index): hand it the transposed map.
    mesher.mesh(np.asfortranarray(segmentation.T))
    ours = {m.label: m for m in voxlod.labels(segmentation, spacing=SPACING)}
    for label in (1, 2, 3):
        theirs = mesher.get(label, normals=False, voxel_centered=False)  # samples at index × spacing
        their_mesh = as_trimesh(theirs.vertices, theirs.faces)
        our_mesh = as_trimesh(ours[label].vertices, ours[label].faces)
        # Same place and size: volumes within 3 % and every vertex of ours within 1.5 voxels.
        assert abs(our_mesh.volume / abs(their_mesh.volume) - 1) < 0.03, label
        distance, _ = nearest(ours[label].vertices, theirs.vertices)
        assert distance.max() < 1.5 * max(SPACING), (label, distance.max())


def test_shared_neighbours_meet_on_the_same_triangles_and_keep_their_volume(segmentation):
    found = voxlod.labels(segmentation, spacing=SPACING, shared=True)
    assert [m.label for m in found] == [1, 2, 3]
    corners = {}
    for m in found:
        mesh = as_trimesh(m.vertices, m.faces)
        assert mesh.is_watertight and mesh.is_winding_consistent, m.label
        assert abs(mesh.volume / m.voxel_volume - 1) < 0.01, (m.label, mesh.volume, m.voxel_volume)
        for face in m.faces:
            key = tuple(sorted(map(tuple, m.vertices[face])))
            corners.setdefault(key, []).append(m.label)
    # Balls 1 and 2 touch: the triangles between them are used by both, no triangle by three.
    between = sum(1 for used in corners.values() if sorted(used) == [1, 2])
    assert between > 50, between
    assert max(len(used) for used in corners.values()) == 2


def test_labels_beyond_two_to_the_24_keep_their_ids(segmentation):
    big = segmentation.astype(np.uint32) * np.uint32(1_000_000_000)
    found = voxlod.labels(big, spacing=SPACING, labels=[3_000_000_000, 1_000_000_000])
    assert [m.label for m in found] == [3_000_000_000, 1_000_000_000]
    plain = {m.label: m for m in voxlod.labels(segmentation, spacing=SPACING)}
    assert np.array_equal(found[0].faces, plain[3].faces)
    assert np.array_equal(found[0].vertices, plain[3].vertices)
    # The filtered levels too: the labels reach the pyramid as they are, not as float32.
    found = voxlod.labels(big, spacing=SPACING, labels=[3_000_000_000], levels=2)
    plain = voxlod.labels(segmentation, spacing=SPACING, labels=[3], levels=2)
    assert found[0].label == 3_000_000_000
    for ours, theirs in zip(found[0].levels, plain[0].levels):
        assert len(ours.faces) > 0
        assert np.array_equal(ours.faces, theirs.faces)
        assert np.array_equal(ours.vertices, theirs.vertices)


def test_the_mesher_answers_as_zmesh_does(segmentation):
    zmesh = pytest.importorskip("zmesh", reason="zmesh is not installed: no comparison with "
                                "its Mesher (pip install zmesh)")
    data = np.asfortranarray(segmentation.T)  # zmesh's [x, y, z] indexing
    theirs, ours = zmesh.Mesher(SPACING[::-1]), voxlod.Mesher(SPACING[::-1])
    for close, centred, label in [(False, False, 1), (False, False, 2), (False, False, 3),
                                  (True, False, 1), (False, True, 2), (True, True, 3)]:
        theirs.mesh(data, close=close)
        ours.mesh(data, close=close)
        assert sorted(theirs.ids()) == ours.ids() == [1, 2, 3]
        a = theirs.get(label, normals=False, voxel_centered=centred)
        b = ours.get(label, normals=True, voxel_centered=centred)
        # The same surface (marching cubes of the label's voxels at ½): as many triangles on
        # the same vertices; the volumes differ by a few in ten thousand where the two tables
        # cut a cell's polygon along other diagonals.
        assert len(a.faces) == len(b.faces), label
        assert b.normals.shape == b.vertices.shape
        distance, _ = nearest(b.vertices, a.vertices)
        assert distance.max() < 1e-4, (close, centred, label, distance.max())
        va, vb = as_trimesh(a.vertices, a.faces).volume, as_trimesh(b.vertices, b.faces).volume
        assert abs(abs(va) / vb - 1) < 2e-3, (label, va, vb)
    with pytest.raises(voxlod.UsageError, match="reduction_factor"):
        ours.get(1, reduction_factor=10)


def test_a_precomputed_layer_reads_back_in_cloud_volume(segmentation, tmp_path):
    layer = tmp_path / "layer"
    report = voxlod.precomputed(layer, segmentation, spacing=SPACING, levels=2, unit="nm")
    assert [label for label, _ in report["labels"]] == [1, 2, 3]
    assert (layer / "info").is_file() and (layer / "mesh" / "info").is_file()
    cloudvolume = pytest.importorskip("cloudvolume", reason="cloud-volume is not installed: "
                                      "the layer is not read back (pip install cloud-volume)")
    cv = cloudvolume.CloudVolume(f"file://{layer}", progress=False)
    assert np.array_equal(np.asarray(cv[:, :, :])[..., 0], segmentation.T)
    for label, lods in report["labels"]:
        for lod, (_, triangles, _) in enumerate(lods):
            mesh = cv.mesh.get(label, lod=lod)[label]
            assert len(mesh.faces) == triangles, (label, lod)


def test_a_precomputed_layer_of_filtered_levels_holds_the_filter_pyramid(segmentation,
                                                                         tmp_path):
    layer = tmp_path / "layer"
    report = voxlod.precomputed(layer, segmentation, spacing=SPACING, levels=3, filter="hypercone")
    pyramid = voxlod.labels(segmentation, spacing=SPACING, levels=3, filter="hypercone")
    assert [label for label, _ in report["labels"]] == [m.label for m in pyramid] == [1, 2, 3]
    assert report["carried"] == []
    with pytest.raises(voxlod.UsageError, match="has 3 levels, the layer 2"):
        voxlod.precomputed(tmp_path / "other", segmentation, pyramid, levels=2, radius=1.0)
    with pytest.raises(voxlod.UsageError, match="does not go with filter or radius"):
        voxlod.precomputed(tmp_path / "other", segmentation, shared=True, radius=1.0)
    # A label of one voxel has no surface under the filter, a thin plate none at the coarser
    # levels: both are named in warnings.
    speckled = segmentation.copy()
    speckled[5, 5, 5] = 9
    speckled[30:31, 5:40, 5:60] = 8
    with pytest.warns(UserWarning, match=r"some levels .* empty \(labels 8, 9\)"):
        voxlod.labels(speckled, spacing=SPACING, levels=3, filter="hypercone")
    with pytest.warns(UserWarning) as caught:
        more = voxlod.precomputed(tmp_path / "speckled", speckled, spacing=SPACING, levels=3,
                                  filter="hypercone")
    said = [str(w.message) for w in caught]
    assert len(said) == 2, said
    assert any("(labels 9)" in w and "no surface even at level 0" in w for w in said), said
    assert any("(labels 8)" in w and "coarser levels" in w for w in said), said
    assert more["carried"] == [8]
    cloudvolume = pytest.importorskip("cloudvolume", reason="cloud-volume is not installed: "
                                      "the layer is not read back (pip install cloud-volume)")
    cv = cloudvolume.CloudVolume(f"file://{layer}", progress=False)
    for (label, lods), mesh in zip(report["labels"], pyramid):
        for lod, (_, triangles, _) in enumerate(lods):
            read = cv.mesh.get(label, lod=lod)[label]
            assert len(read.faces) == triangles >= len(mesh.levels[lod].faces), (label, lod)
            # Level k of the layer is the pyramid's level k, cut on the octree's grid: the same
            # volume, within the 16-bit quantization.
            ours = as_trimesh(mesh.levels[lod].vertices, mesh.levels[lod].faces).volume
            theirs = as_trimesh(read.vertices, read.faces).volume
            assert abs(theirs / ours - 1) < 1e-3, (label, lod, ours, theirs)


def test_triangles_budgets_each_label_and_neighbours_still_share_their_triangles(segmentation):
    plain = {m.label: m for m in voxlod.labels(segmentation, spacing=SPACING, shared=True)}
    found = voxlod.labels(segmentation, spacing=SPACING, shared=True, triangles=800)
    for m in found:
        assert 400 <= len(m.faces) <= 800 < len(plain[m.label].faces), (m.label, len(m.faces))
        mesh = as_trimesh(m.vertices, m.faces)
        assert mesh.is_watertight and mesh.is_winding_consistent, m.label
        assert abs(mesh.volume / m.voxel_volume - 1) < 0.02, (m.label, mesh.volume)
    # Balls 1 and 2 still meet on the same triangles; ball 3 shares none.
    keys = {m.label: {frozenset(map(tuple, m.vertices[f])) for f in m.faces} for m in found}
    assert len(keys[1] & keys[2]) > 10
    assert not (keys[1] | keys[2]) & keys[3]
    for m in voxlod.labels(segmentation, spacing=SPACING, triangles=800):
        assert len(m.faces) <= 800 and as_trimesh(m.vertices, m.faces).is_watertight, m.label
    with pytest.raises(voxlod.UsageError, match="triangles must be at least 4"):
        voxlod.labels(segmentation, triangles=3)
    with pytest.raises(voxlod.UsageError, match="triangles reduces the one-pass surfaces"):
        voxlod.labels(segmentation, levels=2, triangles=800)
