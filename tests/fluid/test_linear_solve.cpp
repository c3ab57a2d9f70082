// The fluid's linear-solver front end: OpenFOAM-scaled residuals checked against a host
// recomputation, the solves stopping at the first iterate whose scaled residual is below the
// tolerance (or relTol times the initial one), solveMomentum3 against three solveMomentum calls,
// bitwise repeatability, and the pressure (CG) path.
#include "fluid/LinearSolve.hpp"

#include "kernels/CsrBuild.hpp"
#include "support/Approx.hpp"
#include "support/HostVectors.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace {

using mfsi::lid_t;
using mfsi::fluid::LinearSolverOptions;
using mfsi::fluid::LinearSolveStats;
using mfsi::test::column;
using mfsi::test::device;
using mfsi::test::device3;
using mfsi::test::host;
using mfsi::test::HostVec;
using mfsi::test::near;
using mfsi::test::relDiff;
using mfsi::test::Tol;

/// The host CSR with OpenFOAM's residual scaling.
struct HostCsr : mfsi::test::HostCsr {
  using mfsi::test::HostCsr::HostCsr;
  /// OpenFOAM's normalisation factor sum |A x0 - A xbar| + |b - A xbar| (xbar: mean of x0).
  double normFactor(const HostVec& b, const HostVec& x0) const {
    double xbar = 0;
    for (double v : x0) xbar += v;
    xbar /= n;
    const HostVec ax = apply(x0);
    double nf = 0;
    for (lid_t i = 0; i < n; ++i) {
      double rs = 0;
      for (lid_t k = rowPtr[i]; k < rowPtr[i + 1]; ++k) rs += values[k];
      nf += std::abs(ax[i] - rs * xbar) + std::abs(b[i] - rs * xbar);
    }
    return nf;
  }
  /// OpenFOAM's scaled residual of x, normalised with the factor of the initial guess x0.
  double scaledResidual(const HostVec& b, const HostVec& x, const HostVec& x0) const {
    const HostVec ax = apply(x);
    double r1 = 0;
    for (lid_t i = 0; i < n; ++i) r1 += std::abs(b[i] - ax[i]);
    return r1 / normFactor(b, x0);
  }
};

/// A momentum predictor system on an N^3 unit box: implicit Euler (V/dt), central convection by
/// the exactly divergence-free face fluxes of the vortex u = curl(psi(y,z), 0, psi(x,y)),
/// psi = sin(pi a) sin(pi b) / pi (zero on the walls), diffusion nu; Courant number 0.3. b =
/// (V/dt) U_old - V grad p, x0 = U_old: the system FluidSolver hands to the momentum solver.
/// `offset` adds a uniform velocity to U_old (a non-zero mean, which the scaled residual removes).
struct MomentumSystem {
  mfsi::CsrMatrix A;
  std::array<HostVec, 3> b, x0;
};

