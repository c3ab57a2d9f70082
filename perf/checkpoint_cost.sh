#!/usr/bin/env bash
# What checkpoints cost: the 64^3 cube cavity (perf/scenes/cavity3d.yaml, 10 steps) with a
# checkpoint every step (keep 2), REPS runs; prints the median time to write one checkpoint against
# the median time of a step (the timers of summary.json), the size of a checkpoint, and the time
# a restart takes to load it (its `restore` timer).
#   perf/checkpoint_cost.sh [BUILD_DIR] [REPS] [THREADS]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}; reps=${2:-3}; threads=${3:-2}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mfsi() { OMP_PROC_BIND=false "$build/apps/mfsi" "$@" --threads "$threads" > /dev/null; }
step=(); ckpt=(); load=()
for r in $(seq "$reps"); do
  mfsi run perf/scenes/cavity3d.yaml --out "$work/run" --overwrite --set output.checkpoint.everySteps=1
  read -r s c <<< "$(/usr/bin/python3 -c "import json; s=json.load(open('$work/run/summary.json')); t=s['timers']; print(t['advance']/s['steps'], t['checkpoint']/s['steps'])")"
  step+=("$s"); ckpt+=("$c")
  # Continue from the checkpoint of step 9 for one step, into a new folder.
  rm -f "$work"/run/checkpoints/checkpoint_000000010.h5
  mfsi run --restart "$work/run" --out "$work/restarted" --overwrite
  load+=("$(/usr/bin/python3 -c "import json; print(json.load(open('$work/restarted/summary.json'))['timers']['restore'])")")
done
size=$(stat -c %s "$work"/run/checkpoints/checkpoint_000000009.h5)
/usr/bin/python3 - "$size" "${step[*]}" "${ckpt[*]}" "${load[*]}" <<'PY'
import statistics, sys
size = int(sys.argv[1]) / 1e6
step, ckpt, load = ([float(x) for x in a.split()] for a in sys.argv[2:5])
s, c, l = statistics.median(step), statistics.median(ckpt), statistics.median(load)
print(f"a step:             {s:.4f} s (runs: {', '.join(f'{x:.4f}' for x in step)})")
print(f"writing checkpoint: {c:.4f} s (runs: {', '.join(f'{x:.4f}' for x in ckpt)}), {c / s:.2f} steps' time")
print(f"loading it:         {l:.3f} s (runs: {', '.join(f'{x:.3f}' for x in load)})")
print(f"size:               {size:.1f} MB ({size * 1e6 / 64**3:.0f} bytes per cell)")
PY
