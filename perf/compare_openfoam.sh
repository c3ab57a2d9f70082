#!/usr/bin/env bash
# Side-by-side speed of our fluid solver and OpenFOAM's icoFoam on the 3D lid-driven cube cavity
# (Re = 100), measured back to back in one run: seconds per cell and time step at 1 and 2
# threads (ours, OpenMP) / ranks (OpenFOAM, MPI), medians over REPEATS runs, and the ratio.
#
#   perf/compare_openfoam.sh [N] [STEPS] [REPEATS]          # default: 64 20 3
#   MFSI_BUILD=/work/main/build-perfcmp perf/compare_openfoam.sh 64 20 3
#
# Both sides: unit cube, lid y = 1 at u = (1, 0, 0), no-slip elsewhere, nu = 0.01, N^3 uniform
# hexes, from rest, dt = 0.32 / N (0.005 at N = 64), STEPS steps, steps 6..STEPS timed, no output.
#  - OpenFOAM (perf/openfoam/cases/cavity, as in perf/openfoam/cavity3d_timing.sh): icoFoam, PISO
#    with 2 correctors, Euler, Gauss linear; p: GAMG (GaussSeidel, abs 1e-6, relTol 0.05, final 0);
#    U: symGaussSeidel abs 1e-5. 2 ranks: decomposePar (2 slabs along z) + mpirun -np 2.
#    Timed between the time-stamped ExecutionTime lines of step 5 and of the last step.
#  - Ours (perf/bench_cavity3d.cpp): PISO with momentum predictor and 2 correctors, Euler, central
#    convection; p: CG + smoothed-aggregation AMG, abs 1e-6 (OpenFOAM's scaled residual), relTol 0.05
#    on the first corrector and 0 on the final one (as icoFoam's p/pFinal; the first with two
#    finest-level smoother applications per V-cycle, solvers.pressure.finestSweeps); U: the three components
#    in one BiCGStab3 + Jacobi, abs 1e-5; all solves stop on OpenFOAM's scaled 1-norm residual.
#    Initial guesses (pimple.extrapolateGuess, on by default): U extrapolated in time for the
#    momentum solve, the final pressure solve from the last step's final-corrector change (icoFoam
#    starts from the last values). OMP_PROC_BIND=spread OMP_PLACES=cores,
#    OMP_NUM_THREADS = 1 or 2. Timed around steps 6..STEPS (fenced).
#  - Ours on 2 MPI ranks x 1 thread (perf/distributed_fluid.cpp, the same settings; the mesh cut by
#    METIS, the pressure by CG + the distributed AMG): mpirun -np 2, steps 6..STEPS timed.
# Order per repeat: OpenFOAM 1 rank, ours 1 thread, OpenFOAM 2 ranks, ours 2 threads, ours 2 ranks,
# so slow drifts in the machine load hit both sides alike. `uptime` is recorded around every run. After
# the timing runs ours runs once more per thread count with region profiling (phase fractions).
#
# Ghia errors of the 2D cavity (Re = 100, N = 64, 128) are taken from
# perf/openfoam/results/cavity2d_ghia.json (OpenFOAM, icoFoam to t = 30) and
# perf/results/cavity2d_ghia_ours.json (ours, tests/fluid/test_cavity_ghia.cpp Report, steady
# SIMPLE with the same central convection); set MFSI_GHIA=1 to recompute ours first.
#
# Output: a markdown table on stdout and perf/results/cavity3d_vs_openfoam.json.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
source "$here/openfoam/foam_env.sh"

n=${1:-64}
steps=${2:-20}
repeats=${3:-3}
build=${MFSI_BUILD:-$REPO/build}
bench=$build/perf/bench_cavity3d
[ -x "$bench" ] || { echo "no $bench: build target bench_cavity3d (MFSI_BUILD=...)" >&2; exit 1; }
dist=$build/perf/perf_distributed_fluid
[ -x "$dist" ] || { echo "no $dist: build target perf_distributed_fluid (MFSI_BUILD=...)" >&2; exit 1; }
out_dir=$here/results
mkdir -p "$out_dir"