MomentumSystem momentumSystem(lid_t N, double nu, std::array<double, 3> offset = {0, 0, 0}) {
  const double pi = 3.14159265358979323846;
  const double h = 1.0 / N, V = h * h * h, D = nu * h;
  auto psi = [&](double a, double b) { return std::sin(pi * a) * std::sin(pi * b) / pi; };
  auto flux = [&](int d, lid_t i, lid_t j, lid_t k) {  // out of cell (i, j, k) through its +d face
    const double x = (i + (d == 0)) * h, y = (j + (d == 1)) * h, z = (k + (d == 2)) * h;
    if (d == 0) return h * (psi(x, y + h) - psi(x, y));
    if (d == 1) return h * (psi(y, z + h) - psi(y, z)) - h * (psi(x + h, y) - psi(x, y));
    return -h * (psi(y + h, z) - psi(y, z));
  };
  const lid_t n = N * N * N, stride[3] = {1, N, N * N};
  double maxOut = 0;
  for (lid_t k = 0; k < N; ++k)
    for (lid_t j = 0; j < N; ++j)
      for (lid_t i = 0; i < N; ++i) {
        const lid_t ijk[3] = {i, j, k};
        double s = 0;
        for (int d = 0; d < 3; ++d) {
          s += std::abs(flux(d, i, j, k));
          if (ijk[d] > 0) s += std::abs(flux(d, i - (d == 0), j - (d == 1), k - (d == 2)));
        }
        maxOut = std::max(maxOut, s);
      }
  const double dt = 0.3 * V / (0.5 * maxOut);
  MomentumSystem m;
  m.A = mfsi::buildPoisson7({N, N, N}, mfsi::ModelBoundary::Dirichlet);
  const HostCsr pattern(m.A);
  auto at = [&](lid_t r, lid_t c) { return mfsi::findEntry(pattern.rowPtr, pattern.colIdx, r, c); };
  HostVec val(pattern.values.size(), 0.0);
  for (lid_t k = 0; k < N; ++k)
    for (lid_t j = 0; j < N; ++j)
      for (lid_t i = 0; i < N; ++i) {
        const lid_t P = i + N * (j + N * k), ijk[3] = {i, j, k};
        val[at(P, P)] += V / dt;
        for (int d = 0; d < 3; ++d) {
          if (ijk[d] == 0) val[at(P, P)] += 2 * D;
          if (ijk[d] + 1 == N) {
            val[at(P, P)] += 2 * D;
            continue;
          }
          const lid_t Q = P + stride[d];
          const double F = flux(d, i, j, k);
          val[at(P, P)] += 0.5 * F + D;
          val[at(P, Q)] += 0.5 * F - D;
          val[at(Q, Q)] += -0.5 * F + D;
          val[at(Q, P)] += -0.5 * F - D;
        }
      }
  Kokkos::deep_copy(m.A.values, device(val));
  for (int c = 0; c < 3; ++c) {
    m.b[c].resize(n);
    m.x0[c].resize(n);
  }
  for (lid_t k = 0; k < N; ++k)
    for (lid_t j = 0; j < N; ++j)
      for (lid_t i = 0; i < N; ++i) {
        const lid_t c = i + N * (j + N * k);
        const double x = (i + 0.5) * h, y = (j + 0.5) * h, z = (k + 0.5) * h;
        const double u[3] = {std::sin(pi * x) * std::cos(pi * y),
                             std::sin(pi * y) * std::cos(pi * z) - std::cos(pi * x) * std::sin(pi * y),
                             -std::cos(pi * y) * std::sin(pi * z)};
        const double gp[3] = {0.5 * pi * std::sin(2 * pi * x), 0.5 * pi * std::sin(2 * pi * y),
                              0.5 * pi * std::sin(2 * pi * z)};
        for (int d = 0; d < 3; ++d) {
          m.x0[d][c] = u[d] + offset[d];
          m.b[d][c] = V / dt * m.x0[d][c] - V * gp[d];
        }
      }
  return m;
}

mfsi::fluid::LinearSolver momentumSolver(const mfsi::CsrMatrix& A) {
  mfsi::fluid::LinearSolver s(A.nRows, mfsi::fluid::PressurePreconditioner::Jacobi);
  s.momentumMatrixChanged(mfsi::ExecSpace(), A);
  return s;
}

}  // namespace

TEST(LinearSolve, Momentum3ReportsOpenFoamScaledResiduals) {
  const auto m = momentumSystem(12, 0.01, {1.0, 0.5, -0.25});
  const HostCsr hA(m.A);
  mfsi::ExecSpace exec;
  auto solver = momentumSolver(m.A);
  const LinearSolverOptions o{1e-6, 0.0, 100};
  auto x3 = device3(m.x0);
  const auto st = solver.solveMomentum3(exec, m.A, device3(m.b), x3, o);
  for (int c = 0; c < 3; ++c) {
    const std::string col = "component " + std::to_string(c);
    const HostVec x = column(x3, c);
    EXPECT_TRUE(st[c].converged) << col;
    EXPECT_FALSE(st[c].breakdown) << col;
    EXPECT_GE(st[c].iterations, 2) << col;
    EXPECT_TRUE(near(st[c].initialResidual, hA.scaledResidual(m.b[c], m.x0[c], m.x0[c]), Tol{0, 1e-12},
                     col + " initial scaled residual"));
    // The reported final residual is the solver's recursive one: equal to the true one to
    // round-off relative to the terms it is made of (|b|_1 ~ nf), far below 1e-6 relative here.
    EXPECT_TRUE(near(st[c].finalResidual, hA.scaledResidual(m.b[c], x, m.x0[c]), Tol{1e-12, 1e-6},
                     col + " final scaled residual"));
    EXPECT_GT(st[c].initialResidual, 1e-4) << col;
    EXPECT_LE(hA.scaledResidual(m.b[c], x, m.x0[c]), 1e-6) << col;
    std::printf("[ momentum3] component %d: %d iterations, scaled residual %.3e -> %.3e\n", c, st[c].iterations,
                st[c].initialResidual, st[c].finalResidual);
  }
}

