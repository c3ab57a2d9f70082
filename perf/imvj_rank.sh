#!/usr/bin/env bash
# IQN-IMVJ's carried inverse Jacobian in low-rank form: what its rank cap (coupling.iqnJacobianRank)
# costs and saves on the elastic tube (cases/membrane-tube.yaml, 100 steps of 1e-4 s, 1,920
# interface unknowns), against IQN-ILS with the columns of 16 steps. For each setting: coupling
# iterations per step, the acceleration's time (the coupling.acceleration timer: quasi-Newton
# steps, Jacobian updates and compressions), the wall time and the pulse speed; medians of REPS runs
# taken in turns, 1 thread each.
#   perf/imvj_rank.sh [caps...]        # default caps: 50 100 200 400 1000 (1000: never compressed here)
#   EXE=... REPS=3 MESH="32 6 80" STEPS=10 perf/imvj_rank.sh 200 1000   # the finer tube (8,000 unknowns)
# EXTRA="label:path/to/mfsi" adds another build of mfsi (e.g. an earlier commit's) run on the scene
# as it is. Writes perf/results/imvj_rank[-MESH].txt (raw lines, then the table).
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
exe=${EXE:-$repo/build/apps/mfsi}
[ -x "$exe" ] || { echo "$exe not found: build the project first" >&2; exit 1; }
reps=${REPS:-3}
caps=("$@")
[ ${#caps[@]} -gt 0 ] || caps=(50 100 200 400 1000)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
scene=(membrane-tube)
if [ -n "${MESH:-}" ]; then
  # shellcheck disable=SC2086
  /usr/bin/python3 "$repo/scripts/tube_mesh.py" $MESH 0.55 "$work/tube.msh" | head -1
  scene+=(--set mesh.file="$work/tube.msh")
fi
[ -n "${STEPS:-}" ] && scene+=(--set time.endTime="$(/usr/bin/python3 -c "print(${STEPS} * 1e-4)")")
out=$repo/perf/results/imvj_rank${MESH:+-${MESH// /-}}.txt
mkdir -p "$(dirname "$out")"
: > "$work/raw"
labels=()
for cap in "${caps[@]}"; do labels+=("imvj-$cap"); done
labels+=(ils-16)
[ -n "${EXTRA:-}" ] && labels+=("${EXTRA%%:*}")
for rep in $(seq "$reps"); do
  for label in "${labels[@]}"; do
    bin=$exe
    case $label in
      imvj-*) set_args=(--set coupling.iqnJacobianRank="${label#imvj-}") ;;
      ils-16) set_args=(--set coupling.iqnJacobian=leastSquares --set coupling.iqnReuseCols=16
                        --set coupling.omegaInit=0.1) ;;
      *) bin=${EXTRA#*:}; set_args=() ;;
    esac
    OMP_PROC_BIND=false "$bin" run "${scene[@]}" "${set_args[@]}" --threads 1 --out "$work/run" --overwrite \
      > "$work/log" 2>&1 || { cat "$work/log" >&2; exit 1; }
    /usr/bin/python3 - "$work/run" "$label" >> "$work/raw" <<'EOF'
import csv, json, sys
d = json.load(open(sys.argv[1] + "/summary.json"))
m, t = d["metrics"], d["timers"]
rows = list(csv.DictReader(open(sys.argv[1] + "/steps.csv")))
def crossing(col, level=0.5 * 1333.2):  # first time the axis pressure rises through half the inlet's
    for a, b in zip(rows, rows[1:]):
        va, vb = float(a[col]), float(b[col])
        if va < level <= vb:
            return float(a["time"]) + (float(b["time"]) - float(a["time"])) * (level - va) / (vb - va)
    return float("nan")
speed = 0.02 / (crossing("fluid.probe.p_z30") - crossing("fluid.probe.p_z10"))
print(sys.argv[2], m["coupling.mean_iterations"], m["coupling.max_iterations"], t["coupling.acceleration"],
      d["wall_s"], speed)
EOF
    tail -1 "$work/raw"
  done
done
{
  echo "# raw: label, mean its/step, max, acceleration s, wall s, pulse speed m/s"
  cat "$work/raw"
  echo
  /usr/bin/python3 - "$work/raw" <<'EOF'
import statistics, sys
rows = {}
for line in open(sys.argv[1]):
    f = line.split()
    rows.setdefault(f[0], []).append([float(x) for x in f[1:]])
print("| setting | its/step (max) | acceleration, s (median; range) | wall, s (median; range) | pulse speed, m/s |")
print("|---|---|---|---|---|")
for k, v in rows.items():
    acc = [r[2] for r in v]
    wall = [r[3] for r in v]
    print(f"| {k} | {v[0][0]:.2f} ({v[0][1]:.0f}) | {statistics.median(acc):.3f} ({min(acc):.3f}-{max(acc):.3f}) | "
          f"{statistics.median(wall):.2f} ({min(wall):.2f}-{max(wall):.2f}) | "
          + (f"{v[0][4]:.4f} |" if v[0][4] == v[0][4] else "— (the pulse has not reached z = 30 mm) |"))
EOF
} | tee "$out"
