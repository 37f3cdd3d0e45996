#!/usr/bin/env python3
"""Independent views of meshes: self-intersecting triangles (MeshLab's and Open3D's) and tiny
triangles.

Usage: open3d-self-intersections.py [--open3d-pairs-up-to N] MESH [MESH ...]
(OBJ, PLY, STL, OFF)

Prints one line per mesh: triangles; MeshLab's self-intersecting faces (pymeshlab's
`compute_selection_by_self_intersections_per_face`, vcglib's test over a uniform grid of the
faces' boxes, so fast on large meshes; it counts faces, not pairs); Open3D's
get_self_intersecting_triangles() pairs (Open3D skips pairs that share a vertex and tests all
others, O(F^2): only for meshes of at most N triangles, 50 000 by default, since a level of
167k triangles did not finish in hours; "-" above); Open3D's edge- and vertex-manifoldness; and
the triangles under 1e-12, 1e-9 and 1e-6 in area (mesh units², not cells²). Run with the peers'
Python (~/.cache/voxlod-peers/bin/python, see ../shared/peers/setup.sh); the contouring crate's
ignored test `clean_real_data` calls it on the bunny's and the CT skull's level 1.
"""
import argparse
import sys

import numpy as np
import open3d as o3d
import pymeshlab


def meshlab_self_intersecting_faces(path):
    """Faces MeshLab selects as intersecting another face of the mesh."""
    meshes = pymeshlab.MeshSet()
    meshes.load_new_mesh(path)
    meshes.compute_selection_by_self_intersections_per_face()
    return meshes.current_mesh().selected_face_number()


def main():
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--open3d-pairs-up-to", type=int, default=50_000, metavar="N")
    parser.add_argument("meshes", nargs="+", metavar="MESH")
    args = parser.parse_args()
    for path in args.meshes:
        mesh = o3d.io.read_triangle_mesh(path)
        v = np.asarray(mesh.vertices)
        t = np.asarray(mesh.triangles)
        a, b, c = v[t[:, 0]], v[t[:, 1]], v[t[:, 2]]
        area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
        if len(t) <= args.open3d_pairs_up_to:
            pairs = str(len(np.asarray(mesh.get_self_intersecting_triangles())))
        else:
            pairs = "-"
        small = " ".join(f"<{x:g}: {(area < x).sum()}" for x in (1e-12, 1e-9, 1e-6))
        print(
            f"{path}: triangles {len(t)}, "
            f"meshlab self-intersecting faces {meshlab_self_intersecting_faces(path)}, "
            f"open3d pairs {pairs}, edge-manifold {mesh.is_edge_manifold()}, "
            f"vertex-manifold {mesh.is_vertex_manifold()}, small areas {small}",
            flush=True,
        )


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main()
