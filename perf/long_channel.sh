#!/usr/bin/env bash
# The membrane channel for many flow-through times (issue 17, long runs): runs cases/membrane-channel.yaml
# to N flow-throughs (6 s each: 6 m at 1 m/s) and reports, per flow-through, the frame's mean position
# and its swing, the panels' centre deflection, the coupling iterations per step and the smallest
# scaled Jacobian, so drift shows as a trend down the table.
#
#   perf/long_channel.sh            # 20 flow-throughs (120 s), ~10 min on 1 thread
#   perf/long_channel.sh 5          # 5 flow-throughs
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
mfsi=${MFSI:-$repo/build/apps/mfsi}
n=${1:-20}
out=${OUT:-/tmp/mfsi-long-channel}
[ -x "$mfsi" ] || { echo "$mfsi not found: build the project first (or set MFSI=...)" >&2; exit 1; }
end=$((6 * n))
OMP_PROC_BIND=false "$mfsi" run membrane-channel --set time.endTime=$end --out "$out" --overwrite --threads 1 \
  > "$out.log" 2>&1 || { tail -3 "$out.log"; exit 1; }
/usr/bin/python3 - "$out" "$n" <<'PY'
import csv, json, sys
out, n = sys.argv[1], int(sys.argv[2])
steps = list(csv.DictReader(open(out + "/steps.csv")))
bodies = [r for r in csv.DictReader(open(out + "/bodies.csv"))]
s = json.load(open(out + "/summary.json"))
print("status %s, %d steps, wall %.0f s" % (s["status"], len(steps), s["wall_s"]))
print("| flow-through | frame x mean [m] | frame x min / max [m] | panel A centre u_x mean [m] | its/step (max) | min scaled Jacobian |")
print("|---|---|---|---|---|---|")
for k in range(n):
    t0, t1 = 6 * k, 6 * (k + 1)
    b = [float(r["x"]) for r in bodies if t0 < float(r["time"]) <= t1]
    w = [r for r in steps if t0 < float(r["time"]) <= t1]
    if not b or not w:
        break
    x0 = float(bodies[0]["x"])
    its = [int(r["coupling.iterations"]) for r in w]
    defl = [float(r["membrane.panelA.centreUx"]) for r in w]
    sj = min(float(r["coupling.minScaledJacobian"]) for r in w)
    print("| %d | %.6f | %.6f / %.6f | %.6f | %.2f (%d) | %.4f |" % (
        k + 1, sum(b) / len(b) - x0, min(b) - x0, max(b) - x0, sum(defl) / len(defl), sum(its) / len(its), max(its), sj))
PY
