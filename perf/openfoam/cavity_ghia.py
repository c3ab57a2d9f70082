#!/usr/bin/env python3
"""Compare OpenFOAM cavity results with Ghia et al. (1982), Re = 100 (see cavity2d_ghia.sh).

    cavity_ghia.py RESULT.json CASE_DIR ...     # cases made by cavity2d_ghia.sh (N read from the case)

For each case, at its last time directory: u on the vertical centreline x = 0.5 and v on the
horizontal centreline y = 0.5 at Ghia's 17 points each, interpolated linearly between cell
centres (mean of the two cell columns / rows beside the centreline) and the wall values (u = 1 on
the lid). Also reports steadiness: max |U(last) - U(previous write)| over all cells.
"""
import json
import os
import re
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import foamtools  # noqa: E402


def load_ghia():
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "ghia1982_re100.csv")
    rows = [line.strip().split(",") for line in open(path) if line.strip() and not line.startswith("#")]
    out = {"u_vs_y": [], "v_vs_x": []}
    for re_, kind, coord, value in rows[1:]:
        out[kind].append((float(coord), float(value)))
    return out


def time_dirs(case):
    ts = []
    for d in os.listdir(case):
        try:
            t = float(d)
        except ValueError:
            continue
        if t > 0 and os.path.exists(os.path.join(case, d, "U")):
            ts.append((t, d))
    return [d for _, d in sorted(ts)]


def mesh_size(case):
    text = open(os.path.join(case, "system/blockMeshDict")).read()
    m = re.search(r"\((\d+) (\d+) (\d+)\) simpleGrading", text)
    return int(m.group(1)), int(m.group(2))


def profile(line_values, n, s):
    """Linear interpolation at s in [0, 1] of values at cell centres (i + 0.5) / n, with the
    boundary values line_values[0] at s = 0 and line_values[-1] at s = 1."""
    xs = [0.0] + [(i + 0.5) / n for i in range(n)] + [1.0]
    for i in range(len(xs) - 1):
        if xs[i] <= s <= xs[i + 1]:
            w = (s - xs[i]) / (xs[i + 1] - xs[i])
            return (1 - w) * line_values[i] + w * line_values[i + 1]
    raise ValueError(s)


def analyse(case, ghia):
    nx, ny = mesh_size(case)
    assert nx == ny and nx % 2 == 0, "needs an even N x N mesh"
    n = nx
    dirs = time_dirs(case)
    U = foamtools.read_internal_field(os.path.join(case, dirs[-1], "U"), n * n)
    Uprev = foamtools.read_internal_field(os.path.join(case, dirs[-2], "U"), n * n) if len(dirs) > 1 else U
    change = max(max(abs(a[k] - b[k]) for k in range(3)) for a, b in zip(U, Uprev))

    def cell(i, j):  # blockMesh order: x fastest, then y
        return U[i + n * j]

    h = n // 2
    u_line = [0.0] + [0.5 * (cell(h - 1, j)[0] + cell(h, j)[0]) for j in range(n)] + [1.0]
    v_line = [0.0] + [0.5 * (cell(i, h - 1)[1] + cell(i, h)[1]) for i in range(n)] + [0.0]
    rows = []
    for kind, line in (("u_vs_y", u_line), ("v_vs_x", v_line)):
        for s, ref in ghia[kind]:
            rows.append((kind, s, ref, profile(line, n, s)))
    err = {k: max(abs(v - r) for kk, s, r, v in rows if kk == k) for k in ("u_vs_y", "v_vs_x")}
    return {
        "N": n, "cells": n * n, "time": float(dirs[-1]),
        "openfoam_settings": foamtools.case_settings(case),
        "steady_change_max_abs_dU": change, "change_since_time": float(dirs[-2]) if len(dirs) > 1 else None,
        "max_abs_err_u": err["u_vs_y"], "max_abs_err_v": err["v_vs_x"],
        "profiles": [{"kind": k, "coord": s, "ghia": r, "openfoam": round(v, 6)} for k, s, r, v in rows],
    }


def main():
    out, cases = sys.argv[1], sys.argv[2:]
    ghia = load_ghia()
    res = [analyse(c, ghia) for c in cases]
    doc = {
        "what": "2D lid-driven cavity Re=100, OpenFOAM v1912 icoFoam vs Ghia et al. 1982 (17 points per profile)",
        "settings": "perf/openfoam/cavity2d_ghia.sh, template perf/openfoam/cases/cavity",
        "results": res,
    }
    with open(out, "w") as f:
        json.dump(doc, f, indent=1)
    print("%6s %8s %14s %14s %18s" % ("N", "cells", "max|u-Ghia|", "max|v-Ghia|", "max|dU| last 5 s"))
    for r in res:
        print("%6d %8d %14.5f %14.5f %18.2e" % (r["N"], r["cells"], r["max_abs_err_u"], r["max_abs_err_v"],
                                              r["steady_change_max_abs_dU"]))
    print("->", out)


if __name__ == "__main__":
    main()