TEST(LinearSolve, Momentum3EqualsThreeSingleComponentSolves) {
  const auto m = momentumSystem(10, 0.005);
  mfsi::ExecSpace exec;
  auto solver = momentumSolver(m.A);
  for (const LinearSolverOptions o : {LinearSolverOptions{1e-5, 0.0, 100}, LinearSolverOptions{1e-9, 0.0, 100},
                                      LinearSolverOptions{0.0, 0.01, 100}}) {
    auto x3 = device3(m.x0);
    const auto st3 = solver.solveMomentum3(exec, m.A, device3(m.b), x3, o);
    for (int c = 0; c < 3; ++c) {
      const std::string col = "tolerance " + std::to_string(o.tolerance) + " component " + std::to_string(c);
      auto x = device(m.x0[c]);
      const LinearSolveStats st = solver.solveMomentum(exec, m.A, device(m.b[c]), x, o);
      EXPECT_EQ(st3[c].iterations, st.iterations) << col;
      EXPECT_EQ(st3[c].converged, st.converged) << col;
      EXPECT_LE(relDiff(column(x3, c), host(x)), 1e-12) << col;
      EXPECT_TRUE(near(st3[c].initialResidual, st.initialResidual, Tol{0, 1e-12}, col + " initial"));
      EXPECT_TRUE(near(st3[c].finalResidual, st.finalResidual, Tol{0, 1e-10}, col + " final"));
    }
  }
}

TEST(LinearSolve, StopsAtTheFirstIterateBelowTheScaledTolerance) {
  // OpenFOAM's rule: stop as soon as the scaled residual is below the tolerance, or below relTol
  // times the initial one. The iterate one iteration earlier must still be above it (a solver
  // stopping on a conservative 2-norm bound would over-solve and fail this).
  const auto m = momentumSystem(12, 0.01);
  const HostCsr hA(m.A);
  mfsi::ExecSpace exec;
  auto solver = momentumSolver(m.A);
  for (const LinearSolverOptions o : {LinearSolverOptions{1e-5, 0.0, 100}, LinearSolverOptions{1e-8, 0.0, 100},
                                      LinearSolverOptions{1e-12, 1e-3, 100}}) {
    for (int c = 0; c < 3; ++c) {
      const std::string what = "tol " + std::to_string(o.tolerance) + " relTol " + std::to_string(o.relTol) +
                               " component " + std::to_string(c);
      auto x = device(m.x0[c]);
      const auto st = solver.solveMomentum(exec, m.A, device(m.b[c]), x, o);
      const double target = std::max(o.tolerance, o.relTol * st.initialResidual);
      ASSERT_TRUE(st.converged) << what;
      ASSERT_GE(st.iterations, 1) << what;
      EXPECT_LE(hA.scaledResidual(m.b[c], host(x), m.x0[c]), target) << what;
      LinearSolverOptions fewer = o;
      fewer.maxIter = st.iterations - 1;
      auto xPrev = device(m.x0[c]);
      const auto prev = solver.solveMomentum(exec, m.A, device(m.b[c]), xPrev, fewer);
      EXPECT_FALSE(prev.converged) << what;
      EXPECT_GT(hA.scaledResidual(m.b[c], host(xPrev), m.x0[c]), target) << what;
    }
  }
}

