#!/usr/bin/env python3
"""Makes the generated samples of data/ (see data/README.md); Python 3.8+, standard library only.

    python3 data/generate.py          # (re)writes the samples beside this script
    python3 data/generate.py --check  # exits 1 if a committed sample differs from what it makes

Everything is computed from closed-form shapes, so the output is the same on every machine (the
gzip stream of the NRRD may differ between zlib versions; --check compares its samples).
"""

import gzip
import math
import struct
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent

# --- The head phantom ------------------------------------------------------------------------
#
# Ten ellipsoids in the cube [-1, 1]^3 after the 3-D Shepp-Logan head phantom (x left-right,
# y back-front, z foot-head), with the high-contrast ("modified") intensities: values add where
# ellipsoids overlap. Skull 1.0, brain 0.2, the two ventricles 0.0, the small structures 0.3.
# Each row: intensity, centre (x, y, z), semi-axes (x, y, z), rotation about z in degrees.
PHANTOM = [
    (1.0, (0.0, 0.0, 0.0), (0.69, 0.92, 0.81), 0),  # skull, outer surface
    (-0.8, (0.0, -0.0184, 0.0), (0.6624, 0.874, 0.78), 0),  # brain inside the skull
    (-0.2, (0.22, 0.0, 0.0), (0.11, 0.31, 0.22), -18),  # right ventricle
    (-0.2, (-0.22, 0.0, 0.0), (0.16, 0.41, 0.28), 18),  # left ventricle
    (0.1, (0.0, 0.35, -0.15), (0.21, 0.25, 0.41), 0),
    (0.1, (0.0, 0.1, 0.25), (0.046, 0.046, 0.05), 0),
    (0.1, (0.0, -0.1, 0.25), (0.046, 0.046, 0.05), 0),
    (0.1, (-0.08, -0.605, 0.0), (0.046, 0.023, 0.05), 0),
    (0.1, (0.0, -0.606, 0.0), (0.023, 0.023, 0.02), 0),
    (0.1, (0.06, -0.605, 0.0), (0.023, 0.046, 0.02), 0),
]
HEAD_MM = 200.0  # the cube's side: a head about 140 x 180 x 160 mm
SCALE = 1000  # stored sample = intensity x SCALE, as 16-bit signed integers
SUBSAMPLES = 4  # rows per voxel along y and along z (x is integrated exactly)


def ellipsoid_span(ellipsoid, y, z):
    """The x interval of the line (., y, z) inside the ellipsoid, or None."""
    _, (cx, cy, cz), (ax, ay, az), degrees = ellipsoid
    c, s = math.cos(math.radians(degrees)), math.sin(math.radians(degrees))
    # The point (x, y, z) in the ellipsoid's frame is u + x * v (rotation by -degrees about z).
    px, py, pz = -cx, y - cy, z - cz
    u = (c * px + s * py, -s * px + c * py, pz)
    v = (c, -s, 0.0)
    axes = (ax, ay, az)
    qa = sum(v[i] * v[i] / axes[i] ** 2 for i in range(3))
    qb = sum(2 * u[i] * v[i] / axes[i] ** 2 for i in range(3))
    qc = sum(u[i] * u[i] / axes[i] ** 2 for i in range(3)) - 1
    disc = qb * qb - 4 * qa * qc
    if disc <= 0:
        return None
    root = math.sqrt(disc)
    return (-qb - root) / (2 * qa), (-qb + root) / (2 * qa)


def phantom_row(nx, y, z, weight, diff, direct):
    """Adds weight x (each ellipsoid's intensity x the length of its span in each voxel, in
    voxels) to the row: whole voxels through the difference array, the two ends directly."""
    for ellipsoid in PHANTOM:
        span = ellipsoid_span(ellipsoid, y, z)
        if span is None:
            continue
        w = ellipsoid[0] * weight
        # Voxel i covers [i, i + 1) in these units.
        s = min(max((span[0] + 1) * nx / 2, 0.0), nx)
        e = min(max((span[1] + 1) * nx / 2, 0.0), nx)
        i0, i1 = int(s), int(e)
        if i0 == i1:
            if i0 < nx:
                direct[i0] += (e - s) * w
            continue
        direct[i0] += (i0 + 1 - s) * w
        if i1 < nx:
            direct[i1] += (e - i1) * w
        diff[i0 + 1] += w
        diff[i1] -= w


