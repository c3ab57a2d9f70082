#!/usr/bin/env bash
# build-variant.sh — the portability and correctness builds, each in a build directory of its own.
#
#   scripts/build-variant.sh cuda           # CUDA + OpenMP Kokkos (sm_80), nvcc_wrapper: compile and link
#                                           # every library, the command and every test or benchmark that
#                                           # writes kernels of its own (nothing runs: no GPU is assumed)
#   scripts/build-variant.sh checked --test # both checks below in one build (what .ci/run uses)
#   scripts/build-variant.sh asan  --test   # AddressSanitizer + UndefinedBehaviorSanitizer, the suite but its longest accuracy runs
#   scripts/build-variant.sh bounds --test  # Kokkos bounds checking + debug checks, the suite but its longest accuracy runs
#
# Environment: JOBS (default nproc), BUILD_DIR (default build-<variant>), DEBUG_INFO (default -g0;
# -g1 for line numbers in a sanitizer's report).
# Where nvcc is absent the cuda variant says so in one line and exits 0 (skipped, not failed).
set -euo pipefail
cd "$(dirname "$0")/.."
variant=${1:?usage: build-variant.sh cuda|checked|asan|bounds [--test]}
run_tests=${2:-}
JOBS=${JOBS:-$(nproc)}
BUILD_DIR=${BUILD_DIR:-build-$variant}
say() { echo "[$variant] $*"; }
t0=$(date +%s)

# Headers are checked once, by the main build. The correctness builds keep MFSI_ASSERT on (no
# NDEBUG), optimised; they leave the benchmarks out (the main build runs each as a tiny CTest, the
# CUDA build compiles them): the product code they exercise runs in the suite. Debug information
# is off (DEBUG_INFO=-g1 puts line tables back): the sanitizers' stack traces name the functions
# from the symbols, and line tables cost a tenth of the build time that .ci/run cannot spare.
cmake_args=(-DMFSI_CHECK_HEADERS=OFF -DMFSI_ENABLE_BENCHMARKS=OFF -DCMAKE_BUILD_TYPE=RelWithDebInfo
            "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O2 ${DEBUG_INFO:--g0}")
case "$variant" in
  cuda)
    nvcc=$(command -v nvcc || true)
    [ -n "$nvcc" ] || { [ -x "${CUDA_HOME:-/usr/local/cuda}/bin/nvcc" ] && nvcc="${CUDA_HOME:-/usr/local/cuda}/bin/nvcc"; } || true
    if [ -z "$nvcc" ]; then say "skipped: no nvcc (CUDA toolkit) on this machine"; exit 0; fi
    export PATH="$(dirname "$nvcc"):$PATH"
    kokkos=$(bash scripts/setup-deps.sh --cuda | sed -n 's/^KOKKOS_ROOT=//p')
    # Every library and the command; of the tests and benchmarks, those that write kernels (the
    # others are host code the main build compiles). Headers are checked by the main build. The
    # host side is compiled without optimisation (nothing runs; the main build's -O3 sees the same
    # host code with the same g++), which takes a third off each library's compile; the device
    # side is compiled for sm_80 as always.
    # Sources are compiled in unity batches of 8 (cmake/MfsiHelpers.cmake, OWN_UNIT): nvcc spends
    # about 7 s on every translation unit before it reaches the file's own code (Kokkos' headers
    # through cudafe++, cicc and g++), about a third of this build's time.
    cmake_args=(-DMFSI_CHECK_HEADERS=OFF -DMFSI_KERNEL_TARGETS_ONLY=ON -DCMAKE_BUILD_TYPE=Release
                "-DCMAKE_CXX_FLAGS_RELEASE=-O0 -DNDEBUG" -DMFSI_TEST_COMPILE_OPTIONS= -DCMAKE_CXX_COMPILER="$kokkos/bin/nvcc_wrapper"
                -DCMAKE_UNITY_BUILD=ON -DCMAKE_UNITY_BUILD_BATCH_SIZE=8)
    ;;
  asan|bounds|checked)
    if [ "$variant" = asan ]; then
      kokkos=$(bash scripts/setup-deps.sh | sed -n 's/^KOKKOS_ROOT=//p')
    else
      kokkos=$(bash scripts/setup-deps.sh --bounds | sed -n 's/^KOKKOS_ROOT=//p')
    fi
    # The longest command-line and stability runs shortened to what takes their code paths once
    # (tests/CMakeLists.txt, MFSI_TESTS_SHORT).
    cmake_args+=(-DMFSI_TESTS_SHORT=ON)
    # The tests' own sources at -O1 (40 % less compile time, under the sanitizers); the
    # libraries, whose code the tests run hot, at -O2, in unity batches of 8 sources as in the
    # CUDA build (the libraries of the checked build: 654 s -> 470 s on 2 cores).
    cmake_args+=(-DMFSI_TEST_COMPILE_OPTIONS=-O1 -DCMAKE_UNITY_BUILD=ON -DCMAKE_UNITY_BUILD_BATCH_SIZE=8)
    if [ "$variant" != bounds ]; then
      san="-fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer"
      cmake_args+=("-DCMAKE_CXX_FLAGS=$san" "-DCMAKE_EXE_LINKER_FLAGS=-fsanitize=address,undefined")
    fi
    ;;
  *) echo "unknown variant '$variant' (cuda, checked, asan, bounds)" >&2; exit 2 ;;
