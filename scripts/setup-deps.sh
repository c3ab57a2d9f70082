#!/usr/bin/env bash
# setup-deps.sh — install everything membrane-fsi needs on a bare Debian bookworm machine.
#
# Idempotent: a second run checks and returns in well under a second.
#   scripts/setup-deps.sh            # apt packages + Kokkos (OpenMP) into the cache
#   scripts/setup-deps.sh --cuda     # ... + Kokkos (CUDA + OpenMP, sm_80), patched for CUDA 13
#   scripts/setup-deps.sh --bounds   # ... + Kokkos (OpenMP) with bounds checking and debug checks
#   MFSI_DEPS_DIR=/opt/mfsi scripts/setup-deps.sh
#   MFSI_SKIP_KOKKOS=1 scripts/setup-deps.sh   # you bring -DKokkos_ROOT=... yourself
#
# Every Kokkos is 3.4.1 from Debian's Trilinos source package (the only Kokkos source Debian
# bookworm has), extracted once into $DEPS_DIR/src and built into a prefix of its own.
# Prints the chosen Kokkos prefix on its last line as "KOKKOS_ROOT=<path>" for the Makefile.
set -euo pipefail

t0=$(date +%s.%N)
say() { echo "[setup-deps] $*" >&2; }

FLAVOUR=openmp
case "${1:-}" in
  "") ;;
  --cuda) FLAVOUR=cuda ;;
  --bounds) FLAVOUR=bounds ;;
  *) say "unknown option '$1' (expected --cuda or --bounds)"; exit 2 ;;
esac
HERE=$(cd "$(dirname "$0")" && pwd)
DEPS_DIR=${MFSI_DEPS_DIR:-${XDG_CACHE_HOME:-$HOME/.cache}/mfsi}
KOKKOS_SRC="$DEPS_DIR/src/kokkos-3.4.1"

