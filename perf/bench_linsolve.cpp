// Linear-solver kernels and pressure-solver iteration counts, next to a STREAM triad measured in
// the same run and backend (so kernel bandwidths can be quoted as a fraction of STREAM).
//
//   OMP_PROC_BIND=false OMP_NUM_THREADS=2 build/perf/bench_linsolve
//   OMP_PROC_BIND=false OMP_NUM_THREADS=2 build/perf/bench_linsolve --benchmark_filter='Stream|Spmv|Dot'
//   OMP_PROC_BIND=false OMP_NUM_THREADS=2 build/perf/bench_linsolve --benchmark_filter=PressureSolve
//
// Kernels (3D 7-point Poisson matrix, 64^3 cells): "GB/s" is compulsory traffic over time - the
// matrix (8 B value + 4 B column per entry, 4 B per row pointer; SpMV sweeps row runs on host
// backends and reads no column index: 8 B per entry), x read once, y written once (no
// write-allocate, as STREAM counts it) - i.e. what a perfectly cached kernel needs.
//
// SpmvDot/N/lattice: CG's fused q = A p with p.q on the N^3 Dirichlet Poisson matrix, CSR
// (blas::spmvDot) vs the symmetric lattice copy (SymmetricLatticeMatrix); counter update_s: one
// refresh of the copy (ConjugateGradient::matrixChanged). Compare in one run:
//   OMP_PROC_BIND=spread OMP_PLACES=cores OMP_NUM_THREADS=1 build/perf/bench_linsolve
//     --benchmark_filter='SpmvDot' --benchmark_repetitions=5
//
// PressureSolve/N/P/M: CG to 1e-8 relative on the Dirichlet Poisson matrix of N^3 cells with a rough
// right-hand side; P = 0 Jacobi, 1 smoothed-aggregation AMG; M = 0 AMG V-cycle in double, 1 in mixed
// precision (float cycle, AmgPrecision::Mixed). Compare the two AMG variants in one run:
//   OMP_PROC_BIND=spread OMP_PLACES=cores OMP_NUM_THREADS=1 build/perf/bench_linsolve
//     --benchmark_filter='PressureSolve/N:(64|128)/amg:1' --benchmark_repetitions=5
// Counters: its (CG iterations), setup_s (preconditioner set-up), update_s (AMG value update on
// the same sparsity), s_per_it (mean over the solves), min_s_per_it (fastest solve), rel_res
// (final/initial residual). Jacobi-CG is capped at 1500 iterations and solves once per
// repetition; AMG solves 5 times after one set-up (the benchmark time is a solve's mean).
#include "support/BenchMain.hpp"

#include "kernels/Amg.hpp"
#include "kernels/CsrBuild.hpp"
#include "kernels/Krylov.hpp"
#include "kernels/LatticeMatrix.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;

