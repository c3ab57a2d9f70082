// Jacobi point-Laplacian mesh smoothing (kernels/JacobiSmoothing) next to a STREAM triad measured
// in the same run, same backend: the fraction of the machine's bandwidth one sweep reaches.
//
//   OMP_PROC_BIND=false OMP_NUM_THREADS=1 build/perf/bench_smoothing --benchmark_repetitions=5
//   OMP_PROC_BIND=false OMP_NUM_THREADS=2 build/perf/bench_smoothing --benchmark_repetitions=5
//
// "GB/s" is the compulsory traffic of one sweep: per node the offsets (4 B), the neighbour list
// (4 B per entry), the fixed flag (1 B), its displacement read and the result written (2 x 24 B);
// neighbour displacements are counted once (they are the same array, reused from cache).
#include "support/BenchMain.hpp"

#include "core/BlockMesh.hpp"
#include "kernels/JacobiSmoothing.hpp"

#include <cstdint>

namespace {

void BM_JacobiSweep(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  auto mesh = mfsi::buildHexMesh(mfsi::generateBlockMesh(mfsi::boxSpec({0, 0, 0}, {1, 1, 1}, {n, n, n})));
  const mfsi::lid_t nn = mesh.nNodes();
  Kokkos::View<std::uint8_t*, mfsi::MemSpace> fixed("mfsi::perf::smoothing::fixed", nn);
  mfsi::SmoothingGraph g;
  g.offsets = mesh.nodeNodeOffsets();
  g.neighbours = mesh.nodeNodes();
  g.fixed = fixed;
  mfsi::Real3View a("mfsi::perf::smoothing::a", nn), b("mfsi::perf::smoothing::b", nn);
  Kokkos::deep_copy(a, 1.0);
  mfsi::ExecSpace exec;
  for (auto _ : state) {
    mfsi::jacobiSweep(exec, g, a, b);
    exec.fence();
  }
  const double entries = static_cast<double>(mesh.nodeNodes().extent(0));
  const double bytes = nn * (4.0 + 1.0 + 48.0) + entries * 4.0;
  mfsi::bench::setRates(state, bytes, nn, "nodes/s");
  state.counters["nodes"] = nn;
}

}  // namespace

BENCHMARK(mfsi::bench::streamTriad)->Arg(mfsi::bench::streamSize())->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_JacobiSweep)->Arg(mfsi::bench::tiny() ? 4 : 64)->Arg(mfsi::bench::tiny() ? 6 : 128)
    ->Unit(benchmark::kMillisecond)->UseRealTime();