if [ "${MFSI_GHIA:-0}" = 1 ]; then
  ghia_exe=$build/tests/mfsi_fluid_test_cavity_ghia
  [ -x "$ghia_exe" ] || { echo "no $ghia_exe: build target mfsi_fluid_test_cavity_ghia" >&2; exit 1; }
  ghia_lines=()
  for gn in 64 128; do
    report=$(MFSI_GHIA_N=$gn OMP_PROC_BIND=false OMP_NUM_THREADS=2 "$ghia_exe" --gtest_filter='*Report*')
    line="$(grep "cavity N=$gn:" <<<"$report") $(grep "cavity N=$gn, linear" <<<"$report")"
    echo "$line"
    ghia_lines+=("$line")
  done
  python3 - "$out_dir/cavity2d_ghia_ours.json" "${ghia_lines[@]}" <<'PY'
import json, re, sys
rows = []
for line in sys.argv[2:]:
    m = re.search(r"N=(\d+): max \|u - ghia\| = (\S+), max \|v - ghia\| = (\S+), SIMPLE iterations (\d+) converged (\d)", line)
    lin = re.search(r"linear interpolation: max \|u - ghia\| = (\S+), max \|v - ghia\| = (\S+)", line)
    # Linear interpolation between cell centres is how perf/openfoam/cavity_ghia.py samples
    # OpenFOAM's fields: those are the like-for-like numbers; cubic is what the tests assert.
    rows.append({"N": int(m.group(1)), "max_abs_err_u": float(lin.group(1)), "max_abs_err_v": float(lin.group(2)),
                 "max_abs_err_u_cubic": float(m.group(2)), "max_abs_err_v_cubic": float(m.group(3)),
                 "simple_iterations": int(m.group(4)), "converged": m.group(5) == "1"})
json.dump({"what": "2D lid-driven cavity Re=100, ours vs Ghia et al. 1982 (17 points per profile), steady SIMPLE, "
                   "central convection, Gauss linear gradients; profiles sampled by linear interpolation between cell "
                   "centres as for OpenFOAM (max_abs_err_*_cubic: cubic, as the tests)",
           "reproduce": "MFSI_GHIA_N=<N> tests/mfsi_fluid_test_cavity_ghia --gtest_filter='*Report*'",
           "results": rows}, open(sys.argv[1], "w"), indent=1)
PY
fi

cavity3d_case "$n" "$steps"

ours() {  # ours THREADS PROFILE JSON
  OMP_PROC_BIND=spread OMP_PLACES=cores OMP_NUM_THREADS=$1 MFSI_CAVITY3D_N=$n MFSI_CAVITY3D_STEPS=$steps \
    "$bench" --benchmark_filter="^BM_Cavity3d/N:$n/profile:$2/" --benchmark_out="$3" \
    --benchmark_out_format=json >"${3%.json}.txt" 2>&1
}

logdir=$WORK/compare_N$n
rm -rf "$logdir"
mkdir -p "$logdir"
runs=()
load_start=$(load_note)
echo "load at start: $load_start"
for r in $(seq 1 "$repeats"); do
  for np in 1 2; do
    log=$logdir/openfoam.np$np.run$r.log
    before=$(load_note)
    if [ "$np" = 1 ]; then cmd="icoFoam"; else cmd="$MPIRUN -np $np icoFoam -parallel"; fi
    (cd "$case" && $cmd 2>&1 | stamp >"$log") || { tail -20 "$log"; exit 1; }
    runs+=("openfoam|$np|$r|$log|$before|$(load_note)")

    log=$logdir/ours.t$np.run$r.json
    before=$(load_note)
    ours "$np" 0 "$log"
    runs+=("ours|$np|$r|$log|$before|$(load_note)")
    if [ "$np" = 2 ]; then
      log=$logdir/ours-mpi.np2.run$r.log
      before=$(load_note)
      OMP_NUM_THREADS=1 OMP_PROC_BIND=false $MPIRUN --bind-to none -np 2 "$dist" "$n" "$steps" 5 distributed \
        >"$log" 2>&1 || { tail -20 "$log"; exit 1; }
      runs+=("ours-mpi|2|$r|$log|$before|$(load_note)")
    fi
    echo "repeat $r, $np thread(s)/rank(s) done; load $(load_note)"
  done
done
for np in 1 2; do
  log=$logdir/ours.t$np.profile.json
  before=$(load_note)
  ours "$np" 1 "$log"
  runs+=("profile|$np|1|$log|$before|$(load_note)")
done
load_end=$(load_note)
echo "load at end: $load_end"

LOAD_START=$load_start LOAD_END=$load_end OF_DIR=$OF_DIR CASE=$case python3 - "$out_dir/cavity3d_vs_openfoam.json" "$n" "$steps" "$dt" "$repeats" \
  "$RESULTS/cavity2d_ghia.json" "$out_dir/cavity2d_ghia_ours.json" "${runs[@]}" <<'PY'
