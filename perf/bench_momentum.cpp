// Momentum predictor solve: the three velocity components solved one after another (BiCGStab +
// Jacobi, as FluidSolver did) against the three-right-hand-side BiCGStab of one matrix
// (LinearSolver::solveMomentum3), both to OpenFOAM's scaled residual 1e-5 (icoFoam's setting).
//
//   OMP_PROC_BIND=false OMP_NUM_THREADS=1 build/perf/bench_momentum
//   OMP_PROC_BIND=false OMP_NUM_THREADS=2 build/perf/bench_momentum
//   OMP_PROC_BIND=false OMP_NUM_THREADS=2 build/perf/bench_momentum --benchmark_filter=Momentum
//       --benchmark_repetitions=5 --benchmark_report_aggregates_only=true   (one line)
//
// Matrix (N^3 cells of the unit box, default N = 64; 8 in tiny mode): implicit Euler + central
// ("Gauss linear") convection + diffusion, i.e. diagonal V/dt, 7-point diffusion nu A/h, and
// +-F/2 convection from the face fluxes F of a 3D vortex u = curl(psi(y,z), 0, psi(x,y)),
// psi(a,b) = sin(pi a) sin(pi b) / pi, integrated exactly over each face, so the discrete fluxes
// are divergence-free and vanish on the walls. nu = 0.01 (cell Peclet ~1.5 at N = 64), dt set for
// a maximum Courant number 0.3. Right-hand side (V/dt) U_old - V grad p with a Taylor-Green-like
// pressure, initial guess U_old: the residual a real predictor starts from.
//
// MomentumSeparate: per component, the copy-in kernel (b = rhs - V grad p, x = U) of FluidSolver,
// LinearSolver::solveMomentum, the copy-back kernel. MomentumFused3: one kernel forming b3, then
// LinearSolver::solveMomentum3 on U in place. Counters: its_x/y/z (iterations per component),
// res0 and res (largest initial / final scaled residual), cells/s (N^3 per momentum solve).
//
// KrylovSeparate / KrylovFused3: the Krylov solvers alone at a fixed 10 iterations (relTol 0), on
// the same matrix: BiCGStab + JacobiPreconditioner three times vs BiCGStab3 - the cost of one
// iteration for three components (s_per_it).
#include "support/BenchMain.hpp"

#include "fluid/LinearSolve.hpp"
#include "kernels/CsrBuild.hpp"
#include "kernels/Krylov.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <memory>
#include <vector>

