// Algebraic multigrid: mesh-independent CG iterations on the 3D Poisson equation (Jacobi-CG
// iterations double from 16^3 to 32^3, AMG-CG iterations do not), singular Neumann systems,
// value updates on a fixed sparsity, and a finite-volume matrix assembled on a graded hex mesh;
// the device cycle against a serial textbook V-cycle, and the mixed-precision (float) cycle:
// iterations, repeatability, symmetry.
#include "kernels/Amg.hpp"

#include "core/BlockMesh.hpp"
#include "core/MeshGeometry.hpp"
#include "kernels/CsrBuild.hpp"
#include "kernels/Krylov.hpp"
#include "support/AmgChecks.hpp"
#include "support/Approx.hpp"
#include "support/FvLaplacian.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <string>
#include <type_traits>
#include <utility>
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

/// A rough right-hand side (all frequencies present), optionally shifted to zero mean.
mfsi::RealView roughRhs(lid_t n, bool zeroMean) { return mfsi::test::roughVector(n, zeroMean); }

double trueResidual(const mfsi::CsrMatrix& A, const mfsi::RealView& b, const mfsi::RealView& x) {
  mfsi::RealView r("test::r", A.nRows);
  return std::sqrt(mfsi::blas::residual(mfsi::ExecSpace(), mfsi::SolverComm(), A, x, b, r));
}

mfsi::KrylovResult solveCg(const mfsi::CsrMatrix& A, const mfsi::RealView& b, mfsi::Preconditioner& M,
                           mfsi::RealView& x, mfsi::NullSpace ns = mfsi::NullSpace::None) {
  mfsi::KrylovOptions opt;
  opt.relTol = 1e-8;
  opt.maxIterations = 2000;
  opt.nullSpace = ns;
  x = mfsi::RealView("test::x", A.nRows);
  return mfsi::ConjugateGradient(opt).solve(mfsi::ExecSpace(), A, b, x, M);
}

/// A with the same sparsity Views as M and its own copy of `values` (a host View).
template <class HostValues>
mfsi::CsrMatrix B0(const mfsi::CsrMatrix& M, const HostValues& values) {
  mfsi::CsrMatrix out = M;
  out.values = mfsi::RealView("test::values", M.nnz());
  Kokkos::deep_copy(out.values, values);
  return out;
}

}  // namespace

TEST(Amg, CgIterationsStayFlatUnderRefinement) {
  mfsi::ExecSpace exec;
  std::vector<int> amgIts, jacIts;
  for (lid_t n : {16, 24, 32}) {
    const auto A = mfsi::buildPoisson7({n, n, n}, mfsi::ModelBoundary::Dirichlet);
    const auto b = roughRhs(A.nRows, false);
    mfsi::AmgPreconditioner amg;
    amg.setup(exec, A);
    mfsi::JacobiPreconditioner jacobi;
    jacobi.setup(exec, A);
    mfsi::RealView x;
    const auto ra = solveCg(A, b, amg, x);
    ASSERT_TRUE(ra.converged) << mfsi::toString(ra.status);
    EXPECT_LE(trueResidual(A, b, x), 2e-8 * ra.initialResidual);
    const auto rj = solveCg(A, b, jacobi, x);
    ASSERT_TRUE(rj.converged);
    EXPECT_LE(trueResidual(A, b, x), 2e-8 * rj.initialResidual);
    amgIts.push_back(ra.iterations);
    jacIts.push_back(rj.iterations);
    const auto info = amg.info();
    std::cout << "[ amg      ] N=" << n << "^3: AMG-CG " << ra.iterations << " its, Jacobi-CG " << rj.iterations
              << " its; levels " << info.levels.size() << ", coarsest " << info.levels.back().rows
              << " rows, operator complexity " << info.operatorComplexity << "\n";
  }
  // Jacobi-CG grows like N (condition number ~ N^2): ~2x from 16 to 32. AMG-CG is nearly flat.
  EXPECT_GE(jacIts[2], 1.7 * jacIts[0]);
  EXPECT_LE(amgIts[2], 1.3 * amgIts[0]);
  EXPECT_LE(amgIts[2], 20);
  EXPECT_LE(amgIts[1], amgIts[2] + 1);
}

TEST(Amg, HierarchyShape) {
  mfsi::ExecSpace exec;
  const auto A = mfsi::buildPoisson7({24, 24, 24}, mfsi::ModelBoundary::Dirichlet);
  mfsi::AmgPreconditioner amg;
  EXPECT_TRUE(amg.info().levels.empty());
  amg.setup(exec, A);
  const auto info = amg.info();
  ASSERT_GE(info.levels.size(), 3u);
  EXPECT_EQ(info.levels[0].rows, A.nRows);
  EXPECT_EQ(info.levels[0].nnz, A.nnz());
  EXPECT_LE(info.levels.back().rows, 200);
  EXPECT_TRUE(info.directCoarseSolve);
  for (std::size_t l = 1; l < info.levels.size(); ++l) EXPECT_LT(info.levels[l].rows, info.levels[l - 1].rows / 4);
  EXPECT_LT(info.operatorComplexity, 2.0);
  EXPECT_GT(info.operatorComplexity, 1.0);
  // lambda_max(D^{-1}A) of the 7-point Laplacian with Dirichlet walls is just below 2; the
  // Lanczos estimate is a lower bound within a few percent (ten power steps give ~1.7).
  EXPECT_GT(info.levels[0].lambdaMax, 1.85);
  EXPECT_LT(info.levels[0].lambdaMax, 2.0);
}

