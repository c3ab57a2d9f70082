#!/usr/bin/env python3
"""Block-structured all-hex meshes of the Schaefer-Turek 2D-1 channel (flow past a cylinder).

    python3 scripts/make_cylinder_mesh.py                    # coarse + medium into the repository
    python3 scripts/make_cylinder_mesh.py --level fine -o /tmp/cylinder_fine.msh
    python3 scripts/make_cylinder_mesh.py --n 16 -o x.msh    # any resolution (n divisible by 4)
    python3 scripts/make_cylinder_mesh.py --level coarse --info   # cell count and quality only

Geometry (Schaefer & Turek 1996): channel [0, 2.2] x [0, 0.41], cylinder centre (0.2, 0.2),
radius 0.05, one cell thick in z: z in [0, 0.01] (H = 0.01, so c = 2F/(rho U^2 D H) with U = 0.2,
D = 0.1 uses H = 0.01). Output: Gmsh MSH 4.1 ASCII with 8-node hexahedra (type 5) and boundary
quadrangles (type 3) in the physical surfaces inlet (x = 0), outlet (x = 2.2), walls (y = 0 and
y = 0.41), cylinder, frontAndBack (z = 0 and z = 0.01), and the physical volume "fluid". Boundary
quads are written with outward normals. Read it with mfsi::readGmsh (core/GmshReader.hpp); for
OpenFOAM, perf/openfoam/schaefer_turek.sh converts it (gmsh -> MSH 2.2 -> gmshToFoam).

Block layout (n = cells along each side of the square around the cylinder):

    y=0.41 +------+--------+-------------------------------------------+
           | nL   |   n    |                nR (graded in x)           |  nT = round(0.55 n)
     0.3   +------+--------+-------------------------------------------+
           |      | O-grid |                                           |  n
           |      | ring   |                                           |
     0.1   +------+--------+-------------------------------------------+
           |      |        |                                           |  nB = n/2
     y=0   +------+--------+-------------------------------------------+
          x=0    0.1      0.3                                         2.2

The square [0.1, 0.3]^2 holds an O-grid ring: 4 blocks of n (around) x m = 3n/4 (radial) cells,
nodes uniform in angle on the circle and uniform along the square's sides, joined by straight
lines; radial spacing geometric, outermost cell 4x the one on the cylinder. The right block's
cells grow geometrically from 0.2/n (matching the square) to about 5x that at the outlet,
nR = round(23 n / 6). All other spacings are uniform, so every level has the same shape of grading
and halving h doubles every count.

Levels: coarse n = 12 (1,888 cells), medium n = 24 (7,424 cells), fine n = 48 (29,696 cells).
Coarse goes to tests/data/meshes/cylinder_coarse.msh, medium to cases/meshes/cylinder_medium.msh.
The fine mesh (~5 MB as MSH 4.1 ASCII, above the 3 MB limit for committed meshes) is not committed:
regenerate it with the second command above (a few seconds, standard library only, deterministic).

Every cell is checked before writing: the scaled Jacobian at its 8 corners must be positive (the
minimum is printed). Coordinates are written with 9 significant digits to keep files small.
"""
import argparse
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gmsh_hex import write_hex_msh  # noqa: E402

L_CHANNEL, H_CHANNEL = 2.2, 0.41
CX, CY, RADIUS = 0.2, 0.2, 0.05
SQ_LO, SQ_HI = 0.1, 0.3  # the square around the cylinder that holds the O-grid
DZ = 0.01
RING_GRADING = 4.0       # radial: outermost / innermost cell size in the ring
LEVELS = {"coarse": 12, "medium": 24, "fine": 48}
PATCHES = ["inlet", "outlet", "walls", "cylinder", "frontAndBack"]  # physical tags 1..5
VOLUME_TAG = 6

# Hex faces (core/HexMesh.hpp kHexFaces), outward normals.
FACE_XM, FACE_XP, FACE_YM, FACE_YP, FACE_ZM, FACE_ZP = (0, 4, 7, 3), (1, 2, 6, 5), (0, 1, 5, 4), \
    (2, 3, 7, 6), (0, 3, 2, 1), (4, 5, 6, 7)
HEX_CORNERS = [(-1, -1, -1), (1, -1, -1), (1, 1, -1), (-1, 1, -1),
               (-1, -1, 1), (1, -1, 1), (1, 1, 1), (-1, 1, 1)]


