#!/usr/bin/env python3
"""Helpers of schaefer_turek.sh (Schaefer-Turek 2D-1 with OpenFOAM).

    schaefer_turek.py inlet CASE                  # write the parabolic inlet profile into CASE/0/U
    schaefer_turek.py analyse RESULT.json CASE ...   # c_D, c_L, delta p of finished cases, table

Inlet: u = 4 Um y (H - y) / H^2, Um = 0.3, H = 0.41, evaluated at each inlet face's area centroid
(the value a face-centred boundary condition would use; the face-average would differ by
Um * h^2 * 2 / (3 H^2) relative, 0.03 % of the flux on the coarse mesh).
"""
import json
import os
import re
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import foamtools  # noqa: E402

UM, H = 0.3, 0.41
PUBLISHED = {"c_D": [5.57, 5.59], "c_L": [0.0104, 0.0110], "delta_p": [0.1172, 0.1176]}


def write_inlet(case):
    points = foamtools.read_points(case)
    faces = foamtools.read_faces(case)
    start, size = foamtools.read_patches(case)["inlet"]
    vals = []
    for f in faces[start:start + size]:
        y = foamtools.face_centre(points, f)[1]
        vals.append("(%.12g 0 0)" % (4.0 * UM * y * (H - y) / H ** 2))
    path = os.path.join(case, "0/U")
    text = open(path).read().replace("__INLET_U__", "nonuniform List<vector> %d(%s)" % (size, " ".join(vals)))
    open(path, "w").write(text)


def last_numbers(path):
    last = None
    for line in open(path):
        if line.strip() and not line.startswith("#"):
            last = line.split()
    return last


def history(path, column):
    out = []
    for line in open(path):
        if line.strip() and not line.startswith("#"):
            parts = line.split()
            out.append((float(parts[0]), float(parts[column])))
    return out


def find_post(case, name, filename):
    base = os.path.join(case, "postProcessing", name)
    for t in sorted(os.listdir(base), key=float):
        p = os.path.join(base, t, filename)
        if os.path.exists(p):
            return p
    raise FileNotFoundError(base + "/*/" + filename)


def analyse(case):
    coeff = find_post(case, "forceCoeffs", "coefficient.dat")
    header = [line for line in open(coeff) if line.startswith("#")][-1].lstrip("#").split()
    icd, icl = header.index("Cd"), header.index("Cl")
    cd = history(coeff, icd)
    cl = history(coeff, icl)
    probe = last_numbers(find_post(case, "probes", "p"))
    it = int(cd[-1][0])
    back = max(0, len(cd) - 101)
    log = open(os.path.join(case, "log.simpleFoam")).read()
    res = re.findall(r"Solving for p, Initial residual = (\S+),", log)
    info = open(os.path.join(case, "mesh.info")).read().split()
    return {
        "mesh": os.path.basename(case), "cells": int(info[0]), "msh_file": info[1],
        "convection": info[2], "iterations": it,
        "converged": "SIMPLE solution converged" in log,
        "last_p_initial_residual": float(res[-1]) if res else None,
        "c_D": cd[-1][1], "c_L": cl[-1][1],
        "delta_p": float(probe[1]) - float(probe[2]),
        "c_D_change_last_100_iterations": abs(cd[-1][1] - cd[back][1]),
        "c_L_change_last_100_iterations": abs(cl[-1][1] - cl[back][1]),
        "wall_seconds": float(info[3]) if len(info) > 3 else None,
    }


def main():
    cmd = sys.argv[1]
    if cmd == "inlet":
        write_inlet(sys.argv[2])
        return
    out, cases = sys.argv[2], sys.argv[3:]
    res = [analyse(c) for c in cases]
    doc = {"what": "Schaefer-Turek 2D-1 (Re = 20), OpenFOAM v1912 simpleFoam (SIMPLEC) on the project's cylinder meshes",
           "definitions": "c = 2F/(rho U^2 D H), U = 0.2, D = 0.1, H = 0.01 (forceCoeffs on patch cylinder); "
                          "delta_p = p(0.15,0.2) - p(0.25,0.2) by cellPoint probes 1e-6 inside the fluid",
           "published": PUBLISHED, "settings": "perf/openfoam/schaefer_turek.sh, template perf/openfoam/cases/cylinder",
           "openfoam_settings": foamtools.case_settings(cases[0]),
           "results": res}
    with open(out, "w") as f:
        json.dump(doc, f, indent=1)
    print("%-30s %7s %-22s %6s %9s %10s %9s %10s" % ("mesh", "cells", "convection", "iters", "c_D", "c_L",
                                                     "delta_p", "|dc_D|/100it"))
    for r in res:
        print("%-30s %7d %-22s %6d %9.5f %10.6f %9.5f %10.1e%s" % (
            r["mesh"], r["cells"], r["convection"], r["iterations"], r["c_D"], r["c_L"], r["delta_p"],
            r["c_D_change_last_100_iterations"], "" if r["converged"] else "  (not converged)"))
    print("published: c_D in [5.57, 5.59], c_L in [0.0104, 0.0110], delta_p in [0.1172, 0.1176]")
    print("->", out)


if __name__ == "__main__":
    main()