TEST(Amg, GalerkinOperatorMatchesAHostProduct) {
  // Kernel vs host gold: A_1 = P^T A P computed densely on the host from the device P and A.
  mfsi::ExecSpace exec;
  const auto A = mfsi::buildPoisson7({9, 8, 7}, mfsi::ModelBoundary::Neumann);
  mfsi::AmgOptions opt;
  opt.coarseSize = 20;
  for (auto pro : {mfsi::AmgProlongation::Smoothed, mfsi::AmgProlongation::Unsmoothed}) {
    opt.prolongation = pro;
    mfsi::AmgPreconditioner amg(opt);
    amg.setup(exec, A);
    ASSERT_GE(amg.info().levels.size(), 2u);
    auto dense = [](const mfsi::CsrMatrix& M) {
      auto rp = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), M.rowPtr);
      auto ci = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), M.colIdx);
      auto v = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), M.values);
      std::vector<std::vector<double>> d(M.nRows, std::vector<double>(M.nCols, 0.0));
      for (lid_t i = 0; i < M.nRows; ++i)
        for (lid_t k = rp(i); k < rp(i + 1); ++k) d[i][ci(k)] = v(k);
      return d;
    };
    const auto a = dense(A), p = dense(amg.prolongator(0)), c = dense(amg.levelMatrix(1));
    const std::size_t nf = a.size(), nc = c.size();
    ASSERT_EQ(p[0].size(), nc);
    std::vector<std::vector<double>> ap(nf, std::vector<double>(nc, 0.0));
    for (std::size_t i = 0; i < nf; ++i)
      for (std::size_t k = 0; k < nf; ++k)
        if (a[i][k] != 0.0)
          for (std::size_t J = 0; J < nc; ++J) ap[i][J] += a[i][k] * p[k][J];
    double maxErr = 0, maxVal = 0;
    for (std::size_t I = 0; I < nc; ++I)
      for (std::size_t J = 0; J < nc; ++J) {
        double g = 0;
        for (std::size_t i = 0; i < nf; ++i) g += p[i][I] * ap[i][J];
        maxErr = std::max(maxErr, std::abs(g - c[I][J]));
        maxVal = std::max(maxVal, std::abs(g));
      }
    EXPECT_LE(maxErr, 1e-13 * maxVal);
    // The constant null space survives: P 1 = 1 (smoothing keeps it since A 1 = 0), and every
    // coarse row sums to zero.
    for (std::size_t i = 0; i < nf; ++i) {
      double s = 0;
      for (double v : p[i]) s += v;
      EXPECT_TRUE(near(s, 1.0, Tol{1e-13, 0}, "row sum of P " + std::to_string(i)));
    }
    for (std::size_t I = 0; I < nc; ++I) {
      double s = 0;
      for (double v : c[I]) s += v;
      EXPECT_TRUE(near(s, 0.0, Tol{1e-12 * maxVal, 0}, "row sum of A_1 " + std::to_string(I)));
    }
  }
}

TEST(Amg, OptionsChangeTheCycle) {
  // Smoothed prolongation beats piecewise-constant; Jacobi smoothing works but needs more
  // iterations than Chebyshev; more sweeps, fewer iterations.
  mfsi::ExecSpace exec;
  const auto A = mfsi::buildPoisson7({20, 20, 20}, mfsi::ModelBoundary::Dirichlet);
  const auto b = roughRhs(A.nRows, false);
  auto iterations = [&](const mfsi::AmgOptions& o) {
    mfsi::AmgPreconditioner amg(o);
    amg.setup(exec, A);
    mfsi::RealView x;
    const auto r = solveCg(A, b, amg, x);
    EXPECT_TRUE(r.converged);
    EXPECT_LE(trueResidual(A, b, x), 2e-8 * r.initialResidual);
    return r.iterations;
  };
  mfsi::AmgOptions base;
  const int sa = iterations(base);
  mfsi::AmgOptions ua = base;
  ua.prolongation = mfsi::AmgProlongation::Unsmoothed;
  mfsi::AmgOptions jac = base;
  jac.smoother = mfsi::AmgSmoother::Jacobi;
  mfsi::AmgOptions twoSweeps = base;
  twoSweeps.sweeps = 2;
  // Greedy aggregation (as on unstructured meshes), and lattice cubes (the default on this
  // matrix), whose aligned aggregates suit piecewise-constant prolongation better.
  mfsi::AmgOptions greedy = base, uaGreedy = ua;
  greedy.aggregation = uaGreedy.aggregation = mfsi::AmgAggregation::Greedy;
  const int saGreedy = iterations(greedy), itUaGreedy = iterations(uaGreedy);
  const int itUa = iterations(ua), itJac = iterations(jac), itTwo = iterations(twoSweeps);
  std::cout << "[ amg      ] 20^3: SA+Chebyshev " << sa << ", unsmoothed " << itUa << ", SA+Jacobi " << itJac
            << ", SA+Chebyshev x2 sweeps " << itTwo << " its; greedy aggregation: SA " << saGreedy
            << ", unsmoothed " << itUaGreedy << " its\n";
  EXPECT_GT(itUaGreedy, saGreedy + 3);
  EXPECT_GT(itUa, sa + 2);
  EXPECT_GE(itJac, sa);
  EXPECT_LT(itTwo, sa);
}

