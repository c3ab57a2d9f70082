// CG and BiCGStab: convergence to tolerance checked on the true residual and against a known
// solution, reported (not thrown) non-convergence, NaN detection, stopping rules (2-norm, and the
// 1-norm rule against host-recomputed residuals of every iterate). The three-column BiCGStab3
// against three separate BiCGStab solves (iterate by iterate, frozen columns, independent
// failures), and solves started from a caller-provided residual.
#include "kernels/Krylov.hpp"

#include "core/Error.hpp"
#include "kernels/CsrBuild.hpp"
#include "support/Approx.hpp"
#include "support/HostVectors.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

namespace {

using mfsi::lid_t;
using mfsi::test::near;
using mfsi::test::Tol;
using mfsi::test::column;
using mfsi::test::device;
using mfsi::test::device3;
using mfsi::test::host;
using mfsi::test::HostVec;
using mfsi::test::relDiff;

/// Smooth-plus-oscillating exact solution.
HostVec exactSolution(lid_t n) {
  HostVec x(n);
  for (lid_t i = 0; i < n; ++i) x[i] = std::sin(0.37 * i) + 0.5 * std::cos(0.011 * i * i);
  return x;
}

/// ||b - A x|| computed afresh (not the solver's recursive residual).
double trueResidual(const mfsi::CsrMatrix& A, const mfsi::RealView& b, const mfsi::RealView& x) {
  mfsi::RealView r("test::r", A.nRows);
  return std::sqrt(mfsi::blas::residual(mfsi::ExecSpace(), mfsi::SolverComm(), A, x, b, r));
}

double errorNorm(const mfsi::RealView& x, const HostVec& exact) {
  const HostVec h = host(x);
  double e = 0, s = 0;
  for (std::size_t i = 0; i < exact.size(); ++i) {
    e += (h[i] - exact[i]) * (h[i] - exact[i]);
    s += exact[i] * exact[i];
  }
  return std::sqrt(e / s);
}

/// Upwind convection-diffusion on an n^3 grid (Dirichlet walls): the 7-point diffusion matrix
/// plus first-order upwind fluxes of velocity pe * (1, 0.6, -0.3). Non-symmetric, diagonally
/// dominant, an M-matrix: what the momentum equation produces.
mfsi::CsrMatrix convectionDiffusion(lid_t n, double pe) {
  auto A = mfsi::buildPoisson7({n, n, n}, mfsi::ModelBoundary::Dirichlet);
  auto hv = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), A.values);
  auto rp0 = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), A.rowPtr);
  auto ci0 = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), A.colIdx);
  const std::vector<lid_t> rp(rp0.data(), rp0.data() + rp0.extent(0)), ci(ci0.data(), ci0.data() + ci0.extent(0));
  const double u[3] = {pe, 0.6 * pe, -0.3 * pe};
  const lid_t stride[3] = {1, n, n * n};
  for (lid_t k = 0; k < n; ++k)
    for (lid_t j = 0; j < n; ++j)
      for (lid_t i = 0; i < n; ++i) {
        const lid_t c = i + n * (j + n * k);
        const lid_t ijk[3] = {i, j, k};
        for (int d = 0; d < 3; ++d) {
          // Flux out of c through its +d face (and, for the -d face, -u[d]).
          for (int side : {-1, 1}) {
            const double F = side * u[d];
            hv(mfsi::findEntry(rp, ci, c, c)) += std::max(F, 0.0);
            const bool inside = side > 0 ? ijk[d] + 1 < n : ijk[d] > 0;
            if (inside) hv(mfsi::findEntry(rp, ci, c, c + side * stride[d])) += std::min(F, 0.0);
          }
        }
      }
  Kokkos::deep_copy(A.values, hv);
  return A;
}

struct System {
  mfsi::CsrMatrix A;
  HostVec exact;
  mfsi::RealView b;
};

System makeSystem(mfsi::CsrMatrix A) {
  System s;
  s.A = A;
  s.exact = exactSolution(A.nRows);
  s.b = mfsi::RealView("test::b", A.nRows);
  mfsi::blas::spmv(mfsi::ExecSpace(), A, device(s.exact), s.b);
  return s;
}

}  // namespace

