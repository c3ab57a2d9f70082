#!/usr/bin/env bash
# Steady Schaefer-Turek 2D-1 (Re = 20) side by side: OpenFOAM v1912 simpleFoam and `mfsi run
# cylinder`, each converging to 1e-10 on the same five meshes: iterations, whole-process wall time
# (start-up, mesh reading and output included on both sides), c_D, c_L and delta p.
#
#   perf/cylinder_vs_openfoam.sh [REPEATS]        # default 5; medians of REPEATS runs
#   MFSI_BUILD=/path/to/build perf/cylinder_vs_openfoam.sh 3
#
# The OpenFOAM cases are set up (and run once, for their coefficients) by
# perf/openfoam/schaefer_turek.sh: SIMPLEC, U relaxed 0.9, Gauss linear, GAMG for p, until both
# initial residuals are below 1e-10. Ours runs the cylinder scene as committed (SIMPLEC, U 0.9,
# p 1, outerTolerance 1e-10), only mesh.file changed. Per repeat and mesh: OpenFOAM (1 process),
# ours on 1 thread, ours on 2 threads, so drifts in the machine load hit both alike.
#
# Output: a markdown table on stdout and perf/results/cylinder_vs_openfoam.json.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
source "$here/openfoam/foam_env.sh"
repeats=${1:-5}
build=${MFSI_BUILD:-$REPO/build}
mfsi=$build/apps/mfsi
[ -x "$mfsi" ] || { echo "no $mfsi (make build, or MFSI_BUILD=...)" >&2; exit 1; }
levels=(coarse medium fine graded graded-medium)

bash "$here/openfoam/schaefer_turek.sh" "${levels[@]}" >"$WORK/schaefer_turek.log"
declare -A msh=([coarse]=$REPO/tests/data/meshes/cylinder_coarse.msh [medium]=$REPO/cases/meshes/cylinder_medium.msh
  [fine]=$WORK/cylinder_fine.msh [graded]=$REPO/tests/data/meshes/cylinder_graded.msh
  [graded-medium]=$WORK/cylinder_graded_medium.msh)

now() { date +%s.%N; }
rows=$WORK/cylinder_vs_openfoam.rows
: >"$rows"
echo "load before: $(load_note)"
for ((r = 1; r <= repeats; r++)); do
  for level in "${levels[@]}"; do
    case=$WORK/cylinder_$level
    (cd "$case" && rm -rf postProcessing && find . -maxdepth 1 -regex './[0-9.e+-]+' ! -name 0 -exec rm -rf {} +)
    t0=$(now)
    run_foam "$case" log.simpleFoam simpleFoam
    echo "$level openfoam 1 $(python3 -c "print($(now) - $t0)") $(grep -c '^Time = ' "$case/log.simpleFoam")" >>"$rows"
    for threads in 1 2; do
      out=$WORK/mfsi_cylinder_$level
      t0=$(now)
      OMP_PROC_BIND=false OMP_NUM_THREADS=$threads "$mfsi" run cylinder --set "mesh.file=${msh[$level]}" --out "$out" \
        --overwrite >"$out.log" 2>&1 || { echo "mfsi failed on $level:" >&2; tail -5 "$out.log" >&2; exit 1; }
      echo "$level mfsi $threads $(python3 -c "print($(now) - $t0)") $out" >>"$rows"
    done
  done
done
echo "load after: $(load_note)"

python3 - "$rows" "$RESULTS/schaefer_turek.json" "$here/results/cylinder_vs_openfoam.json" "$repeats" <<'PY'
import json, statistics, sys
rows, of_json, out, repeats = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
of = {r["mesh"].replace("cylinder_", ""): r for r in json.load(open(of_json))["results"]}
runs = {}
for line in open(rows):
    level, code, threads, wall, extra = line.split()
    runs.setdefault((level, code, int(threads)), []).append((float(wall), extra))
table = []
for level in ["coarse", "medium", "fine", "graded", "graded-medium"]:
    o = of[level]
    walls_of = [w for w, _ in runs[(level, "openfoam", 1)]]
    row = {"mesh": level, "cells": o["cells"],
           "openfoam": {"iterations": o["iterations"], "converged": o["converged"], "c_D": o["c_D"], "c_L": o["c_L"],
                        "delta_p": o["delta_p"], "wall_s": walls_of, "wall_median_s": statistics.median(walls_of)}}
    for t in (1, 2):
        rr = runs[(level, "mfsi", t)]
        s = json.load(open(rr[-1][1] + "/summary.json"))
        m = s["metrics"]
        walls = [w for w, _ in rr]
        row["mfsi_%dt" % t] = {"iterations": int(m["fluid.outer_iterations"]), "converged": m["fluid.converged"] == 1,
                               "final_residuals": [m["fluid.final_momentum_residual"], m["fluid.final_pressure_residual"]],
                               "c_D": m["fluid.cylinder.c_D"], "c_L": m["fluid.cylinder.c_L"], "delta_p": m["fluid.dp"],
                               "wall_s": walls, "wall_median_s": statistics.median(walls)}
    table.append(row)
json.dump({"what": "Schaefer-Turek 2D-1 steady, converged to 1e-10: OpenFOAM v1912 simpleFoam (1 process) "
                   "against mfsi run cylinder (1 and 2 OpenMP threads), whole-process wall times, medians of %d" % repeats,
           "command": "perf/cylinder_vs_openfoam.sh %d" % repeats, "results": table}, open(out, "w"), indent=1)
print("| mesh | cells | OpenFOAM its | ours its | OpenFOAM wall | ours 1 thread | ours 2 threads | speed-up 1 thr | c_D OF / ours | c_L OF / ours |")
print("|---|---|---|---|---|---|---|---|---|---|")
for r in table:
    o, a, b = r["openfoam"], r["mfsi_1t"], r["mfsi_2t"]
    print("| %s | %d | %d | %d | %.2f s | %.2f s | %.2f s | %.1fx | %.4f / %.4f | %.5f / %.5f |" % (
        r["mesh"], r["cells"], o["iterations"], a["iterations"], o["wall_median_s"], a["wall_median_s"],
        b["wall_median_s"], o["wall_median_s"] / a["wall_median_s"], o["c_D"], a["c_D"], o["c_L"], a["c_L"]))
print("-> " + out)
PY