double seconds(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

/// Compulsory matrix traffic of a kernel that reads CSR rows: 8 B value + 4 B column per entry and
/// 4 B per row pointer. Kernels that sweep the matrix's row runs (host backends; blas::spmv,
/// spmvDot, BiCGStab3) read no column index and one row pointer per run (`runs`).
double matrixBytes(const mfsi::CsrMatrix& A, bool runs = false) {
  if (runs && mfsi::kHostExec && A.runs.count > 0) return 8.0 * A.nnz() + 12.0 * A.runs.count;
  return 12.0 * A.nnz() + 4.0 * (A.nRows + 1);
}

void BM_Spmv(benchmark::State& state) {
  const mfsi::lid_t n = static_cast<mfsi::lid_t>(state.range(0));
  const auto A = mfsi::buildPoisson7({n, n, n}, mfsi::ModelBoundary::Dirichlet);
  mfsi::RealView x("mfsi::perf::linsolve::x", A.nRows), y("mfsi::perf::linsolve::y", A.nRows);
  Kokkos::deep_copy(x, 1.0);
  mfsi::ExecSpace exec;
  for (auto _ : state) {
    exec.fence();
    const auto t0 = Clock::now();
    mfsi::blas::spmv(exec, A, x, y);
    exec.fence();
    state.SetIterationTime(seconds(t0, Clock::now()));
  }
  mfsi::bench::setRates(state, matrixBytes(A, /*runs=*/true) + 16.0 * A.nRows, A.nRows, "rows/s");
  state.counters["nnz"] = A.nnz();
  state.counters["runs"] = A.runs.count;
}

void BM_ResidualDot(benchmark::State& state) {
  // Fused r = b - A x and r.r: one extra vector read (b) over the SpMV.
  const mfsi::lid_t n = static_cast<mfsi::lid_t>(state.range(0));
  const auto A = mfsi::buildPoisson7({n, n, n}, mfsi::ModelBoundary::Dirichlet);
  mfsi::RealView x("mfsi::perf::linsolve::x", A.nRows), b("mfsi::perf::linsolve::b", A.nRows),
      r("mfsi::perf::linsolve::r", A.nRows);
  Kokkos::deep_copy(x, 1.0);
  Kokkos::deep_copy(b, 2.0);
  mfsi::ExecSpace exec;
  const mfsi::SolverComm comm;
  double rr = 0;
  for (auto _ : state) {
    exec.fence();
    const auto t0 = Clock::now();
    rr = mfsi::blas::residual(exec, comm, A, x, b, r);  // returns on the host: includes the fence
    state.SetIterationTime(seconds(t0, Clock::now()));
  }
  benchmark::DoNotOptimize(rr);
  mfsi::bench::setRates(state, matrixBytes(A) + 24.0 * A.nRows, A.nRows, "rows/s");
}

/// CG's fused q = A p with p.q: the CSR kernel (blas::spmvDot, row runs on host backends) vs the
/// symmetric lattice copy ConjugateGradient takes after matrixChanged (SymmetricLatticeMatrix).
/// GB/s: matrix (CSR row runs: 8 B per entry; lattice: 32 B per row) + p read + q written.
void BM_SpmvDot(benchmark::State& state) {
  const mfsi::lid_t n = static_cast<mfsi::lid_t>(state.range(0));
  const bool lattice = state.range(1) == 1;
  const auto A = mfsi::buildPoisson7({n, n, n}, mfsi::ModelBoundary::Dirichlet);
  mfsi::RealView p("mfsi::perf::linsolve::p", A.nRows), q("mfsi::perf::linsolve::q", A.nRows);
  {
    auto h = Kokkos::create_mirror_view(p);
    for (mfsi::lid_t i = 0; i < A.nRows; ++i) h(i) = std::sin(0.7 * i) + 0.3;
    Kokkos::deep_copy(p, h);
  }
  mfsi::ExecSpace exec;
  const mfsi::SolverComm comm;
  mfsi::SymmetricLatticeMatrix L;
  if (lattice && !L.update(exec, A)) {
    state.SkipWithError("not a symmetric lattice matrix");
    return;
  }
  double pq = 0;
  for (auto _ : state) {
    exec.fence();
    const auto t0 = Clock::now();
    pq = lattice ? L.spmvDot(exec, comm, p, q, p) : mfsi::blas::spmvDot(exec, comm, A, p, q, p);
    state.SetIterationTime(seconds(t0, Clock::now()));
  }
  benchmark::DoNotOptimize(pq);
  const double bytes = (lattice ? 32.0 * A.nRows : matrixBytes(A, /*runs=*/true)) + 16.0 * A.nRows;
  mfsi::bench::setRates(state, bytes, A.nRows, "rows/s");
  // One refresh of the copy (what matrixChanged costs per new set of values).
  if (lattice) {
    exec.fence();
    const auto t0 = Clock::now();
    L.update(exec, A);
    exec.fence();
    state.counters["update_s"] = seconds(t0, Clock::now());
  }
}

void BM_Dot(benchmark::State& state) {
  const mfsi::lid_t n = static_cast<mfsi::lid_t>(state.range(0));
  const mfsi::lid_t rows = n * n * n;
  mfsi::RealView x("mfsi::perf::linsolve::x", rows), y("mfsi::perf::linsolve::y", rows);
  Kokkos::deep_copy(x, 1.0);
  Kokkos::deep_copy(y, 0.5);
  mfsi::ExecSpace exec;
  const mfsi::SolverComm comm;
  double d = 0;
  for (auto _ : state) {
    exec.fence();
    const auto t0 = Clock::now();
    d = mfsi::blas::dot(exec, comm, rows, x, y);
    state.SetIterationTime(seconds(t0, Clock::now()));
  }
  benchmark::DoNotOptimize(d);
  mfsi::bench::setRates(state, 16.0 * rows, rows, "rows/s");
}

void BM_PressureSolve(benchmark::State& state) {
  const mfsi::lid_t n = static_cast<mfsi::lid_t>(state.range(0));
  const bool amg = state.range(1) == 1;
  const bool mixed = state.range(2) == 1;
  const auto A = mfsi::buildPoisson7({n, n, n}, mfsi::ModelBoundary::Dirichlet);
  mfsi::RealView b("mfsi::perf::linsolve::b", A.nRows), x("mfsi::perf::linsolve::x", A.nRows);
  {
    auto h = Kokkos::create_mirror_view(b);
    for (mfsi::lid_t i = 0; i < A.nRows; ++i) h(i) = std::sin(0.7 * i) + std::cos(0.013 * i * i) + 0.3;
    Kokkos::deep_copy(b, h);
  }
  mfsi::ExecSpace exec;
  std::unique_ptr<mfsi::Preconditioner> M;
  if (amg) {
    mfsi::AmgOptions o;
    o.precision = mixed ? mfsi::AmgPrecision::Mixed : mfsi::AmgPrecision::Double;
    M = std::make_unique<mfsi::AmgPreconditioner>(o);
  } else {
    M = std::make_unique<mfsi::JacobiPreconditioner>();
  }
  exec.fence();
  auto t0 = Clock::now();
  M->setup(exec, A);
  exec.fence();
  const double setup = seconds(t0, Clock::now());
  t0 = Clock::now();
  M->updateValues(exec, A);
  exec.fence();
  const double update = seconds(t0, Clock::now());

  mfsi::KrylovOptions opt;
  opt.relTol = 1e-8;
  opt.maxIterations = 1500;
  mfsi::ConjugateGradient cg(opt);
  mfsi::KrylovResult res;
  double best = 1e30;
  for (auto _ : state) {
    Kokkos::deep_copy(x, 0.0);
    exec.fence();
    const auto t1 = Clock::now();
    res = cg.solve(exec, A, b, x, *M);
    exec.fence();
    const double t = seconds(t1, Clock::now());
    best = std::min(best, t);
    state.SetIterationTime(t);
  }
  state.counters["its"] = res.iterations;
  state.counters["converged"] = res.converged ? 1 : 0;
  state.counters["rel_res"] = res.finalResidual / res.initialResidual;
  state.counters["setup_s"] = setup;
  state.counters["update_s"] = update;
  state.counters["s_per_it"] =
      benchmark::Counter(res.iterations > 0 ? res.iterations : 1,
                         benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["min_s_per_it"] = best / std::max(res.iterations, 1);
  state.counters["rows"] = A.nRows;
  if (amg) {
    const auto info = static_cast<mfsi::AmgPreconditioner&>(*M).info();
    state.counters["levels"] = static_cast<double>(info.levels.size());
    state.counters["op_complexity"] = info.operatorComplexity;
  }
}

const int kSmall = mfsi::bench::tiny() ? 8 : 64;
const int kLarge = mfsi::bench::tiny() ? 10 : 128;

// On a shared machine the best of several repetitions is the meaningful number: report min and
// max beside Google Benchmark's mean/median (apply them to time and to GB/s respectively).
double minOf(const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); }
double maxOf(const std::vector<double>& v) { return *std::max_element(v.begin(), v.end()); }

std::vector<int64_t> pressureSizes() {
  return mfsi::bench::tiny() ? std::vector<int64_t>{8} : std::vector<int64_t>{32, 64, 128};
}
void jacobiArgs(benchmark::internal::Benchmark* b) {
  for (int64_t n : pressureSizes()) b->Args({n, 0, 0});
}
void amgArgs(benchmark::internal::Benchmark* b) {
  for (int64_t n : pressureSizes()) {
    b->Args({n, 1, 0});  // double V-cycle
    b->Args({n, 1, 1});  // mixed-precision V-cycle
  }
}

}  // namespace