TEST(Krylov, CgSolvesThePoissonMatrixWithAndWithoutJacobi) {
  auto sys = makeSystem(mfsi::buildPoisson7({12, 10, 9}, mfsi::ModelBoundary::Dirichlet));
  mfsi::ExecSpace exec;
  mfsi::KrylovOptions opt;
  opt.relTol = 1e-10;
  mfsi::ConjugateGradient cg(opt);
  mfsi::JacobiPreconditioner jacobi;
  mfsi::IdentityPreconditioner none;
  for (mfsi::Preconditioner* M : std::initializer_list<mfsi::Preconditioner*>{&none, &jacobi}) {
    M->setup(exec, sys.A);
    mfsi::RealView x("x", sys.A.nRows);
    const auto res = cg.solve(exec, sys.A, sys.b, x, *M);
    EXPECT_TRUE(res.converged) << M->name() << " " << mfsi::toString(res.status);
    EXPECT_EQ(res.status, mfsi::KrylovStatus::Converged);
    EXPECT_GT(res.iterations, 10);
    EXPECT_LE(res.finalResidual, 1e-10 * res.initialResidual);
    // The recursive residual may drift from the true one by rounding; allow a factor 10.
    EXPECT_LE(trueResidual(sys.A, sys.b, x), 1e-9 * res.initialResidual) << M->name();
    EXPECT_TRUE(near(errorNorm(x, sys.exact), 0.0, Tol{1e-8, 0}, "relative error " + M->name()));
  }
}

TEST(Krylov, BiCGStabSolvesNonSymmetricConvectionDiffusion) {
  for (double pe : {0.5, 20.0}) {
    auto sys = makeSystem(convectionDiffusion(12, pe));
    mfsi::ExecSpace exec;
    mfsi::KrylovOptions opt;
    opt.relTol = 1e-10;
    auto solver = mfsi::makeKrylovSolver(mfsi::KrylovMethod::BiCGStab, opt);
    ASSERT_NE(dynamic_cast<mfsi::BiCGStab*>(solver.get()), nullptr);
    mfsi::JacobiPreconditioner jacobi;
    jacobi.setup(exec, sys.A);
    mfsi::RealView x("x", sys.A.nRows);
    const auto res = solver->solve(exec, sys.A, sys.b, x, jacobi);
    EXPECT_TRUE(res.converged) << "Pe " << pe << ": " << mfsi::toString(res.status);
    EXPECT_LE(trueResidual(sys.A, sys.b, x), 1e-9 * res.initialResidual) << "Pe " << pe;
    EXPECT_TRUE(near(errorNorm(x, sys.exact), 0.0, Tol{1e-8, 0}, "relative error"));
  }
}

TEST(Krylov, NonConvergenceIsReportedNotThrown) {
  auto sys = makeSystem(mfsi::buildPoisson7({10, 10, 10}, mfsi::ModelBoundary::Dirichlet));
  mfsi::ExecSpace exec;
  mfsi::KrylovOptions opt;
  opt.maxIterations = 3;
  mfsi::JacobiPreconditioner jacobi;
  jacobi.setup(exec, sys.A);
  for (auto method : {mfsi::KrylovMethod::CG, mfsi::KrylovMethod::BiCGStab}) {
    mfsi::RealView x("x", sys.A.nRows);
    mfsi::KrylovResult res;
    EXPECT_NO_THROW(res = mfsi::makeKrylovSolver(method, opt)->solve(exec, sys.A, sys.b, x, jacobi));
    EXPECT_FALSE(res.converged);
    EXPECT_EQ(res.status, mfsi::KrylovStatus::MaxIterations);
    EXPECT_EQ(res.iterations, 3);
    EXPECT_GT(res.finalResidual, 1e-8 * res.initialResidual);
    EXPECT_LT(res.finalResidual, res.initialResidual);
  }
}

