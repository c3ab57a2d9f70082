// Geometry kernel throughput next to a STREAM triad measured in the same run, same backend.
//
//   OMP_PROC_BIND=false OMP_NUM_THREADS=1 build/perf/bench_geometry
//   OMP_PROC_BIND=false OMP_NUM_THREADS=2 build/perf/bench_geometry
//   perf/run_geometry_bench.sh build     # both, medians of 5 repetitions, prints the RESULTS table
//
// "GB/s" is the compulsory traffic of the two geometry kernels (every node coordinate, cell and
// face connectivity read once per kernel, every result written once) divided by time: the
// bandwidth a perfectly cached kernel would need. The triad counts 3 x 8 bytes per element.
#include "support/BenchMain.hpp"

#include "core/BlockMesh.hpp"
#include "core/MeshGeometry.hpp"

namespace {

void BM_Geometry(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  auto mesh = mfsi::buildHexMesh(mfsi::generateBlockMesh(mfsi::boxSpec({0, 0, 0}, {1, 1, 1}, {n, n, n})));
  auto geo = mfsi::allocateGeometry(mesh);
  mfsi::ExecSpace exec;
  for (auto _ : state) {
    mfsi::computeGeometry(exec, mesh, geo);
    exec.fence();
  }
  const double cells = mesh.nCells(), faces = mesh.nFaces(), nodes = mesh.nNodes();
  // cells: 8 ids read (32 B) + volume and centroid written (32 B); faces: 4 ids (16 B) + area
  // vector, magnitude and centroid written (56 B); node coordinates read once per kernel (2 x 24 B).
  const double bytes = cells * 64.0 + faces * 72.0 + nodes * 48.0;
  mfsi::bench::setRates(state, bytes, cells, "cells/s");
  state.counters["cells"] = cells;
}

}  // namespace

BENCHMARK(mfsi::bench::streamTriad)->Arg(mfsi::bench::streamSize())->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Geometry)->Arg(mfsi::bench::tiny() ? 4 : 64)->Arg(mfsi::bench::tiny() ? 6 : 128)
    ->Unit(benchmark::kMillisecond)->UseRealTime();