namespace {

using mfsi::lid_t;
using Clock = std::chrono::steady_clock;

double seconds(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

struct MomentumModel {
  mfsi::CsrMatrix A;
  mfsi::Real3View U0, rhs, gradP;
  mfsi::RealView V;
};

/// The matrix and fields of the file comment, assembled on the host.
MomentumModel buildMomentumModel(lid_t N, double courant, double nu) {
  const double pi = 3.14159265358979323846;
  const double h = 1.0 / N, V = h * h * h, D = nu * h;
  auto psi = [&](double a, double b) { return std::sin(pi * a) * std::sin(pi * b) / pi; };
  const lid_t n = N * N * N, stride[3] = {1, N, N * N};
  auto cell = [&](lid_t i, lid_t j, lid_t k) { return i + N * (j + N * k); };
  // Flux through the +d face of cell (i, j, k) (its lower corner at (i, j, k) h), out of the cell.
  auto flux = [&](int d, lid_t i, lid_t j, lid_t k) {
    const double x = (i + (d == 0)) * h, y = (j + (d == 1)) * h, z = (k + (d == 2)) * h;
    if (d == 0) return h * (psi(x, y + h) - psi(x, y));
    if (d == 1) return h * (psi(y, z + h) - psi(y, z)) - h * (psi(x + h, y) - psi(x, y));
    return -h * (psi(y + h, z) - psi(y, z));
  };
  double maxOut = 0;
  for (lid_t k = 0; k < N; ++k)
    for (lid_t j = 0; j < N; ++j)
      for (lid_t i = 0; i < N; ++i) {
        double s = 0;
        const lid_t ijk[3] = {i, j, k};
        for (int d = 0; d < 3; ++d) {
          s += std::abs(flux(d, i, j, k));
          if (ijk[d] > 0) s += std::abs(flux(d, i - (d == 0), j - (d == 1), k - (d == 2)));
        }
        maxOut = std::max(maxOut, s);
      }
  const double dt = courant * V / (0.5 * maxOut);

  MomentumModel m;
  m.A = mfsi::buildPoisson7({N, N, N}, mfsi::ModelBoundary::Dirichlet, "mfsi::perf::momentum::A");
  auto rp0 = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), m.A.rowPtr);
  auto ci0 = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), m.A.colIdx);
  const std::vector<lid_t> rp(rp0.data(), rp0.data() + rp0.extent(0)), ci(ci0.data(), ci0.data() + ci0.extent(0));
  auto val = Kokkos::create_mirror_view(m.A.values);
  Kokkos::deep_copy(val, 0.0);
  for (lid_t c = 0; c < n; ++c) val(mfsi::findEntry(rp, ci, c, c)) = V / dt;
  for (lid_t k = 0; k < N; ++k)
    for (lid_t j = 0; j < N; ++j)
      for (lid_t i = 0; i < N; ++i) {
        const lid_t P = cell(i, j, k), ijk[3] = {i, j, k};
        for (int d = 0; d < 3; ++d) {
          if (ijk[d] == 0) val(mfsi::findEntry(rp, ci, P, P)) += 2 * D;  // wall at the -d side
          if (ijk[d] + 1 == N) {
            val(mfsi::findEntry(rp, ci, P, P)) += 2 * D;  // wall at the +d side
            continue;
          }
          const lid_t Q = P + stride[d];
          const double F = flux(d, i, j, k);
          val(mfsi::findEntry(rp, ci, P, P)) += 0.5 * F + D;
          val(mfsi::findEntry(rp, ci, P, Q)) += 0.5 * F - D;
          val(mfsi::findEntry(rp, ci, Q, Q)) += -0.5 * F + D;
          val(mfsi::findEntry(rp, ci, Q, P)) += -0.5 * F - D;
        }
      }
  Kokkos::deep_copy(m.A.values, val);

  m.U0 = mfsi::Real3View("mfsi::perf::momentum::U0", n);
  m.rhs = mfsi::Real3View("mfsi::perf::momentum::rhs", n);
  m.gradP = mfsi::Real3View("mfsi::perf::momentum::gradP", n);
  m.V = mfsi::RealView("mfsi::perf::momentum::V", n);
  auto U = Kokkos::create_mirror_view(m.U0);
  auto rhs = Kokkos::create_mirror_view(m.rhs);
  auto gp = Kokkos::create_mirror_view(m.gradP);
  auto hV = Kokkos::create_mirror_view(m.V);
  for (lid_t k = 0; k < N; ++k)
    for (lid_t j = 0; j < N; ++j)
      for (lid_t i = 0; i < N; ++i) {
        const lid_t c = cell(i, j, k);
        const double x = (i + 0.5) * h, y = (j + 0.5) * h, z = (k + 0.5) * h;
        U(c, 0) = std::sin(pi * x) * std::cos(pi * y);
        U(c, 1) = std::sin(pi * y) * std::cos(pi * z) - std::cos(pi * x) * std::sin(pi * y);
        U(c, 2) = -std::cos(pi * y) * std::sin(pi * z);
        // p = -(cos 2 pi x + cos 2 pi y + cos 2 pi z) / 4
        gp(c, 0) = 0.5 * pi * std::sin(2 * pi * x);
        gp(c, 1) = 0.5 * pi * std::sin(2 * pi * y);
        gp(c, 2) = 0.5 * pi * std::sin(2 * pi * z);
        for (int d = 0; d < 3; ++d) rhs(c, d) = V / dt * U(c, d);
        hV(c) = V;
      }
  Kokkos::deep_copy(m.U0, U);
  Kokkos::deep_copy(m.rhs, rhs);
  Kokkos::deep_copy(m.gradP, gp);
  Kokkos::deep_copy(m.V, hV);
  return m;
}

const lid_t kN = mfsi::bench::tiny() ? 8 : 64;
const mfsi::fluid::LinearSolverOptions kMomentumSolver{1e-5, 0.0, 1000};

