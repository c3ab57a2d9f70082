#!/usr/bin/env bash
# What each rank holds after start-up: the cube cavity (perf/scenes/cavity3d.yaml, N^3 cells, one
# step, no output) on 1 and 2 ranks, 1 thread each. Prints every rank's peak resident memory and
# rank 0's set-up timers (reading the mesh, partitioning it and handing out the parts). On several
# ranks rank 0 alone reads the whole mesh; the others build only their part.
#   perf/startup_memory.sh [N ...]        (default: 64 128; MFSI=<path> measures another build;
#                                          RANKS="1 2 4" the rank counts, default "1 2")
set -euo pipefail
cd "$(dirname "$0")/.."
sizes=("$@")
[ ${#sizes[@]} -eq 0 ] && sizes=(64 128)
mfsi=${MFSI:-build/apps/mfsi}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
flags=(--oversubscribe --bind-to none)
[ "$(id -u)" = 0 ] && flags+=(--allow-run-as-root)
for n in "${sizes[@]}"; do
  for np in ${RANKS:-1 2}; do
    dir=$work/n$n.np$np
    # Each process writes its own peak (KiB) to time.<rank> (Open MPI names the rank).
    OMP_NUM_THREADS=1 OMP_PROC_BIND=false KOKKOS_DISABLE_WARNINGS=1 \
      mpirun "${flags[@]}" -np "$np" sh -c '/usr/bin/time -f "%M" -o "$0.${OMPI_COMM_WORLD_RANK:-0}" "$@"' \
      "$work/time.n$n.np$np" "$mfsi" run perf/scenes/cavity3d.yaml --threads 1 --out "$dir" --overwrite \
      --set mesh.blocks.0.cells="[$n,$n,$n]" --set time.maxSteps=1 --set output.fields.final=false > /dev/null
    /usr/bin/python3 - "$dir/summary.json" "$work/time.n$n.np$np" "$n" "$np" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
n, np = int(sys.argv[3]), int(sys.argv[4])
peaks = [int(open(f"{sys.argv[2]}.{r}").read().split()[-1]) for r in range(np)]
t = s["timers"]
phases = ("mesh", "decompose", "decompose.partition", "decompose.scatter", "decompose.faceIds", "setup.fluid")
setup = ", ".join(f"{k} {t[k]:.2f} s" for k in phases if k in t)
print(f"{n}^3 on {np} rank(s): peak memory " + ", ".join(f"rank {r} {p / 1024:.0f} MB" for r, p in enumerate(peaks)) +
      f"; rank 0 set-up: {setup}")
PY
  done
done
