// Extrapolated initial guesses (PimpleOptions::extrapolateGuess): they only move where the linear
// solves start, so a transient cavity gives the same fields (to the solvers' tolerances) with
// fewer momentum and pressure iterations; and repeated solves of one step (FSI coupling
// iterations) start from the last iterate, not from a new extrapolation.
#include "fluid/FluidSolver.hpp"
#include "support/FluidCases.hpp"
#include "support/HostVectors.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

using namespace mfsi;
using namespace mfsi::fluid;

namespace {

constexpr double kDt = 0.005;

FluidOptions cavityOptions(bool extrapolate) {
  FluidOptions o;
  o.viscosity = 0.01;
  o.timeScheme = TimeScheme::BDF2;
  o.pimple.nCorrectors = 2;
  o.pimple.extrapolateGuess = extrapolate;
  // OpenFOAM's cavity tolerances (scaled residuals), as in perf/bench_cavity3d.
  o.pressureSolver = {1e-6, 0.05, 500};
  o.pressureFinalRelTol = 0.0;
  o.momentumSolver = {1e-5, 0.0, 500};
  o.boundaries["lid"].type = BoundaryType::Wall;
  o.boundaries["lid"].velocity = {1, 0, 0};
  return o;
}

struct Outcome {
  std::array<test::HostVec, 3> U;
  test::HostVec p;
  int momentumIterations = 0;
  int pressureIterations = 0;
};

Outcome run(const HexMesh& mesh, bool extrapolate, int steps, bool project = true) {
  FluidOptions o = cavityOptions(extrapolate);
  o.pimple.projectFinalGuess = project;
  FluidSolver fluid(mesh, o);
  Outcome out;
  for (int s = 0; s < steps; ++s) {
    const auto r = fluid.solveStep(s * kDt, kDt);
    EXPECT_TRUE(r.ok) << "step " << s;
    out.momentumIterations += r.momentumIterations;
    out.pressureIterations += r.pressureIterations;
  }
  for (int c = 0; c < 3; ++c) out.U[c] = test::column(fluid.velocity(), c);
  out.p = test::host(fluid.pressure());
  return out;
}

}  // namespace

TEST(InitialGuess, SameFieldsWithFewerIterations) {
  const HexMesh mesh = test::cubeCavityMesh(12);
  const Outcome off = run(mesh, false, 20), on = run(mesh, true, 20);
  double du = 0;
  for (int c = 0; c < 3; ++c) du = std::max(du, test::relDiff(on.U[c], off.U[c]));
  const double dp = test::relDiff(on.p, off.p);
  std::printf("[ guess    ] 20 steps: momentum its %d -> %d, pressure its %d -> %d; max rel diff U %.2e p %.2e\n",
              off.momentumIterations, on.momentumIterations, off.pressureIterations, on.pressureIterations, du, dp);
  // Both runs meet the same tolerances (momentum 1e-5 on the scaled residual): they differ by
  // about that much (measured 6.6e-6 / 5.6e-9), far below the discretisation error. Iterations
  // measured: momentum 78 -> 60, pressure 103 -> 88.
  EXPECT_LE(du, 5e-5);
  EXPECT_LE(dp, 1e-6);
  EXPECT_LE(on.momentumIterations, 0.85 * off.momentumIterations);
  EXPECT_LE(on.pressureIterations, 0.95 * off.pressureIterations);
}

TEST(InitialGuess, RepeatedSolvesOfOneStepStartFromTheLastIterate) {
  // A second solve() of the same step (an FSI coupling iteration with unchanged boundaries) starts
  // from the first solve's velocity, not from a new extrapolation.
  const HexMesh mesh = test::cubeCavityMesh(12);
  FluidSolver fluid(mesh, cavityOptions(true));
  for (int s = 0; s < 4; ++s) ASSERT_TRUE(fluid.solveStep(s * kDt, kDt).ok);
  fluid.beginStep(4 * kDt, kDt);
  const auto first = fluid.solve();
  const auto second = fluid.solve();
  ASSERT_TRUE(first.ok && second.ok);
  std::printf("[ guess    ] same step solved twice: momentum its %d then %d, initial residual %.3e then %.3e\n",
              first.momentumIterations, second.momentumIterations, first.momentumResidual, second.momentumResidual);
  // Re-extrapolating would restart the second solve as far out as the first (same guess); from the
  // first solve's result only the change of the fluxes is left (measured: 36x smaller).
  EXPECT_GT(first.momentumIterations, 0);
  EXPECT_LT(second.momentumResidual, 0.2 * first.momentumResidual);
}

TEST(InitialGuess, ProjectedFinalPressureGuessSavesIterations) {
  // The final corrector's guess p + s dp with the energy-optimal s (projectFinalGuess) against the
  // whole last change (s = 1): the same fields to the solvers' tolerances, fewer final pressure
  // iterations (the first corrector's solves are the same: relTol makes their count independent
  // of where they start).
  const HexMesh mesh = test::cubeCavityMesh(24);
  const Outcome whole = run(mesh, true, 20, false), projected = run(mesh, true, 20, true);
  double du = 0;
  for (int c = 0; c < 3; ++c) du = std::max(du, test::relDiff(projected.U[c], whole.U[c]));
  const double dp = test::relDiff(projected.p, whole.p);
  std::printf(
      "[ guess    ] 20 steps, final guess p + dp vs p + s dp: pressure its %d -> %d, momentum its %d -> %d; "
      "max rel diff U %.2e p %.2e\n",
      whole.pressureIterations, projected.pressureIterations, whole.momentumIterations, projected.momentumIterations,
      du, dp);
  EXPECT_LE(du, 5e-5);
  EXPECT_LE(dp, 1e-6);
  // Measured: pressure 108 -> 94 iterations, U and p differ by 1.1e-7 / 2.1e-8.
  EXPECT_LE(projected.pressureIterations, 0.95 * whole.pressureIterations);
}