/// Built once (the host assembly at 64^3 takes a while) and released before Kokkos finalises.
const MomentumModel& model() {
  static std::unique_ptr<MomentumModel> m;
  if (!m) {
    m = std::make_unique<MomentumModel>(buildMomentumModel(kN, 0.3, 0.01));
    Kokkos::push_finalize_hook([] { m.reset(); });
  }
  return *m;
}

void counters(benchmark::State& state, const std::array<mfsi::fluid::LinearSolveStats, 3>& st) {
  const char* names[3] = {"its_x", "its_y", "its_z"};
  double r0 = 0, r = 0;
  for (int d = 0; d < 3; ++d) {
    state.counters[names[d]] = st[d].iterations;
    r0 = std::max(r0, st[d].initialResidual);
    r = std::max(r, st[d].finalResidual);
  }
  state.counters["res0"] = r0;
  state.counters["res"] = r;
  state.counters["cells/s"] = benchmark::Counter(model().A.nRows, benchmark::Counter::kIsIterationInvariantRate);
}

void BM_MomentumSeparate(benchmark::State& state) {
  const auto& m = model();
  const lid_t n = m.A.nRows;
  mfsi::ExecSpace exec;
  mfsi::fluid::LinearSolver solver(n, mfsi::fluid::PressurePreconditioner::Jacobi);
  solver.momentumMatrixChanged(exec, m.A);
  mfsi::Real3View U("mfsi::perf::momentum::U", n);
  mfsi::RealView x("mfsi::perf::momentum::x", n), b("mfsi::perf::momentum::b", n);
  const mfsi::ConstReal3View rhs = m.rhs, gp = m.gradP;
  const mfsi::ConstRealView V = m.V;
  std::array<mfsi::fluid::LinearSolveStats, 3> st{};
  for (auto _ : state) {
    Kokkos::deep_copy(exec, U, m.U0);
    exec.fence();
    const auto t0 = Clock::now();
    for (int j = 0; j < 3; ++j) {
      Kokkos::parallel_for(
          "mfsi::perf::momentum::rhsComponent", mfsi::RangePolicy(exec, 0, n), KOKKOS_LAMBDA(lid_t c) {
            b(c) = rhs(c, j) - V(c) * gp(c, j);
            x(c) = U(c, j);
          });
      st[j] = solver.solveMomentum(exec, m.A, b, x, kMomentumSolver);
      Kokkos::parallel_for(
          "mfsi::perf::momentum::storeComponent", mfsi::RangePolicy(exec, 0, n),
          KOKKOS_LAMBDA(lid_t c) { U(c, j) = x(c); });
    }
    exec.fence();
    state.SetIterationTime(seconds(t0, Clock::now()));
  }
  counters(state, st);
}

void BM_MomentumFused3(benchmark::State& state) {
  const auto& m = model();
  const lid_t n = m.A.nRows;
  mfsi::ExecSpace exec;
  mfsi::fluid::LinearSolver solver(n, mfsi::fluid::PressurePreconditioner::Jacobi);
  solver.momentumMatrixChanged(exec, m.A);
  mfsi::Real3View U("mfsi::perf::momentum::U", n), b3("mfsi::perf::momentum::b3", n);
  const mfsi::ConstReal3View rhs = m.rhs, gp = m.gradP;
  const mfsi::ConstRealView V = m.V;
  std::array<mfsi::fluid::LinearSolveStats, 3> st{};
  for (auto _ : state) {
    Kokkos::deep_copy(exec, U, m.U0);
    exec.fence();
    const auto t0 = Clock::now();
    Kokkos::parallel_for(
        "mfsi::perf::momentum::rhs3", mfsi::RangePolicy(exec, 0, n), KOKKOS_LAMBDA(lid_t c) {
          for (int j = 0; j < 3; ++j) b3(c, j) = rhs(c, j) - V(c) * gp(c, j);
        });
    st = solver.solveMomentum3(exec, m.A, b3, U, kMomentumSolver);
    exec.fence();
    state.SetIterationTime(seconds(t0, Clock::now()));
  }
  counters(state, st);
}

constexpr int kFixedIterations = 10;

