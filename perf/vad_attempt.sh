#!/usr/bin/env bash
# The pulsatile VAD, work in progress (issue 17): builds the blood chamber's mesh, runs
# perf/scenes/vad_lumped.yaml and reports how far it gets (its stop reason, the time reached, the
# membrane's centre deflection and the air chamber's pressure there, FSI iterations per step).
#
#   perf/vad_attempt.sh              # ~1 min on 1 thread
#   perf/vad_attempt.sh --set coupling.interfaceMass=5    # extra options go to mfsi run
#   VAD_MESH_ARGS="--around 48 --ring 9" perf/vad_attempt.sh  # options of scripts/vad_mesh.py
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
mfsi=${MFSI:-$repo/build/apps/mfsi}
work=${WORK:-/tmp/mfsi-vad}
py=/usr/bin/python3
[ -x "$mfsi" ] || { echo "$mfsi not found: build the project first (or set MFSI=...)" >&2; exit 1; }
mkdir -p "$work"
# shellcheck disable=SC2086
$py "$repo/scripts/vad_mesh.py" --blood-only ${VAD_MESH_ARGS:-} "$work/vad_blood.msh" > /dev/null
cp "$repo/perf/scenes/vad_lumped.yaml" "$work/"
export OMP_PROC_BIND=false
"$mfsi" run "$work/vad_lumped.yaml" --out "$work/out" --overwrite --threads 1 "$@" > "$work/run.log" 2>&1 || true
$py - "$work/out" <<'PY'
import csv, json, sys
out = sys.argv[1]
s = json.load(open(out + "/summary.json"))
rows = list(csv.DictReader(open(out + "/steps.csv")))
its = [int(r["coupling.iterations"]) for r in rows]
print("status:", s["status"], "-", s.get("error", ""))
if rows:
    r = rows[-1]
    print("reached t = %s s of 1.5 (%d steps), wall %.1f s" % (r["time"], len(rows), s["wall_s"]))
    print("membrane centre deflection %.2f mm, largest displacement %.2f mm" % (
        1000 * float(r["membrane.membrane.centreDeflection"]), 1000 * float(r["membrane.membrane.maxDisplacement"])))
    print("air chamber pressure %.1f mmHg, FSI iterations per step %.2f (max %d)" % (
        float(r["coupling.chamberPressure"]) / 133.322, sum(its) / len(its), max(its)))
PY