TEST(Amg, FinestSweepsChangeBetweenSolvesWithoutASetUp) {
  // setFinestSweeps(2) smooths the finest level twice: fewer iterations than once; back to 0 the
  // cycle is the set-up's again (bitwise the same iterates). Two finest sweeps from the options
  // at set-up give the same cycle as switching to them afterwards.
  mfsi::ExecSpace exec;
  const auto A = mfsi::buildPoisson7({20, 20, 20}, mfsi::ModelBoundary::Dirichlet);
  const auto b = roughRhs(A.nRows, false);
  mfsi::AmgPreconditioner amg;
  amg.setup(exec, A);
  mfsi::RealView x1, x2, x1again, x2fresh;
  const auto once = solveCg(A, b, amg, x1);
  amg.setFinestSweeps(2);
  const auto twice = solveCg(A, b, amg, x2);
  amg.setFinestSweeps(0);
  const auto again = solveCg(A, b, amg, x1again);
  mfsi::AmgOptions o;
  o.finestSweeps = 2;
  mfsi::AmgPreconditioner fresh(o);
  fresh.setup(exec, A);
  const auto fromSetup = solveCg(A, b, fresh, x2fresh);
  std::cout << "[ amg      ] 20^3: finest sweeps 1 / 2: " << once.iterations << " / " << twice.iterations << " its\n";
  EXPECT_TRUE(once.converged && twice.converged);
  EXPECT_LT(twice.iterations, once.iterations);
  EXPECT_EQ(again.iterations, once.iterations);
  EXPECT_EQ(host(x1again), host(x1));
  EXPECT_EQ(fromSetup.iterations, twice.iterations);
  EXPECT_EQ(host(x2fresh), host(x2));
  EXPECT_THROW(amg.setFinestSweeps(-1), std::exception);
}

TEST(Amg, SingularNeumannSystemConverges) {
  mfsi::ExecSpace exec;
  const auto A = mfsi::buildPoisson7({20, 18, 16}, mfsi::ModelBoundary::Neumann);
  const lid_t n = A.nRows;
  const mfsi::SolverComm comm;
  mfsi::AmgPreconditioner amg;
  amg.setup(exec, A);
  mfsi::JacobiPreconditioner jacobi;
  jacobi.setup(exec, A);

  // Consistent right-hand side (zero mean): the true residual goes to zero, x has zero mean.
  const auto b = roughRhs(n, true);
  mfsi::RealView x;
  const auto ra = solveCg(A, b, amg, x, mfsi::NullSpace::Constant);
  ASSERT_TRUE(ra.converged) << mfsi::toString(ra.status);
  EXPECT_LE(ra.iterations, 20);
  EXPECT_LE(trueResidual(A, b, x), 2e-8 * ra.initialResidual);
  EXPECT_TRUE(near(mfsi::blas::mean(exec, comm, n, x), 0.0, Tol{1e-12, 0}, "mean of x"));
  const auto rj = solveCg(A, b, jacobi, x, mfsi::NullSpace::Constant);
  ASSERT_TRUE(rj.converged);
  EXPECT_LE(trueResidual(A, b, x), 2e-8 * rj.initialResidual);
  EXPECT_GT(rj.iterations, 2 * ra.iterations);

  // Inconsistent right-hand side (mean 0.3): the solver converges on its consistent part; the
  // remaining residual is the constant mean(b) in every row.
  const auto bi = roughRhs(n, false);
  const double mb = mfsi::blas::mean(exec, comm, n, bi);
  ASSERT_GT(std::abs(mb), 0.1);
  const auto ri = solveCg(A, bi, amg, x, mfsi::NullSpace::Constant);
  ASSERT_TRUE(ri.converged);
  mfsi::RealView r("r", n);
  mfsi::blas::residual(exec, comm, A, x, bi, r);
  const HostVec hr = host(r);
  double dev = 0;
  for (double v : hr) dev = std::max(dev, std::abs(v - mb));
  EXPECT_LE(dev, 1e-7 * ri.initialResidual);

  // Without the projection the same inconsistent system cannot converge: reported, not thrown.
  mfsi::KrylovOptions opt;
  opt.maxIterations = 50;
  mfsi::RealView x2("x2", n);
  const auto rn = mfsi::ConjugateGradient(opt).solve(exec, A, bi, x2, amg);
  EXPECT_FALSE(rn.converged);
}

