// Algebraic multigrid: mesh-independent CG iterations on the 3D Poisson equation (Jacobi-CG
// iterations double from 16^3 to 32^3, AMG-CG iterations do not), singular Neumann systems,
// value updates on a fixed sparsity, and a finite-volume matrix assembled on a graded hex mesh.
#include "kernels/Amg.hpp"

#include "core/BlockMesh.hpp"
#include "core/MeshGeometry.hpp"
#include "kernels/CsrBuild.hpp"
#include "kernels/Krylov.hpp"
#include "support/Approx.hpp"

#include <cmath>
#include <iostream>
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
mfsi::RealView roughRhs(lid_t n, bool zeroMean) {
  mfsi::RealView b("test::b", n);
  auto h = Kokkos::create_mirror_view(b);
  double s = 0;
  for (lid_t i = 0; i < n; ++i) {
    h(i) = std::sin(0.7 * i) + std::cos(0.013 * i * i) + 0.3;
    s += h(i);
  }
  if (zeroMean)
    for (lid_t i = 0; i < n; ++i) h(i) -= s / n;
  Kokkos::deep_copy(b, h);
  return b;
}

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
  const int itUa = iterations(ua), itJac = iterations(jac), itTwo = iterations(twoSweeps);
  std::cout << "[ amg      ] 20^3: SA+Chebyshev " << sa << ", unsmoothed " << itUa << ", SA+Jacobi " << itJac
            << ", SA+Chebyshev x2 sweeps " << itTwo << " its\n";
  EXPECT_GT(itUa, sa + 3);
  EXPECT_GE(itJac, sa);
  EXPECT_LT(itTwo, sa);
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
  const auto offs = mesh.cellFaceOffsets();
  const auto faces = mesh.cellFaces();
  const auto owner = mesh.faceOwner(), neigh = mesh.faceNeighbour();
  const auto pn = cc.faceMap.ownerRow, np = cc.faceMap.neighbourRow;
  const auto diag = cc.matrix.diagIdx;
  const auto val = cc.matrix.values;
  const auto area = geo.faceAreaMag;
  const auto cen = geo.cellCentroid;
  const lid_t nIf = mesh.nInternalFaces();
  Kokkos::parallel_for(
      "test::assemble", mfsi::RangePolicy(exec, 0, mesh.nCells()), KOKKOS_LAMBDA(lid_t c) {
        double d = 0;
        for (lid_t k = offs(c); k < offs(c + 1); ++k) {
          const lid_t f = faces(k);
          if (f >= nIf) continue;
          const lid_t P = owner(f), N = neigh(f);
          const double dx = cen(N, 0) - cen(P, 0), dy = cen(N, 1) - cen(P, 1), dz = cen(N, 2) - cen(P, 2);
          const double coef = area(f) / mfsi::kmath::sqrt(dx * dx + dy * dy + dz * dz);
          val(c == P ? pn(f) : np(f)) = -coef;
          d += coef;
        }
        val(diag(c)) = d;
      });
  exec.fence();
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
