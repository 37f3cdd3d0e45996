"""Where the command line puts a scan's meshes: every command that turns a volume into a mesh,
on oblique and flipped scans written by nibabel (NIfTI) and SimpleITK (MetaImage, NRRD), checked
against the world position those libraries give the object's centre.

Each file holds a ball (radius 7 mm, in millimetres of the scan, so a true ball in the world)
centred at a fractional index of a 40 x 36 x 28 grid with spacing 0.8, 1.1, 1.5 mm. The
expected centre is the file's own index-to-world map of that index: nibabel's affine for NIfTI
(``apply_affine``), SimpleITK's ``TransformContinuousIndexToPhysicalPoint`` for MetaImage and
NRRD. A mesh's centre is the centroid of the solid it bounds (signed tetrahedra), checked within
half the finest spacing (0.4 mm), or half a level's voxel for coarser levels.

Frames: voxlod writes a volume's meshes in the input's own anatomical frame unless ``--frame``
says otherwise (``crates/voxlod-core/src/world.rs``; ``frame`` in the reports). A NIfTI file is
in RAS, as nibabel's affine is; ITK, MetaImage and NRRD (``space: left-posterior-superior``) are
in LPS, as SimpleITK's physical points are. The cases with ``--frame`` ask for the other frame,
where the expected point is the library's with x and y negated.

The voxlod binary is taken from ``VOXLOD_BIN`` or ``<repo>/target/release/voxlod``; without it the
tests skip and say why.
"""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest
import trimesh

from conftest import REPO

nibabel = pytest.importorskip("nibabel")
sitk = pytest.importorskip("SimpleITK")

DIMS = (40, 36, 28)  # samples along index axes i, j, k
SPACING = np.array([0.8, 1.1, 1.5])  # millimetres
CENTRE = np.array([17.3, 15.6, 12.2])  # the ball's centre, as a fractional index
RADIUS = 7.0  # millimetres
ORIGIN = np.array([-20.5, 13.25, -7.0])  # world position of index 0
TOLERANCE = 0.5 * SPACING.min()
# Voxelize's resolution: samples across the longest side of the thresholded ball.
VOXELIZE_RESOLUTION = 40


def rotation(axis: str, degrees: float) -> np.ndarray:
    c, s = np.cos(np.radians(degrees)), np.sin(np.radians(degrees))
    i, j = {"x": (1, 2), "y": (2, 0), "z": (0, 1)}[axis]
    r = np.eye(3)
    r[i, i], r[i, j], r[j, i], r[j, j] = c, -s, s, c
    return r


# Direction cosines (column a: the world direction of index axis a).
POSES = {
    # 30° about z, then a tilt of 8° about the rotated x axis.
    "oblique": rotation("z", 30.0) @ rotation("x", 8.0),
    # Index axis i runs against world x: a left-handed index-to-world map.
    "flipped": np.diag([-1.0, 1.0, 1.0]),
}


def field() -> np.ndarray:
    """The ball's signed distance in millimetres, positive inside, indexed [i, j, k]."""
    i, j, k = np.meshgrid(*(np.arange(n, dtype=float) for n in DIMS), indexing="ij")
    offset = np.stack([i, j, k], axis=-1) - CENTRE
    return (RADIUS - np.linalg.norm(offset * SPACING, axis=-1)).astype(np.float32)


def labels() -> np.ndarray:
    """The ball as label 1 of a uint8 label map, indexed [i, j, k]."""
    return (field() > 0).astype(np.uint8)


