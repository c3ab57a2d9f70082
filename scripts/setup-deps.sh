#!/usr/bin/env bash
# setup-deps.sh — install everything membrane-fsi needs on a bare Debian bookworm machine.
#
# Idempotent: a second run checks and returns in well under a second.
#   scripts/setup-deps.sh            # apt packages + Kokkos (OpenMP) into the cache
#   MFSI_DEPS_DIR=/opt/mfsi scripts/setup-deps.sh
#   MFSI_SKIP_KOKKOS=1 scripts/setup-deps.sh   # you bring -DKokkos_ROOT=... yourself
#
# Prints the Kokkos prefix on its last line as "KOKKOS_ROOT=<path>" so the Makefile can pick it up.
set -euo pipefail

t0=$(date +%s.%N)
say() { echo "[setup-deps] $*" >&2; }

DEPS_DIR=${MFSI_DEPS_DIR:-${XDG_CACHE_HOME:-$HOME/.cache}/mfsi}
KOKKOS_PREFIX="$DEPS_DIR/kokkos-openmp"
KOKKOS_STAMP="$KOKKOS_PREFIX/.mfsi-kokkos-3.4.1-openmp"

APT_PACKAGES=(
  build-essential cmake pkg-config
  libopenmpi-dev openmpi-bin
  libeigen3-dev libhdf5-openmpi-dev libmetis-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libyaml-cpp-dev libcli11-dev
  python3 python3-numpy python3-matplotlib python3-h5py
  dpkg-dev
)

SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1 && sudo -n true 2>/dev/null; then
    SUDO="sudo"
  else
    SUDO="__none__"
  fi
fi

missing=()
for p in "${APT_PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -gt 0 ]; then
  if [ "$SUDO" = "__none__" ]; then
    say "missing packages and no root/sudo. Please run as root:"
    say "  apt-get update && apt-get install -y ${missing[*]}"
    exit 1
  fi
  say "installing: ${missing[*]}"
  # Refresh the package lists when they are absent or older than a day.
  if [ -z "$(find /var/lib/apt/lists -maxdepth 1 -name '*Packages*' -mmin -1440 2>/dev/null | head -n1)" ]; then
    say "apt-get update"
    $SUDO apt-get update -qq
  fi
  if ! DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null; then
    say "install failed; retrying after apt-get update"
    $SUDO apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
  fi
else
  say "apt packages: all present"
fi

# ---------------------------------------------------------------------------------------------
# Kokkos 3.4.1 with OpenMP, built from Debian's Trilinos source package.
# ---------------------------------------------------------------------------------------------
if [ -n "${MFSI_SKIP_KOKKOS:-}" ]; then
  say "MFSI_SKIP_KOKKOS set: not building Kokkos"
elif [ -f "$KOKKOS_STAMP" ]; then
  say "Kokkos (OpenMP) already in $KOKKOS_PREFIX"
else
  if [ "$SUDO" = "__none__" ]; then
    say "need root/sudo once to enable deb-src lists for the Trilinos source package"; exit 1
  fi
  # Derive deb-src entries from the machine's own apt sources (never a hard-coded mirror).
  if ! apt-get source --print-uris trilinos >/dev/null 2>&1; then
    say "enabling deb-src entries derived from the existing apt sources"
    for f in /etc/apt/sources.list.d/*.sources; do
      [ -e "$f" ] || continue
      case "$f" in *mfsi-src*) continue ;; esac
      grep -q '^Types:.*\bdeb\b' "$f" || continue
      sed -e 's/^Types:.*/Types: deb-src/' "$f" | $SUDO tee "/etc/apt/sources.list.d/mfsi-src-$(basename "$f")" >/dev/null
    done
    for f in /etc/apt/sources.list /etc/apt/sources.list.d/*.list; do
      [ -e "$f" ] || continue
      case "$f" in *mfsi-src*) continue ;; esac
      grep -E '^deb\s' "$f" | sed -e 's/^deb\s/deb-src /' | $SUDO tee "/etc/apt/sources.list.d/mfsi-src-$(basename "$f" .list).list" >/dev/null || true
    done
    $SUDO apt-get update -qq
  fi
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
  say "downloading Debian's trilinos source package"
  (cd "$work" && apt-get source --download-only -qq trilinos >/dev/null)
  orig=$(ls "$work"/trilinos_*.orig.tar.* | head -n1)
  say "extracting packages/kokkos from $(basename "$orig")"
  tar -xf "$orig" -C "$work" --wildcards '*/packages/kokkos/*'
  src=$(find "$work" -maxdepth 3 -type d -path '*/packages/kokkos' | head -n1)
  say "configuring Kokkos (OpenMP + Serial, C++17, Release, PIC)"
  cmake -S "$src" -B "$work/build" -DCMAKE_BUILD_TYPE=Release -DCMAKE_INSTALL_PREFIX="$KOKKOS_PREFIX" \
    -DCMAKE_CXX_STANDARD=17 -DCMAKE_POSITION_INDEPENDENT_CODE=ON -DKokkos_ENABLE_OPENMP=ON \
    -DKokkos_ENABLE_SERIAL=ON -DKokkos_ENABLE_TESTS=OFF -DKokkos_ENABLE_EXAMPLES=OFF >"$work/configure.log" 2>&1 \
    || { cat "$work/configure.log" >&2; exit 1; }
  say "building Kokkos"
  cmake --build "$work/build" -j "$(nproc)" >"$work/build.log" 2>&1 || { tail -50 "$work/build.log" >&2; exit 1; }
  cmake --install "$work/build" >/dev/null
  touch "$KOKKOS_STAMP"
fi

t1=$(date +%s.%N)
say "done in $(python3 -c "print(f'{$t1-$t0:.1f}')" 2>/dev/null || echo "?") s"
if [ -z "${MFSI_SKIP_KOKKOS:-}" ]; then echo "KOKKOS_ROOT=$KOKKOS_PREFIX"; fi
