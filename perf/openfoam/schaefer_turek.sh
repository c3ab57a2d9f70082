#!/usr/bin/env bash
# OpenFOAM reference: Schaefer-Turek 2D-1 (steady flow past a cylinder, Re = 20) on the project's
# hex meshes, with simpleFoam.
#
#   perf/openfoam/schaefer_turek.sh [LEVEL ...]      # default: coarse medium fine
#   CONV="linearUpwind grad(U)" perf/openfoam/schaefer_turek.sh coarse   # other convection scheme
#
# Meshes (scripts/make_cylinder_mesh.py): coarse = tests/data/meshes/cylinder_coarse.msh (1,888
# cells), medium = cases/meshes/cylinder_medium.msh (7,424), fine = generated into $OF_WORK
# (29,696; not kept in the repository). Each is converted exactly as committed: gmsh re-saves the
# MSH 4.1 file as MSH 2.2, gmshToFoam reads that, the patch types are set (walls, cylinder: wall;
# frontAndBack: empty) and checkMesh must pass.
#
# Case (template perf/openfoam/cases/cylinder): nu = 0.001, rho = 1; inlet u = 4 Um y (H - y) / H^2,
# Um = 0.3, at the inlet face centres; outlet p = 0, zero-gradient U; no-slip walls and cylinder.
# simpleFoam with SIMPLEC (consistent), U relaxation 0.9, until both normalised initial residuals
# are below 1e-10 (or ITERS iterations, default 20000). Schemes: Gauss linear gradients, bounded
# Gauss $CONV convection (default "linear" = central), Gauss linear corrected Laplacian. Forces by
# the forceCoeffs function object: c = 2F/(rho U^2 D H) with U = 0.2, D = 0.1, H = 0.01 (the mesh
# thickness). delta p = p(0.15, 0.2) - p(0.25, 0.2) from cellPoint-interpolated probes 1e-6 inside
# the fluid.
#
# Output: results/schaefer_turek[_<conv>].json and a table. Cases live in $OF_WORK (default
# /tmp/mfsi-openfoam).
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/foam_env.sh"

levels=("$@")
[ ${#levels[@]} -gt 0 ] || levels=(coarse medium fine)
conv=${CONV:-linear}
iters=${ITERS:-20000}
tag=$(echo "$conv" | sed 's/[^A-Za-z]//g; s/gradU$//')
suffix=$([ "$conv" = linear ] && echo "" || echo "_$tag")

command -v gmsh >/dev/null || { echo "gmsh not found (Debian package gmsh)" >&2; exit 1; }
echo "load before: $(load_note)"
cases=()
for level in "${levels[@]}"; do
  case $level in
    coarse) msh=$REPO/tests/data/meshes/cylinder_coarse.msh ;;
    medium) msh=$REPO/cases/meshes/cylinder_medium.msh ;;
    fine)
      msh=$WORK/cylinder_fine.msh
      python3 "$REPO/scripts/make_cylinder_mesh.py" --level fine -o "$msh" >/dev/null ;;
    *) echo "unknown level $level (coarse, medium, fine)" >&2; exit 1 ;;
  esac
  case=$WORK/cylinder_${level}$suffix
  make_case cylinder "$case" ITERS="$iters" CONV="$conv" INLET_U=__INLET_U__
  gmsh "$msh" -save -format msh22 -o "$case/mesh22.msh" >"$case/log.gmsh" 2>&1
  run_foam "$case" log.gmshToFoam gmshToFoam mesh22.msh
  python3 "$OF_DIR/foamtools.py" set-patch-types "$case" walls=wall cylinder=wall frontAndBack=empty
  run_foam "$case" log.checkMesh checkMesh
  grep -q "Mesh OK" "$case/log.checkMesh" || { echo "checkMesh failed for $msh" >&2; exit 1; }
  python3 "$OF_DIR/schaefer_turek.py" inlet "$case"
  start=$(date +%s.%N)
  run_foam "$case" log.simpleFoam simpleFoam
  wall=$(python3 -c "print(round($(date +%s.%N) - $start, 1))")
  ncells=$(sed -n 's/^ *cells: *\([0-9]*\).*/\1/p' "$case/log.checkMesh" | head -1)
  echo "$ncells ${msh#"$REPO/"} $tag $wall" >"$case/mesh.info"
  echo "$level: $ncells cells, simpleFoam $wall s wall; checkMesh: $(grep -E 'Mesh non-orthogonality' "$case/log.checkMesh" | sed 's/^ *//')"
  cases+=("$case")
done
echo "load after: $(load_note)"
python3 "$OF_DIR/schaefer_turek.py" analyse "$RESULTS/schaefer_turek$suffix.json" "${cases[@]}"