def write_nifti(path: Path, data: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """Writes ``data`` with nibabel; returns the ball's centre in the file's world (RAS)."""
    affine = np.eye(4)
    affine[:3, :3] = direction * SPACING
    affine[:3, 3] = ORIGIN
    image = nibabel.Nifti1Image(data, affine)
    image.set_sform(affine, code=1)
    image.set_qform(affine, code=1)
    nibabel.save(image, path)
    return nibabel.affines.apply_affine(affine, CENTRE)


def write_itk(path: Path, data: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """Writes ``data`` with SimpleITK (the format by the extension); returns the ball's centre in
    the file's world (LPS)."""
    image = sitk.GetImageFromArray(np.ascontiguousarray(data.transpose(2, 1, 0)))
    image.SetSpacing(SPACING.tolist())
    image.SetOrigin(ORIGIN.tolist())
    image.SetDirection(direction.flatten().tolist())
    sitk.WriteImage(image, str(path))
    return np.array(image.TransformContinuousIndexToPhysicalPoint(CENTRE.tolist()))


WRITERS = {"nii.gz": write_nifti, "mha": write_itk, "nrrd": write_itk}
FRAMES = {"nii.gz": "ras", "mha": "lps", "nrrd": "lps"}


def binary() -> Path:
    path = Path(os.environ.get("VOXLOD_BIN", REPO / "target" / "release" / "voxlod"))
    if not path.is_file():
        reason = f"no voxlod binary at {path} (build it with cargo build --release or set VOXLOD_BIN)"
        print(reason)
        pytest.skip(reason)
    return path


def voxlod(*args) -> dict:
    """Runs the binary with ``--json``; returns its report."""
    done = subprocess.run([str(binary()), *map(str, args), "--json"], capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 0, (args, done.stderr)
    return json.loads(done.stdout)


def centroid(path: Path) -> np.ndarray:
    """The centroid of the solid a closed mesh file bounds, whose triangles must face outwards
    (a positive enclosed volume, flipped scans included)."""
    mesh = trimesh.load(path, process=False, force="mesh")
    a, b, c = (np.asarray(mesh.vertices, float)[mesh.faces[:, n]] for n in range(3))
    volumes = np.einsum("ij,ij->i", a, np.cross(b, c)) / 6.0
    assert mesh.is_watertight, path
    assert volumes.sum() > 0, (path, "inside out")
    return ((a + b + c) / 4.0 * volumes[:, None]).sum(axis=0) / volumes.sum()


# Every command that turns a volume into meshes: each runs on `source` (a file of the ball's
# distance field, or of its label map for `labels`) in `work`, and returns the mesh files with
# the tolerance of each.
def contour(source, work, *flags):
    out = work / "ball.ply"
    voxlod("contour", source, "-o", out, "--iso", 0, *flags)
    return [(out, TOLERANCE)]


def lod(source, work, *flags):
    report = voxlod("lod", source, "-o", work / "levels", "--threshold", 0, "--resolutions",
                    "40,20", *flags)
    return [(work / "levels" / level["file"], max(TOLERANCE, 0.5 * level["voxel_size"]))
            for level in report["levels"]]


def labels_command(source, work, *flags):
    voxlod("labels", source, "-o", work / "labels", *flags)
    return [(work / "labels" / "label-1.ply", TOLERANCE)]


def voxelize_then_contour(source, work, *flags):
    density = work / "density.nrrd"
    report = voxlod("voxelize", source, "-o", density, "--resolution", VOXELIZE_RESOLUTION,
                    "--threshold", 0, *flags)
    out = work / "ball.ply"
    voxlod("contour", density, "-o", out, "--iso", 0.5)
    return [(out, max(TOLERANCE, 0.5 * report["spacing"]))]


def layers(source, work, extension, *flags):
    """The layered shells in one file of ``extension`` (a .glb read as one mesh, or a .ply of all
    layers): nested closed shells about the ball, so the centroid of all of them is its centre."""
    out = work / f"shells.{extension}"
    voxlod("layers", source, "-o", out, "--threshold", 0, "--resolution", VOXELIZE_RESOLUTION,
           "--error", 0.05, *flags)
    return [(out, TOLERANCE)]


# name: (the command, the input it takes, its flags; "other-frame" asks for the frame the file
# is not in).
COMMANDS = {
    "contour": (contour, "field", []),
    "contour --close": (contour, "field", ["--close"]),
    "contour --frame": (contour, "field", ["other-frame"]),
    "contour --close --frame": (contour, "field", ["--close", "other-frame"]),
    "lod": (lod, "field", []),
    "lod --frame": (lod, "field", ["other-frame"]),
    # Read blockwise (NRRD with raw encoding and MetaImage with uncompressed data only).
    "lod --blockwise": (lod, "field", ["--blockwise"]),
    "labels": (labels_command, "labels", []),
    "labels --frame": (labels_command, "labels", ["other-frame"]),
    "voxelize + contour": (voxelize_then_contour, "field", []),
    # The first flag of `layers` is the output's extension.
    "layers": (layers, "field", ["glb"]),
    "layers .ply": (layers, "field", ["ply"]),
    "layers --lod": (layers, "field", ["glb", "--lod", "--levels", 2]),
}

# Every file with every command (--blockwise reads NRRD and MetaImage blockwise, not NIfTI).
CASES = [(ext, pose, command) for ext in WRITERS for pose in POSES for command in COMMANDS
         if not (ext == "nii.gz" and "--blockwise" in COMMANDS[command][2])]


@pytest.fixture(scope="module")
def scans(tmp_path_factory):
    """Every file of the table, written once: {(ext, pose, input): (path, expected centre)}."""
    root = tmp_path_factory.mktemp("scans")
    data = {"field": field(), "labels": labels()}
    written = {}
    for ext, write in WRITERS.items():
        for pose, direction in POSES.items():
            for name, values in data.items():
                path = root / f"{pose}-{name}.{ext}"
                written[(ext, pose, name)] = (path, write(path, values, direction))
    return written


@pytest.mark.parametrize("ext,pose,command", CASES,
                         ids=[f"{e}-{p}-{c.replace(' ', '')}" for e, p, c in CASES])
def test_meshes_land_where_the_file_puts_the_ball(scans, tmp_path, ext, pose, command):
    run, input_name, flags = COMMANDS[command]
    source, expected = scans[(ext, pose, input_name)]
    frame = FRAMES[ext]
    if "other-frame" in flags:
        frame = {"ras": "lps", "lps": "ras"}[frame]
        flags = [f for f in flags if f != "other-frame"] + ["--frame", frame]
        expected = expected * np.array([-1.0, -1.0, 1.0])
    for mesh, tolerance in run(source, tmp_path, *flags):
        found = centroid(mesh)
        miss = float(np.linalg.norm(found - expected))
        print(f"{ext} {pose} {command} ({frame}) {mesh.name}: {miss:.3f} mm off")
        assert miss < tolerance, (mesh.name, found, expected, miss)