BENCHMARK(mfsi::bench::streamTriad)
    ->Arg(mfsi::bench::streamSize())
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->ComputeStatistics("min", minOf)
    ->ComputeStatistics("max", maxOf);
// 64^3: the matrix (27 MB with the vectors) mostly fits a 32 MB L3; 128^3 (216 MB) is DRAM-bound.
BENCHMARK(BM_Spmv)
    ->Arg(kSmall)
    ->Arg(kLarge)
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime()
    ->ComputeStatistics("min", minOf)
    ->ComputeStatistics("max", maxOf);
BENCHMARK(BM_ResidualDot)
    ->Arg(kSmall)
    ->Arg(kLarge)
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime()
    ->ComputeStatistics("min", minOf)
    ->ComputeStatistics("max", maxOf);
BENCHMARK(BM_SpmvDot)
    ->ArgsProduct({{kSmall, kLarge}, {0, 1}})
    ->ArgNames({"N", "lattice"})
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime()
    ->ComputeStatistics("min", minOf)
    ->ComputeStatistics("max", maxOf);
BENCHMARK(BM_Dot)
    ->Arg(kSmall)
    ->Arg(kLarge)
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime()
    ->ComputeStatistics("min", minOf)
    ->ComputeStatistics("max", maxOf);
BENCHMARK(BM_PressureSolve)
    ->Apply(jacobiArgs)
    ->ArgNames({"N", "amg", "mixed"})
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime();
// AMG: several solves after one set-up (the time is their mean; min_s_per_it the fastest).
BENCHMARK(BM_PressureSolve)
    ->Apply(amgArgs)
    ->ArgNames({"N", "amg", "mixed"})
    ->Iterations(mfsi::bench::tiny() ? 1 : 5)
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime();
