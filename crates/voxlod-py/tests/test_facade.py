"""voxlod.lod, lod_volume, the file calls, inspect and compare, checked with trimesh and
against analytic shapes."""

from __future__ import annotations

import os
import signal
import threading
import time

import numpy as np
import pytest
import trimesh

import voxlod
from meshes import as_trimesh


@pytest.fixture(scope="module")
def torus():
    mesh = trimesh.creation.torus(major_radius=1.0, minor_radius=0.35, major_sections=64,
                                  minor_sections=32)
    return np.asarray(mesh.vertices, np.float32), np.asarray(mesh.faces)


def test_lod_levels_are_watertight_with_falling_counts(torus):
    levels = voxlod.lod(*torus, resolution=64, levels=4)
    assert [level.resolution for level in levels] == [64, 32, 16, 8]
    counts = [len(level.faces) for level in levels]
    assert all(a > b for a, b in zip(counts, counts[1:])), counts
    for level in levels[:3]:
        mesh = as_trimesh(level.vertices, level.faces)
        assert mesh.is_watertight and mesh.is_winding_consistent and mesh.volume > 0
        assert level.genus == 1 and level.topology["triangles"] == len(level.faces)
        assert level.normals.shape == level.vertices.shape
    # The finest level is close to the torus: its volume within 3 % of 2π²Rr².
    assert abs(as_trimesh(levels[0].vertices, levels[0].faces).volume
               / (2 * np.pi**2 * 1.0 * 0.35**2) - 1) < 0.03


def test_lod_volume_threshold_and_direct_routes():
    z, y, x = np.mgrid[-16:17, -16:17, -16:17]
    ball = np.where(x**2 + y**2 + (z * 2.0) ** 2 < 144, 1000, 0).astype(np.int16)
    spacing = (2.0, 1.0, 1.0)  # axis 0 in 2-unit steps: the ball is a sphere of radius 12
    for kwargs in ({"threshold": 500}, {"direct": True, "iso": 500.0}):
        levels = voxlod.lod_volume(ball, spacing, resolution=48, levels=2, **kwargs)
        mesh = as_trimesh(levels[0].vertices, levels[0].faces)
        assert mesh.is_watertight and levels[0].genus == 0, kwargs
        extent = levels[0].vertices.max(0) - levels[0].vertices.min(0)
        # World (x, y, z): every extent near the diameter 24, z included thanks to the spacing.
        assert np.all(np.abs(extent - 24.0) < 2.5), (kwargs, extent)
    with pytest.raises(ValueError, match="threshold"):
        voxlod.lod_volume(ball, spacing)


def test_progress_callback_sees_every_step_and_can_stop(torus):
    seen = []
    voxlod.lod(*torus, resolution=16, levels=2, progress=lambda d, t, w: seen.append((d, t, w)))
    assert seen[0][2] == "started" and seen[-1][0] == seen[-1][1] and len(seen) >= 4
    with pytest.raises(voxlod.Cancelled):
        voxlod.lod(*torus, resolution=16, levels=3, progress=lambda d, t, w: d < 1)