TEST(Krylov, NaNStopsTheSolveWithConvergedFalse) {
  auto sys = makeSystem(mfsi::buildPoisson7({6, 6, 6}, mfsi::ModelBoundary::Dirichlet));
  mfsi::ExecSpace exec;
  mfsi::IdentityPreconditioner none;
  none.setup(exec, sys.A);
  // NaN in the right-hand side.
  HostVec hb = host(sys.b);
  hb[17] = std::numeric_limits<double>::quiet_NaN();
  auto bad = device(hb);
  for (auto method : {mfsi::KrylovMethod::CG, mfsi::KrylovMethod::BiCGStab}) {
    mfsi::RealView x("x", sys.A.nRows);
    const auto res = mfsi::makeKrylovSolver(method)->solve(exec, sys.A, bad, x, none);
    EXPECT_FALSE(res.converged);
    EXPECT_EQ(res.status, mfsi::KrylovStatus::NotFinite);
    EXPECT_EQ(res.iterations, 0);
  }
  // NaN appearing during the iteration: an off-diagonal coefficient (the initial residual with
  // x0 = 0 does not see it; the first A p does).
  auto hv = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), sys.A.values);
  hv(1) = std::numeric_limits<double>::quiet_NaN();
  Kokkos::deep_copy(sys.A.values, hv);
  for (auto method : {mfsi::KrylovMethod::CG, mfsi::KrylovMethod::BiCGStab}) {
    mfsi::RealView x("x", sys.A.nRows);
    const auto res = mfsi::makeKrylovSolver(method)->solve(exec, sys.A, sys.b, x, none);
    EXPECT_FALSE(res.converged);
    EXPECT_EQ(res.status, mfsi::KrylovStatus::NotFinite);
    EXPECT_LE(res.iterations, 1);
  }
}

TEST(Krylov, StoppingRules) {
  auto sys = makeSystem(mfsi::buildPoisson7({10, 10, 10}, mfsi::ModelBoundary::Dirichlet));
  mfsi::ExecSpace exec;
  mfsi::JacobiPreconditioner jacobi;
  jacobi.setup(exec, sys.A);
  // Initial guess = solution plus a small perturbation, as in a time step.
  HostVec guess = sys.exact;
  for (std::size_t i = 0; i < guess.size(); ++i) guess[i] += 1e-4 * std::sin(1.3 * i);

  mfsi::KrylovOptions opt;
  opt.relTol = 1e-6;
  mfsi::ConjugateGradient cg(opt);
  auto x1 = device(guess);
  const auto relInitial = cg.solve(exec, sys.A, sys.b, x1, jacobi);
  opt.relativeTo = mfsi::ResidualReference::RightHandSide;
  cg.setOptions(opt);
  auto x2 = device(guess);
  const auto relRhs = cg.solve(exec, sys.A, sys.b, x2, jacobi);
  ASSERT_TRUE(relInitial.converged && relRhs.converged);
  // ||r0|| << ||b||, so relative-to-rhs asks for less.
  EXPECT_LT(relRhs.iterations, relInitial.iterations);
  EXPECT_LE(trueResidual(sys.A, sys.b, x2), 1.1e-6 * mfsi::blas::norm2(exec, mfsi::SolverComm(), sys.A.nRows, sys.b));

  // An absolute tolerance above the initial residual stops at once.
  opt = {};
  opt.absTol = 2.0 * relInitial.initialResidual;
  cg.setOptions(opt);
  auto x3 = device(guess);
  const auto res = cg.solve(exec, sys.A, sys.b, x3, jacobi);
  EXPECT_TRUE(res.converged);
  EXPECT_EQ(res.iterations, 0);
  EXPECT_EQ(host(x3), guess);
}

TEST(Krylov, RepeatedSolvesAreBitwiseIdentical) {
  auto sys = makeSystem(convectionDiffusion(9, 5.0));
  mfsi::ExecSpace exec;
  mfsi::JacobiPreconditioner jacobi;
  jacobi.setup(exec, sys.A);
  mfsi::BiCGStab solver;
  mfsi::RealView x1("x1", sys.A.nRows), x2("x2", sys.A.nRows);
  const auto r1 = solver.solve(exec, sys.A, sys.b, x1, jacobi);
  const auto r2 = solver.solve(exec, sys.A, sys.b, x2, jacobi);
  EXPECT_EQ(r1.iterations, r2.iterations);
  EXPECT_EQ(r1.finalResidual, r2.finalResidual);
  EXPECT_EQ(host(x1), host(x2));
}

