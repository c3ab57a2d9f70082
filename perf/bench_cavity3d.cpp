// 3D lid-driven cube cavity at Re = 100, timed the way perf/openfoam/cavity3d_timing.sh times
// OpenFOAM's icoFoam, so the two can be compared per cell and time step (perf/compare_openfoam.sh
// runs both back to back and writes perf/results/cavity3d_vs_openfoam.json).
//
//   OMP_PROC_BIND=spread OMP_PLACES=cores OMP_NUM_THREADS=1 build/perf/bench_cavity3d
//   OMP_PROC_BIND=spread OMP_PLACES=cores OMP_NUM_THREADS=2 build/perf/bench_cavity3d
//   MFSI_CAVITY3D_N=32 build/perf/bench_cavity3d --benchmark_filter='Cavity3d/.*/0'   # smaller, no profile
//
// Case (same as OpenFOAM's): unit cube, lid y = 1 moving at u = (1, 0, 0), other faces no-slip
// walls, nu = 0.01 (Re = 100), N^3 uniform hexes (MFSI_CAVITY3D_N, default 64), starting from rest,
// fixed dt = 0.32 / N, MFSI_CAVITY3D_STEPS steps (default 20). Steps 1..5 are not timed (start-up
// transient, first AMG hierarchy), steps 6..STEPS are: "s/cell-step" = time / ((STEPS - 5) N^3).
//
// Settings, chosen to be as close to icoFoam's as our solver allows:
//  - PISO: 1 outer iteration, momentum predictor, 2 pressure correctors, no non-orthogonal corrector;
//  - implicit Euler, central (Gauss linear) convection, Green-Gauss gradients;
//  - momentum: the three components in one BiCGStab3 + Jacobi solve, scaled residual 1e-5, relTol 0
//    (icoFoam: symGaussSeidel, 1e-5); every solve stops on OpenFOAM's scaled 1-norm residual;
//  - pressure: CG + smoothed-aggregation AMG, scaled residual 1e-6, relTol 0.05 on the first
//    corrector and 0 on the final one (pFinal), as icoFoam's GAMG settings. The AMG values are
//    refreshed at most every 50 pressure assemblies, earlier when the final solve slows down (a
//    stale hierarchy is still an SPD preconditioner); the V-cycle runs in float, with two
//    finest-level smoother applications in the first corrector's solve (the fluid's default,
//    solvers.pressure.finestSweeps).
//
// Second argument 1 = profile: Kokkos Tools region callbacks accumulate inclusive wall time per
// solver phase (fluid::momentum::assemble, ...::solve, fluid::pressure::assemble, ...::solve,
// kernels::amg::*) and report them as fractions of the timed steps. It is a separate run because
// any registered tool callback puts every kernel launch on Kokkos' profiling path.
// Second argument 2 = the same plus the wall time of every kernel per step, printed to stderr
// (exact on host backends, where a launch returns when the kernel is done).
#include "support/BenchMain.hpp"

#include "core/BlockMesh.hpp"
#include "core/Error.hpp"
#include "fluid/FluidSolver.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <map>
#include <string>
#include <vector>