def test_ctrl_c_stops_the_work(torus):
    # Python's own Ctrl-C handler, whatever this process inherited (a shell's background job
    # starts with SIGINT ignored, and Python then installs no handler).
    inherited = signal.signal(signal.SIGINT, signal.default_int_handler)
    timer = threading.Timer(0.05, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    # Until the signal lands, however loaded the machine (a fixed count of calls finished
    # before a starved timer fired once); a minute without it is a failure.
    deadline = time.monotonic() + 60
    with pytest.raises(KeyboardInterrupt):
        while time.monotonic() < deadline:
            voxlod.lod(*torus, resolution=96, levels=3)
    timer.cancel()
    signal.signal(signal.SIGINT, inherited)


def test_callback_errors_reach_the_caller(torus):
    def fail(done, total, what):
        raise ZeroDivisionError("from the callback")
    with pytest.raises(ZeroDivisionError, match="from the callback"):
        voxlod.lod(*torus, resolution=16, levels=2, progress=fail)


def test_files_round_trip(tmp_path, torus):
    path = tmp_path / "torus.ply"
    voxlod.write_mesh(path, *torus)
    vertices, faces = voxlod.read_mesh(path)
    np.testing.assert_array_equal(faces, torus[1])
    np.testing.assert_allclose(vertices, torus[0])
    volume = np.random.default_rng(3).random((5, 6, 7)).astype(np.float32)
    voxlod.write_volume(tmp_path / "v.nrrd", volume, spacing=(3.0, 2.0, 1.0), origin=(1, 2, 3))
    samples, spacing, origin = voxlod.read_volume(tmp_path / "v.nrrd")
    np.testing.assert_array_equal(samples, volume)
    assert spacing == (3.0, 2.0, 1.0) and origin == (1.0, 2.0, 3.0)
    raw = tmp_path / "v.raw"
    counts = (volume * 60000).astype(">u2")
    counts.tofile(raw)
    samples, spacing, _ = voxlod.read_volume(raw, shape=(5, 6, 7), dtype="u16", endian="big",
                                             spacing=(2, 1, 1))
    np.testing.assert_array_equal(samples, counts.astype(np.float32))
    assert spacing == (2.0, 1.0, 1.0) and samples.max() > 1000


def test_file_errors_are_os_errors(tmp_path):
    with pytest.raises(OSError) as info:
        voxlod.read_mesh(tmp_path / "missing.obj")
    assert isinstance(info.value, voxlod.FileError) and "missing.obj" in str(info.value)
    (tmp_path / "empty.obj").write_text("v 0 0 0\n")
    with pytest.raises(ValueError, match="empty.obj"):
        voxlod.read_mesh(tmp_path / "empty.obj")


def test_inspect_agrees_with_trimesh(torus):
    report = voxlod.inspect(*torus)
    mesh = as_trimesh(*torus)
    assert report["closed_manifold"] and report["genus"] == 1
    assert report["area"] == pytest.approx(mesh.area, rel=1e-5)
    assert report["volume"] == pytest.approx(mesh.volume, rel=1e-5)
    open_mesh = voxlod.inspect(torus[0], torus[1][:-10])
    assert not open_mesh["closed_manifold"] and open_mesh["boundary_loops"] >= 1


def test_compare_has_the_cli_keys_and_measures_a_shift(torus):
    v, f = torus
    report = voxlod.compare((v, f), (v + np.float32([0, 0, 0.05]), f), samples=20000)
    for key in ("a", "b", "a_triangles", "b_triangles", "hausdorff", "mean", "rms",
                "hausdorff_fraction", "samples", "diagonal", "first_to_second",
                "second_to_first", "read_seconds", "total_seconds", "warnings"):
        assert key in report, key
    assert 0.03 < report["hausdorff"] <= 0.0501


@pytest.mark.parametrize(
    "vertices, faces",
    [
        (np.zeros((3, 2)), [[0, 1, 2]]),
        (np.zeros((3, 3)), [[0, 1, 3]]),
        (np.zeros((3, 3)), [[0, -1, 2]]),
        (np.zeros((3, 3)), [[0.0, 1.0, 2.0]]),
    ],
)
def test_bad_meshes_are_value_errors(vertices, faces):
    with pytest.raises(ValueError):
        voxlod.lod(vertices, faces, resolution=8, levels=1)


def test_nan_vertices_are_refused(torus):
    v = torus[0].copy()
    v[5, 1] = np.nan
    with pytest.raises(ValueError):
        voxlod.lod(v, torus[1], resolution=8, levels=1)


def test_layers_are_nested_closed_shells(torus):
    shells = voxlod.layers(*torus, 0.025, resolution=32)
    assert len(shells) == 5  # the hyper-cone needs five layers for 0.025 (README, plan_table)
    assert shells[0]["translucency"] == 0.0 and shells[0]["alpha"] == 1.0
    volumes = [as_trimesh(s["vertices"], s["faces"]).volume for s in shells]
    assert all(as_trimesh(s["vertices"], s["faces"]).is_watertight for s in shells)
    # Innermost first: each shell (a lower isodensity) encloses more than the one before.
    assert all(a < b for a, b in zip(volumes, volumes[1:])), volumes


def test_cluster_and_envelope_simplify(torus):
    (level,) = voxlod.cluster(*torus, cells=12)
    assert 0 < len(level["faces"]) < len(torus[1])
    assert level["lines"].shape[1] == 2
    (level,) = voxlod.envelope(*torus, 0.02)
    simplified = as_trimesh(level["vertices"], level["faces"])
    assert simplified.is_watertight and len(level["faces"]) < len(torus[1]) / 2
    # Within ε of the input: every simplified vertex is an input vertex.
    assert len(np.setdiff1d(level["vertices"].view("V12"), torus[0].view("V12"))) == 0


def test_lod_by_triangle_budgets_lands_each_level_near_its_budget(torus):
    budgets = [2000, 500, 120]
    # An option that does not apply to the mesh portfolio is named, not silently dropped.
    with pytest.warns(UserWarning, match="time_cap does not apply"):
        levels = voxlod.lod(*torus, triangles=budgets, time_cap=float("inf"))
    assert [level.budget["budget"] for level in levels] == budgets
    for level, budget in zip(levels, budgets):
        assert abs(len(level.faces) / budget - 1) <= 0.10, (budget, len(level.faces))
        mesh = as_trimesh(level.vertices, level.faces)
        assert mesh.is_watertight and mesh.is_winding_consistent and mesh.volume > 0
        assert level.budget["triangles"] == len(level.faces)
        assert level.budget["genus"] == level.genus
        # The report's distance is measured against the input: a torus of tube radius 0.35
        # kept by every level, so well under the tube's radius, and above zero.
        assert 0 < level.budget["hausdorff"] < 0.35
    genera = [level.genus for level in levels]
    assert all(b <= a for a, b in zip(genera, genera[1:])), genera
    # The same budgets as the command line's --triangles, and an error target alone.
    near = voxlod.lod(*torus, error="1%")
    assert len(near) == 1 and near[0].budget["error_target"] > 0
    assert near[0].budget["hausdorff"] <= 3 * near[0].budget["error_target"]


def test_lod_says_what_preparing_the_mesh_repaired(torus):
    # The torus's triangles given twice: the copies are dropped, with a warning that says so,
    # as the command line says it on standard error.
    vertices, faces = torus
    twice = np.concatenate([faces, faces])
    with pytest.warns(UserWarning, match=f"{len(faces)} duplicate triangles dropped"):
        levels = voxlod.lod(vertices, twice, triangles=[500])
    assert abs(len(levels[0].faces) / 500 - 1) <= 0.10
    with pytest.warns(UserWarning, match=f"{len(faces)} duplicate triangles dropped"):
        voxlod.lod(vertices, twice, resolution=24, levels=1)


def test_lod_by_budget_refuses_bad_arguments(torus):
    for kwargs, match in [
        ({"triangles": [1000], "resolution": 64}, "resolution"),
        ({"triangles": [2.5]}, "whole number"),
        ({"triangles": [0]}, "whole number"),
        ({"triangles": [2**70]}, "whole number"),
        ({"triangles": ["1000"]}, "whole number"),
        ({"triangles": [3]}, "tetrahedron"),
        ({"triangles": []}, "at least one"),
        ({"error": "-1%"}, "error"),
        ({"triangles": [100], "then": "magic"}, "then"),
        ({"triangles": [100], "time_cap": float("nan")}, "time_cap"),
    ]:
        with pytest.raises(voxlod.UsageError, match=match):
            voxlod.lod(*torus, **kwargs)
