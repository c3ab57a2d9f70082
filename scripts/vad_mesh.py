#!/usr/bin/env python3
"""Structured hex mesh of a pulsatile ventricular-assist device (reduced, after Long et al. 2013),
written as Gmsh MSH 4.1 ASCII; SI units (m).

    python3 scripts/vad_mesh.py                         # cases/meshes/vad.msh
    python3 scripts/vad_mesh.py --around 16 --ring 2 --blood 4 --air 2 /tmp/vad_coarse.msh
    python3 scripts/vad_mesh.py --blood-only cases/meshes/vad_blood.msh   # the blood chamber alone (cases/vad.yaml)
    python3 scripts/vad_mesh.py --info                  # counts and quality only

Geometry. Two domed chambers of width 2R = 7.7 cm separated by a membrane pinned at its rim
(R = 3.85 cm). The membrane's initial dome bulges d = 1.52 cm toward the air chamber (+z):
z_m(r) = d cos(pi r / (2 R)). The housings are domes with apexes at z = +-A (A = 2.25 cm: 4.5 cm
apex to apex) and a short cylindrical rim wall of height h (2 mm) where they meet the membrane:
z_air(r) = h + (A - h) cos(pi r / (2 R)), z_blood(r) = -z_air(r). Reduced against the paper: the
blood chamber's inlet and outlet arms (1.5 cm diameter at 30 degrees) and the air port (0.8 cm) are
not tubes but patches of the housings where the arms would meet them: the faces of the blood dome
whose centres lie within 0.75 cm (in plan) of (x, y) = (-+2 cm, 0), and of the air dome within
0.4 cm of the axis (at least the central cell).

Mesh. The cross-section is the elastic tube's O-grid (scripts/tube_mesh.py: a core square and a
ring, --around cells around, --ring cells in the ring); each node column is spread in --blood
uniform layers from the blood dome to the membrane and --air layers from the membrane to the air
dome. The membrane is the internal face layer between the chambers: a physical surface of internal
faces, which core/GmshReader.cpp reads as a baffle named "membrane" (normal +z, out of the blood
side: the blood chamber is its master side). Patches: bloodInlet, bloodOutlet, bloodWall, airPort,
airWall. Every cell's scaled Jacobian is checked (> 0) before writing. Needs numpy.
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gmsh_hex import write_hex_msh  # noqa: E402
from tube_mesh import FACE_XP, FACE_ZM, FACE_ZP, cross_section, min_scaled_jacobian  # noqa: E402

PATCHES = ["bloodInlet", "bloodOutlet", "bloodWall", "airPort", "airWall", "membrane"]
VOLUME_TAG = 7


def build(around, ring, n_blood, n_air, core_fraction, R, d, A, h, port_offset, port_radius, air_port_radius):
    pts2, quads, wall = cross_section(around, ring, core_fraction, R)
    n2 = len(pts2)
    r = np.minimum(np.hypot(pts2[:, 0], pts2[:, 1]), R)
    c = np.cos(0.5 * np.pi * r / R)
    z_m = d * c
    z_air = h + (A - h) * c
    z_blood = -z_air
    if np.any(z_air - z_m <= 0) or np.any(z_m - z_blood <= 0):
        raise SystemExit("the membrane dome leaves the housing (d >= A?)")
    nl = n_blood + n_air
    coords = np.empty(((nl + 1) * n2, 3))
    for k in range(nl + 1):
        if k <= n_blood:
            z = z_blood + (z_m - z_blood) * k / n_blood
        else:
            z = z_m + (z_air - z_m) * (k - n_blood) / n_air
        coords[k * n2:(k + 1) * n2, :2] = pts2
        coords[k * n2:(k + 1) * n2, 2] = z
    nq = len(quads)
    cells = np.vstack([np.hstack([quads + k * n2, quads + (k + 1) * n2]) for k in range(nl)])
    bottom = cells[:nq][:, FACE_ZM]          # the blood dome
    top = cells[(nl - 1) * nq:][:, FACE_ZP]  # the air dome
    centre_b = pts2[quads].mean(axis=1)      # plan centre of each column
    inlet = np.hypot(centre_b[:, 0] + port_offset, centre_b[:, 1]) < port_radius
    outlet = np.hypot(centre_b[:, 0] - port_offset, centre_b[:, 1]) < port_radius
    air = np.hypot(centre_b[:, 0], centre_b[:, 1]) < air_port_radius
    if not air.any():
        air[np.argmin(np.hypot(centre_b[:, 0], centre_b[:, 1]))] = True
    if not inlet.any() or not outlet.any():
        raise SystemExit("a port holds no face: refine the cross-section (--around)")
    side = lambda layers: np.vstack([cells[k * nq + np.array(wall)][:, FACE_XP] for k in layers])
    faces = {
        "bloodInlet": bottom[inlet],
        "bloodOutlet": bottom[outlet],
        "bloodWall": np.vstack([bottom[~(inlet | outlet)], side(range(n_blood))]),
        "airPort": top[air],
        "airWall": np.vstack([top[~air], side(range(n_blood, nl))]),
        "membrane": cells[(n_blood - 1) * nq:n_blood * nq][:, FACE_ZP],  # +z: out of the blood side
    }
    return coords, cells, faces, z_m, pts2


def main():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("output", nargs="?", default=os.path.join(root, "cases/meshes/vad.msh"))
    ap.add_argument("--around", type=int, default=32, help="cells around (multiple of 4; default 32)")
    ap.add_argument("--ring", type=int, default=6, help="cells in the O-grid's ring (default 6)")
    ap.add_argument("--blood", type=int, default=10, help="layers in the blood chamber (default 10)")
    ap.add_argument("--air", type=int, default=5, help="layers in the air chamber (default 5)")
    ap.add_argument("--core", type=float, default=0.55, help="core square corner radius / R (default 0.55)")
    ap.add_argument("--blood-only", action="store_true",
                    help="the blood chamber alone, the membrane a boundary patch on top of it (for an air chamber "
                         "the coupling lumps: coupling.lumpedChamber)")
    ap.add_argument("--info", action="store_true", help="print counts and quality, write nothing")
    a = ap.parse_args()
    if a.blood < 1 or a.air < 1:
        sys.exit("each chamber needs at least one layer")
    R, d, A, h = 0.0385, 0.0152, 0.0225, 0.002
    coords, cells, faces, z_m, pts2 = build(a.around, a.ring, a.blood, a.air, a.core, R, d, A, h,
                                            0.02, 0.0075, 0.004)
    patches = PATCHES
    if a.blood_only:
        # Drop the air layers: the membrane faces become the blood chamber's top boundary.
        nq = len(faces["membrane"])
        cells = cells[:a.blood * nq]
        used = np.unique(cells)
        renumber = -np.ones(len(coords), dtype=np.int64)
        renumber[used] = np.arange(len(used))
        coords, cells = coords[used], renumber[cells]
        faces = {p: renumber[faces[p]] for p in ("bloodInlet", "bloodOutlet", "bloodWall", "membrane")}
        patches = ["bloodInlet", "bloodOutlet", "bloodWall", "membrane"]
        a.air = 0
    sj = min_scaled_jacobian(coords, cells)
    if not sj > 0.0:
        sys.exit("inverted cell (min scaled Jacobian %g)" % sj)
    n2 = len(pts2)

    def chamber_volume(k0, k1):  # noqa: E306
        """Volume between node layers k0 and k1 (sum of the cells' trilinear volumes, midpoint rule)."""
        v = 0.0
        for cell in cells:
            k = cell[0] // n2
            if k0 <= k < k1:
                x = coords[cell]
                e1, e2, e3 = x[1] - x[0], x[3] - x[0], x[4] - x[0]
                v += abs(np.dot(np.cross(e1, e2), e3))
        return v

    line = ("vad: %d cells, %d nodes (%d around, ring %d, %d blood + %d air layers), min scaled Jacobian %.3f; "
            "blood chamber ~%.1f mL, air chamber ~%.1f mL"
            % (len(cells), len(coords), a.around, a.ring, a.blood, a.air, sj,
               chamber_volume(0, a.blood) * 1e6, chamber_volume(a.blood, a.blood + a.air) * 1e6))
    if not a.info:
        write_hex_msh(a.output, patches, coords, cells, faces, (-R, -R, -A, R, R, A), VOLUME_TAG)
        line += "\n  -> %s (%.0f kB; faces %s)" % (a.output, os.path.getsize(a.output) / 1e3,
                                                   {p: len(f) for p, f in faces.items()})
    print(line)


if __name__ == "__main__":
    main()