TEST(Amg, UpdateValuesReusesTheHierarchyAndMatchesAFreshSetup) {
  mfsi::ExecSpace exec;
  auto A = mfsi::buildPoisson7({18, 18, 18}, mfsi::ModelBoundary::Dirichlet);
  const auto b = roughRhs(A.nRows, false);
  mfsi::AmgPreconditioner amg;
  amg.setup(exec, A);
  const auto before = amg.info();
  auto original = Kokkos::create_mirror(A.values);  // a real copy (a mirror *view* may alias on the host)
  Kokkos::deep_copy(original, A.values);

  // New values, same sparsity, refilled in place: a variable-coefficient operator with k_ij in
  // [0.5, 2] (what changes from step to step with mesh motion).
  {
    auto rp = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), A.rowPtr);
    auto ci = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), A.colIdx);
    auto hv = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), A.values);
    for (lid_t i = 0; i < A.nRows; ++i) {
      double diag = 0;
      lid_t d = -1;
      for (lid_t k = rp(i); k < rp(i + 1); ++k) {
        const lid_t j = ci(k);
        if (j == i) {
          d = k;
          continue;
        }
        const double kij = 1.25 + 0.75 * std::sin(0.1 * (i + j));  // symmetric in i, j
        hv(k) = -kij;
        diag += kij;
      }
      hv(d) = diag + 2.0 * (6 - (rp(i + 1) - rp(i) - 1));
    }
    Kokkos::deep_copy(A.values, hv);
  }
  // Finest-level refresh only: coarse levels still hold the old operator. Still converges, a
  // little slower than the full update below.
  mfsi::AmgPreconditioner stale;
  stale.setup(exec, B0(A, original));
  stale.updateFinestSmoother(exec, A);
  mfsi::RealView xs;
  const auto rs = solveCg(A, b, stale, xs);
  EXPECT_TRUE(rs.converged);
  EXPECT_LE(trueResidual(A, b, xs), 2e-8 * rs.initialResidual);

  amg.updateValues(exec, A);
  const auto after = amg.info();
  ASSERT_EQ(after.levels.size(), before.levels.size());
  for (std::size_t l = 0; l < after.levels.size(); ++l) {
    EXPECT_EQ(after.levels[l].rows, before.levels[l].rows);
    EXPECT_EQ(after.levels[l].nnz, before.levels[l].nnz);
  }
  EXPECT_GT(std::abs(after.levels[0].lambdaMax - before.levels[0].lambdaMax), 1e-3);
  mfsi::RealView x;
  const auto r = solveCg(A, b, amg, x);
  EXPECT_TRUE(r.converged);
  EXPECT_LE(r.iterations, 20);
  EXPECT_LE(trueResidual(A, b, x), 2e-8 * r.initialResidual);
  std::cout << "[ amg      ] variable coefficients: full update " << r.iterations << " its, finest-level refresh "
            << rs.iterations << " its\n";
  EXPECT_LE(rs.iterations, 2 * r.iterations);

  // Back to the original values: the updated hierarchy is the one a fresh set-up builds (same
  // aggregates, every value recomputed), so the V-cycles agree to rounding.
  Kokkos::deep_copy(A.values, original);
  amg.updateValues(exec, A);
  mfsi::AmgPreconditioner fresh;
  fresh.setup(exec, A);
  mfsi::RealView z1("z1", A.nRows), z2("z2", A.nRows);
  amg.apply(exec, b, z1);
  fresh.apply(exec, b, z2);
  const HostVec h1 = host(z1), h2 = host(z2);
  EXPECT_TRUE(mfsi::test::allNear(h1, h2, h1.size(), Tol{1e-13, 1e-12}, "updated vs fresh V-cycle"));

  // A different sparsity falls back to a full set-up.
  const auto B = mfsi::buildPoisson7({10, 10, 10}, mfsi::ModelBoundary::Dirichlet);
  amg.updateValues(exec, B);
  EXPECT_EQ(amg.info().levels[0].rows, 1000);
}