def uniform(a, b, n):
    return [a + (b - a) * i / n for i in range(n + 1)]


def geometric(a, b, n, first):
    """n cells from a to b, the first of size `first`, growing by a constant ratio (bisection)."""
    total = b - a
    if abs(first * n - total) < 1e-14 * total:
        return uniform(a, b, n)
    lo, hi = (1.0 + 1e-12, 2.0) if first * n < total else (1e-6, 1.0 - 1e-12)
    for _ in range(200):
        q = 0.5 * (lo + hi)
        s = first * (q ** n - 1.0) / (q - 1.0)
        if (s < total) == (first * n < total):
            lo = q
        else:
            hi = q
    x, h = [a], first
    for _ in range(n):
        x.append(x[-1] + h)
        h *= q
    x[n] = b
    return x


def ratio_fractions(m, grading):
    """m + 1 fractions in [0, 1], geometric, last cell `grading` times the first."""
    if m == 1:
        return [0.0, 1.0]
    q = grading ** (1.0 / (m - 1))
    sizes = [q ** k for k in range(m)]
    total = sum(sizes)
    f, s = [0.0], 0.0
    for h in sizes:
        s += h
        f.append(s / total)
    f[m] = 1.0
    return f


class Mesh2D:
    """Quads (counter-clockwise seen from +z) with boundary edges tagged by patch."""

    def __init__(self, n):
        if n < 4 or n % 4:
            raise SystemExit("n must be a positive multiple of 4")
        self.n = n
        nL, nB, nT, nR, m = n // 2, n // 2, int(round(0.55 * n)), int(round(23 * n / 6)), 3 * n // 4
        xs = uniform(0.0, SQ_LO, nL)[:-1] + uniform(SQ_LO, SQ_HI, n)[:-1] + \
            geometric(SQ_HI, L_CHANNEL, nR, (SQ_HI - SQ_LO) / n)
        ys = uniform(0.0, SQ_LO, nB)[:-1] + uniform(SQ_LO, SQ_HI, n)[:-1] + uniform(SQ_HI, H_CHANNEL, nT)
        NX, NY = len(xs) - 1, len(ys) - 1
        i0, j0 = nL, nB  # grid index of the square's lower-left corner
        self.points = []
        grid = {}

        def inside(i, j):
            return i0 < i < i0 + n and j0 < j < j0 + n

        for j in range(NY + 1):
            for i in range(NX + 1):
                if not inside(i, j):
                    grid[i, j] = len(self.points)
                    self.points.append((xs[i], ys[j]))
        # O-grid ring: angular index a = 0..4n-1 counter-clockwise from the lower-left corner
        # (225 degrees), radial index k = 0 (cylinder) .. m (square, shared with the grid).
        def square_node(a):
            s, t = divmod(a % (4 * n), n)
            return grid[[(i0 + t, j0), (i0 + n, j0 + t), (i0 + n - t, j0 + n), (i0, j0 + n - t)][s]]

        frac = ratio_fractions(m, RING_GRADING)
        ring = {}
        for a in range(4 * n):
            th = math.radians(225.0 + 90.0 * a / n)
            cx, cy = CX + RADIUS * math.cos(th), CY + RADIUS * math.sin(th)
            sx, sy = self.points[square_node(a)]
            for k in range(m):
                g = frac[k]
                ring[a, k] = len(self.points)
                self.points.append(((1 - g) * cx + g * sx, (1 - g) * cy + g * sy))
        for a in range(4 * n):
            ring[a, m] = square_node(a)

        self.quads = []  # node quads, counter-clockwise
        self.edges = {p: [] for p in PATCHES if p != "frontAndBack"}  # (quad index, local face)
        for j in range(NY):
            for i in range(NX):
                if i0 <= i < i0 + n and j0 <= j < j0 + n:
                    continue
                q = len(self.quads)
                self.quads.append((grid[i, j], grid[i + 1, j], grid[i + 1, j + 1], grid[i, j + 1]))
                if i == 0:
                    self.edges["inlet"].append((q, FACE_XM))
                if i == NX - 1:
                    self.edges["outlet"].append((q, FACE_XP))
                if j == 0:
                    self.edges["walls"].append((q, FACE_YM))
                if j == NY - 1:
                    self.edges["walls"].append((q, FACE_YP))
        for a in range(4 * n):
            b = (a + 1) % (4 * n)
            for k in range(m):
                # (a,k) -> (a,k+1) -> (a+1,k+1) -> (a+1,k): radial then angular = counter-clockwise
                q = len(self.quads)
                self.quads.append((ring[a, k], ring[a, k + 1], ring[b, k + 1], ring[b, k]))
                if k == 0:
                    self.edges["cylinder"].append((q, FACE_XM))
        self.sizes = dict(n=n, m=m, nL=nL, nB=nB, nT=nT, nR=nR, NX=NX, NY=NY)