import json, os, re, statistics, sys
sys.dont_write_bytecode = True
sys.path.insert(0, os.environ["OF_DIR"])
import foamtools
out, n, steps, dt, repeats, of_ghia, our_ghia = sys.argv[1:8]
n, steps, dt, repeats = int(n), int(steps), float(dt), int(repeats)
cells, timed = n ** 3, steps - 5

def openfoam_run(log):
    stamps, cpu, piters = [], [], []
    for line in open(log):
        ts, _, body = line.partition(" ")
        m = re.match(r"ExecutionTime = (\S+) s", body)
        if m:
            stamps.append(float(ts))
            cpu.append(float(m.group(1)))
        m = re.search(r"GAMG:  Solving for p, .*No Iterations (\d+)", body)
        if m and len(stamps) >= 5:
            piters.append(int(m.group(1)))
    assert len(stamps) == steps, (log, len(stamps))
    # Wall time from the arrival stamps of the log lines. On small meshes icoFoam's output reaches
    # the pipe in blocks (stamps collapse), so rank 0's CPU time is kept as a cross-check.
    return {"s_per_cell_step": (stamps[-1] - stamps[4]) / (timed * cells),
            "cpu_s_per_cell_step": (cpu[-1] - cpu[4]) / (timed * cells),
            "s_per_step": (stamps[-1] - stamps[4]) / timed,
            "p_iters_per_step": sum(piters) / timed}

def ours_mpi_run(log):
    line = [l for l in open(log) if l.startswith("n=")][-1]
    m = re.search(r"\| ([0-9.e+-]+) s/cell-step, ([0-9.]+) s/step \| pressure its/step ([0-9.]+), momentum its/step "
                  r"([0-9.]+) .*ok=1", line)
    assert m, (log, line)
    return {"s_per_cell_step": float(m.group(1)), "s_per_step": float(m.group(2)),
            "p_iters_per_step": float(m.group(3)), "u_iters_per_step": float(m.group(4))}

def ours_run(log):
    b = json.load(open(log))["benchmarks"][0]
    assert "error_message" not in b, b
    keep = ("s_per_cell_step", "s_per_step", "p_iters_per_step", "u_iters_per_step", "continuity_max")
    r = {k: b[k] for k in keep}
    r.update({k: b[k] for k in b if k.startswith("f_")})
    return r

runs, profiles = [], {}
for spec in sys.argv[8:]:
    who, np_, r, log, before, after = spec.split("|")
    if who == "profile":
        profiles[np_] = dict(ours_run(log), log=log, load_before=before, load_after=after)
        continue
    res = {"openfoam": openfoam_run, "ours": ours_run, "ours-mpi": ours_mpi_run}[who](log)
    runs.append(dict(res, code=who, threads_or_ranks=int(np_), run=int(r), log=log, load_before=before, load_after=after))

med, best = {}, {}
for who in ("openfoam", "ours", "ours-mpi"):
    for np_ in (1, 2):
        rs = [x for x in runs if x["code"] == who and x["threads_or_ranks"] == np_]
        if not rs: continue
        keys = [k for k in rs[0] if isinstance(rs[0][k], float) and k != "run"]
        med.setdefault(who, {})[str(np_)] = {k: statistics.median(x[k] for x in rs) for k in keys}
        best.setdefault(who, {})[str(np_)] = {k: min(x[k] for x in rs) for k in keys}
ratio = {np_: med["openfoam"][np_]["s_per_cell_step"] / med["ours"][np_]["s_per_cell_step"] for np_ in ("1", "2")}
ratio_min = {np_: best["openfoam"][np_]["s_per_cell_step"] / best["ours"][np_]["s_per_cell_step"] for np_ in ("1", "2")}
ratio_mpi = med["openfoam"]["2"]["s_per_cell_step"] / med["ours-mpi"]["2"]["s_per_cell_step"]

ghia = {}
if os.path.exists(of_ghia):
    for r in json.load(open(of_ghia))["results"]:
        ghia.setdefault(str(r["N"]), {})["openfoam"] = {"u": r["max_abs_err_u"], "v": r["max_abs_err_v"]}
if os.path.exists(our_ghia):
    for r in json.load(open(our_ghia))["results"]:
        ghia.setdefault(str(r["N"]), {})["ours"] = {"u": r["max_abs_err_u"], "v": r["max_abs_err_v"]}

