# shellcheck shell=bash disable=SC2034
# Sourced by the perf/openfoam/*.sh scripts: OpenFOAM environment, paths and small helpers.
#
# Debian's package (openfoam 1912.200626, OpenFOAM v1912) installs the solvers in /usr/bin and the
# environment in /usr/share/openfoam/etc/bashrc. That bashrc prints errors about missing
# bin/foamEtcFile while sourcing, but still sets WM_PROJECT_DIR etc., which the solvers need
# (without it they stop with "Could not find mandatory etc entry 'controlDict'"). Override the
# file with FOAM_BASHRC=..., the scratch directory (default /tmp/mfsi-openfoam) with OF_WORK=...
OF_DIR=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
REPO=$(cd "$OF_DIR/../.." && pwd)
RESULTS=$OF_DIR/results
WORK=${OF_WORK:-/tmp/mfsi-openfoam}
MPIRUN="mpirun --allow-run-as-root --oversubscribe"
mkdir -p "$RESULTS" "$WORK"

set +eu
# shellcheck disable=SC1090
source "${FOAM_BASHRC:-/usr/share/openfoam/etc/bashrc}" >/dev/null 2>&1
set -eu
for tool in blockMesh icoFoam simpleFoam decomposePar gmshToFoam checkMesh; do
  command -v "$tool" >/dev/null || { echo "OpenFOAM tool $tool not found (Debian package openfoam)" >&2; exit 1; }
done
[ -n "${WM_PROJECT_DIR:-}" ] || { echo "OpenFOAM environment not set (FOAM_BASHRC)" >&2; exit 1; }

# make_case TEMPLATE CASE KEY=VALUE ...: copy a case template from cases/, filling in @KEY@.
make_case() {
  local template=$1 case=$2
  shift 2
  python3 "$OF_DIR/foamtools.py" instantiate "$OF_DIR/cases/$template" "$case" "$@"
}

# run_foam CASE LOG COMMAND...: run an OpenFOAM command in CASE, output to CASE/LOG; on failure
# print the log's tail and stop.
run_foam() {
  local case=$1 log=$2
  shift 2
  if ! (cd "$case" && "$@" >"$log" 2>&1); then
    echo "FAILED: $* (in $case); last lines of $case/$log:" >&2
    tail -20 "$case/$log" >&2
    exit 1
  fi
}

load_note() { echo "$(date -u +%FT%TZ) $(uptime | sed 's/.*load average/load average/')"; }

# cavity3d_case N STEPS: the 3D lid-driven cube cavity timing case (N^3 cells, dt = 0.32 / N,
# STEPS steps, no output, decomposed into 2 slabs), meshed and decomposed in $WORK/cavity3d_N<N>;
# sets `case`, `dt` and `end`.
cavity3d_case() {
  local n=$1 steps=$2
  dt=$(python3 -c "print(0.32 / $n)")
  end=$(python3 -c "print(repr($steps * 0.32 / $n))")
  case=$WORK/cavity3d_N$n
  make_case cavity "$case" N="$n" NZ="$n" LZ=1 FB_TYPE=wall FB_U=noSlip FB_P=zeroGradient \
    DT="$dt" END_TIME="$end" WRITE_CONTROL=timeStep WRITE_INTERVAL=1000000 NCORR=2 NP=2
  run_foam "$case" log.blockMesh blockMesh
  run_foam "$case" log.decomposePar decomposePar -force
}

# stamp: prefix every line of stdin with the wall time it arrived at (for timing solver logs).
stamp() { python3 -u -c '
import sys, time
for line in sys.stdin:
    sys.stdout.write("%.6f %s" % (time.time(), line))
    sys.stdout.flush()'; }