def hexes(mesh):
    n2 = len(mesh.points)
    return [tuple(q) + tuple(v + n2 for v in q) for q in mesh.quads]


def node_coords(mesh):
    return [(x, y, 0.0) for x, y in mesh.points] + [(x, y, DZ) for x, y in mesh.points]


def min_scaled_jacobian(coords, cells):
    """Smallest corner Jacobian determinant / product of the three edge lengths, over all cells."""
    worst = 2.0
    for c in cells:
        p = [coords[v] for v in c]
        for a, (xi, eta, zeta) in enumerate(HEX_CORNERS):
            # Edges from corner a along +xi, +eta, +zeta directions of the reference cell.
            nb = []
            for d in range(3):
                corner = list(HEX_CORNERS[a])
                corner[d] = -corner[d]
                b = HEX_CORNERS.index(tuple(corner))
                sign = 1.0 if HEX_CORNERS[a][d] < 0 else -1.0
                nb.append([sign * (p[b][k] - p[a][k]) for k in range(3)])
            e1, e2, e3 = nb
            det = (e1[0] * (e2[1] * e3[2] - e2[2] * e3[1]) - e1[1] * (e2[0] * e3[2] - e2[2] * e3[0]) +
                   e1[2] * (e2[0] * e3[1] - e2[1] * e3[0]))
            lens = [math.sqrt(sum(v * v for v in e)) for e in nb]
            worst = min(worst, det / (lens[0] * lens[1] * lens[2]))
    return worst


def write_msh(path, mesh):
    coords = node_coords(mesh)
    cells = hexes(mesh)
    faces = {p: [tuple(cells[q][k] for k in f) for q, f in mesh.edges[p]] for p in mesh.edges}
    faces["frontAndBack"] = [tuple(c[k] for k in FACE_ZM) for c in cells] + \
        [tuple(c[k] for k in FACE_ZP) for c in cells]
    write_hex_msh(path, PATCHES, coords, cells, faces, (0, 0, 0, L_CHANNEL, H_CHANNEL, DZ), VOLUME_TAG)
    return faces


def build(n, path=None, quiet=False):
    mesh = Mesh2D(n)
    coords = node_coords(mesh)
    cells = hexes(mesh)
    sj = min_scaled_jacobian(coords, cells)
    if sj <= 0.0:
        raise SystemExit("inverted cell in the n = %d mesh (min scaled Jacobian %g)" % (n, sj))
    line = "n = %d: %d cells, %d nodes, min scaled Jacobian %.3f, blocks %s" % (
        n, len(cells), len(coords), sj, mesh.sizes)
    if path:
        faces = write_msh(path, mesh)
        line += "\n  -> %s (%.0f kB; boundary faces %s)" % (
            path, os.path.getsize(path) / 1e3, {p: len(f) for p, f in faces.items()})
    if not quiet:
        print(line)
    return mesh


def main():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--level", choices=sorted(LEVELS), help="one named level (default: coarse and medium)")
    ap.add_argument("--n", type=int, help="cells per side of the square around the cylinder (multiple of 4)")
    ap.add_argument("-o", "--output", help="output .msh file (with --level or --n)")
    ap.add_argument("--info", action="store_true", help="print counts and quality, write nothing")
    args = ap.parse_args()
    if args.level or args.n:
        n = args.n or LEVELS[args.level]
        path = args.output
        if not path and not args.info:
            if args.level == "coarse":
                path = os.path.join(root, "tests/data/meshes/cylinder_coarse.msh")
            elif args.level == "medium":
                path = os.path.join(root, "cases/meshes/cylinder_medium.msh")
            else:
                sys.exit("give -o for this level (the fine mesh is not kept in the repository)")
        build(n, None if args.info else path)
        return
    build(LEVELS["coarse"], os.path.join(root, "tests/data/meshes/cylinder_coarse.msh"))
    build(LEVELS["medium"], os.path.join(root, "cases/meshes/cylinder_medium.msh"))


if __name__ == "__main__":
    main()
