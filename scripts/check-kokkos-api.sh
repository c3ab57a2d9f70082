#!/usr/bin/env bash
# check-kokkos-api.sh — fail on Kokkos API that Kokkos 4 removed or renamed.
#
#   scripts/check-kokkos-api.sh [dir or file ...]   (default: the project's source folders)
#
# No Kokkos 4 source can be reached from this project's machines (Debian bookworm ships 3.4.1
# only), so the code is guarded instead of compiled against Kokkos 4: every construct below either
# does not exist in Kokkos 4.x or was renamed there (Kokkos 4.0 release notes: "removed deprecated
# code 3"; the 3.7 deprecations). Each line: a regular expression, then what to use instead.
# core/Types.hpp may name Kokkos::Experimental math inside its KOKKOS_VERSION < 30700 branch only.
# Runs in CTest (portability.kokkos4_api); a fixture with every entry checks that it can fail.
set -euo pipefail
cd "$(dirname "$0")/.."
skip='-false'  # explicit arguments are all scanned; the default skips the fixtures in tests/data
if [ $# -eq 0 ]; then set -- core kernels fluid structure coupling apps perf tests; skip='tests/data/*'; fi

# pattern<TAB>why / what instead
rules=$(cat <<'RULES'
Kokkos::Impl::	implementation namespace: renamed and removed freely between releases (use public API)
KOKKOS_IMPL_	implementation macros: not API
Kokkos::InitArguments	removed in 4.0: pass argc/argv (3.4 has no InitializationSettings)
InitializationSettings	does not exist in 3.4: pass argc/argv
partition_master	removed in 4.0 (OpenMP partitioning): no replacement
thread_pool_(size|rank)	removed in 4.0: ExecSpace().concurrency()
(OpenMP|Serial|Cuda|HIP|Threads|DefaultExecutionSpace|DefaultHostExecutionSpace|ExecSpace|HostExecSpace)::(concurrency|is_initialized|initialize|finalize|print_configuration)\(	static backend members removed or deprecated in 4.x: ExecSpace().concurrency(), Kokkos::is_initialized(), Kokkos::initialize/finalize
::Rank\b	View::Rank removed in 4.0: View::rank
\.dimension_[0-7]\(	removed: extent(i)
\.ptr_on_device\(	removed: data()
\bfinalize_all\(	removed in 4.0: Kokkos::finalize()
\batomic_assign\(	deprecated in 4.x: atomic_store
vector_length\(\)	deprecated in 4.0 on team policies/members: impl_vector_length or team_size
KOKKOS_ENABLE_PROFILING\b	macro removed (profiling is always on): no guard needed
KOKKOS_ENABLE_DEPRECATED_CODE	3.x-only switch: write code that needs no deprecated API
Kokkos::Experimental::HIP\b	renamed in 4.0: Kokkos::HIP
Kokkos::Experimental::(sqrt|cbrt|pow|exp|log|sin|cos|tan|asin|acos|atan|atan2|fabs|abs|fmin|fmax|isfinite|isnan|isinf|floor|ceil|round|hypot|copysign)\b	moved to Kokkos:: in 3.7, removed from Experimental in 4.x: mfsi::kmath
\bKokkos::(abs|fabs|sqrt|cbrt|pow|exp|log|sin|cos|tan|asin|acos|atan|atan2|fmin|fmax|min|max|clamp|isfinite|isnan|isinf|floor|ceil|round|hypot|copysign)\(	not in 3.4 (3.7+): mfsi::kmath
--kokkos-threads\b	deprecated in 4.x: --kokkos-num-threads (3.7+), chosen by KOKKOS_VERSION
RULES
)

if [ "${1:-}" = "--count-rules" ]; then grep -c $'\t' <<< "$rules"; exit 0; fi

fail=0
files=$(find "$@" -type f \( -name '*.hpp' -o -name '*.cpp' -o -name '*.h' \) -not -path "$skip" | sort)
while IFS=$'\t' read -r pattern why; do
  [ -n "$pattern" ] || continue
  hits=$(echo "$files" | xargs grep -nHE -- "$pattern" || true)
  [ -n "$hits" ] || continue
  while IFS= read -r hit; do
    f=${hit%%:*}
    rest=${hit#*:}
    line=${rest%%:*}
    # The sanctioned version branches: core/Types.hpp's 3.4 math aliases and the launch flag
    # chosen by KOKKOS_VERSION in apps/mfsi.cpp (the line must sit in an #if on KOKKOS_VERSION).
    if [[ "$f" == core/Types.hpp || "$f" == apps/mfsi.cpp ]]; then
      branch=$(head -n "$line" "$f" | grep -nE '^#(if|elif|else|endif)' | tail -n1 || true)
      if [[ "$branch" == *KOKKOS_VERSION* || "$branch" == *"#else"* ]]; then continue; fi
    fi
    echo "$hit"
    echo "    Kokkos 4: $why"
    fail=1
  done <<< "$hits"
done <<< "$rules"
if [ "$fail" -ne 0 ]; then echo "check-kokkos-api: Kokkos 4 incompatibilities found (above)"; exit 1; fi
echo "check-kokkos-api: $(echo "$files" | wc -l) files, no API that Kokkos 4 removed or renamed"
