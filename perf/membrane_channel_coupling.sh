#!/usr/bin/env bash
# Implicit against explicit coupling on cases/membrane-channel.yaml (two elastic panels in a
# spring-mounted rigid frame in a 3D channel; the seed's section 7.1 benchmark, scaled down):
# frame displacement at the end time against a converged reference (implicit, fsiTol 1e-7), wall
# clock, fluid outer iterations, mean coupling iterations per step, time shares.
#
#   perf/membrane_channel_coupling.sh            # 3 runs of ~2-3 min each on 2 cores
#   MFSI=path/to/mfsi THREADS=2 perf/membrane_channel_coupling.sh
#
# Output: perf/results/membrane_channel_coupling.txt and stdout.
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
mfsi=${MFSI:-$repo/build/apps/mfsi}
threads=${THREADS:-2}
work=${WORK:-/tmp/mfsi-membrane-channel}
[ -x "$mfsi" ] || { echo "$mfsi not found: build the project first (or set MFSI=...)" >&2; exit 1; }
mkdir -p "$work" "$repo/perf/results"
export OMP_PROC_BIND=false
scene=$repo/cases/membrane-channel.yaml
run() {  # name, --set arguments...
  local name=$1
  shift
  rm -rf "${work:?}/$name"  # a failed run must not leave an earlier run's results to be read
  "$mfsi" run "$scene" "$@" --out "$work/$name" --threads "$threads" > "$work/$name.log" 2>&1 || true
}
run reference --set coupling.fsiTol=1.0e-7 --set coupling.maxFsiIter=60
run implicit
run explicit --set coupling.scheme=explicit
out=$repo/perf/results/membrane_channel_coupling.txt
tmp=$(mktemp "$out.XXXX")
/usr/bin/python3 - "$work" "$(cd "$repo" && git describe --always --dirty 2>/dev/null || echo unknown)" "$threads" > "$tmp" <<'PY'
import csv, json, sys
work, rev, threads = sys.argv[1], sys.argv[2], sys.argv[3]
def load(name):
    try:
        s = json.load(open(f"{work}/{name}/summary.json"))
    except OSError:
        return {"status": "failed", "frame_dx": float("nan"), "wall_s": float("nan"), "metrics": {}}
    rows = list(csv.DictReader(open(f"{work}/{name}/bodies.csv")))
    s["frame_dx"] = float(rows[-1]["x"]) - float(rows[0]["x"]) if s["status"] == "ok" else float("nan")
    return s
ref, imp, exp = load("reference"), load("implicit"), load("explicit")
print(f"# cases/membrane-channel.yaml, {threads} threads, {rev}; perf/membrane_channel_coupling.sh")
print("# frame displacement at t_end against the implicit run with fsiTol 1e-7 (the converged reference)")
print(f"{'run':<10} {'status':<9} {'frame dx [m]':>13} {'vs ref':>9} {'wall [s]':>9} {'fluid outer':>12} {'FSI it/step':>12} {'motion+transfer+acc':>20}")
for name, s in (("reference", ref), ("implicit", imp), ("explicit", exp)):
    m = s.get("metrics", {})
    d = s["frame_dx"]
    rel = 100 * (d / ref["frame_dx"] - 1) if d == d else float("nan")
    print(f"{name:<10} {s['status']:<9} {d:>13.6f} {rel:>+8.3f}% {s['wall_s']:>9.1f} {m.get('fluid.outer_iterations', float('nan')):>12.0f} "
          f"{m.get('coupling.mean_iterations', float('nan')):>12.2f} {100 * m.get('coupling.share_motion_transfer_acceleration', float('nan')):>19.1f}%")
if exp["status"] == "ok" and imp["status"] == "ok":
    print(f"# explicit / implicit wall clock: {exp['wall_s'] / imp['wall_s']:.2f}")
PY
mv "$tmp" "$out"
cat "$out"
