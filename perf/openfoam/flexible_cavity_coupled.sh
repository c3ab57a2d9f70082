#!/usr/bin/env bash
# The flexible-bottom cavity's FSI answer against code that shares nothing with mfsi (the first
# peak is 24 % above Mok's; see perf/RESULTS.md). Two checks, both to t = 12 s at 32 x 32, dt = 0.1:
#   1. mfsi's coupled membrane motion prescribed to OpenFOAM's pimpleFoam (flexible_cavity_fluid.py
#      --bottom membrane): the vertical force of the fluid on the bottom, OpenFOAM against the force
#      mfsi's converged coupling saw, every 0.5 s;
#   2. an independent coupled solution: OpenFOAM for the fluid, a nonlinear string for the membrane,
#      coupled implicitly step by step with IQN-ILS (flexible_cavity_coupled.py, its defaults), its
#      first peak against mfsi's and Mok's.
#
#   perf/openfoam/flexible_cavity_coupled.sh        # ~45 min on one core
#   MFSI=path/to/mfsi END=2 perf/openfoam/flexible_cavity_coupled.sh   # to t = 2 s (a quick check)
#   COUPLED_DIR=dir perf/openfoam/flexible_cavity_coupled.sh   # check 2 from an earlier run's
#                                        # coupled.csv and coupled.log (flexible_cavity_coupled.py WORK)
#
# Output: results/flexible_cavity_coupled.txt (and stdout). Work files in $OF_WORK.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/foam_env.sh"
mfsi=${MFSI:-$REPO/build/apps/mfsi}
[ -x "$mfsi" ] || { echo "$mfsi not found: build the project first (or set MFSI=...)" >&2; exit 1; }
end=${END:-12}
py=/usr/bin/python3   # numpy and h5py
work=$WORK/flexible_cavity_coupled
rm -rf "$work"
mkdir -p "$work"

OMP_PROC_BIND=false "$mfsi" run "$REPO/cases/flexible-cavity.yaml" --out "$work/mfsi" --threads 1 \
  --set time.endTime="$end" --set output.fields.everySteps=1 \
  --set 'fluid.forces=[{patch: bottom, point: [0.5, 0, 0]}]' > "$work/mfsi.log" 2>&1 \
  || { echo "mfsi run failed: $work/mfsi.log" >&2; tail -5 "$work/mfsi.log" >&2; exit 1; }

out=$RESULTS/flexible_cavity_coupled.txt
[ "$end" = 12 ] || out=$work/flexible_cavity_coupled.txt   # a shorter run does not replace the results
status=0
if [ -n "${COUPLED_DIR:-}" ]; then  # an earlier run of check 2 (its coupled.csv and coupled.log)
  mkdir -p "$work/coupled"
  cp "$COUPLED_DIR/coupled.csv" "$work/coupled/" && cp "$COUPLED_DIR/coupled.log" "$work/coupled.log"
  grep -q "^total .* fluid runs" "$work/coupled.log" || { echo "$COUPLED_DIR/coupled.log: not a finished run" >&2; exit 1; }
  ! grep -q "NOT" "$work/coupled.log" || status=1
else
  "$py" "$OF_DIR/flexible_cavity_coupled.py" "$work/coupled" --end "$end" | tee "$work/coupled.log" || status=$?
fi

# check 1: OpenFOAM on mfsi's recorded motion
"$py" -c "import sys; sys.path.insert(0, sys.argv[1]); import flexible_cavity_coupled as c; \
c.motion_from_mfsi(sys.argv[2], 0.1, sys.argv[3])" "$OF_DIR" "$work/mfsi" "$work/motion.json"
case=$work/prescribed
python3 -B "$OF_DIR/flexible_cavity_fluid.py" 32 "$end" --bottom membrane --motion "$work/motion.json" --case "$case"
run_foam "$case" log.blockMesh blockMesh
run_foam "$case" log.pimpleFoam pimpleFoam

"$py" - "$case/postProcessing/forcesBottom/0/force.dat" "$work/mfsi/steps.csv" "$work/coupled/coupled.csv" \
    "$REPO/tests/data/flexible_cavity_mok2001.csv" "$status" "$end" \
    "$(git -C "$REPO" describe --always --dirty 2>/dev/null || echo unknown)" "$OF_DIR" \
    <<'PY' | tee "$out"
import csv, sys
force_dat, steps, coupled, mok, status, end, commit, of_dir = sys.argv[1:]
sys.path.insert(0, of_dir)
import foamtools
n = int(round(float(end) / 0.1))
foam = {k: f[0] for k, f in foamtools.read_force_y(force_dat, 0.1).items()}  # total force
ours = {int(round(float(r["time"]) / 0.1)): (float(r["fluid.bottom.force_y"]), float(r["membrane.bottom.centreUy"]))
        for r in csv.DictReader(open(steps))}
ind = {int(round(float(r["t_s"]) / 0.1)): float(r["midpoint_dy"]) for r in csv.DictReader(open(coupled))}
ref = [(float(r["t_s"]), float(r["midpoint_dy"])) for r in csv.DictReader(l for l in open(mok) if not l.startswith("#"))]
print("# flexible cavity, 32 x 32, dt = 0.1, to t = %s s (perf/openfoam/flexible_cavity_coupled.sh, repository %s)" % (end, commit))
print("# 1. vertical force of the fluid on the bottom [N] (0.05 m deep), mfsi's coupled motion prescribed")
print("#    to OpenFOAM; rel = (mfsi - OpenFOAM) / max |OpenFOAM|")
print("# t [s]  mid-point uy   mfsi force     OpenFOAM force   rel")
peak = max(abs(v) for v in foam.values())
worst = 0
for k in range(5, n + 1, 5):
    rel = (ours[k][0] - foam[k]) / peak
    worst = max(worst, abs(rel))
    print("%6.1f  %10.5f  %13.6e  %13.6e  %+7.2f%%" % (k / 10, ours[k][1], ours[k][0], foam[k], 100 * rel))
print("# largest |rel| %.2f%% of the peak force" % (100 * worst))
print("# 2. mid-point displacement: mfsi, the independent coupled solution (OpenFOAM + string), Mok")
print("# t [s]   mfsi      independent")
for k in range(10, n + 1, 10):
    print("%6.1f  %8.5f  %8.5f" % (k / 10, ours[k][1], ind[k]))
km = max(range(1, n + 1), key=lambda k: ours[k][1])
ki = max(range(1, n + 1), key=lambda k: ind[k])
tm, um = max(ref, key=lambda r: r[1] if r[0] < float(end) else -1)
print("# first peak: mfsi %.4f at %.1f s; independent %.4f at %.1f s%s; Mok %.4f at %.1f s"
      % (ours[km][1], km / 10, ind[ki], ki / 10,
         "" if status == "0" else " (a window NOT converged: see coupled.log)", um, tm))
PY
exit "$status"
