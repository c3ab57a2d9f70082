MAKEFLAGS += --no-print-directory
# Thin driver around CMake. The two commands of the README:
#   make run    set-up -> configure -> build -> run the default scene
#   make test   set-up -> configure -> build -> ctest
# Portability and correctness builds (scripts/build-variant.sh, each in its own build directory):
#   make build-cuda    CUDA + OpenMP Kokkos, nvcc_wrapper: compiles and links every library, the command
#                      and the tests and benchmarks that write kernels (no GPU run)
#   make test-checked  ASan + UBSan against a bounds-checked Kokkos in one build, the suite but its
#                      longest accuracy runs (no benchmarks): what .ci/run uses
#   make test-asan     AddressSanitizer + UndefinedBehaviorSanitizer build, the suite but its longest accuracy runs (no benchmarks)
#   make test-bounds   Kokkos bounds-checked (debug) build, the suite but its longest accuracy runs (no benchmarks)
# Options: BUILD_DIR=build  JOBS=<n>  SCENE=<file or name>  KOKKOS_ROOT=<your Kokkos>
BUILD_DIR ?= build
JOBS ?= $(shell nproc)
SCENE ?=
OUT ?= results/default
CMAKE_ARGS ?=

ifdef KOKKOS_ROOT
  SETUP_ENV = MFSI_SKIP_KOKKOS=1
  KOKKOS_ARG = -DKokkos_ROOT=$(KOKKOS_ROOT)
endif

.PHONY: all deps configure build run test bench clean build-cuda test-checked test-asan test-bounds

all: build

deps:
	@$(SETUP_ENV) bash scripts/setup-deps.sh > $(BUILD_DIR).deps.env.tmp && mv $(BUILD_DIR).deps.env.tmp $(BUILD_DIR).deps.env

configure: deps
	@kr="$(KOKKOS_ARG)"; if [ -z "$$kr" ]; then kr="-DKokkos_ROOT=$$(sed -n 's/^KOKKOS_ROOT=//p' $(BUILD_DIR).deps.env)"; fi; \
	cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=Release $$kr $(CMAKE_ARGS) > /dev/null

build: configure
	@cmake --build $(BUILD_DIR) -j $(JOBS)

run: build
	@OMP_PROC_BIND=false ./$(BUILD_DIR)/apps/mfsi run $(SCENE) --out $(OUT) --overwrite

test: build
	@cd $(BUILD_DIR) && OMP_PROC_BIND=false ctest --output-on-failure -j $(JOBS) --timeout 900

bench: build
	@bash perf/run_benchmarks.sh $(BUILD_DIR)

build-cuda:
	@JOBS=$(JOBS) bash scripts/build-variant.sh cuda

test-checked:
	@JOBS=$(JOBS) bash scripts/build-variant.sh checked --test

test-asan:
	@JOBS=$(JOBS) bash scripts/build-variant.sh asan --test

test-bounds:
	@JOBS=$(JOBS) bash scripts/build-variant.sh bounds --test

clean:
	rm -rf $(BUILD_DIR) $(BUILD_DIR).deps.env build-cuda build-checked build-asan build-bounds
