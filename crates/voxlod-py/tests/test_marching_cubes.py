"""voxlod.marching_cubes against skimage.measure.marching_cubes on the same inputs."""

from __future__ import annotations

import numpy as np
import pytest
from skimage import measure

import voxlod
from conftest import gyroid
from meshes import area, as_trimesh, nearest, on_grid_edges, signed_volume


def compare_with_skimage(volume, level, **kw):
    ours = voxlod.marching_cubes(volume, level, **kw)
    theirs = measure.marching_cubes(volume, level, **kw)
    return ours, theirs


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_gyroid_is_closed_and_matches_skimage(dtype):
    volume = gyroid(72, dtype=dtype)
    (v, f, n, val), (sv, sf, sn, sval) = compare_with_skimage(volume, 0.0)
    mesh = as_trimesh(v, f)
    assert mesh.is_watertight and mesh.is_winding_consistent
    assert len(f) > 20000
    ours, theirs = area(v, f), area(sv, sf)
    assert abs(ours - theirs) / theirs < 0.005, (ours, theirs)
    # Same vertices: every one of ours is one of theirs; every one of theirs on a grid edge
    # (scikit-image adds cell-centre vertices in some ambiguous cases) is one of ours.
    distance, index = nearest(v, sv)
    assert distance.max() < 1e-4
    edge_vertices = sv[on_grid_edges(sv)]
    assert len(edge_vertices) == len(v)
    assert nearest(edge_vertices, v)[0].max() < 1e-4
    # Same orientation (scikit-image's signed volume is negative in axis order for descent),
    # normals pointing the same way, the same per-vertex values.
    assert np.sign(signed_volume(v, f)) == np.sign(signed_volume(sv, sf)) == -1
    assert np.mean(np.einsum("ij,ij->i", n, sn[index])) > 0.98
    assert np.mean(np.isclose(val, sval[index], rtol=1e-5)) > 0.99
    assert v.dtype == np.float32 and f.dtype == np.int32 and n.dtype == np.float32


def test_ascent_reverses_the_winding_like_skimage():
    # The object is below the level (the negated field is low inside the ball's gyroid): its
    # surface encloses the low region, so its signed volume is negative with 'ascent'.
    volume = -gyroid(40)
    (v, f, _, _), (sv, sf, _, _) = compare_with_skimage(volume, 0.0, gradient_direction="ascent")
    descent = voxlod.marching_cubes(volume, 0.0)
    assert np.sign(signed_volume(v, f)) == np.sign(signed_volume(sv, sf)) == -1
    assert signed_volume(descent[0], descent[1]) == pytest.approx(-signed_volume(v, f))
    assert as_trimesh(v, f).is_watertight


def test_spacing_scales_vertices_as_skimage_does():
    volume = gyroid(40)
    spacing = (2.0, 0.5, 1.25)
    (v, f, n, _), (sv, sf, sn, _) = compare_with_skimage(volume, 0.0, spacing=spacing)
    assert v.dtype == sv.dtype == np.float64
    # voxlod keeps vertices 1e-4 of an edge off its samples: 2e-4 at spacing 2.
    assert nearest(v, sv)[0].max() < 2.5e-4
    plain = voxlod.marching_cubes(volume, 0.0)
    np.testing.assert_allclose(v, plain[0] * np.asarray(spacing), rtol=1e-6)
    assert abs(area(v, f) - area(sv, sf)) / area(sv, sf) < 0.005


