// Membrane solver performance: Hencky's problem solved by the lumped Newton-Raphson (seed) and by
// the consistent-tangent Newton at tolerances 1e-4, 1e-6, 1e-8 (iterations, CG iterations, wall
// time, error against the exact centre deflection), and the element-loop kernels' throughput
// next to a STREAM triad measured in the same run.
//
//   OMP_PROC_BIND=false OMP_NUM_THREADS=2 build/perf/bench_membrane
//   OMP_PROC_BIND=false OMP_NUM_THREADS=2 build/perf/bench_membrane --benchmark_filter=Kernel
//
// "GB/s" of a kernel is its compulsory traffic divided by time: every input read once (element
// connectivity, the per-Gauss-point reference data, four nodes' reference position and
// displacement, their pressure) and every output written once; the traffic of a perfectly cached
// kernel. Residual: 16 + 288 + 192 + 32 reads, 192 writes = 720 B/element. Tangent: 528 reads +
// 1152 writes = 1680 B/element. Gather of the element matrices into CSR: per row the 12 x 12 block
// values of its node's elements (~ 4 x 12 x 8 B) + the CSR row written, per matrix entry ~ 16 B.
#include "support/BenchMain.hpp"

#include "structure/membrane/MembraneSolver.hpp"

#include <cmath>

namespace {

using namespace mfsi;

MembraneMesh discMesh(int n) {
  MembraneDiscSpec d;
  d.nCore = n;
  d.nRing = n;
  return buildMembraneMesh(generateDiscMesh(d));
}

/// Hencky: args {solver (0 lumped, 1 Newton), -log10(tolerance), mesh n}.
void BM_Hencky(benchmark::State& state) {
  const bool newton = state.range(0) == 1;
  const double tol = std::pow(10.0, -static_cast<double>(state.range(1)));
  const MembraneMesh mesh = discMesh(static_cast<int>(state.range(2)));
  MembraneOptions opt;
  opt.material = {1e9, 0.3, 1e-3, 0, 0};
  opt.solver = newton ? MembraneStaticSolver::Newton : MembraneStaticSolver::LumpedNewtonRaphson;
  opt.tolerance = tol;
  opt.lumped.maxIterations = mfsi::bench::tiny() ? 500 : 400000;
  MembraneBoundary bc;
  bc.clamps.push_back({mesh.nodeSet("boundary"), {}, {}});
  MembraneLoads loads;
  const double load = 1e-5;
  loads.pressure = load * 1e6;
  MembraneSolveReport rep;
  double w0 = 0;
  for (auto _ : state) {
    MembraneSolver s(mesh, opt, bc, loads);
    rep = s.solveStatic();
    w0 = s.summary().at("centreDeflection");
    state.SetIterationTime(rep.seconds);
  }
  const double exact = 0.6535 * std::cbrt(load);
  state.counters["elements"] = mesh.nElements();
  state.counters["iterations"] = rep.iterations;
  state.counters["cgIterations"] = rep.linearIterations;
  state.counters["converged"] = rep.converged ? 1 : 0;
  state.counters["relResidual"] = rep.relativeResidual;
  state.counters["w0RelErr"] = std::abs(w0 - exact) / exact;
  state.SetLabel(newton ? "newton" : "lumpedNR");
}

/// Element kernels: arg {kernel (0 residual, 1 tangent, 2 gather matrices), mesh n}.
void BM_Kernel(benchmark::State& state) {
  const int kind = static_cast<int>(state.range(0));
  const MembraneMesh mesh = discMesh(static_cast<int>(state.range(1)));
  MembraneOptions opt;
  opt.material = {1e9, 0.3, 1e-3, 0, 10};
  ExecSpace exec;
  const MembraneReferenceGeometry geo = computeMembraneReferenceGeometry(exec, mesh);
  const MembraneElementData data = makeMembraneElementData(mesh, geo, opt);
  const lid_t nE = mesh.nElements(), n3 = 3 * mesh.nNodes();
  RealView u("u", n3), p("p", mesh.nNodes());
  Kokkos::deep_copy(u, 1e-3);
  Kokkos::deep_copy(p, 100.0);
  MembranePressureKernel pr;
  pr.nodePressure = p;
  const MembraneLineItems lines{};
  ItemValuesView vec("vec", nE, kMembraneItemDofs), ext("ext", nE, kMembraneItemDofs);
  ItemValuesView mat("mat", nE, kMembraneItemMatrix);
  const CsrAssemblyMap map = buildCsrAssemblyMap(mesh.hostElements(), mesh.nNodes(), 3, "bench::membrane");
  CsrMatrix K = makeMatrix(map, "bench::membrane::K");
  if (kind == 2) membraneTangentItems(exec, data, pr, lines, u, mat);
  exec.fence();
  for (auto _ : state) {
    if (kind == 0)
      membraneResidualItems(exec, data, pr, lines, u, vec, ext);
    else if (kind == 1)
      membraneTangentItems(exec, data, pr, lines, u, mat);
    else
      gatherItemMatrices(exec, map, mat, K);
    exec.fence();
  }
  double bytes = 0;
  if (kind == 0) bytes = 720.0 * nE;
  if (kind == 1) bytes = 1680.0 * nE;
  if (kind == 2) bytes = 144.0 * 8 * nE + 16.0 * K.nnz();
  mfsi::bench::setRates(state, bytes, nE, "elements/s");
  state.counters["elements"] = nE;
  state.SetLabel(kind == 0 ? "residual" : kind == 1 ? "tangent" : "gatherMatrices");
}

void henckyArgs(benchmark::internal::Benchmark* b) {
  const int n = mfsi::bench::tiny() ? 4 : 8;
  for (int tol : {4, 6, 8})
    for (int solver : {0, 1}) b->Args({solver, tol, n});
}

void kernelArgs(benchmark::internal::Benchmark* b) {
  for (int kind : {0, 1, 2})
    for (int n : mfsi::bench::tiny() ? std::vector<int>{4} : std::vector<int>{32, 96}) b->Args({kind, n});
}

}  // namespace

BENCHMARK(mfsi::bench::streamTriad)->Arg(mfsi::bench::streamSize())->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Hencky)->Apply(henckyArgs)->UseManualTime()->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Kernel)->Apply(kernelArgs)->Unit(benchmark::kMicrosecond)->UseRealTime();
