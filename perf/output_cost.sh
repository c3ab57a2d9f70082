#!/usr/bin/env bash
# What field output costs: the 64^3 cube cavity (perf/scenes/cavity3d.yaml, 10 steps) without
# frames and with a frame every step, alternating, REPS runs each; prints the median wall time per
# step of each (advance + output timers of summary.json), their ratio and the size of the frames.
#   perf/output_cost.sh [BUILD_DIR] [REPS] [THREADS]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}; reps=${2:-3}; threads=${3:-2}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
run() {  # $1 tag, then --set overrides; prints wall seconds per step
  OMP_PROC_BIND=false "$build/apps/mfsi" run perf/scenes/cavity3d.yaml --threads "$threads" --out "$work/$1" \
    --overwrite "${@:2}" > /dev/null
  /usr/bin/python3 -c "import json,sys; s=json.load(open('$work/$1/summary.json')); print(s['timers']['advance']/s['steps'] + s['timers'].get('output',0)/s['steps'])"
}
none=(); every=()
for r in $(seq "$reps"); do
  none+=("$(run none)")
  every+=("$(run every --set output.fields.everySteps=1)")
done
sizes=$(stat -c %s "$work"/every/fields/*.h5 | tr '\n' ' ')
/usr/bin/python3 - "$sizes" "${none[*]}" "${every[*]}" <<'PY'
import statistics, sys
sizes = [int(x) / 1e6 for x in sys.argv[1].split()]
none = [float(x) for x in sys.argv[2].split()]; every = [float(x) for x in sys.argv[3].split()]
n, e = statistics.median(none), statistics.median(every)
print(f"no output:        {n:.4f} s per step (runs: {', '.join(f'{x:.4f}' for x in none)})")
print(f"a frame per step: {e:.4f} s per step (runs: {', '.join(f'{x:.4f}' for x in every)})")
print(f"ratio {e / n:.3f}; first frame {sizes[0]:.1f} MB, later frames {statistics.median(sizes[1:]):.1f} MB "
      f"(median of {len(sizes) - 1})")
PY