def head_phantom(dims):
    """The phantom's samples (x fastest) on a grid of dims voxels over the cube, each the mean
    intensity over its voxel (exact along x, SUBSAMPLES^2 rows along y and z)."""
    nx, ny, nz = dims
    out = []
    weight = 1.0 / SUBSAMPLES**2
    for k in range(nz):
        for j in range(ny):
            diff, direct = [0.0] * (nx + 1), [0.0] * nx
            for sk in range(SUBSAMPLES):
                z = -1 + 2 * (k + (sk + 0.5) / SUBSAMPLES) / nz
                for sj in range(SUBSAMPLES):
                    y = -1 + 2 * (j + (sj + 0.5) / SUBSAMPLES) / ny
                    phantom_row(nx, y, z, weight, diff, direct)
            running = 0.0
            for i in range(nx):
                running += diff[i]
                out.append(round((running + direct[i]) * SCALE))
    return out


def spacing_and_origin(dims):
    spacing = [HEAD_MM / n for n in dims]
    origin = [-HEAD_MM / 2 + s / 2 for s in spacing]
    return spacing, origin


def nrrd_header(dims):
    spacing, origin = spacing_and_origin(dims)
    directions = " ".join(
        "(" + ",".join(f"{spacing[a] if b == a else 0:.10g}" for b in range(3)) + ")"
        for a in range(3)
    )
    return (
        "NRRD0004\n"
        "# A Shepp-Logan-like head phantom made by data/generate.py: x 1000, skull 1000,\n"
        "# brain 200, ventricles 0, small structures 300, air 0.\n"
        "type: short\n"
        "dimension: 3\n"
        "space: right-anterior-superior\n"
        f"sizes: {dims[0]} {dims[1]} {dims[2]}\n"
        f"space directions: {directions}\n"
        "kinds: domain domain domain\n"
        "endian: little\n"
        "encoding: gzip\n"
        f"space origin: ({origin[0]:.10g},{origin[1]:.10g},{origin[2]:.10g})\n"
        'space units: "mm" "mm" "mm"\n'
        "\n"
    ).encode()


def int16s(values, order):
    return struct.pack(f"{order}{len(values)}h", *values)


# --- Meshes ----------------------------------------------------------------------------------


def tube(curve, segments, sides, radius):
    """A closed tube of `radius` around the closed curve `curve(t)`, t in [0, 1): vertices and
    triangles (1-based). The cross-section follows a rotation-minimising frame (each normal the
    last one made perpendicular to the new tangent), its twist on closing spread evenly."""
    points = [curve(s / segments) for s in range(segments)]
    tangents = [
        normalize([b - a for a, b in zip(points[s - 1], points[(s + 1) % segments])])
        for s in range(segments)
    ]
    normals = [perpendicular(tangents[0])]
    for t in tangents[1:] + tangents[:1]:
        n = normals[-1]
        normals.append(normalize([n[i] - dot(n, t) * t[i] for i in range(3)]))
    # The transported normal comes back turned by `twist` about the first tangent.
    closing, first = normals.pop(), normals[0]
    twist = math.atan2(dot(cross(first, closing), tangents[0]), dot(first, closing))
    vertices = []
    for s in range(segments):
        t, n = tangents[s], normals[s]
        b = cross(t, n)
        for k in range(sides):
            a = 2 * math.pi * k / sides - twist * s / segments
            c, sn = math.cos(a), math.sin(a)
            vertices.append([points[s][i] + radius * (c * n[i] + sn * b[i]) for i in range(3)])
    faces = []
    for s in range(segments):
        for k in range(sides):
            a = s * sides + k + 1
            b = s * sides + (k + 1) % sides + 1
            c = ((s + 1) % segments) * sides + k + 1
            d = ((s + 1) % segments) * sides + (k + 1) % sides + 1
            faces += [(a, c, d), (a, d, b)]
    return vertices, faces


def perpendicular(v):
    """A unit vector perpendicular to the unit vector v."""
    other = [1.0, 0.0, 0.0] if abs(v[0]) < 0.9 else [0.0, 1.0, 0.0]
    return normalize(cross(v, other))


def torus_knot(p, q, major, minor):
    def curve(t):
        a = 2 * math.pi * t
        r = major + minor * math.cos(q * a)
        return [r * math.cos(p * a), r * math.sin(p * a), minor * math.sin(q * a)]

    return curve


