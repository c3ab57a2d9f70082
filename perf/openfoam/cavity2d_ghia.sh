#!/usr/bin/env bash
# OpenFOAM reference: 2D lid-driven cavity, Re = 100, against Ghia et al. (1982).
#
#   perf/openfoam/cavity2d_ghia.sh [N ...]        # default: 64 128
#
# Case (template perf/openfoam/cases/cavity): unit square, lid y = 1 moving at u = 1, nu = 0.01,
# N x N x 1 uniform hexes (blockMesh), z faces "empty". icoFoam (PISO, 2 pressure correctors,
# Euler implicit, Gauss linear everywhere, see cases/cavity/system/fv*), starting from rest,
# dt = 0.32 / N (Courant 0.32 based on the lid speed), run to t = 30 (steady: the script reports
# max |U(30) - U(25)|). Pressure GAMG abs tol 1e-6 (relTol 0.05, final corrector 0); U
# symGaussSeidel abs tol 1e-5.
#
# Post-processing (perf/openfoam/cavity_ghia.py, no OpenFOAM sampling): u on x = 0.5 is the mean of
# the two cell columns beside it, v on y = 0.5 the mean of the two rows; along the line, linear
# interpolation between cell centres and the wall values (0, and 1 on the lid). Error = max abs
# difference at Ghia's 17 points of each profile (ghia1982_re100.csv, with its source line).
#
# Output: results/cavity2d_ghia.json and a table. Cases live in $OF_WORK (default /tmp/mfsi-openfoam).
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/foam_env.sh"

sizes=("$@")
[ ${#sizes[@]} -gt 0 ] || sizes=(64 128)
echo "load before: $(load_note)"
for n in "${sizes[@]}"; do
  case=$WORK/cavity2d_N$n
  dt=$(python3 -c "print(0.32 / $n)")
  make_case cavity "$case" N="$n" NZ=1 LZ=0.1 FB_TYPE=empty FB_U=empty FB_P=empty \
    DT="$dt" END_TIME=30 WRITE_CONTROL=runTime WRITE_INTERVAL=5 NCORR=2 NP=1
  run_foam "$case" log.blockMesh blockMesh
  start=$(date +%s.%N)
  run_foam "$case" log.icoFoam icoFoam
  echo "N = $n: icoFoam to t = 30 took $(python3 -c "print(round($(date +%s.%N) - $start, 1))") s wall ($case)"
done
echo "load after: $(load_note)"
cases=()
for n in "${sizes[@]}"; do cases+=("$WORK/cavity2d_N$n"); done
python3 "$OF_DIR/cavity_ghia.py" "$RESULTS/cavity2d_ghia.json" "${cases[@]}"