TEST(Amg, PressureMatrixOfAGradedHexMesh) {
  // The fluid's use: FV Laplacian assembled through the face map on a stretched (graded) box,
  // pure Neumann, with cells up to 8:1 aspect ratio near a wall.
  mfsi::BlockMeshSpec spec = mfsi::boxSpec({0, 0, 0}, {1, 1, 1}, {20, 20, 20});
  spec.blocks[0].grading = {1, 1, 8};
  const auto mesh = mfsi::buildHexMesh(mfsi::generateBlockMesh(spec));
  auto geo = mfsi::allocateGeometry(mesh);
  mfsi::ExecSpace exec;
  mfsi::computeGeometry(exec, mesh, geo);
  const auto cc = mfsi::buildCellCsr(mesh);
  mfsi::test::assembleFvLaplacian(exec, mesh, geo, cc);
  const auto& A = cc.matrix;
  const auto b = roughRhs(A.nRows, true);
  mfsi::AmgPreconditioner amg;
  amg.setup(exec, A);
  mfsi::JacobiPreconditioner jacobi;
  jacobi.setup(exec, A);
  mfsi::RealView x;
  const auto ra = solveCg(A, b, amg, x, mfsi::NullSpace::Constant);
  ASSERT_TRUE(ra.converged);
  EXPECT_LE(trueResidual(A, b, x), 2e-8 * ra.initialResidual);
  const auto rj = solveCg(A, b, jacobi, x, mfsi::NullSpace::Constant);
  std::cout << "[ amg      ] graded 20^3 Neumann: AMG-CG " << ra.iterations << " its, Jacobi-CG " << rj.iterations
            << " its\n";
  EXPECT_LE(ra.iterations, 25);
  EXPECT_LT(3 * ra.iterations, rj.iterations);
}

TEST(Amg, PreconditionsBiCGStabOnMildConvection) {
  // Not its design target, but the fluid may try it on the momentum equation: Poisson plus
  // first-order upwind convection in x (non-symmetric; the coarsest level then takes the
  // non-symmetric pseudo-inverse path).
  mfsi::ExecSpace exec;
  const lid_t n = 16;
  auto A = mfsi::buildPoisson7({n, n, n}, mfsi::ModelBoundary::Dirichlet);
  {
    auto rp = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), A.rowPtr);
    auto ci = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), A.colIdx);
    auto hv = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), A.values);
    const std::vector<lid_t> rpv(rp.data(), rp.data() + rp.extent(0)), civ(ci.data(), ci.data() + ci.extent(0));
    const double pe = 2.0;
    for (lid_t c = 0; c < A.nRows; ++c) {
      hv(mfsi::findEntry(rpv, civ, c, c)) += pe;
      if (c % n > 0) hv(mfsi::findEntry(rpv, civ, c, c - 1)) -= pe;
    }
    Kokkos::deep_copy(A.values, hv);
  }
  const auto b = roughRhs(A.nRows, false);
  mfsi::AmgPreconditioner amg;
  amg.setup(exec, A);
  mfsi::JacobiPreconditioner jacobi;
  jacobi.setup(exec, A);
  mfsi::KrylovOptions opt;
  opt.relTol = 1e-8;
  mfsi::BiCGStab solver(opt);
  mfsi::RealView x("x", A.nRows);
  const auto ra = solver.solve(exec, A, b, x, amg);
  ASSERT_TRUE(ra.converged) << mfsi::toString(ra.status);
  EXPECT_LE(trueResidual(A, b, x), 2e-8 * ra.initialResidual);
  Kokkos::deep_copy(x, 0.0);
  const auto rj = solver.solve(exec, A, b, x, jacobi);
  ASSERT_TRUE(rj.converged);
  std::cout << "[ amg      ] 16^3 upwind Pe=2: AMG-BiCGStab " << ra.iterations << " its, Jacobi-BiCGStab "
            << rj.iterations << " its\n";
  EXPECT_LT(2 * ra.iterations, rj.iterations);
}

TEST(Amg, TinySystemIsSolvedDirectly) {
  // Below coarseSize the hierarchy is one level: the preconditioner is the exact inverse, and CG
  // converges in one iteration.
  mfsi::ExecSpace exec;
  const auto A = mfsi::buildPoisson7({5, 4, 3}, mfsi::ModelBoundary::Dirichlet);
  const auto b = roughRhs(A.nRows, false);
  mfsi::AmgPreconditioner amg;
  amg.setup(exec, A);
  ASSERT_EQ(amg.info().levels.size(), 1u);
  mfsi::RealView x;
  const auto r = solveCg(A, b, amg, x);
  EXPECT_TRUE(r.converged);
  EXPECT_EQ(r.iterations, 1);
  EXPECT_LE(trueResidual(A, b, x), 1e-10 * r.initialResidual);
}

namespace {

/// Host copy of a device CSR matrix, for the serial reference cycle.
struct HostMatrix {
  lid_t nRows = 0, nCols = 0;
  std::vector<lid_t> ptr, col;
  std::vector<double> val;
  std::vector<double> apply(const std::vector<double>& x) const {
    std::vector<double> y(nRows, 0.0);
    for (lid_t i = 0; i < nRows; ++i)
      for (lid_t k = ptr[i]; k < ptr[i + 1]; ++k) y[i] += val[k] * x[col[k]];
    return y;
  }
  std::vector<double> applyTransposed(const std::vector<double>& x) const {
    std::vector<double> y(nCols, 0.0);
    for (lid_t i = 0; i < nRows; ++i)
      for (lid_t k = ptr[i]; k < ptr[i + 1]; ++k) y[col[k]] += val[k] * x[i];
    return y;
  }
  double diag(lid_t i) const {
    for (lid_t k = ptr[i]; k < ptr[i + 1]; ++k)
      if (col[k] == i) return val[k];
    return 0.0;
  }
};

HostMatrix hostMatrix(const mfsi::CsrMatrix& M) {
  HostMatrix h;
  h.nRows = M.nRows;
  h.nCols = M.nCols;
  auto rp = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), M.rowPtr);
  auto ci = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), M.colIdx);
  auto v = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), M.values);
  h.ptr.assign(rp.data(), rp.data() + rp.extent(0));
  h.col.assign(ci.data(), ci.data() + ci.extent(0));
  h.val.assign(v.data(), v.data() + v.extent(0));
  return h;
}