TEST(LinearSolve, ToleranceJustAboveAnIterateStopsThere) {
  // The scaled residual s_k of the iterate after k iterations (host-recomputed), and a tolerance
  // 0.1 % above it: the solve must stop after exactly k iterations. Stopping on the 2-norm bound
  // |r|_1 <= sqrt(n) |r|_2 instead would need one more iteration (|r|_1 is well below
  // sqrt(n) |r|_2 for any residual that is not constant in magnitude). Single and 3-component.
  const auto m = momentumSystem(12, 0.01, {0.2, 0.0, 0.0});
  const HostCsr hA(m.A);
  mfsi::ExecSpace exec;
  auto solver = momentumSolver(m.A);
  int checked = 0;
  for (int c = 0; c < 3; ++c) {
    double prev = hA.scaledResidual(m.b[c], m.x0[c], m.x0[c]);
    for (int k = 1; k <= 3; ++k) {
      auto xk = device(m.x0[c]);
      solver.solveMomentum(exec, m.A, device(m.b[c]), xk, LinearSolverOptions{0.0, 0.0, k});
      const double sk = hA.scaledResidual(m.b[c], host(xk), m.x0[c]);
      const std::string what = "component " + std::to_string(c) + " k " + std::to_string(k);
      ASSERT_LT(sk, 0.5 * prev) << what << ": the iterates must converge monotonically for this test";
      prev = sk;
      const LinearSolverOptions o{1.001 * sk, 0.0, 100};
      auto x = device(m.x0[c]);
      const auto st = solver.solveMomentum(exec, m.A, device(m.b[c]), x, o);
      EXPECT_EQ(st.iterations, k) << what;
      EXPECT_LE(hA.scaledResidual(m.b[c], host(x), m.x0[c]), o.tolerance) << what;
      auto x3 = device3(m.x0);
      const auto st3 = solver.solveMomentum3(exec, m.A, device3(m.b), x3, o);
      EXPECT_EQ(st3[c].iterations, k) << what << " (solveMomentum3)";
      EXPECT_LE(hA.scaledResidual(m.b[c], column(x3, c), m.x0[c]), o.tolerance) << what << " (solveMomentum3)";
      ++checked;
    }
  }
  EXPECT_EQ(checked, 9);
}

TEST(LinearSolve, ConvergedStartLeavesTheSolutionAlone) {
  // x0 solves the system to round-off: no iteration, x untouched, for every component.
  const auto m = momentumSystem(6, 0.01);
  const HostCsr hA(m.A);
  mfsi::ExecSpace exec;
  auto solver = momentumSolver(m.A);
  std::array<HostVec, 3> b;
  for (int c = 0; c < 3; ++c) b[c] = hA.apply(m.x0[c]);
  auto x3 = device3(m.x0);
  const auto st = solver.solveMomentum3(exec, m.A, device3(b), x3, LinearSolverOptions{1e-10, 0.0, 100});
  for (int c = 0; c < 3; ++c) {
    EXPECT_TRUE(st[c].converged);
    EXPECT_EQ(st[c].iterations, 0);
    EXPECT_EQ(column(x3, c), m.x0[c]);
  }
}

TEST(LinearSolve, Momentum3IsBitwiseRepeatable) {
  const auto m = momentumSystem(10, 0.01);
  mfsi::ExecSpace exec;
  auto solver = momentumSolver(m.A);
  const auto b3 = device3(m.b);
  auto x1 = device3(m.x0), x2 = device3(m.x0);
  const auto s1 = solver.solveMomentum3(exec, m.A, b3, x1, LinearSolverOptions{1e-8, 0.0, 100});
  const auto s2 = solver.solveMomentum3(exec, m.A, b3, x2, LinearSolverOptions{1e-8, 0.0, 100});
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(s1[c].iterations, s2[c].iterations);
    EXPECT_EQ(s1[c].finalResidual, s2[c].finalResidual);
    EXPECT_EQ(column(x1, c), column(x2, c));
  }
}

