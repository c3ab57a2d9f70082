#!/usr/bin/env bash
# Strong added mass with an exact answer (cases/piston.yaml): the piston's period against
# 2 pi / sqrt(k / (m + rho A L)) for m / m_a = 10 ... 0.01, implicit coupling with IQN-ILS and with
# Aitken (omegaMin lowered below the secant 1 / (1 + m_a / m)), and the explicit scheme; coupling
# iterations per step and wall time from summary.json. 100 steps per period, 3 periods.
#
#   perf/piston_added_mass.sh                     # ~1 min on 2 cores
#   MFSI=path/to/mfsi perf/piston_added_mass.sh
#
# Output: perf/results/piston_added_mass.txt and stdout.
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
mfsi=${MFSI:-$repo/build/apps/mfsi}
work=${WORK:-/tmp/mfsi-piston}
py=/usr/bin/python3
[ -x "$mfsi" ] || { echo "$mfsi not found: build the project first (or set MFSI=...)" >&2; exit 1; }
mkdir -p "$work" "$repo/perf/results"
out=$repo/perf/results/piston_added_mass.txt
tmp=$(mktemp "$out.XXXX")
export OMP_PROC_BIND=false
ma=10  # rho A L = 1000 * 0.01 * 1
{
  echo "# piston: period T against 2 pi / sqrt(k / (m + m_a)), k = 1000 N/m, m_a = 10 kg; dt = T_exact / 100, 3 periods"
  echo "# $(cd "$repo" && git describe --always --dirty 2>/dev/null || echo unknown), perf/piston_added_mass.sh"
  printf "%-8s %-10s %-9s %-12s %-12s %-9s %-8s %-7s\n" "m/m_a" "coupling" "status" "T" "T_exact" "rel" "iter" "wall_s"
} > "$tmp"
for ratio in 10 1 0.1 0.01; do
  m=$($py -c "print($ratio * $ma)")
  T=$($py -c "import math; print(2 * math.pi / math.sqrt(1000 / ($ratio * $ma + $ma)))")
  for mode in iqn aitken explicit; do
    case $mode in
      iqn) extra=() ;;
      aitken) w=$($py -c "print(min(0.5, 0.5 / (1 + 1 / $ratio)))"); extra=(--set coupling.iqnMaxCols=0 --set coupling.omegaMin=$($py -c "print($w / 5)") --set coupling.omegaInit=$w) ;;
      explicit) extra=(--set coupling.scheme=explicit) ;;
    esac
    dir=$work/${mode}_$ratio
    rm -rf "${dir:?}"  # a failed run must not leave an earlier run's results to be read
    "$mfsi" run "$repo/cases/piston.yaml" --set bodies.members.piston.mass=$m --set time.dt=$($py -c "print($T / 100)") \
      --set time.endTime=$($py -c "print(3 * $T)") "${extra[@]}" --out "$dir" --threads 2 > "$dir.log" 2>&1 || true
    $py - "$dir" "$ratio" "$mode" "$T" >> "$tmp" <<'PY'
import csv, json, sys
d, ratio, mode, T0 = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4])
s = json.load(open(d + "/summary.json"))
t, x = [], []
try:
    for r in csv.DictReader(open(d + "/bodies.csv")):
        t.append(float(r["time"])); x.append(float(r["x"]))
except FileNotFoundError:
    pass
zc = [t[i - 1] + (t[i] - t[i - 1]) * x[i - 1] / (x[i - 1] - x[i]) for i in range(1, len(x)) if (x[i - 1] > 0) != (x[i] > 0)]
T = 2 * (zc[-1] - zc[0]) / (len(zc) - 1) if s["status"] == "ok" and len(zc) >= 3 else float("nan")
it = s.get("metrics", {}).get("coupling.mean_iterations", float("nan"))
print("%-8s %-10s %-9s %-12.6g %-12.6g %-+9.3f %-8.3g %-7.2f" % (ratio, mode, s["status"], T, T0, 100 * (T / T0 - 1) if T == T else float("nan"), it, s.get("wall_s", 0)))
PY
  done
done
mv "$tmp" "$out"
cat "$out"