/// The documented V-cycle, serially and in double, on the hierarchy of `amg` (its level matrices,
/// prolongators and lambda_max): the smoother polynomial of `opt`'s kind and degree in D^{-1}A
/// with rho = 1.1 lambda_max (1.1: Amg.cpp's margin over the Lanczos estimate) - 4th kind
/// (Lottes 2023) on [0, rho], or first kind on [rho / ratio, rho] - `sweeps` before and after the
/// coarse correction, R = P^T, and 10 sweeps on a coarsest level that is not solved densely (set
/// maxDirectSize = 0). Written from the textbook forms, with none of the cycle's scaling, layouts
/// or fusions.
std::vector<double> referenceCycle(const mfsi::AmgPreconditioner& amg, std::size_t l, const std::vector<double>& b) {
  const auto& o = amg.options();
  const HostMatrix A = hostMatrix(amg.levelMatrix(l));
  const auto info = amg.info();
  const bool coarsest = l + 1 == info.levels.size();
  const double lmax = 1.1 * info.levels[l].lambdaMax, lmin = lmax / o.chebyshevRatio;
  const double theta = 0.5 * (lmax + lmin), delta = 0.5 * (lmax - lmin), sigma = theta / delta;
  const bool fourth = o.smoother == mfsi::AmgSmoother::ChebyshevFourthKind;
  std::vector<double> x(A.nRows, 0.0), d(A.nRows, 0.0);
  auto smooth = [&](int sweeps) {
    for (int s = 0; s < sweeps; ++s) {
      double rho = 1.0 / sigma;
      for (int k = 0; k < o.chebyshevDegree; ++k) {
        double c1 = 0.0, c2 = 0.0;
        if (fourth) {
          // d_k = (2k - 1) / (2k + 3) d_{k-1} + (8k + 4) / ((2k + 3) lmax) D^{-1} r_k, d_0 = 4 / (3 lmax) D^{-1} r_0
          c1 = k == 0 ? 0.0 : (2.0 * k - 1.0) / (2.0 * k + 3.0);
          c2 = k == 0 ? 4.0 / (3.0 * lmax) : (8.0 * k + 4.0) / ((2.0 * k + 3.0) * lmax);
        } else {
          const double rhoNew = k == 0 ? rho : 1.0 / (2.0 * sigma - rho);
          c1 = k == 0 ? 0.0 : rhoNew * rho;
          c2 = k == 0 ? 1.0 / theta : 2.0 * rhoNew / delta;
          rho = rhoNew;
        }
        const std::vector<double> ax = A.apply(x);
        for (lid_t i = 0; i < A.nRows; ++i) {
          d[i] = c1 * d[i] + c2 * (b[i] - ax[i]) / A.diag(i);
          x[i] += d[i];
        }
      }
    }
  };
  if (coarsest) {
    smooth(10);
    return x;
  }
  smooth(o.sweeps);
  const std::vector<double> ax = A.apply(x);
  std::vector<double> r(A.nRows);
  for (lid_t i = 0; i < A.nRows; ++i) r[i] = b[i] - ax[i];
  const HostMatrix P = hostMatrix(amg.prolongator(l));
  const std::vector<double> xc = referenceCycle(amg, l + 1, P.applyTransposed(r));
  const std::vector<double> px = P.apply(xc);
  for (lid_t i = 0; i < A.nRows; ++i) x[i] += px[i];
  smooth(o.sweeps);
  return x;
}

