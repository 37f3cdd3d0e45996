"""voxlod.gaussian_filter against scipy.ndimage.gaussian_filter on the same inputs."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage

import voxlod

MODES = ["reflect", "nearest", "constant", "mirror", "wrap"]


def noise(shape, dtype, seed=7):
    return np.random.default_rng(seed).random(shape).astype(dtype)


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("sigma", [1.0, 2.0, (0.8, 0.0, 2.5)])
def test_float32_within_1e4_of_scipy(mode, sigma):
    volume = noise((23, 31, 17), np.float32)
    ours = voxlod.gaussian_filter(volume, sigma, mode=mode, cval=0.3)
    theirs = ndimage.gaussian_filter(volume, sigma, mode=mode, cval=0.3)
    assert ours.dtype == theirs.dtype == np.float32 and ours.shape == volume.shape
    assert np.abs(ours - theirs).max() < 1e-4


@pytest.mark.parametrize("mode", MODES)
def test_float64_matches_scipy_to_rounding(mode):
    volume = noise((12, 9, 20), np.float64) * 1000.0
    ours = voxlod.gaussian_filter(volume, (1.5, 3.0, 0.7), mode=mode, truncate=3.0)
    theirs = ndimage.gaussian_filter(volume, (1.5, 3.0, 0.7), mode=mode, truncate=3.0)
    assert ours.dtype == np.float64
    np.testing.assert_allclose(ours, theirs, rtol=1e-12, atol=1e-9)


def test_kernels_wider_than_the_volume_fold_like_scipy():
    volume = noise((5, 3, 4), np.float64)
    for mode in MODES:
        ours = voxlod.gaussian_filter(volume, 3.0, mode=mode)
        np.testing.assert_allclose(ours, ndimage.gaussian_filter(volume, 3.0, mode=mode),
                                   rtol=1e-12, atol=1e-12, err_msg=mode)


def test_nan_spreads_as_in_scipy():
    volume = noise((16, 16, 16), np.float32)
    volume[8, 8, 8] = np.nan
    ours = voxlod.gaussian_filter(volume, 1.0)
    theirs = ndimage.gaussian_filter(volume, 1.0)
    np.testing.assert_array_equal(np.isnan(ours), np.isnan(theirs))


def test_big_endian_input_is_filtered_as_its_values():
    # A scan read with np.fromfile(..., ">f4") or ">f8", as SciPy takes it.
    for dtype in (">f4", ">f8"):
        volume = noise((10, 12, 14), np.dtype(dtype).newbyteorder("=")).astype(dtype)
        ours = voxlod.gaussian_filter(volume, 1.2)
        assert ours.dtype == np.dtype(dtype).newbyteorder("=")
        assert np.abs(ours - ndimage.gaussian_filter(volume, 1.2)).max() < 1e-4, dtype


def test_non_contiguous_input_is_filtered_correctly():
    volume = noise((20, 22, 24), np.float32)[::2, :, ::-1]
    ours = voxlod.gaussian_filter(volume, 1.3)
    assert np.abs(ours - ndimage.gaussian_filter(volume, 1.3)).max() < 1e-4


@pytest.mark.parametrize(
    "kwargs, error",
    [
        ({"input": np.zeros((4, 4), np.float32), "sigma": 1.0}, "3-D"),
        ({"input": np.zeros((4, 4, 4), np.int16), "sigma": 1.0}, "float32 and float64"),
        ({"input": np.zeros((0, 4, 4), np.float32), "sigma": 1.0}, "at least"),
        ({"input": np.zeros((4, 4, 4), np.float32), "sigma": -1.0}, "sigma"),
        ({"input": np.zeros((4, 4, 4), np.float32), "sigma": (1.0, 2.0)}, "sigma"),
        ({"input": np.zeros((4, 4, 4), np.float32), "sigma": 1.0, "mode": "bogus"}, "mode"),
        ({"input": np.zeros((4, 4, 4), np.float32), "sigma": 1.0, "order": 1}, "order=0"),
    ],
)
def test_bad_calls_raise_value_errors(kwargs, error):
    with pytest.raises(ValueError, match=error) as info:
        voxlod.gaussian_filter(**kwargs)
    assert isinstance(info.value, voxlod.Error)


def test_huge_inputs_are_refused_before_allocating():
    huge = np.broadcast_to(np.float32(0.0), (100_000, 100_000, 100_000))
    with pytest.raises(MemoryError):
        voxlod.gaussian_filter(huge, 1.0)