namespace {

using namespace mfsi;
using namespace mfsi::fluid;
using Clock = std::chrono::steady_clock;

/// CPU time consumed so far by all threads of this process.
double processCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

constexpr int kUntimedSteps = 5;

int envInt(const char* name, int fallback) {
  const char* v = std::getenv(name);
  return v != nullptr ? std::atoi(v) : fallback;
}

/// Inclusive wall time per Kokkos region name, from the push/pop region callbacks.
struct RegionTimes {
  static std::map<std::string, double>& total() {
    static std::map<std::string, double> t;
    return t;
  }
  static std::vector<std::pair<std::string, Clock::time_point>>& stack() {
    static std::vector<std::pair<std::string, Clock::time_point>> s;
    return s;
  }
  static void push(const char* name) { stack().emplace_back(name, Clock::now()); }
  static void pop() {
    auto& s = stack();
    if (s.empty()) return;
    total()[s.back().first] += std::chrono::duration<double>(Clock::now() - s.back().second).count();
    s.pop_back();
  }
  static void start() {
    total().clear();
    stack().clear();
    Kokkos::Tools::Experimental::set_push_region_callback(&push);
    Kokkos::Tools::Experimental::set_pop_region_callback(&pop);
  }
  static void stop() {
    Kokkos::Tools::Experimental::set_push_region_callback(nullptr);
    Kokkos::Tools::Experimental::set_pop_region_callback(nullptr);
  }
  /// Per-kernel times (profile mode 2). On host backends a kernel launch is synchronous, so the
  /// begin/end callbacks bracket its execution.
  static std::map<std::string, std::pair<double, long>>& kernels() {
    static std::map<std::string, std::pair<double, long>> k;
    return k;
  }
  static std::vector<std::pair<std::string, Clock::time_point>>& open() {
    static std::vector<std::pair<std::string, Clock::time_point>> o;
    return o;
  }
  static void beginKernel(const char* name, uint32_t, uint64_t* id) {
    *id = open().size();
    open().emplace_back(name, Clock::now());
  }
  static void endKernel(uint64_t id) {
    auto& e = kernels()[open()[id].first];
    e.first += std::chrono::duration<double>(Clock::now() - open()[id].second).count();
    ++e.second;
    open().resize(id);
  }
  static void startKernels() {
    kernels().clear();
    open().clear();
    Kokkos::Tools::Experimental::set_begin_parallel_for_callback(&beginKernel);
    Kokkos::Tools::Experimental::set_end_parallel_for_callback(&endKernel);
    Kokkos::Tools::Experimental::set_begin_parallel_reduce_callback(&beginKernel);
    Kokkos::Tools::Experimental::set_end_parallel_reduce_callback(&endKernel);
    Kokkos::Tools::Experimental::set_begin_parallel_scan_callback(&beginKernel);
    Kokkos::Tools::Experimental::set_end_parallel_scan_callback(&endKernel);
  }
  static void stopKernels(double total, int steps) {
    Kokkos::Tools::Experimental::set_begin_parallel_for_callback(nullptr);
    Kokkos::Tools::Experimental::set_end_parallel_for_callback(nullptr);
    Kokkos::Tools::Experimental::set_begin_parallel_reduce_callback(nullptr);
    Kokkos::Tools::Experimental::set_end_parallel_reduce_callback(nullptr);
    Kokkos::Tools::Experimental::set_begin_parallel_scan_callback(nullptr);
    Kokkos::Tools::Experimental::set_end_parallel_scan_callback(nullptr);
    std::vector<std::pair<double, std::string>> rows;
    double sum = 0;
    for (const auto& [name, e] : kernels()) {
      rows.emplace_back(e.first, name + " (" + std::to_string(e.second / steps) + "/step)");
      sum += e.first;
    }
    std::sort(rows.rbegin(), rows.rend());
    std::fprintf(stderr, "kernels: %.1f%% of the timed wall time; per step:\n", 100.0 * sum / total);
    for (const auto& [t, name] : rows)
      if (t > 0.002 * total) std::fprintf(stderr, "  %8.2f ms  %5.1f%%  %s\n", 1e3 * t / steps, 100.0 * t / total, name.c_str());
  }
  static double get(const std::string& name) {
    auto it = total().find(name);
    return it == total().end() ? 0.0 : it->second;
  }
};

FluidOptions cavityOptions() {
  FluidOptions o;
  o.density = 1.0;
  o.viscosity = 0.01;  // Re = U L / nu = 100
  o.timeScheme = TimeScheme::Euler;
  o.convection = ConvectionScheme::Linear;
  o.gradient = GradientScheme::GaussLinear;
  o.pimple.nOuterCorrectors = 1;
  o.pimple.nCorrectors = 2;
  o.pimple.nNonOrthogonalCorrectors = 0;
  o.pimple.momentumPredictor = true;
  o.momentumSolver = {1e-5, 0.0, 1000};
  o.pressureSolver = {1e-6, 0.05, 1000};  // as icoFoam's p: relTol 0.05 on the first corrector
  o.pressureFinalRelTol = 0.0;              // and pFinal: relTol 0
  o.pressurePreconditioner = PressurePreconditioner::Amg;
  PatchBC lid;
  lid.type = BoundaryType::Wall;
  lid.velocity = {1, 0, 0};
  o.boundaries["lid"] = lid;
  return o;
}

void BM_Cavity3d(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const bool profile = state.range(1) != 0;
  const int steps = mfsi::bench::tiny() ? kUntimedSteps + 2 : envInt("MFSI_CAVITY3D_STEPS", 20);
  MFSI_CHECK(steps > kUntimedSteps, "MFSI_CAVITY3D_STEPS must exceed " + std::to_string(kUntimedSteps));
  auto spec = boxSpec({0, 0, 0}, {1, 1, 1}, {n, n, n});
  spec.blocks[0].patches = {"walls", "walls", "walls", "lid", "walls", "walls"};
  spec.patchKinds = {{"walls", PatchKind::Wall}, {"lid", PatchKind::Wall}};
  const HexMesh mesh = buildHexMesh(generateBlockMesh(spec));
  const FluidOptions o = cavityOptions();
  const double dt = 0.32 / n;  // lid Courant number 0.32, as in the OpenFOAM case
  const double cells = mesh.nCells();
  const int timed = steps - kUntimedSteps;

  double seconds = 0, cpuSeconds = 0, pIters = 0, uIters = 0, contMax = 0;
  bool ok = true;
  for (auto _ : state) {
    // A fresh solver per iteration: every iteration is the same 20-step run from rest.
    FluidSolver fluid(mesh, o);
    for (int s = 0; s < kUntimedSteps; ++s) ok = fluid.solveStep(s * dt, dt).ok && ok;
    if (profile) RegionTimes::start();
    if (state.range(1) == 2) RegionTimes::startKernels();
    Kokkos::fence();
    const double c0 = processCpuSeconds();
    const auto t0 = Clock::now();
    int pi = 0, ui = 0;
    for (int s = kUntimedSteps; s < steps; ++s) {
      const auto r = fluid.solveStep(s * dt, dt);  // ends with a fence
      ok = r.ok && ok;
      pi += r.pressureIterations;
      ui += r.momentumIterations;
      contMax = r.continuityMax;
    }
    Kokkos::fence();
    const double t = std::chrono::duration<double>(Clock::now() - t0).count();
    cpuSeconds += processCpuSeconds() - c0;
    if (profile) RegionTimes::stop();
    if (state.range(1) == 2) RegionTimes::stopKernels(t, timed);
    state.SetIterationTime(t);
    seconds += t;
    pIters += pi;
    uIters += ui;
  }
  if (!ok) state.SkipWithError("solver reported a NaN or a linear-solver breakdown");
  const double runs = static_cast<double>(state.iterations());
  state.counters["s_per_cell_step"] = seconds / (runs * timed * cells);
  state.counters["s_per_step"] = seconds / (runs * timed);
  // CPU seconds of all threads per step: on a shared machine, unlike the wall time, not inflated
  // by time the threads wait for a core (a cross-check of s_per_step x threads, never reported
  // as the speed).
  state.counters["cpu_s_per_step"] = cpuSeconds / (runs * timed);
  // Summed over the 2 correctors, and over the 3 velocity components for momentum.
  state.counters["p_iters_per_step"] = pIters / (runs * timed);
  state.counters["u_iters_per_step"] = uIters / (runs * timed);
  state.counters["continuity_max"] = contMax;
  state.counters["cells"] = cells;
  state.counters["timed_steps"] = timed;
  state.counters["dt"] = dt;
  if (profile) {
    // Fractions of the timed wall time of the last iteration (the region totals are reset per run).
    const double total = state.iterations() > 0 ? seconds / runs : 1.0;
    const double mAsm = RegionTimes::get("mfsi::fluid::momentum::assemble");
    const double mSol = RegionTimes::get("mfsi::fluid::momentum::solve");
    const double pAsm = RegionTimes::get("mfsi::fluid::pressure::assemble");
    const double pSol = RegionTimes::get("mfsi::fluid::pressure::solve");
    const double amgSetup = RegionTimes::get("mfsi::kernels::amg::setup");
    const double amgUpdate =
        RegionTimes::get("mfsi::kernels::amg::updateValues") + RegionTimes::get("mfsi::kernels::amg::updateFinestSmoother");
    const double cg = RegionTimes::get("mfsi::kernels::krylov::cg");
    const double correct = RegionTimes::get("mfsi::fluid::correct");
    state.counters["f_momentum_assemble"] = mAsm / total;
    state.counters["f_momentum_solve"] = mSol / total;
    state.counters["f_pressure_assemble"] = pAsm / total;
    state.counters["f_pressure_solve"] = pSol / total;
    state.counters["f_pressure_cg"] = cg / total;
    state.counters["f_amg_setup"] = amgSetup / total;
    state.counters["f_amg_update"] = amgUpdate / total;
    state.counters["f_correct"] = correct / total;
    state.counters["f_other"] = 1.0 - (mAsm + mSol + pAsm + pSol + correct) / total;
  }
}

const int kN = mfsi::bench::tiny() ? 4 : envInt("MFSI_CAVITY3D_N", 64);

}  // namespace

BENCHMARK(BM_Cavity3d)
    ->Args({kN, 0})
    ->Args({kN, 1})
    ->Args({kN, 2})
    ->ArgNames({"N", "profile"})
    ->Iterations(1)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);