/// The 7-point Poisson matrix with rows and columns renumbered by a fixed pseudo-random
/// permutation: no two rows share a column pattern relative to the row.
mfsi::CsrMatrix shuffled(const mfsi::CsrMatrix& M) {
  const HostMatrix h = hostMatrix(M);
  const lid_t n = h.nRows;
  const std::vector<lid_t> perm = mfsi::test::randomPermutation(n, 12345u);
  std::vector<lid_t> inv(n);
  for (lid_t i = 0; i < n; ++i) inv[perm[i]] = i;
  // New row perm[i] = old row i, columns mapped and sorted.
  std::vector<lid_t> ptr(n + 1, 0), col, diag(n);
  std::vector<double> val;
  for (lid_t r = 0; r < n; ++r) {
    const lid_t i = inv[r];
    std::vector<std::pair<lid_t, double>> row;
    for (lid_t k = h.ptr[i]; k < h.ptr[i + 1]; ++k) row.emplace_back(perm[h.col[k]], h.val[k]);
    std::sort(row.begin(), row.end());
    for (const auto& [c, v] : row) {
      if (c == r) diag[r] = static_cast<lid_t>(col.size());
      col.push_back(c);
      val.push_back(v);
    }
    ptr[r + 1] = static_cast<lid_t>(col.size());
  }
  mfsi::CsrMatrix out;
  out.nRows = out.nCols = n;
  auto upload = [](const auto& v, const std::string& label) {
    using T = typename std::decay_t<decltype(v)>::value_type;
    Kokkos::View<T*, mfsi::MemSpace> d(label, v.size());
    Kokkos::deep_copy(
        d, Kokkos::View<const T*, mfsi::HostSpace, Kokkos::MemoryTraits<Kokkos::Unmanaged>>(v.data(), v.size()));
    return d;
  };
  out.rowPtr = upload(ptr, "test::rowPtr");
  out.colIdx = upload(col, "test::colIdx");
  out.diagIdx = upload(diag, "test::diagIdx");
  out.values = upload(val, "test::values");
  return out;
}

}  // namespace

TEST(Amg, CycleMatchesASerialTextbookVCycle) {
  // Kernel vs host gold. The device cycle runs on D^{-1}-scaled off-diagonal copies, in ELL rows
  // with column patterns (natural order; level 1 of the lattice cube aggregates: ELL32, of the 2D
  // squares: ELL12), ELL rows with explicit columns (shuffled order: no shared patterns; the
  // restriction of cube aggregates), ELL4 (one cell thick, 5-point) and CSR (coarse levels of
  // greedy aggregation), with fused smoother steps; the reference is the plain cycle on the
  // set-up's double matrices.
  mfsi::ExecSpace exec;
  const auto natural = mfsi::buildPoisson7({16, 16, 16}, mfsi::ModelBoundary::Dirichlet);
  const std::vector<std::pair<std::string, mfsi::CsrMatrix>> cases = {
      {"16^3", natural},
      {"16^3 shuffled", shuffled(natural)},
      {"30x30x1 Neumann", mfsi::buildPoisson7({30, 30, 1}, mfsi::ModelBoundary::Neumann)}};
  for (const auto& [name, A] : cases) {
    const auto b = roughRhs(A.nRows, true);
    std::vector<double> hb = host(b);
    // Both smoother kinds: the 4th-kind default (degree 2) and the first kind (degree 3).
    for (auto [precision, kind] : {std::pair{mfsi::AmgPrecision::Double, mfsi::AmgSmoother::ChebyshevFourthKind},
                                   std::pair{mfsi::AmgPrecision::Mixed, mfsi::AmgSmoother::ChebyshevFourthKind},
                                   std::pair{mfsi::AmgPrecision::Double, mfsi::AmgSmoother::Chebyshev},
                                   std::pair{mfsi::AmgPrecision::Mixed, mfsi::AmgSmoother::Chebyshev}}) {
      mfsi::AmgOptions o;
      o.smoother = kind;
      o.chebyshevDegree = kind == mfsi::AmgSmoother::Chebyshev ? 3 : 2;
      o.maxDirectSize = 0;
      o.coarseSize = 30;
      o.precision = precision;
      mfsi::AmgPreconditioner amg(o);
      amg.setup(exec, A);
      const auto info = amg.info();
      ASSERT_GE(info.levels.size(), 3u) << name;
      // The layouts named above are the ones exercised.
      const bool lattice = name != "16^3 shuffled";
      EXPECT_EQ(info.levels[0].cyclePatterned, lattice) << name;
      EXPECT_EQ(info.levels[1].cyclePatterned, lattice) << name;
      EXPECT_EQ(info.levels[1].cycleWidth, !lattice ? 0 : name == "16^3" ? 32 : 12) << name;
      const std::vector<double> gold = referenceCycle(amg, 0, hb);
      mfsi::RealView z("test::z", A.nRows);
      amg.apply(exec, b, z);
      const HostVec hz = host(z);
      double scale = 0;
      for (double v : gold) scale = std::max(scale, std::abs(v));
      // Double: the same arithmetic up to the order of operations. Mixed: float rounding, a few
      // 1e-7 relative per operation, through ~20 operations per level.
      const bool dbl = precision == mfsi::AmgPrecision::Double;
      const Tol tol = dbl ? Tol{1e-12 * scale, 1e-11} : Tol{1e-5 * scale, 1e-5};
      const std::string what = name + (dbl ? " double" : " mixed") + (o.chebyshevDegree == 3 ? " first kind" : "");
      EXPECT_TRUE(mfsi::test::allNear(hz, gold, gold.size(), tol, what));
      if (!dbl) {
        // Mixed really runs in float: it differs from the double cycle by rounding.
        double maxDiff = 0;
        for (std::size_t i = 0; i < gold.size(); ++i) maxDiff = std::max(maxDiff, std::abs(hz[i] - gold[i]));
        EXPECT_GT(maxDiff, 1e-10 * scale) << what;
      }
    }
  }
}

