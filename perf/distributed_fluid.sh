#!/usr/bin/env bash
# The 3D cube cavity (perf/distributed_fluid.cpp) at 1 and 2 ranks x 1 and 2 threads, and the
# one-rank solver with its fast paths for reference: time per cell-step (median of `reps` runs),
# pressure iterations, the cells' halo traffic, parallel efficiency against the one-rank solver
# and against the decomposed solver on one rank. Writes perf/results/distributed_fluid.txt (the
# raw lines, then the table). 2 ranks x 2 threads oversubscribe a 2-core machine.
#
#   perf/distributed_fluid.sh [n ...]        # default: 64 128; REPS=3
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
exe=${EXE:-$repo/build/perf/perf_distributed_fluid}
[ -x "$exe" ] || { echo "$exe not found: build the project first" >&2; exit 1; }
sizes=("$@")
[ ${#sizes[@]} -gt 0 ] || sizes=(64 128)
reps=${REPS:-3}
flags=(--oversubscribe --bind-to none)
[ "$(id -u)" = 0 ] && flags+=(--allow-run-as-root)
out=$repo/perf/results/distributed_fluid.txt
mkdir -p "$(dirname "$out")"
raw=$(mktemp)
{
  echo "# perf/distributed_fluid.sh ${sizes[*]} (REPS=$reps; $(date -u +%Y-%m-%dT%H:%MZ), $(nproc) cores, $(git -C "$repo" rev-parse --short HEAD))"
  for n in "${sizes[@]}"; do
    steps=20 untimed=5
    [ "$n" -ge 128 ] && steps=10 untimed=3
    for rep in $(seq "$reps"); do
      for cfg in "1 1 serial" "1 2 serial" "1 1 distributed" "1 2 distributed" "2 1 distributed" "2 2 distributed"; do
        read -r np threads mode <<<"$cfg"
        # More threads than cores: threads that spin while they wait starve the other rank
        # (2 ranks x 2 threads on 2 cores ran 30x slower than 2 x 1); passive waiting yields.
        wait=active
        [ $((np * threads)) -gt "$(nproc)" ] && wait=passive
        OMP_WAIT_POLICY=$wait OMP_NUM_THREADS=$threads OMP_PROC_BIND=false KOKKOS_DISABLE_WARNINGS=1 \
          mpirun "${flags[@]}" -np "$np" "$exe" "$n" "$steps" "$untimed" "$mode" 2>/dev/null | grep '^n='
      done
    done
  done
} | tee "$raw"
/usr/bin/python3 - "$raw" <<'PY' | tee -a "$raw"
import re, sys, statistics
rows = {}
for line in open(sys.argv[1]):
    m = re.match(r"n=(\d+)\^3 .* mode=(\w+) ranks=(\d) threads=(\d) edgecut=(\d+).*\| ([0-9.e+-]+) s/cell-step.*"
                 r"pressure its/step ([0-9.]+).*cell halo per step \(all ranks\): ([0-9.]+) messages, ([0-9.]+) bytes", line)
    if not m: continue
    n, mode, r, t, cut, s, pits, msg, byt = m.groups()
    w = re.search(r"halo transfers ([0-9.]+) %, reductions ([0-9.]+) %", line)
    waits = (float(w.group(1)), float(w.group(2))) if w else (float("nan"), float("nan"))
    rows.setdefault((int(n), mode, int(r), int(t)), []).append((float(s), float(pits), int(cut), float(msg), float(byt), *waits))
print("\n| n³ | solver | ranks × threads | s/cell-step (median) | runs | pressure its/step | edge cut | cell-halo messages / MB per step | halo transfers / reductions, % of the step (median) | efficiency vs one-rank solver, same cores | vs decomposed on 1 rank × 1 thread |")
print("|---|---|---|---|---|---|---|---|---|---|---|")
for key in sorted(rows, key=lambda k: (k[0], k[1] != "serial", k[2], k[3])):
    n, mode, r, t = key
    v = rows[key]
    s = statistics.median(x[0] for x in v)
    base = rows.get((n, "serial", 1, 1)); dist1 = rows.get((n, "distributed", 1, 1))
    cores = r * t
    e1 = statistics.median(x[0] for x in base) / (s * cores) if base else float("nan")
    e2 = statistics.median(x[0] for x in dist1) / (s * cores) if dist1 else float("nan")
    hw = statistics.median(x[5] for x in v); rw = statistics.median(x[6] for x in v)
    print(f"| {n} | {mode} | {r} × {t} | {s:.3e} | {len(v)} | {v[0][1]:.2f} | {v[0][2]} | {v[0][3]:.0f} / {v[0][4]/1e6:.2f} | {hw:.1f} / {rw:.1f} | {100*e1:.0f} % | {100*e2:.0f} % |")
PY
mv "$raw" "$out"
