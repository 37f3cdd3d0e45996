#!/usr/bin/env python3
"""Open3D's view of meshes: self-intersecting triangle pairs and tiny triangles.

Usage: open3d-self-intersections.py MESH [MESH ...]   (OBJ, PLY, STL, OFF)

Prints one line per mesh: triangles, Open3D's is_self_intersecting() and the number of pairs
from get_self_intersecting_triangles() (Open3D skips pairs that share a vertex and tests all
others, O(F^2): a level of 100k triangles takes a while), edge- and vertex-manifoldness, and
the triangles under 1e-12, 1e-9 and 1e-6 in area. Run with the peers' Python
(~/.cache/voxlod-peers/bin/python, see ../shared/peers/setup.sh); the contouring crate's
ignored test `clean_real_data` calls it on the bunny's and the CT skull's level 1.
"""
import sys

import numpy as np
import open3d as o3d


def main(paths):
    for path in paths:
        mesh = o3d.io.read_triangle_mesh(path)
        v = np.asarray(mesh.vertices)
        t = np.asarray(mesh.triangles)
        a, b, c = v[t[:, 0]], v[t[:, 1]], v[t[:, 2]]
        area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
        pairs = np.asarray(mesh.get_self_intersecting_triangles())
        small = " ".join(f"<{x:g}: {(area < x).sum()}" for x in (1e-12, 1e-9, 1e-6))
        print(
            f"{path}: triangles {len(t)}, self-intersecting {mesh.is_self_intersecting()}, "
            f"pairs {len(pairs)}, edge-manifold {mesh.is_edge_manifold()}, "
            f"vertex-manifold {mesh.is_vertex_manifold()}, small areas {small}"
        )


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1:])
