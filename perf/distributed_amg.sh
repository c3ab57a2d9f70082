#!/usr/bin/env bash
# Distributed AMG-CG on the cell Laplacian of an n^3 box (perf/distributed_amg.cpp) on 1, 2 and 4
# ranks, Dirichlet and Neumann: iterations, set-up and solve times, levels, halo traffic. Writes
# perf/results/distributed_amg.txt. Iteration counts do not depend on the machine's load; times do
# (and 4 ranks on a 2-core machine are oversubscribed).
#
#   perf/distributed_amg.sh [n]      # n = 64 by default
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
exe=${EXE:-$repo/build/perf/perf_distributed_amg}
n=${1:-64}
[ -x "$exe" ] || { echo "$exe not found: build the project first" >&2; exit 1; }
flags=(--oversubscribe)
[ "$(id -u)" = 0 ] && flags+=(--allow-run-as-root)
out=$repo/perf/results/distributed_amg.txt
mkdir -p "$(dirname "$out")"
{
  echo "# perf/distributed_amg.sh $n ($(date -u +%Y-%m-%d), $(nproc) cores)"
  for bc in dirichlet neumann; do
    for np in 1 2 4; do
      OMP_NUM_THREADS=1 OMP_PROC_BIND=false KOKKOS_DISABLE_WARNINGS=1 \
        mpirun "${flags[@]}" -np "$np" "$exe" "$n" "$bc" 2>/dev/null | grep -v '^$'
    done
  done
} | tee "$out.part"
mv "$out.part" "$out"