APT_PACKAGES=(
  build-essential cmake pkg-config
  libopenmpi-dev openmpi-bin
  libeigen3-dev libhdf5-openmpi-dev libmetis-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libyaml-cpp-dev libcli11-dev
  python3 python3-numpy python3-matplotlib python3-h5py python3-paraview
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
# Kokkos 3.4.1 from Debian's Trilinos source package.
# ---------------------------------------------------------------------------------------------
# The source, once: packages/kokkos of the Trilinos orig tarball, into $KOKKOS_SRC.
fetch_kokkos_source() {
  [ -f "$KOKKOS_SRC/.mfsi-complete" ] && return 0
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
  local dl
  dl=$(mktemp -d)
  say "downloading Debian's trilinos source package"
  (cd "$dl" && apt-get source --download-only -qq trilinos >/dev/null 2>&1)
  local orig
  orig=$(ls "$dl"/trilinos_*.orig.tar.* | head -n1)
  say "extracting packages/kokkos from $(basename "$orig")"
  tar -xf "$orig" -C "$dl" --wildcards '*/packages/kokkos/*'
  rm -rf "$KOKKOS_SRC"
  mkdir -p "$(dirname "$KOKKOS_SRC")"
  mv "$(find "$dl" -maxdepth 3 -type d -path '*/packages/kokkos' | head -n1)" "$KOKKOS_SRC"
  rm -rf "$dl"
  touch "$KOKKOS_SRC/.mfsi-complete"
}

# build_kokkos <prefix> <stamp> <patch files (space-separated, may be empty)> <cmake args...>
# Configures and builds a copy of the source with the patches applied, installs into <prefix>.
build_kokkos() {
  local prefix=$1 stamp=$2 patches=$3
  shift 3
  if [ -f "$prefix/$stamp" ]; then
    say "Kokkos ($FLAVOUR) already in $prefix"
    return 0
  fi
  fetch_kokkos_source
  local work
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
  cp -r "$KOKKOS_SRC" "$work/kokkos"
  for p in $patches; do
    say "patching Kokkos: $(basename "$p")"
    patch -s -p1 -d "$work/kokkos" < "$p"
  done
  say "configuring Kokkos ($FLAVOUR)"
  rm -rf "$prefix"
  local args=()
  for a in "$@"; do args+=("${a//@SRC@/$work/kokkos}"); done  # @SRC@: the patched source copy
  cmake -S "$work/kokkos" -B "$work/build" -DCMAKE_INSTALL_PREFIX="$prefix" -DCMAKE_CXX_STANDARD=17 \
    -DCMAKE_POSITION_INDEPENDENT_CODE=ON -DKokkos_ENABLE_SERIAL=ON -DKokkos_ENABLE_OPENMP=ON \
    -DKokkos_ENABLE_TESTS=OFF -DKokkos_ENABLE_EXAMPLES=OFF "${args[@]}" >"$work/configure.log" 2>&1 \
    || { cat "$work/configure.log" >&2; exit 1; }
  say "building Kokkos ($FLAVOUR)"
  cmake --build "$work/build" -j "$(nproc)" >"$work/build.log" 2>&1 || { tail -50 "$work/build.log" >&2; exit 1; }
  cmake --install "$work/build" >/dev/null
  touch "$prefix/$stamp"
  rm -rf "$work"
  trap - EXIT
}

KOKKOS_PREFIX=""
if [ -n "${MFSI_SKIP_KOKKOS:-}" ]; then
  say "MFSI_SKIP_KOKKOS set: not building Kokkos"
else
  case "$FLAVOUR" in
    openmp)
      KOKKOS_PREFIX="$DEPS_DIR/kokkos-openmp"
      build_kokkos "$KOKKOS_PREFIX" .mfsi-kokkos-3.4.1-openmp "" -DCMAKE_BUILD_TYPE=Release
      ;;
    bounds)
      # Every View access checked against its extents (Kokkos::abort on a miss), plus Kokkos' own
      # debug checks; optimised, so the whole test suite stays affordable.
      KOKKOS_PREFIX="$DEPS_DIR/kokkos-openmp-bounds"
      build_kokkos "$KOKKOS_PREFIX" .mfsi-kokkos-3.4.1-openmp-bounds "" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
        -DKokkos_ENABLE_DEBUG=ON -DKokkos_ENABLE_DEBUG_BOUNDS_CHECK=ON
      ;;
    cuda)
      NVCC=$(command -v nvcc || true)
      [ -n "$NVCC" ] || { [ -x "${CUDA_HOME:-/usr/local/cuda}/bin/nvcc" ] && NVCC="${CUDA_HOME:-/usr/local/cuda}/bin/nvcc"; } || true
      if [ -z "$NVCC" ]; then say "no nvcc (CUDA toolkit) found: cannot build the CUDA Kokkos"; exit 3; fi
      export PATH="$(dirname "$NVCC"):$PATH"
      # The fixes Kokkos 3.4.1 needs for CUDA 13 (each patch says why); the stamp names their hash,
      # so a changed patch rebuilds.
      patches=$(ls "$HERE"/patches/kokkos-3.4.1-*.patch | sort | tr '\n' ' ')
      hash=$(cat $patches | sha1sum | cut -c1-10)
      KOKKOS_PREFIX="$DEPS_DIR/kokkos-cuda"
      # nvcc_wrapper is the C++ compiler of every CUDA Kokkos build; the patched one is installed
      # with Kokkos ($KOKKOS_PREFIX/bin/nvcc_wrapper) for the project's build to use.
      build_kokkos "$KOKKOS_PREFIX" ".mfsi-kokkos-3.4.1-cuda-sm80-$hash" "$patches" -DCMAKE_BUILD_TYPE=Release \
        -DCMAKE_CXX_COMPILER=@SRC@/bin/nvcc_wrapper -DKokkos_ENABLE_CUDA=ON -DKokkos_ENABLE_CUDA_LAMBDA=ON \
        -DKokkos_ARCH_AMPERE80=ON
      ;;
  esac
fi

t1=$(date +%s.%N)
say "done in $(python3 -c "print(f'{$t1-$t0:.1f}')" 2>/dev/null || echo "?") s"
if [ -n "$KOKKOS_PREFIX" ]; then echo "KOKKOS_ROOT=$KOKKOS_PREFIX"; fi