def ring(centre, normal_axis, radius):
    """A circle of `radius` about `centre`, perpendicular to axis 2 (z) or 1 (y)."""

    def curve(t):
        a = 2 * math.pi * t
        c, s = radius * math.cos(a), radius * math.sin(a)
        offset = [c, s, 0.0] if normal_axis == 2 else [c, 0.0, s]
        return [centre[i] + offset[i] for i in range(3)]

    return curve


def normalize(v):
    n = math.sqrt(dot(v, v))
    return [x / n for x in v]


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def signed_volume(vertices, faces):
    return sum(
        dot(vertices[a - 1], cross(vertices[b - 1], vertices[c - 1])) / 6 for a, b, c in faces
    )


def closest_approach(curves, samples, skip):
    """The smallest distance between curve points more than `skip` samples apart along one
    curve (or on different curves): the tubes do not touch while their radii sum to less."""
    points = [
        (n, s, curve(s / samples)) for n, curve in enumerate(curves) for s in range(samples)
    ]
    best = math.inf
    for i, (n1, s1, p1) in enumerate(points):
        for n2, s2, p2 in points[i + 1 :]:
            if n1 == n2 and min(abs(s1 - s2), samples - abs(s1 - s2)) <= skip:
                continue
            best = min(best, math.dist(p1, p2))
    return best


def obj_text(title, parts):
    lines = [f"# {line}" for line in title] + []
    offset = 0
    vertex_lines, face_lines = [], []
    for vertices, faces in parts:
        if signed_volume(vertices, faces) < 0:
            faces = [(a, c, b) for a, b, c in faces]
        vertex_lines += [f"v {x:.6g} {y:.6g} {z:.6g}" for x, y, z in vertices]
        face_lines += [f"f {a + offset} {b + offset} {c + offset}" for a, b, c in faces]
        offset += len(vertices)
    return "\n".join(lines + vertex_lines + face_lines) + "\n"


# --- The samples -----------------------------------------------------------------------------


def samples():
    """File name -> bytes of every generated sample."""
    out = {}
    dims = (128, 128, 128)
    out["head-phantom.nrrd"] = nrrd_header(dims) + gzip.compress(
        int16s(head_phantom(dims), "<"), compresslevel=9, mtime=0
    )
    # The same phantom as a headerless big-endian scan with slices twice as far apart as the
    # in-plane samples, like the CT head of ../shared/data (the README's raw-volume example).
    out["head-phantom-64x64x32-i16be.raw"] = int16s(head_phantom((64, 64, 32)), ">")

    knot = torus_knot(2, 3, 1.0, 0.45)
    assert closest_approach([knot], 240, 20) > 2 * 0.16, "the knot's tube touches itself"
    out["trefoil-knot.obj"] = obj_text(
        [
            "A trefoil knot: a tube of radius 0.16 around the (2,3) torus knot on a torus of",
            "radii 1 and 0.45; closed, one component, genus 1. Made by data/generate.py.",
        ],
        [tube(knot, 240, 12, 0.16)],
    ).encode()

    rings = [ring((0.0, 0, 0), 2, 1.0), ring((1.3, 0, 0), 1, 1.0), ring((2.6, 0, 0), 2, 1.0)]
    assert closest_approach(rings, 96, 10) > 2 * 0.25, "the chain's rings touch"
    out["chain.obj"] = obj_text(
        [
            "Three linked rings: tori of radii 1 and 0.25, 1.3 apart, in alternating planes;",
            "three closed components of genus 1 that filtering fuses. Made by data/generate.py.",
        ],
        [tube(r, 64, 12, 0.25) for r in rings],
    ).encode()
    return out


def same(name, made, committed):
    if name.endswith(".nrrd"):
        # Compare the header and the decompressed samples, not the gzip stream.
        def split(data):
            head, _, body = data.partition(b"\n\n")
            return head, gzip.decompress(body)

        return split(made) == split(committed)
    return made == committed


def main():
    check = "--check" in sys.argv[1:]
    differ = []
    for name, data in samples().items():
        path = HERE / name
        if check:
            if not path.is_file() or not same(name, data, path.read_bytes()):
                differ.append(name)
        else:
            path.write_bytes(data)
            print(f"{path.relative_to(HERE.parent)}: {len(data):,} bytes")
    if differ:
        print("differ from what data/generate.py makes: " + ", ".join(differ))
        sys.exit(1)


if __name__ == "__main__":
    main()