TEST(Krylov, JacobiRejectsAZeroDiagonal) {
  auto A = mfsi::buildPoisson7({3, 3, 3}, mfsi::ModelBoundary::Dirichlet);
  auto hv = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), A.values);
  auto hd = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), A.diagIdx);
  hv(hd(13)) = 0.0;
  Kokkos::deep_copy(A.values, hv);
  mfsi::JacobiPreconditioner jacobi;
  try {
    jacobi.setup(mfsi::ExecSpace(), A);
    FAIL() << "no exception";
  } catch (const mfsi::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("row 13"), std::string::npos) << e.what();
  }
}

// ---------------------------------------------------------------------------------------------
// Three-right-hand-side BiCGStab, caller-provided initial residuals, the 1-norm stopping rule.
// ---------------------------------------------------------------------------------------------
namespace {

/// The host CSR with its diagonal.
struct HostCsr : mfsi::test::HostCsr {
  using mfsi::test::HostCsr::HostCsr;
  HostVec diagonal() const {
    HostVec d(n, 0.0);
    for (lid_t i = 0; i < n; ++i)
      for (lid_t k = rowPtr[i]; k < rowPtr[i + 1]; ++k)
        if (colIdx[k] == i) d[i] = values[k];
    return d;
  }
};

double hostDot(const HostVec& a, const HostVec& b) {
  double s = 0;
  for (std::size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
  return s;
}

mfsi::RealView inverseDiagonal(const mfsi::CsrMatrix& A) {
  mfsi::RealView inv("test::invDiag", A.nRows);
  mfsi::invertDiagonal(mfsi::ExecSpace(), A, inv);
  return inv;
}

/// Three right-hand sides of different difficulty and three initial guesses for one matrix.
struct ThreeSystems {
  mfsi::CsrMatrix A;
  std::array<HostVec, 3> b, x0, exact;
};

ThreeSystems threeSystems(lid_t n, double pe) {
  ThreeSystems s;
  s.A = convectionDiffusion(n, pe);
  const HostCsr hA(s.A);
  const lid_t rows = s.A.nRows;
  for (int c = 0; c < 3; ++c) {
    s.exact[c].resize(rows);
    s.x0[c].resize(rows);
    for (lid_t i = 0; i < rows; ++i) {
      s.exact[c][i] = std::sin(0.37 * (c + 1) * i) + 0.5 * std::cos(0.011 * i * i + c) + c;
      s.x0[c][i] = c == 0 ? 0.0 : s.exact[c][i] + (c == 1 ? 0.3 : 1e-3) * std::cos(0.7 * i);
    }
    s.b[c] = hA.apply(s.exact[c]);
  }
  return s;
}

}  // namespace

TEST(Krylov, BiCGStab3GivesTheIteratesOfThreeSeparateSolves) {
  // Non-symmetric upwind convection-diffusion; the three columns start at different distances
  // from their solutions. After every k iterations (tolerance 0: all columns run k iterations)
  // each column must equal a separate BiCGStab + Jacobi solve of that column.
  const auto s = threeSystems(10, 8.0);
  mfsi::ExecSpace exec;
  mfsi::JacobiPreconditioner jacobi;
  jacobi.setup(exec, s.A);
  const auto inv = inverseDiagonal(s.A);
  const auto b3 = device3(s.b);
  double worst = 0;
  for (int k : {1, 2, 3, 6, 10}) {
    mfsi::KrylovOptions opt;
    opt.relTol = 0.0;
    opt.maxIterations = k;
    mfsi::BiCGStab3 solver3(opt);
    auto x3 = device3(s.x0);
    const auto res3 = solver3.solve(exec, s.A, b3, x3, inv);
    mfsi::BiCGStab solver(opt);
    for (int c = 0; c < 3; ++c) {
      auto x = device(s.x0[c]);
      const auto res = solver.solve(exec, s.A, device(s.b[c]), x, jacobi);
      EXPECT_EQ(res3[c].iterations, k) << "column " << c;
      EXPECT_EQ(res3[c].status, res.status) << "column " << c;
      EXPECT_EQ(res3[c].iterations, res.iterations) << "column " << c;
      const double d = relDiff(column(x3, c), host(x));
      worst = std::max(worst, d);
      EXPECT_LE(d, 1e-12) << "column " << c << " after " << k << " iterations";
      EXPECT_TRUE(near(res3[c].finalResidual, res.finalResidual, Tol{0, 1e-10}, "final 2-norm"));
      EXPECT_TRUE(near(res3[c].finalResidualL1, res.finalResidualL1, Tol{0, 1e-10}, "final 1-norm"));
      EXPECT_TRUE(near(res3[c].initialResidual, res.initialResidual, Tol{0, 1e-14}, "initial 2-norm"));
    }
  }
  std::printf("[ bicgstab3] largest relative difference to separate solves: %.3g\n", worst);
}

TEST(Krylov, BiCGStab3FreezesConvergedColumns) {
  // Column 0 (zero guess) needs many iterations, column 2 (guess 1e-3 off) few; with a tolerance
  // the columns stop at different iterations. Each must stop where its own separate solve stops,
  // with that solve's x: a column that kept being updated while column 0 iterates would drift
  // (checked: more iterations move it by far more than round-off).
  const auto s = threeSystems(10, 8.0);
  mfsi::ExecSpace exec;
  mfsi::JacobiPreconditioner jacobi;
  jacobi.setup(exec, s.A);
  const auto inv = inverseDiagonal(s.A);
  mfsi::KrylovOptions opt;
  opt.relTol = 0.0;
  opt.absTol = 1e-6;
  mfsi::BiCGStab3 solver3(opt);
  auto x3 = device3(s.x0);
  const auto res3 = solver3.solve(exec, s.A, device3(s.b), x3, inv);
  mfsi::BiCGStab solver(opt);
  std::array<mfsi::KrylovResult, 3> sep;
  for (int c = 0; c < 3; ++c) {
    auto x = device(s.x0[c]);
    sep[c] = solver.solve(exec, s.A, device(s.b[c]), x, jacobi);
    EXPECT_TRUE(res3[c].converged) << "column " << c;
    EXPECT_EQ(res3[c].iterations, sep[c].iterations) << "column " << c;
    EXPECT_LE(relDiff(column(x3, c), host(x)), 1e-12) << "column " << c;
    EXPECT_LE(res3[c].finalResidual, 1e-6);
    EXPECT_LE(trueResidual(s.A, device(s.b[c]), device(column(x3, c))), 1.01e-6) << "column " << c;
  }
  std::printf("[ bicgstab3] iterations per column: %d %d %d\n", res3[0].iterations, res3[1].iterations,
              res3[2].iterations);
  ASSERT_GE(res3[0].iterations, res3[2].iterations + 3) << "the columns must stop at different iterations";
  // Continuing column 2 to column 0's iteration count changes it well beyond round-off.
  mfsi::KrylovOptions more = opt;
  more.absTol = 0.0;
  more.maxIterations = res3[0].iterations;
  auto x2 = device(s.x0[2]);
  mfsi::BiCGStab(more).solve(exec, s.A, device(s.b[2]), x2, jacobi);
  EXPECT_GT(relDiff(column(x3, 2), host(x2)), 1e-9);
}

TEST(Krylov, BiCGStab3ColumnsFailIndependently) {
  // A NaN in one right-hand side stops that column only; a column that starts converged is not
  // touched (bitwise).
  auto s = threeSystems(8, 3.0);
  s.b[1][5] = std::numeric_limits<double>::quiet_NaN();
  s.x0[2] = s.exact[2];
  mfsi::ExecSpace exec;
  mfsi::KrylovOptions opt;
  opt.relTol = 0.0;
  opt.absTol = 1e-8;
  mfsi::BiCGStab3 solver3(opt);
  auto x3 = device3(s.x0);
  const auto res = solver3.solve(exec, s.A, device3(s.b), x3, inverseDiagonal(s.A));
  EXPECT_TRUE(res[0].converged);
  EXPECT_GT(res[0].iterations, 5);
  EXPECT_EQ(res[1].status, mfsi::KrylovStatus::NotFinite);
  EXPECT_EQ(res[1].iterations, 0);
  EXPECT_EQ(res[2].status, mfsi::KrylovStatus::Converged);
  EXPECT_EQ(res[2].iterations, 0);
  EXPECT_EQ(column(x3, 2), s.exact[2]);
  EXPECT_EQ(column(x3, 1), s.x0[1]);
  EXPECT_TRUE(near(errorNorm(device(column(x3, 0)), s.exact[0]), 0.0, Tol{1e-6, 0}, "column 0 error"));
}

TEST(Krylov, SolversStartFromAGivenResidual) {
  // The overloads taking r0 = b - A x0 give the same solve (same residual formula: bitwise), and
  // really use the given residual instead of recomputing it: a zero r0 means "converged".
  const auto s = threeSystems(8, 4.0);
  mfsi::ExecSpace exec;
  const mfsi::SolverComm comm;
  mfsi::JacobiPreconditioner jacobi;
  jacobi.setup(exec, s.A);
  const auto spd = makeSystem(mfsi::buildPoisson7({8, 7, 6}, mfsi::ModelBoundary::Dirichlet));
  mfsi::JacobiPreconditioner jacobiSpd;
  jacobiSpd.setup(exec, spd.A);
  mfsi::KrylovOptions opt;
  opt.relTol = 1e-9;
  for (auto method : {mfsi::KrylovMethod::CG, mfsi::KrylovMethod::BiCGStab}) {
    const bool cg = method == mfsi::KrylovMethod::CG;
    const mfsi::CsrMatrix& A = cg ? spd.A : s.A;
    const mfsi::RealView b = cg ? spd.b : device(s.b[0]);
    mfsi::Preconditioner& M = cg ? static_cast<mfsi::Preconditioner&>(jacobiSpd) : jacobi;
    auto solver = mfsi::makeKrylovSolver(method, opt);
    mfsi::RealView x1("x1", A.nRows), x2("x2", A.nRows);
    const auto ref = solver->solve(exec, A, b, x1, M);
    mfsi::InitialResidual r0;
    r0.r = mfsi::RealView("r0", A.nRows);
    const auto norms = mfsi::blas::residualNorms(exec, comm, A, x2, b, r0.r);
    r0.rr = norms.rr;
    r0.l1 = norms.l1;
    const auto given = solver->solve(exec, A, b, x2, M, r0);
    EXPECT_GT(ref.iterations, 5);
    EXPECT_EQ(given.iterations, ref.iterations);
    EXPECT_EQ(host(x2), host(x1));
    EXPECT_EQ(given.initialResidualL1, norms.l1);

    mfsi::InitialResidual zero;
    zero.r = mfsi::RealView("zero", A.nRows);
    mfsi::RealView x3("x3", A.nRows);
    const auto none = solver->solve(exec, A, b, x3, M, zero);
    EXPECT_TRUE(none.converged);
    EXPECT_EQ(none.iterations, 0);
  }
  // Three columns.
  mfsi::BiCGStab3 solver3(opt);
  const auto b3 = device3(s.b);
  const auto inv = inverseDiagonal(s.A);
  auto x1 = device3(s.x0), x2 = device3(s.x0);
  const auto ref = solver3.solve(exec, s.A, b3, x1, inv);
  mfsi::InitialResidual3 r0;
  r0.r = mfsi::Real3View("r0", s.A.nRows);
  const auto norms = mfsi::blas::residualNorms(exec, comm, s.A, x2, b3, r0.r);
  for (int c = 0; c < 3; ++c) {
    r0.rr[c] = norms[c].rr;
    r0.l1[c] = norms[c].l1;
  }
  const auto given = solver3.solve(exec, s.A, b3, x2, inv, r0);
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(given[c].iterations, ref[c].iterations);
    EXPECT_EQ(column(x2, c), column(x1, c));
  }
  mfsi::InitialResidual3 zero;
  zero.r = mfsi::Real3View("zero", s.A.nRows);
  auto x3 = device3(s.x0);
  const auto none = solver3.solve(exec, s.A, b3, x3, inv, zero);
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(none[c].iterations, 0);
    EXPECT_EQ(column(x3, c), s.x0[c]);
  }
}

