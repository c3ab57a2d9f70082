// CG and BiCGStab: convergence to tolerance checked on the true residual and against a known
// solution, reported (not thrown) non-convergence, NaN detection, stopping rules.
#include "kernels/Krylov.hpp"

#include "core/Error.hpp"
#include "kernels/CsrBuild.hpp"
#include "support/Approx.hpp"

#include <cmath>
#include <limits>
#include <vector>

namespace {

using mfsi::lid_t;
using mfsi::test::near;
using mfsi::test::Tol;
using HostVec = std::vector<double>;

HostVec host(const mfsi::RealView& v) {
  auto h = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), v);
  return HostVec(h.data(), h.data() + h.extent(0));
}

mfsi::RealView device(const HostVec& v) {
  mfsi::RealView d("test::vec", v.size());
  auto h = Kokkos::create_mirror_view(d);
  for (std::size_t i = 0; i < v.size(); ++i) h(i) = v[i];
  Kokkos::deep_copy(d, h);
  return d;
}

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
