// Fluid kernels: face-to-cell divergence and matrix assembly, per-face gather (deterministic,
// default) against ScatterView, plus one PISO step of the whole solver; next to a STREAM triad
// measured in the same run and backend.
//
//   OMP_PROC_BIND=false OMP_NUM_THREADS=2 build/perf/bench_fluid
//   OMP_PROC_BIND=false OMP_NUM_THREADS=2 build/perf/bench_fluid --benchmark_filter='Stream|Divergence|Assemble'
//   OMP_PROC_BIND=false OMP_NUM_THREADS=2 build/perf/bench_fluid --benchmark_filter=PisoStep
//
// Second argument: 0 = gather, 1 = scatter. "GB/s" is compulsory traffic over time (every input
// read once, every output written once, no write-allocate), i.e. what a perfectly cached kernel
// needs; compare with the triad.
//  - Divergence (3 components): face fluxes 24 B/face, owner 4 B/face, cell->face CSR
//    (2 x 4 B per face + 4 B per cell), result 24 B/cell.
//  - Assemble: 4 face coefficients 32 B/face, cell diagonal 8 B/cell, matrix values 8 B/entry,
//    plus the gather's CSR maps (cellFaces, cellFacePos: 2 x 2 x 4 B per face, owner 4 B/face).
//  - PisoStep: one BDF2 step (2 correctors, momentum predictor, AMG-CG pressure) of a 3D lid-driven
//    cavity of N^3 cells at Re = 100; counter cells/s.
#include "support/BenchMain.hpp"

#include "core/BlockMesh.hpp"
#include "fluid/FluidSolver.hpp"
#include "fluid/FvAssembly.hpp"

namespace {

using namespace mfsi;
using namespace mfsi::fluid;

HexMesh cube(int n) { return buildHexMesh(generateBlockMesh(boxSpec({0, 0, 0}, {1, 1, 1}, {n, n, n}))); }

ReductionMode modeOf(const benchmark::State& state) {
  return state.range(1) == 0 ? ReductionMode::Gather : ReductionMode::Scatter;
}

void BM_Divergence(benchmark::State& state) {
  HexMesh mesh = cube(static_cast<int>(state.range(0)));
  Real3View flux("bench::flux", mesh.nFaces()), out("bench::div", mesh.nCells());
  Kokkos::deep_copy(flux, 1.0);
  ExecSpace exec;
  const ReductionMode mode = modeOf(state);
  for (auto _ : state) {
    divergence<3>(exec, mesh, flux, out, mode);
    exec.fence();
  }
  const double faces = mesh.nFaces(), cells = mesh.nCells();
  bench::setRates(state, faces * (24 + 4 + 8) + cells * (4 + 24), faces, "faces/s");
  state.SetLabel(toString(mode));
}

void BM_Assemble(benchmark::State& state) {
  HexMesh mesh = cube(static_cast<int>(state.range(0)));
  FvSparsity s = buildSparsity(mesh);
  CsrMatrix A = makeMatrix(s, "bench::A");
  FaceCoefficients fc = allocateFaceCoefficients(mesh, "bench::fc");
  Kokkos::deep_copy(fc.ownerDiag, 1.0);
  Kokkos::deep_copy(fc.neighbourDiag, 1.0);
  Kokkos::deep_copy(fc.upper, -1.0);
  Kokkos::deep_copy(fc.lower, -1.0);
  RealView cellDiag("bench::cellDiag", mesh.nCells());
  ExecSpace exec;
  const ReductionMode mode = modeOf(state);
  for (auto _ : state) {
    assembleMatrix(exec, mesh, s, fc, cellDiag, A, mode);
    exec.fence();
  }
  const double faces = mesh.nFaces(), cells = mesh.nCells(), nnz = A.nnz();
  bench::setRates(state, faces * (32 + 16 + 4) + cells * 8 + nnz * 8, faces, "faces/s");
  state.SetLabel(toString(mode));
}

void BM_PisoStep(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  auto spec = boxSpec({0, 0, 0}, {1, 1, 1}, {n, n, n});
  spec.blocks[0].patches = {"walls", "walls", "walls", "lid", "walls", "walls"};
  spec.patchKinds = {{"walls", PatchKind::Wall}, {"lid", PatchKind::Wall}};
  HexMesh mesh = buildHexMesh(generateBlockMesh(spec));
  FluidOptions o;
  o.viscosity = 0.01;
  o.reduction = modeOf(state);
  o.boundaries["lid"].type = BoundaryType::Wall;
  o.boundaries["lid"].velocity = {1, 0, 0};
  FluidSolver fluid(mesh, o);
  const double dt = 0.5 / n;  // lid Courant number 0.5
  int step = 0;
  fluid.solveStep(0.0, dt);  // set-up of the AMG hierarchy outside the timing
  for (auto _ : state) {
    ++step;
    const auto r = fluid.solveStep(step * dt, dt);
    benchmark::DoNotOptimize(r.continuityMax);
  }
  state.counters["cells/s"] =
      benchmark::Counter(static_cast<double>(mesh.nCells()), benchmark::Counter::kIsIterationInvariantRate);
  state.SetLabel(toString(o.reduction));
}

}  // namespace

BENCHMARK(mfsi::bench::streamTriad)->Arg(mfsi::bench::streamSize())->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Divergence)
    ->Args({mfsi::bench::tiny() ? 4 : 64, 0})
    ->Args({mfsi::bench::tiny() ? 4 : 64, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_Assemble)
    ->Args({mfsi::bench::tiny() ? 4 : 64, 0})
    ->Args({mfsi::bench::tiny() ? 4 : 64, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_PisoStep)
    ->Args({mfsi::bench::tiny() ? 4 : 32, 0})
    ->Args({mfsi::bench::tiny() ? 4 : 32, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