mfsi::KrylovOptions fixedIterations() {
  mfsi::KrylovOptions o;
  o.relTol = 0.0;
  o.maxIterations = kFixedIterations;
  return o;
}

/// b3 = rhs - V grad p on the device.
mfsi::Real3View momentumRhs(const MomentumModel& m) {
  mfsi::Real3View b3("mfsi::perf::momentum::b3", m.A.nRows);
  const mfsi::ConstReal3View rhs = m.rhs, gp = m.gradP;
  const mfsi::ConstRealView V = m.V;
  Kokkos::parallel_for(
      "mfsi::perf::momentum::rhs3", mfsi::RangePolicy(mfsi::ExecSpace(), 0, m.A.nRows), KOKKOS_LAMBDA(lid_t c) {
        for (int j = 0; j < 3; ++j) b3(c, j) = rhs(c, j) - V(c) * gp(c, j);
      });
  return b3;
}

void BM_KrylovSeparate(benchmark::State& state) {
  const auto& m = model();
  const lid_t n = m.A.nRows;
  mfsi::ExecSpace exec;
  mfsi::JacobiPreconditioner jacobi;
  jacobi.setup(exec, m.A);
  mfsi::BiCGStab solver(fixedIterations());
  const auto b3 = momentumRhs(m);
  std::array<mfsi::RealView, 3> b, x;
  for (int j = 0; j < 3; ++j) {
    b[j] = mfsi::RealView("mfsi::perf::momentum::b", n);
    x[j] = mfsi::RealView("mfsi::perf::momentum::x", n);
    Kokkos::deep_copy(b[j], Kokkos::subview(b3, Kokkos::ALL, j));
  }
  int its = 0;
  for (auto _ : state) {
    for (int j = 0; j < 3; ++j) Kokkos::deep_copy(exec, x[j], Kokkos::subview(m.U0, Kokkos::ALL, j));
    exec.fence();
    const auto t0 = Clock::now();
    its = 0;
    for (int j = 0; j < 3; ++j) its += solver.solve(exec, m.A, b[j], x[j], jacobi).iterations;
    exec.fence();
    state.SetIterationTime(seconds(t0, Clock::now()));
  }
  state.counters["its"] = its;
  state.counters["s_per_it"] =
      benchmark::Counter(kFixedIterations, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void BM_KrylovFused3(benchmark::State& state) {
  const auto& m = model();
  const lid_t n = m.A.nRows;
  mfsi::ExecSpace exec;
  mfsi::RealView invDiag("mfsi::perf::momentum::invDiag", n);
  mfsi::invertDiagonal(exec, m.A, invDiag);
  mfsi::BiCGStab3 solver(fixedIterations());
  const auto b3 = momentumRhs(m);
  mfsi::Real3View x("mfsi::perf::momentum::x3", n);
  int its = 0;
  for (auto _ : state) {
    Kokkos::deep_copy(exec, x, m.U0);
    exec.fence();
    const auto t0 = Clock::now();
    const auto res = solver.solve(exec, m.A, b3, x, invDiag);
    exec.fence();
    state.SetIterationTime(seconds(t0, Clock::now()));
    its = res[0].iterations + res[1].iterations + res[2].iterations;
  }
  state.counters["its"] = its;
  state.counters["s_per_it"] =
      benchmark::Counter(kFixedIterations, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

// On a shared machine the best of several repetitions is the meaningful time.
double minOf(const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); }

}  // namespace

BENCHMARK(mfsi::bench::streamTriad)
    ->Arg(mfsi::bench::streamSize())
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->ComputeStatistics("min", minOf);
BENCHMARK(BM_MomentumSeparate)->Unit(benchmark::kMillisecond)->UseManualTime()->ComputeStatistics("min", minOf);
BENCHMARK(BM_MomentumFused3)->Unit(benchmark::kMillisecond)->UseManualTime()->ComputeStatistics("min", minOf);
BENCHMARK(BM_KrylovSeparate)->Unit(benchmark::kMillisecond)->UseManualTime()->ComputeStatistics("min", minOf);
BENCHMARK(BM_KrylovFused3)->Unit(benchmark::kMillisecond)->UseManualTime()->ComputeStatistics("min", minOf);