@pytest.mark.parametrize("dtype", [np.uint8, np.int16])
def test_integer_volumes_and_ties_follow_skimage(dtype):
    # A ball of whole numbers with many samples exactly at the level: inside is strictly above.
    z, y, x = np.mgrid[-12:13, -12:13, -12:13]
    volume = np.clip(100 - np.round(x**2 + y**2 + z**2) // 2, 0, 100).astype(dtype)
    (v, f, _, _), (sv, sf, _, _) = compare_with_skimage(volume, 40)
    assert np.count_nonzero(volume == 40) > 10
    assert as_trimesh(v, f).is_watertight
    assert nearest(v, sv)[0].max() < 1e-3
    assert abs(area(v, f) - area(sv, sf)) / area(sv, sf) < 0.005


def test_default_level_is_the_middle_of_the_range():
    volume = gyroid(32) * 3.0 + 1.0
    v, f, _, _ = voxlod.marching_cubes(volume)
    sv, sf, _, _ = measure.marching_cubes(volume)
    assert nearest(v, sv)[0].max() < 1e-4


def test_mask_contours_the_cells_skimage_contours():
    volume = gyroid(48)
    mask = np.zeros(volume.shape, bool)
    mask[:, :30, :] = True
    (v, f, _, _), (sv, sf, _, _) = compare_with_skimage(volume, 0.0, mask=mask)
    full = voxlod.marching_cubes(volume, 0.0)
    assert len(f) < 0.8 * len(full[1])
    assert abs(area(v, f) - area(sv, sf)) / area(sv, sf) < 0.005
    assert nearest(v, sv)[0].max() < 1e-4


def test_ct_head_matches_skimage(ct_head):
    (v, f, _, _), (sv, sf, _, _) = compare_with_skimage(ct_head, 500.0, method="lorensen")
    mesh = as_trimesh(v, f)
    assert mesh.is_watertight and mesh.is_winding_consistent
    # The same crossed edges, hence the same vertices, as scikit-image's classic tables.
    assert len(v) == len(sv)
    assert nearest(v, sv)[0].max() < 1e-3
    ours, theirs = area(v, f), area(sv, sf)
    assert abs(ours - theirs) / theirs < 0.005, (ours, theirs)
    # scikit-image's default (Lewiner) decides the scan's many ambiguous faces by the
    # asymptotic decider and adds cell-centre vertices, voxlod's tables by a fixed rule: on this
    # noisy scan the areas differ by 0.84 % (on the gyroid by under 0.5 %).
    lv, lf, _, _ = measure.marching_cubes(ct_head, 500.0)
    assert abs(ours - area(lv, lf)) / area(lv, lf) < 0.01


def test_non_contiguous_volumes_give_the_contiguous_result():
    volume = gyroid(40)
    strided = np.asfortranarray(volume)
    assert not strided.flags.c_contiguous
    a = voxlod.marching_cubes(strided, 0.0)
    b = voxlod.marching_cubes(volume, 0.0)
    for x, y in zip(a, b):
        np.testing.assert_array_equal(x, y)


@pytest.mark.parametrize(
    "volume, message",
    [
        (np.zeros((4, 4)), "3-D"),
        (np.zeros((4, 4, 4, 4)), "3-D"),
        (np.zeros((0, 4, 4)), "at least"),
        (np.zeros((1, 4, 4)), "at least"),
        (np.zeros((3, 3, 3), complex), "real numbers"),
        (np.array([[["a"]]]), "real numbers"),
    ],
)
def test_bad_arrays_are_usage_errors(volume, message):
    with pytest.raises(voxlod.UsageError, match=message) as info:
        voxlod.marching_cubes(volume, 0.0)
    assert isinstance(info.value, ValueError)


@pytest.mark.parametrize("spacing", [(0.0, 1.0, 1.0), (1.0, -2.0, 1.0), (1.0, 1.0, np.nan),
                                     np.inf])
def test_spacing_must_be_finite_and_positive(spacing):
    # It scales the vertices: zero, negative or NaN would flatten, mirror or poison them.
    with pytest.raises(voxlod.UsageError, match="finite and positive"):
        voxlod.marching_cubes(gyroid(8), 0.0, spacing=spacing)


def test_nan_is_refused_with_its_index():
    volume = gyroid(16)
    volume[3, 4, 5] = np.nan
    with pytest.raises(voxlod.InputError, match=r"NaN at index \(3, 4, 5\)"):
        voxlod.marching_cubes(volume, 0.0)


def test_the_first_nan_in_array_order_is_named():
    # 70³ samples span several of the scan's parallel chunks; the two NaNs sit in different
    # chunks and lanes, and the error names the one that comes first in array order.
    volume = gyroid(70)
    volume[60, 1, 2] = np.nan
    volume[41, 7, 3] = np.nan
    with pytest.raises(voxlod.InputError, match=r"NaN at index \(41, 7, 3\)"):
        voxlod.marching_cubes(volume, 0.0)
    # Exactly the data's extremes are within range; a hair beyond is not.
    top = float(volume[~np.isnan(volume)].max())
    volume[np.isnan(volume)] = 0.0
    with pytest.raises(RuntimeError, match="No surface"):
        voxlod.marching_cubes(volume, top)
    with pytest.raises(ValueError, match="within volume data range"):
        voxlod.marching_cubes(volume, float(np.nextafter(np.float32(top), np.float32(2))))


def test_huge_arrays_are_refused_before_allocating():
    huge = np.broadcast_to(np.float64(0.0), (100_000, 100_000, 100_000))
    with pytest.raises(voxlod.TooLargeError) as info:
        voxlod.marching_cubes(huge, 0.0)
    assert isinstance(info.value, MemoryError)


def test_the_memory_budget_is_honoured(monkeypatch):
    monkeypatch.setenv("VOXLOD_MAX_MEMORY", "64K")
    with pytest.raises(MemoryError, match="VOXLOD_MAX_MEMORY"):
        voxlod.marching_cubes(gyroid(48), 0.0)


def test_levels_outside_the_data_and_empty_surfaces():
    volume = gyroid(16)
    with pytest.raises(ValueError, match="within volume data range"):
        voxlod.marching_cubes(volume, 10.0)
    with pytest.raises(RuntimeError, match="No surface"):
        voxlod.marching_cubes(volume, float(volume.max()))
    with pytest.raises(ValueError, match="gradient_direction"):
        voxlod.marching_cubes(volume, 0.0, gradient_direction="up")
    with pytest.raises(ValueError, match="spacing"):
        voxlod.marching_cubes(volume, 0.0, spacing=(1.0, 2.0))
