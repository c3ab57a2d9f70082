#!/usr/bin/env bash
# FSI on several ranks, on 1 rank x 1 thread, 1 rank x 2 threads and 2 ranks x 1 thread: wall time
# of the steps per step (median of REPS runs), its parts (fluid, structure, mesh motion; seconds
# per step, from summary.json; the structure's includes waiting for and receiving the membranes
# other ranks solve), coupling iterations per step and a membrane's largest displacement (the same
# on every layout to the solvers' tolerance). Each membrane is solved by the rank that owns its
# cells, which sends the answer to the others.
#   tube         the elastic tube (cases/membrane-tube.yaml) on a finer O-grid (default 32 around,
#                6 in the ring, 80 along: 20,480 cells, one membrane of 2,560 quads): its one
#                membrane is solved on one rank while the other waits.
#   two-screens  cases/two-screens.yaml (65,536 cells, two membranes of 256 quads far apart): on 2
#                ranks each solves one, at the same time.
# Writes perf/results/distributed_fsi[-two-screens].txt (the raw lines, then the table).
#
#   perf/distributed_fsi.sh [around ring along steps]     # the tube; default: 32 6 80 10; REPS=3
#   perf/distributed_fsi.sh two-screens [steps]           # default: 10
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
exe=${EXE:-$repo/build/apps/mfsi}
[ -x "$exe" ] || { echo "$exe not found: build the project first" >&2; exit 1; }
reps=${REPS:-3}
flags=(--oversubscribe --bind-to none)
[ "$(id -u)" = 0 ] && flags+=(--allow-run-as-root)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
if [ "${1:-}" = two-screens ]; then
  steps=${2:-10}
  end=$(/usr/bin/python3 -c "print($steps * 0.02)")
  scene=(two-screens --set time.endTime="$end")
  watch=membrane.screenA.maxDisplacement
  label="two-screens $steps"
  out=$repo/perf/results/distributed_fsi-two-screens.txt
else
  around=${1:-32} ring=${2:-6} along=${3:-80} steps=${4:-10}
  /usr/bin/python3 "$repo/scripts/tube_mesh.py" "$around" "$ring" "$along" 0.55 "$work/tube.msh" | head -1
  end=$(/usr/bin/python3 -c "print($steps * 1e-4)")
  scene=(membrane-tube --set mesh.file="$work/tube.msh" --set time.endTime="$end")
  watch=membrane.wall.maxDisplacement
  label="$around $ring $along $steps"
  out=$repo/perf/results/distributed_fsi.txt
fi
mkdir -p "$(dirname "$out")"
raw=$work/raw.txt
{
  echo "# perf/distributed_fsi.sh $label (REPS=$reps; $(date -u +%Y-%m-%dT%H:%MZ), $(nproc) cores, $(git -C "$repo" rev-parse --short HEAD))"
  for rep in $(seq "$reps"); do
    for cfg in "1 1" "1 2" "2 1"; do
      read -r np threads <<<"$cfg"
      dir=$work/r$np-$threads-$rep
      cmd=("$exe" run "${scene[@]}" --out "$dir")
      [ "$np" -gt 1 ] && cmd=(mpirun "${flags[@]}" -np "$np" "${cmd[@]}")
      OMP_NUM_THREADS=$threads OMP_PROC_BIND=false KOKKOS_DISABLE_WARNINGS=1 "${cmd[@]}" >/dev/null 2>&1
      /usr/bin/python3 - "$dir/summary.json" "$np" "$threads" "$watch" <<'PY'
import json, sys
s = json.load(open(sys.argv[1])); m = s["metrics"]; n = m["coupling.steps"]
print(f"ranks={sys.argv[2]} threads={sys.argv[3]} steps={n:.0f} wall_per_step={s['timers']['advance'] / n:.4f} "
      f"fluid={m['coupling.time_fluid_s'] / n:.4f} structure={m['coupling.time_structure_s'] / n:.4f} "
      f"motion={m['coupling.time_motion_s'] / n:.4f} iterations={m['coupling.mean_iterations']:.2f} "
      f"maxDisplacement={m[sys.argv[4]]:.10e}")
PY
    done
  done
} | tee "$raw"
/usr/bin/python3 - "$raw" <<'PY' | tee -a "$raw"
import re, sys, statistics
rows = {}
for line in open(sys.argv[1]):
    m = re.match(r"ranks=(\d) threads=(\d) .*wall_per_step=(\S+) fluid=(\S+) structure=(\S+) motion=(\S+) "
                 r"iterations=(\S+) maxDisplacement=(\S+)", line)
    if m:
        r, t, *v = m.groups()
        rows.setdefault((int(r), int(t)), []).append([float(x) for x in v])
base = statistics.median(x[0] for x in rows[(1, 1)])
print("\n| ranks × threads | s per step (median) | fluid | structure | mesh motion | coupling its/step | speed-up vs 1 × 1 | membrane max displacement |")
print("|---|---|---|---|---|---|---|---|")
for key in sorted(rows):
    v = rows[key]
    med = [statistics.median(x[i] for x in v) for i in range(6)]
    print(f"| {key[0]} × {key[1]} | {med[0]:.3f} | {med[1]:.3f} | {med[2]:.3f} | {med[3]:.3f} | {med[4]:.2f} | "
          f"{base / med[0]:.2f} | {v[0][5]:.10e} |")
PY
mv "$raw" "$out"
