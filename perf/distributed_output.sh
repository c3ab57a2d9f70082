#!/usr/bin/env bash
# What a field frame costs on 1 and 2 ranks: the 64^3 cube cavity (perf/scenes/cavity3d.yaml,
# 10 steps, a frame every step, 1 thread per rank), REPS runs each; prints the median of the output
# timer per frame (summary.json, rank 0's wall time in the frames), the frames' size and the
# peak resident memory of the run's largest process. On several ranks each rank writes its own
# rows of each frame (core/io/RowWriter); MFSI=<path> measures another build of the command.
# KIND=checkpoint measures a checkpoint every step instead of a frame (the checkpoint timer per
# checkpoint, the checkpoint files' size): on several ranks each rank writes its own file.
#   [KIND=checkpoint] perf/distributed_output.sh [REPS]
set -euo pipefail
cd "$(dirname "$0")/.."
reps=${1:-3}
mfsi=${MFSI:-build/apps/mfsi}
kind=${KIND:-frame}
case $kind in
  frame) every=(--set output.fields.everySteps=1); timer=output; count="s['metrics']['output.field_frames']"; kept=fields ;;
  checkpoint) every=(--set output.checkpoint.everySteps=1 --set output.checkpoint.keep=1); timer=checkpoint
    count="s['steps']"; kept=checkpoints ;;
  *) echo "KIND is frame or checkpoint, not '$kind'" >&2; exit 2 ;;
esac
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
flags=(--oversubscribe --bind-to none)
[ "$(id -u)" = 0 ] && flags+=(--allow-run-as-root)
run() {  # $1 ranks, $2 tag: prints "seconds-per-frame peak-kB"
  local dir=$work/$2
  rm -f "$work/time.$2"
  OMP_NUM_THREADS=1 OMP_PROC_BIND=false KOKKOS_DISABLE_WARNINGS=1 \
    mpirun "${flags[@]}" -np "$1" /usr/bin/time -f "%M" -a -o "$work/time.$2" "$mfsi" run perf/scenes/cavity3d.yaml \
    --threads 1 --out "$dir" --overwrite "${every[@]}" > /dev/null
  /usr/bin/python3 -c "
import json; s = json.load(open('$dir/summary.json'))
peak = max(int(l) for l in open('$work/time.$2').read().split())
print(s['timers']['$timer'] / $count, peak)"
}
declare -A out mem
for r in $(seq "$reps"); do
  for np in 1 2; do
    read -r t m <<<"$(run "$np" "np$np")"
    out[$np]+="$t "; mem[$np]+="$m "
  done
done
size=$(du -sb "$work/np2/$kept" | cut -f1); files=$(ls "$work/np2/$kept" | wc -l)
/usr/bin/python3 - "${out[1]}" "${out[2]}" "${mem[1]}" "${mem[2]}" "$size" "$files" "$kind" <<'PY'
import statistics, sys
one, two = [float(x) for x in sys.argv[1].split()], [float(x) for x in sys.argv[2].split()]
m1, m2 = [int(x) for x in sys.argv[3].split()], [int(x) for x in sys.argv[4].split()]
size, files, kind = int(sys.argv[5]), int(sys.argv[6]), sys.argv[7]
print(f"{kind}s on 2 ranks: {files} files kept, {size / files / 1e6:.1f} MB each (64^3 cells)")
print(f"1 rank : {statistics.median(one) * 1e3:.1f} ms per {kind} (runs {', '.join(f'{x * 1e3:.1f}' for x in one)}); "
      f"peak memory of a process {statistics.median(m1) / 1e3:.0f} MB")
print(f"2 ranks: {statistics.median(two) * 1e3:.1f} ms per {kind} (runs {', '.join(f'{x * 1e3:.1f}' for x in two)}); "
      f"peak memory of a process {statistics.median(m2) / 1e3:.0f} MB")
PY