namespace {

/// One candidate stopping point of a solve: after iteration `it` (BiCGStab: its half step s, or
/// its full step), the iterate x and its true residual 1-norm |b - A x|_1.
struct Candidate {
  int it = 0;
  bool half = false;
  double l1 = 0;
  HostVec x;
};

/// Serial BiCGStab + Jacobi (right preconditioning, as kernels/Krylov.cpp) recording every half
/// and full step with its true residual.
std::vector<Candidate> hostBiCGStab(const HostCsr& A, const HostVec& b, HostVec x, int iterations) {
  const lid_t n = A.n;
  const HostVec d = A.diagonal();
  HostVec r = b, ax = A.apply(x);
  for (lid_t i = 0; i < n; ++i) r[i] -= ax[i];
  const HostVec rhat = r;
  HostVec p(n, 0.0), v(n, 0.0), phat(n), shat(n), xh(n);
  double rho = hostDot(rhat, r), rhoOld = 1, alpha = 1, omega = 1;
  std::vector<Candidate> out;
  for (int it = 1; it <= iterations; ++it) {
    const double beta = (rho / rhoOld) * (alpha / omega);
    for (lid_t i = 0; i < n; ++i) {
      p[i] = it == 1 ? r[i] : r[i] + beta * (p[i] - omega * v[i]);
      phat[i] = p[i] / d[i];
    }
    v = A.apply(phat);
    alpha = rho / hostDot(rhat, v);
    for (lid_t i = 0; i < n; ++i) {
      r[i] -= alpha * v[i];
      shat[i] = r[i] / d[i];
      xh[i] = x[i] + alpha * phat[i];
    }
    out.push_back({it, true, A.residualL1(b, xh), xh});
    const HostVec t = A.apply(shat);
    omega = hostDot(t, r) / hostDot(t, t);
    for (lid_t i = 0; i < n; ++i) {
      x[i] += alpha * phat[i] + omega * shat[i];
      r[i] -= omega * t[i];
    }
    out.push_back({it, false, A.residualL1(b, x), x});
    rhoOld = rho;
    rho = hostDot(rhat, r);
  }
  return out;
}

/// A 1-norm tolerance that candidate m is the first to satisfy: 0.1 % above its true residual (far
/// more than the round-off gap between the solver's recursive residual and the true one, so a
/// correct solver stops there; a solver testing a smaller quantity goes on), when every earlier
/// candidate is at least 1.5 times larger (so stopping earlier is wrong too). Else -1.
double toleranceFirstMetAt(const std::vector<Candidate>& c, std::size_t m) {
  double prevMin = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < m; ++k) prevMin = std::min(prevMin, c[k].l1);
  if (c[m].l1 * 1.5 > prevMin) return -1;
  return 1.001 * c[m].l1;
}

}  // namespace

