#!/usr/bin/env bash
# Geometry kernel vs STREAM triad, 1 and 2 threads, medians of 5 repetitions, in one run each.
#   perf/run_geometry_bench.sh [build-dir]
set -euo pipefail
build=${1:-build}
for t in 1 2; do
  echo "== OMP_NUM_THREADS=$t"
  OMP_PROC_BIND=spread OMP_PLACES=cores OMP_NUM_THREADS=$t "$build/perf/bench_geometry" \
    --benchmark_repetitions=5 --benchmark_report_aggregates_only=true --benchmark_min_time=0.5 \
    --benchmark_format=json > "$build/bench_geometry_t$t.json" 2>/dev/null
  python3 - "$build/bench_geometry_t$t.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
med = {b["run_name"]: b for b in d["benchmarks"] if b.get("aggregate_name") == "median"}
stream = next(v for k, v in med.items() if "streamTriad" in k)["GB/s"]
print(f"STREAM triad: {stream:.1f} GB/s")
for k, v in med.items():
    if "Geometry" in k:
        gbs = v["GB/s"]
        print(f"{k}: {v['cells/s']/1e6:.2f} Mcells/s, {gbs:.2f} GB/s = {100*gbs/stream:.1f} % of STREAM")
PY
done