esac

# Sanitizer settings for everything that runs an instrumented executable: the tests, and the test
# discovery that runs each test executable once at build time. A finding aborts (non-zero exit).
# LeakSanitizer is off: Open MPI's plug-ins leak their start-up allocations by design and are
# unloaded before the leak report, so their frames cannot even be named in a suppression file;
# every allocation of ours is owned by a Kokkos View or a standard container.
export ASAN_OPTIONS="detect_leaks=0:abort_on_error=1:strict_string_checks=1:check_initialization_order=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"

cmake -S . -B "$BUILD_DIR" -DKokkos_ROOT="$kokkos" "${cmake_args[@]}" > /dev/null
cmake --build "$BUILD_DIR" -j "$JOBS"
t1=$(date +%s)
targets=$(cmake --build "$BUILD_DIR" --target help | grep -cE '^\.\.\. mfsi|^\.\.\. bench_' || true)
say "built $targets targets in $((t1 - t0)) s (Kokkos: $kokkos)"

if [ "$run_tests" = "--test" ]; then
  [ "$variant" != cuda ] || { say "no tests run: the CUDA build is compile-only here"; exit 0; }
  # Every test but the longest accuracy runs (the Ghia cavity at N = 64 and 128, and again with the
  # scatter reduction; Schaefer-Turek; Kovasznay's spatial order on both meshes, Taylor-Green's
  # temporal orders and Poiseuille's second order; the membrane's Newmark period and its lumped
  # against consistent Hencky runs; the flexible cavity
  # at 32 x 32 to t = 4 s, three couplings of it at 16 x 16 and its load-handling runs; the swinging
  # panel's frame period (the panel's mass on its frame runs in the frame-period test); the piston's
  # frequency sweep and its Aitken twin; the tube's pulse to 6 ms; the VAD's first 40 ms, 308 s
  # instrumented against 10 s, whose bending, columns and lumped chamber the unit tests, the large
  # deflection and the balloons run; the added-mass sweep, 147 s instrumented, nine 30-step runs of
  # the flexible cavity whose interface mass the membrane's unit tests and whose coupling the
  # other cavity runs take: about a third of the suite's test
  # time in Release, five times that instrumented): the same kernels and coupling paths run in the
  # shorter tests (the other fluid, FSI, piston, mounted-membrane, prescribed-body and
  # space-conservation tests, the scenes' short runs, the unit tests), and what these builds look
  # for (memory errors, undefined behaviour, out-of-bounds indices) does not depend on the mesh size
  # or the run's length.
  skip='^(CavityGhia\.(Re100AtN64AndN128MatchGhiaCentrelines|ScatterReductionGivesTheSameSolution)|SchaeferTurek\.Cylinder2D1DragLiftAndPressureDrop|OrderOfAccuracy\.(KovasznaySpatialOrderDistortedMesh|KovasznaySpatialOrderCartesian|TaylorGreenTemporalOrderBDF2|TaylorGreenTemporalOrderEuler)|Poiseuille\.ParabolicProfileConvergesAtSecondOrder|MembraneDynamics\.NewmarkPeriodFromZeroCrossings|MembraneHencky\.LumpedAndConsistentNewtonAgree|FsiScene\.(FlexibleCavityMeetsMokAtFourSeconds|EveryAccelerationReachesTheSameFixedPoint|TheLoadFilterTheRampAndTheStartTimeHoldTheResponseBack)|MountedMembrane\.ASwingingPanelPushesItsFrameBack|PistonScene\.(ImplicitCouplingMeetsTheAddedMassFrequencyFromTenToOneHundredth|AitkenMeetsTheSameAnswerWhenOmegaMayReachTheSecant)|TubeScene\.PulseTravelsAtTheMoensKortewegSpeed|stability\.(vad_start|added_mass))$'
  (cd "$BUILD_DIR" && OMP_PROC_BIND=false ctest --output-on-failure -j "$JOBS" --timeout 1800 -E "$skip")
  say "test suite passed in $(($(date +%s) - t1)) s"
fi
