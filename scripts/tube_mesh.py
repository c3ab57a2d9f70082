#!/usr/bin/env python3
"""Structured O-grid hex mesh of a straight circular tube, written as Gmsh MSH 4.1 ASCII.

    python3 scripts/tube_mesh.py                                  # the default: cases/meshes/tube.msh
    python3 scripts/tube_mesh.py 16 3 40 0.55 cases/meshes/tube.msh   # the same, spelt out
    python3 scripts/tube_mesh.py 32 6 80 0.55 /tmp/tube_fine.msh  # twice as fine
    python3 scripts/tube_mesh.py 16 3 40 0.55 --info             # counts and quality only

Arguments (positional, all optional): cells around the circumference (a multiple of 4), cells
radially in the outer ring, cells along z, core fraction (radius of the core square's corners / R,
in (0, 1)), output path. --length and --radius change the geometry; the defaults are the
elastic-tube benchmark (Formaggia et al. 2001): L = 0.05 m, R = 0.005 m, axis along +z from z = 0.

Cross-section (the z = const plane, n = cells around, m = cells in the ring):

            +------------+                 the core: a square of (n/4) x (n/4) cells whose corners lie on
          / |  ring (m)  | \               the circle of radius coreFraction R; the ring: 4 curved blocks of
         /  +------------+  \              (n/4) x m cells, nodes uniform in angle on the circle and uniform
        |   |            |   |             along the square's sides, joined by straight lines (radial
        |   |   core     |   |             spacing uniform). Nodes are shared between blocks; the cross
        |   | n/4 x n/4  |   |             section is extruded in n_z uniform layers along z.
        |   |            |   |
         \  +------------+  /
          \ |            | /
            +------------+

Output: Gmsh MSH 4.1 ASCII, the layout core/GmshReader.cpp reads (as scripts/make_cylinder_mesh.py
writes it): 8-node hexahedra (type 5, right-handed: bottom quad counter-clockwise seen from +z, top
quad above it) in the physical volume "fluid", and boundary quadrangles (type 3, outward normals)
in the physical surfaces inlet (z = 0), outlet (z = L) and wall (r = R). Every cell's scaled
Jacobian at its 8 corners is checked (> 0) before writing and its minimum printed. Needs numpy.
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gmsh_hex import write_hex_msh  # noqa: E402

PATCHES = ["inlet", "outlet", "wall"]  # physical surface tags 1..3
VOLUME_TAG = 4
# Hex faces (core/HexMesh.hpp kHexFaces), outward normals.
FACE_XP, FACE_ZM, FACE_ZP = (1, 2, 6, 5), (0, 3, 2, 1), (4, 5, 6, 7)
# For each corner: its neighbours along +xi, +eta, +zeta (core/HexGeometry.hpp hexMinScaledJacobian).
CORNER_NB = np.array([[1, 3, 4], [2, 0, 5], [3, 1, 6], [0, 2, 7], [7, 5, 0], [4, 6, 1], [5, 7, 2], [6, 4, 3]])


def cross_section(n, m, core_fraction, radius):
    """2D nodes (N x 2), quads (counter-clockwise, 4 node ids each) and the quads with a wall edge.

    The wall edge of a ring quad is its local edge 1-2 (local 0 -> 1 runs radially outwards, 0 -> 3
    counter-clockwise around the axis), i.e. face FACE_XP of the extruded hex.
    """
    if n < 4 or n % 4:
        raise SystemExit("cells around must be a positive multiple of 4, got %d" % n)
    if m < 1:
        raise SystemExit("cells in the ring must be >= 1, got %d" % m)
    if not 0.0 < core_fraction < 1.0:
        raise SystemExit("core fraction must be in (0, 1), got %g" % core_fraction)
    c = n // 4
    half = core_fraction * radius / np.sqrt(2.0)  # half-side of the core square
    points = []
    core = {}
    s = np.linspace(-half, half, c + 1)
    for j in range(c + 1):
        for i in range(c + 1):
            core[i, j] = len(points)
            points.append((s[i], s[j]))

    def square_node(a):
        """Core-square boundary node a (0 .. n-1), counter-clockwise from the lower-left corner."""
        side, t = divmod(a % n, c)
        return core[[(t, 0), (c, t), (c - t, c), (0, c - t)][side]]

    ring = {}
    for a in range(n):
        th = np.radians(225.0 + 360.0 * a / n)  # the lower-left corner of the square is at 225 degrees
        wx, wy = radius * np.cos(th), radius * np.sin(th)
        sx, sy = points[square_node(a)]
        ring[a, 0] = square_node(a)
        for k in range(1, m + 1):
            g = k / m
            ring[a, k] = len(points)
            points.append(((1 - g) * sx + g * wx, (1 - g) * sy + g * wy))
    quads, wall = [], []
    for j in range(c):
        for i in range(c):
            quads.append((core[i, j], core[i + 1, j], core[i + 1, j + 1], core[i, j + 1]))
    for a in range(n):
        b = (a + 1) % n
        for k in range(m):
            # radial outwards, then counter-clockwise: (r, theta) is right-handed, so this is counter-clockwise
            if k == m - 1:
                wall.append(len(quads))
            quads.append((ring[a, k], ring[a, k + 1], ring[b, k + 1], ring[b, k]))
    return np.array(points), np.array(quads, dtype=np.int64), wall


def build(n, m, nz, core_fraction, length, radius):
    pts2, quads, wall = cross_section(n, m, core_fraction, radius)
    n2 = len(pts2)
    z = np.linspace(0.0, length, nz + 1)
    coords = np.empty(((nz + 1) * n2, 3))
    for k in range(nz + 1):
        coords[k * n2:(k + 1) * n2, :2] = pts2
        coords[k * n2:(k + 1) * n2, 2] = z[k]
    layers = [np.hstack([quads + k * n2, quads + (k + 1) * n2]) for k in range(nz)]
    cells = np.vstack(layers)  # layer k holds cells k * len(quads) ... (k + 1) * len(quads) - 1
    nq = len(quads)
    faces = {
        "inlet": cells[:nq][:, FACE_ZM],
        "outlet": cells[(nz - 1) * nq:][:, FACE_ZP],
        "wall": np.vstack([cells[k * nq + np.array(wall)][:, FACE_XP] for k in range(nz)]),
    }
    return coords, cells, faces


def min_scaled_jacobian(coords, cells):
    """Smallest corner Jacobian / product of the three edge lengths over all cells (as the reader)."""
    x = coords[cells]                                   # (cells, 8, 3)
    e = x[:, CORNER_NB, :] - x[:, :, None, :]           # (cells, 8 corners, 3 edges, 3)
    det = np.linalg.det(e)
    lens = np.linalg.norm(e, axis=-1).prod(axis=-1)
    return float((det / lens).min())


def write_msh(path, coords, cells, faces, length, radius):
    write_hex_msh(path, PATCHES, coords, cells, faces, (-radius, -radius, 0, radius, radius, length), VOLUME_TAG)


def main():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("around", nargs="?", type=int, default=16, help="cells around (multiple of 4; default 16)")
    ap.add_argument("radial", nargs="?", type=int, default=3, help="cells radially in the outer ring (default 3)")
    ap.add_argument("axial", nargs="?", type=int, default=40, help="cells along z (default 40)")
    ap.add_argument("core_fraction", nargs="?", type=float, default=0.55,
                    help="core square corner radius / R (default 0.55)")
    ap.add_argument("output", nargs="?", default=os.path.join(root, "cases/meshes/tube.msh"),
                    help="output .msh (default cases/meshes/tube.msh)")
    ap.add_argument("--length", type=float, default=0.05, help="tube length L in m (default 0.05)")
    ap.add_argument("--radius", type=float, default=0.005, help="tube radius R in m (default 0.005)")
    ap.add_argument("--info", action="store_true", help="print counts and quality, write nothing")
    args = ap.parse_args()
    if args.axial < 1 or args.length <= 0 or args.radius <= 0:
        sys.exit("cells along z, length and radius must be positive")
    coords, cells, faces = build(args.around, args.radial, args.axial, args.core_fraction, args.length, args.radius)
    sj = min_scaled_jacobian(coords, cells)
    if not sj > 0.0:
        sys.exit("inverted cell (min scaled Jacobian %g)" % sj)
    line = "tube L = %g m, R = %g m: %d around, %d in the ring, core %dx%d, %d along z: %d cells, %d nodes, " \
           "min scaled Jacobian %.3f" % (args.length, args.radius, args.around, args.radial, args.around // 4,
                                         args.around // 4, args.axial, len(cells), len(coords), sj)
    if not args.info:
        write_msh(args.output, coords, cells, faces, args.length, args.radius)
        line += "\n  -> %s (%.0f kB; boundary faces %s)" % (
            args.output, os.path.getsize(args.output) / 1e3, {p: len(f) for p, f in faces.items()})
    print(line)


if __name__ == "__main__":
    main()