TEST(Krylov, OneNormToleranceStopsAtTheFirstIterateBelowIt) {
  // With only the 1-norm rule active (relTol = absTol = 0), BiCGStab must stop at the first half
  // or full step whose true |b - A x|_1 is below l1AbsTol, with that step's iterate. Tolerances
  // are picked between consecutive host-recomputed residuals, for a half-step and a full-step stop.
  const auto s = threeSystems(8, 6.0);
  const HostCsr hA(s.A);
  mfsi::ExecSpace exec;
  mfsi::JacobiPreconditioner jacobi;
  jacobi.setup(exec, s.A);
  const auto inv = inverseDiagonal(s.A);
  const int kMax = 14;
  int checked[2] = {0, 0};
  for (int c = 0; c < 3; ++c) {
    const auto cands = hostBiCGStab(hA, s.b[c], s.x0[c], kMax);
    for (std::size_t m = 1; m < cands.size(); ++m) {
      const double tol = toleranceFirstMetAt(cands, m);
      if (tol < 0 || checked[cands[m].half] >= 4) continue;
      ++checked[cands[m].half];
      mfsi::KrylovOptions opt;
      opt.relTol = 0.0;
      opt.l1AbsTol = tol;
      auto x = device(s.x0[c]);
      const auto res = mfsi::BiCGStab(opt).solve(exec, s.A, device(s.b[c]), x, jacobi);
      const std::string what = "column " + std::to_string(c) + " candidate " + std::to_string(m);
      EXPECT_TRUE(res.converged) << what;
      EXPECT_EQ(res.iterations, cands[m].it) << what;
      EXPECT_LE(relDiff(host(x), cands[m].x), 1e-9) << what << (cands[m].half ? " (half step)" : " (full step)");
      EXPECT_LE(hA.residualL1(s.b[c], host(x)), tol) << what;
      EXPECT_TRUE(near(res.finalResidualL1, cands[m].l1, Tol{0, 1e-6}, what + " reported 1-norm"));
      // The same column inside BiCGStab3 (the other columns with a tolerance never met).
      std::array<mfsi::KrylovOptions, 3> opt3;
      for (auto& o : opt3) {
        o.relTol = 0.0;
        o.maxIterations = kMax;
      }
      opt3[c] = opt;
      mfsi::BiCGStab3 solver3;
      solver3.setOptions(opt3);
      auto x3 = device3(s.x0);
      const auto res3 = solver3.solve(exec, s.A, device3(s.b), x3, inv);
      EXPECT_EQ(res3[c].iterations, cands[m].it) << what << " in BiCGStab3";
      EXPECT_LE(relDiff(column(x3, c), cands[m].x), 1e-9) << what << " in BiCGStab3";
      for (int o = 0; o < 3; ++o)
        if (o != c) {
          EXPECT_EQ(res3[o].iterations, kMax);
        }
    }
  }
  EXPECT_GE(checked[0], 2) << "full-step stops tested";
  EXPECT_GE(checked[1], 2) << "half-step stops tested";
}

