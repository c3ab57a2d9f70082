#!/usr/bin/env bash
# The pulsatile VAD (issue 17): builds the blood chamber's mesh, runs
# cases/vad.yaml on it and reports how far it gets and each cycle (perf/plot_vad.py: wall
# time, FSI iterations, mesh quality, the membrane's centre, outlet and chamber pressures, the
# volume balance; a figure in $VAD_PNG, by default $WORK/vad.png).
#
#   perf/vad_attempt.sh              # two cycles (1.5 s), ~13 min on 1 thread
#   perf/vad_attempt.sh --two-chambers   # the air chamber meshed too (cases/vad-two-chambers.yaml)
#   perf/vad_attempt.sh --set coupling.interfaceMass=5    # extra options go to mfsi run
#   VAD_MESH_ARGS="--around 48 --ring 9" perf/vad_attempt.sh  # options of scripts/vad_mesh.py
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
mfsi=${MFSI:-$repo/build/apps/mfsi}
work=${WORK:-/tmp/mfsi-vad}
py=/usr/bin/python3
[ -x "$mfsi" ] || { echo "$mfsi not found: build the project first (or set MFSI=...)" >&2; exit 1; }
mkdir -p "$work"
scene=vad.yaml mesh=vad_blood.msh only=--blood-only
if [ "${1:-}" = --two-chambers ]; then
  scene=vad-two-chambers.yaml mesh=vad.msh only=
  shift
fi
# shellcheck disable=SC2086
$py "$repo/scripts/vad_mesh.py" $only ${VAD_MESH_ARGS:-} "$work/$mesh" > /dev/null
export OMP_PROC_BIND=false
"$mfsi" run "$repo/cases/$scene" --set mesh.file="$work/$mesh" --out "$work/out" --overwrite --threads 1 "$@" \
  > "$work/run.log" 2>&1 || true
$py "$repo/perf/plot_vad.py" "$work/out" --png "${VAD_PNG:-$work/vad.png}"