doc = {"what": "3D lid-driven cube cavity Re=100, ours (bench_cavity3d) vs OpenFOAM v1912 icoFoam, back to back; "
               "wall seconds per cell and time step over steps 6..%d; medians (and minima) over %d runs" % (steps, repeats),
       "N": n, "cells": cells, "steps": steps, "timed_steps": timed, "dt": dt,
       "reproduce": "MFSI_BUILD=<build dir> perf/compare_openfoam.sh %d %d %d" % (n, steps, repeats),
       "openfoam_settings": foamtools.case_settings(os.environ["CASE"]),
       "ours_settings": "PISO: 1 outer, momentum predictor, 2 pressure correctors, 0 non-orth.; Euler; central "
                        "(Gauss linear) convection, Green-Gauss gradients; p: CG + SA-AMG (float V-cycle, 2 finest-level smoother applications in the relTol 0.05 solve; values refreshed at most every 50 steps, earlier when stale), "
                        "scaled residual 1e-6, relTol 0.05 then 0 (pFinal); U: BiCGStab3 (3 components) + Jacobi 1e-5, relTol 0; stop on the scaled 1-norm; "
                        "extrapolated initial guesses (U in time; final p from the last step's final-corrector change); "
                        "OMP_PROC_BIND=spread OMP_PLACES=cores",
       "load_start": os.environ["LOAD_START"], "load_end": os.environ["LOAD_END"],
       "median": med, "min": best,
       "speedup_openfoam_over_ours_median": ratio,
       "speedup_openfoam_2ranks_over_ours_2ranks_median": ratio_mpi, "speedup_openfoam_over_ours_min": ratio_min,
       "ours_profile_fractions": profiles,
       "ghia_2d_max_abs_err": ghia,
       "runs": runs}
json.dump(doc, open(out, "w"), indent=1)

print()
print("| threads/ranks | OpenFOAM s/cell-step | ours s/cell-step | OpenFOAM / ours | OpenFOAM p iters/step | ours p iters/step | OpenFOAM rank-0 CPU s/cell-step |")
print("|---|---|---|---|---|---|---|")
for np_ in ("1", "2"):
    o, m = med["openfoam"][np_], med["ours"][np_]
    print("| %s | %.3e (min %.3e) | %.3e (min %.3e) | %.2f (min/min %.2f) | %.1f | %.1f | %.3e |" % (
        np_, o["s_per_cell_step"], best["openfoam"][np_]["s_per_cell_step"], m["s_per_cell_step"],
        best["ours"][np_]["s_per_cell_step"], ratio[np_], ratio_min[np_], o["p_iters_per_step"], m["p_iters_per_step"],
        o["cpu_s_per_cell_step"]))
o, m = med["openfoam"]["2"], med["ours-mpi"]["2"]
print("| 2 MPI ranks both (ours decomposed, distributed AMG) | %.3e | %.3e (min %.3e) | %.2f | %.1f | %.1f | |" % (
    o["s_per_cell_step"], m["s_per_cell_step"], best["ours-mpi"]["2"]["s_per_cell_step"], ratio_mpi,
    o["p_iters_per_step"], m["p_iters_per_step"]))
print("\n(N = %d, %d cells, dt = %g, steps 6..%d timed, medians over %d runs; OpenFOAM p iterations: GAMG "
      "cycles, ours: AMG-CG iterations, both summed over the 2 correctors)" % (n, cells, dt, steps, repeats))
print("load (uptime) at start: %s; at end: %s" % (os.environ["LOAD_START"], os.environ["LOAD_END"]))
if profiles:
    print("\nours, phase fractions of the timed steps (inclusive region times):")
    for np_, p in sorted(profiles.items()):
        print("  %s thread(s): " % np_ + ", ".join("%s %.2f" % (k[2:], v) for k, v in sorted(p.items()) if k.startswith("f_")))
if ghia:
    print("\n| 2D cavity N | OpenFOAM max err u / v | ours max err u / v |")
    print("|---|---|---|")
    for gn in sorted(ghia, key=int):
        g = ghia[gn]
        fmt = lambda k: "%.4f / %.4f" % (g[k]["u"], g[k]["v"]) if k in g else "-"
        print("| %s | %s | %s |" % (gn, fmt("openfoam"), fmt("ours")))
print("\n-> %s" % out)
PY