TEST(Krylov, CgOneNormToleranceStopsAtTheFirstIterateBelowIt) {
  auto sys = makeSystem(mfsi::buildPoisson7({9, 8, 7}, mfsi::ModelBoundary::Dirichlet));
  const HostCsr hA(sys.A);
  const HostVec b = host(sys.b);
  mfsi::ExecSpace exec;
  mfsi::JacobiPreconditioner jacobi;
  jacobi.setup(exec, sys.A);
  // Iterates after k = 0..kMax iterations (tolerance 0: CG runs exactly k).
  const int kMax = 25;
  std::vector<Candidate> cands;
  for (int k = 0; k <= kMax; ++k) {
    mfsi::KrylovOptions opt;
    opt.relTol = 0.0;
    opt.maxIterations = k;
    mfsi::RealView x("x", sys.A.nRows);
    mfsi::ConjugateGradient(opt).solve(exec, sys.A, sys.b, x, jacobi);
    const HostVec hx = host(x);
    cands.push_back({k, false, hA.residualL1(b, hx), hx});
  }
  int checked = 0;
  for (std::size_t m = 1; m < cands.size(); ++m) {
    const double tol = toleranceFirstMetAt(cands, m);
    if (tol < 0) continue;
    ++checked;
    mfsi::KrylovOptions opt;
    opt.relTol = 0.0;
    opt.l1AbsTol = tol;
    mfsi::RealView x("x", sys.A.nRows);
    const auto res = mfsi::ConjugateGradient(opt).solve(exec, sys.A, sys.b, x, jacobi);
    EXPECT_TRUE(res.converged);
    EXPECT_EQ(res.iterations, cands[m].it);
    EXPECT_EQ(host(x), cands[m].x);
    EXPECT_LE(hA.residualL1(b, host(x)), tol);
  }
  EXPECT_GE(checked, 4);
}