TEST(LinearSolve, PressureSolveStopsOnTheScaledResidual) {
  // CG (Jacobi and AMG) started from the residual of the scaled-residual pass.
  const auto A = mfsi::buildPoisson7({10, 9, 8}, mfsi::ModelBoundary::Dirichlet);
  const HostCsr hA(A);
  HostVec b(A.nRows), x0(A.nRows);
  for (lid_t i = 0; i < A.nRows; ++i) {
    b[i] = std::sin(0.7 * i) + 0.3;
    x0[i] = 0.1 * std::cos(0.05 * i);
  }
  mfsi::ExecSpace exec;
  // Announced values: the scaled-residual pass runs on CG's lattice copy; not announced: on CSR.
  for (auto [pp, announced] : {std::pair{mfsi::fluid::PressurePreconditioner::Jacobi, false},
                               std::pair{mfsi::fluid::PressurePreconditioner::Amg, false},
                               std::pair{mfsi::fluid::PressurePreconditioner::Amg, true}}) {
    mfsi::fluid::LinearSolver solver(A.nRows, pp);
    solver.pressureMatrixChanged(exec, A);
    if (announced) solver.pressureValuesChanged(exec, A);
    const LinearSolverOptions o{1e-7, 0.0, 500};
    auto x = device(x0);
    const auto st = solver.solvePressure(exec, A, device(b), x, o);
    EXPECT_TRUE(st.converged);
    EXPECT_TRUE(near(st.initialResidual, hA.scaledResidual(b, x0, x0), Tol{0, 1e-12}, "initial"));
    EXPECT_TRUE(near(st.finalResidual, hA.scaledResidual(b, host(x), x0), Tol{1e-13, 1e-6}, "final"));
    EXPECT_LE(hA.scaledResidual(b, host(x), x0), 1e-7);
    LinearSolverOptions fewer = o;
    fewer.maxIter = st.iterations - 1;
    auto xPrev = device(x0);
    solver.solvePressure(exec, A, device(b), xPrev, fewer);
    EXPECT_GT(hA.scaledResidual(b, host(xPrev), x0), 1e-7);
  }
}

TEST(LinearSolve, PressureStepAlongIsTheEnergyOptimalStep) {
  // s = d.(b - A x) / d.A d against a host recomputation, on CSR and on CG's lattice copy (the
  // same to rounding), and the energy norm of the error of x + s d is a minimum in s.
  const auto A = mfsi::buildPoisson7({9, 8, 7}, mfsi::ModelBoundary::Dirichlet);
  const HostCsr hA(A);
  const lid_t n = A.nRows;
  HostVec b(n), x(n), d(n);
  for (lid_t i = 0; i < n; ++i) {
    b[i] = std::sin(0.7 * i) + 0.3;
    x[i] = 0.1 * std::cos(0.05 * i);
    d[i] = std::cos(0.3 * i) - 0.2;
  }
  const HostVec ad = hA.apply(d), ax = hA.apply(x);
  double num = 0, den = 0;
  for (lid_t i = 0; i < n; ++i) {
    num += d[i] * (b[i] - ax[i]);
    den += d[i] * ad[i];
  }
  const double gold = num / den;
  // Energy norm of the error of x + s d, up to a constant: E(s) = (x + s d).A(x + s d) / 2 - b.(x + s d).
  auto energy = [&](double s) {
    HostVec y(n);
    for (lid_t i = 0; i < n; ++i) y[i] = x[i] + s * d[i];
    const HostVec ay = hA.apply(y);
    double e = 0;
    for (lid_t i = 0; i < n; ++i) e += 0.5 * y[i] * ay[i] - b[i] * y[i];
    return e;
  };
  mfsi::ExecSpace exec;
  for (bool announced : {false, true}) {
    mfsi::fluid::LinearSolver solver(n, mfsi::fluid::PressurePreconditioner::Amg);
    solver.pressureMatrixChanged(exec, A);
    if (announced) solver.pressureValuesChanged(exec, A);
    const double s = solver.pressureStepAlong(exec, A, device(b), device(x), device(d));
    EXPECT_TRUE(near(s, gold, Tol{0, 1e-12}, announced ? "lattice" : "csr"));
    EXPECT_LT(energy(s), energy(s + 0.05 * std::abs(s)));
    EXPECT_LT(energy(s), energy(s - 0.05 * std::abs(s)));
  }
  // No step along a zero direction.
  mfsi::fluid::LinearSolver solver(n, mfsi::fluid::PressurePreconditioner::Amg);
  solver.pressureMatrixChanged(exec, A);
  EXPECT_EQ(solver.pressureStepAlong(exec, A, device(b), device(x), device(HostVec(n, 0.0))), 0.0);
}