TEST(Amg, MixedPrecisionKeepsIterationsAndIsRepeatable) {
  mfsi::ExecSpace exec;
  const mfsi::SolverComm comm;
  mfsi::AmgOptions dbl, mixed;
  dbl.precision = mfsi::AmgPrecision::Double;
  mixed.precision = mfsi::AmgPrecision::Mixed;

  // Dirichlet 32^3: the mixed cycle converges CG to 1e-8 in at most one iteration more.
  const auto A = mfsi::buildPoisson7({32, 32, 32}, mfsi::ModelBoundary::Dirichlet);
  const auto b = roughRhs(A.nRows, false);
  mfsi::AmgPreconditioner amgD(dbl), amgM(mixed);
  amgD.setup(exec, A);
  amgM.setup(exec, A);
  mfsi::RealView xd, xm;
  const auto rd = solveCg(A, b, amgD, xd);
  const auto rm = solveCg(A, b, amgM, xm);
  ASSERT_TRUE(rd.converged && rm.converged);
  std::cout << "[ amg      ] 32^3 Dirichlet: double cycle " << rd.iterations << " its, mixed " << rm.iterations
            << " its\n";
  EXPECT_LE(rm.iterations, rd.iterations + 1);
  EXPECT_LE(trueResidual(A, b, xm), 2e-8 * rm.initialResidual);

  // Bitwise repeatable: the same solve again, and with a second preconditioner set up alike.
  mfsi::AmgPreconditioner amgM2(mixed);
  amgM2.setup(exec, A);
  mfsi::RealView xm2, xm3;
  const auto rm2 = solveCg(A, b, amgM, xm2);
  const auto rm3 = solveCg(A, b, amgM2, xm3);
  EXPECT_EQ(rm2.iterations, rm.iterations);
  EXPECT_EQ(rm3.iterations, rm.iterations);
  const HostVec h1 = host(xm), h2 = host(xm2), h3 = host(xm3);
  std::size_t diff2 = 0, diff3 = 0;
  for (std::size_t i = 0; i < h1.size(); ++i) {
    diff2 += h1[i] != h2[i] ? 1 : 0;
    diff3 += h1[i] != h3[i] ? 1 : 0;
  }
  EXPECT_EQ(diff2, 0u);
  EXPECT_EQ(diff3, 0u);

  // Pure Neumann (singular), consistent right-hand side: converges to the zero-mean solution.
  const auto N = mfsi::buildPoisson7({20, 18, 16}, mfsi::ModelBoundary::Neumann);
  const auto bn = roughRhs(N.nRows, true);
  mfsi::AmgPreconditioner nD(dbl), nM(mixed);
  nD.setup(exec, N);
  nM.setup(exec, N);
  const auto nd = solveCg(N, bn, nD, xd, mfsi::NullSpace::Constant);
  const auto nm = solveCg(N, bn, nM, xm, mfsi::NullSpace::Constant);
  ASSERT_TRUE(nd.converged && nm.converged) << mfsi::toString(nm.status);
  std::cout << "[ amg      ] 20x18x16 Neumann: double cycle " << nd.iterations << " its, mixed " << nm.iterations
            << " its\n";
  EXPECT_LE(nm.iterations, nd.iterations + 1);
  EXPECT_LE(trueResidual(N, bn, xm), 2e-8 * nm.initialResidual);
  EXPECT_TRUE(near(mfsi::blas::mean(exec, comm, N.nRows, xm), 0.0, Tol{1e-12, 0}, "mean of x"));
}

TEST(Amg, VCycleIsSymmetricAndPositive) {
  // Plain CG needs a symmetric positive (semi)definite preconditioner: <M u, v> = <u, M v> and
  // <M u, u> > 0, here for two rough vectors, on an SPD and a singular (Neumann, zero-mean
  // vectors) matrix. Float rounding breaks the symmetry at the 1e-7 level only.
  mfsi::ExecSpace exec;
  for (auto bc : {mfsi::ModelBoundary::Dirichlet, mfsi::ModelBoundary::Neumann}) {
    const auto A = mfsi::buildPoisson7({16, 14, 12}, bc);
    const bool neumann = bc == mfsi::ModelBoundary::Neumann;
    for (auto precision : {mfsi::AmgPrecision::Double, mfsi::AmgPrecision::Mixed}) {
      mfsi::AmgOptions o;
      o.precision = precision;
      mfsi::AmgPreconditioner amg(o);
      amg.setup(exec, A);
      const double rel = precision == mfsi::AmgPrecision::Double ? 1e-12 : 1e-5;
      const std::string what = std::string(neumann ? "Neumann" : "Dirichlet") +
                               (precision == mfsi::AmgPrecision::Double ? " double" : " mixed");
      mfsi::test::expectSymmetricPositive(amg, A.nRows, neumann, rel, what);
    }
  }
}
