// CG's symmetric lattice copy (SymmetricLatticeMatrix, ConjugateGradient::matrixChanged): the
// lattice product and p.q equal the CSR ones to rounding on 7-point matrices with variable
// coefficients (Dirichlet and singular Neumann, several blocks of rows, non-cubic extents) and on
// a one-cell-thick 5-point lattice; no copy (CSR, identical results) for a matrix with one
// asymmetric coupling, a shuffled numbering and an unstructured-like sparsity; whole AMG-CG
// solves with and without the copy agree; a copy is never used for another matrix object.
// Also the lane-split deterministic reduction (blas::reduceLanes) against a host sum.
#include "kernels/Amg.hpp"
#include "kernels/CsrBuild.hpp"
#include "kernels/Krylov.hpp"
#include "kernels/LatticeMatrix.hpp"
#include "support/AmgChecks.hpp"
#include "support/Approx.hpp"
#include "support/HostVectors.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

namespace {

using mfsi::lid_t;
using mfsi::test::HostCsr;
using mfsi::test::HostVec;
using mfsi::test::near;
using mfsi::test::Tol;

using Adjacency = std::vector<std::vector<lid_t>>;

/// Symmetric variable coefficients on A's sparsity: a_ij = a_ji = -(1 + 0.6 sin(0.37 i + 1.3 j))
/// for i < j, and a_ii = sum_j |a_ij| + (dirichlet ? 0.5 + 0.3 cos(i) : 0) (Neumann: rows sum to
/// zero, singular with the constants as null space).
void setSymmetricValues(mfsi::CsrMatrix& A, bool dirichlet) {
  HostCsr h(A);
  for (lid_t i = 0; i < h.n; ++i) {
    double off = 0.0;
    lid_t diag = -1;
    for (lid_t k = h.rowPtr[i]; k < h.rowPtr[i + 1]; ++k) {
      const lid_t j = h.colIdx[k];
      if (j == i) {
        diag = k;
        continue;
      }
      const lid_t a = std::min(i, j), b = std::max(i, j);
      h.values[k] = -(1.0 + 0.6 * std::sin(0.37 * a + 1.3 * b));
      off += std::abs(h.values[k]);
    }
    ASSERT_GE(diag, 0);
    h.values[diag] = off + (dirichlet ? 0.5 + 0.3 * std::cos(1.0 * i) : 0.0);
  }
  Kokkos::deep_copy(A.values, mfsi::hostView(h.values));
}

/// The 7-point (nz = 1: 5-point) lattice sparsity with symmetric variable coefficients.
mfsi::CsrMatrix latticeMatrix(std::array<lid_t, 3> n, bool dirichlet) {
  auto A = mfsi::buildPoisson7(n, dirichlet ? mfsi::ModelBoundary::Dirichlet : mfsi::ModelBoundary::Neumann);
  setSymmetricValues(A, dirichlet);
  return A;
}

/// A x and w.(A x) in CSR (blas::spmvDot) and from a lattice copy of A; checks that the copy is
/// made and that both agree to `rel` (entries relative to max |A x|).
void expectLatticeProductMatchesCsr(const mfsi::CsrMatrix& A, std::array<lid_t, 3> extents, const std::string& what) {
  const mfsi::ExecSpace exec;
  const mfsi::SolverComm comm;
  mfsi::SymmetricLatticeMatrix L;
  ASSERT_TRUE(L.update(exec, A)) << what;
  EXPECT_TRUE(L.matches(A)) << what;
  EXPECT_EQ(L.nx(), extents[0]) << what;
  EXPECT_EQ(L.ny(), extents[1]) << what;
  EXPECT_EQ(L.nz(), extents[2]) << what;
  const lid_t n = A.nRows;
  const mfsi::RealView p = mfsi::test::roughVector(n, false, 0), w = mfsi::test::roughVector(n, false, 1);
  mfsi::RealView qCsr("test::qCsr", n), qLat("test::qLat", n), qLat2("test::qLat2", n);
  for (const auto& [wv, name] : {std::make_pair(p, "p.Ap"), std::make_pair(w, "w.Ap")}) {
    const double dCsr = mfsi::blas::spmvDot(exec, comm, A, p, qCsr, wv);
    const double dLat = L.spmvDot(exec, comm, p, qLat, wv);
    const HostVec a = mfsi::test::host(qLat), b = mfsi::test::host(qCsr);
    EXPECT_LE(mfsi::test::relDiff(a, b), 1e-14) << what << " " << name;
    // |sum| may be much smaller than the sum of |terms|: compare relative to the latter.
    double scale = 0.0;
    const HostVec wh = mfsi::test::host(wv);
    for (lid_t i = 0; i < n; ++i) scale += std::abs(wh[i] * b[i]);
    EXPECT_TRUE(near(dLat, dCsr, Tol{0.0, 1e-14 * scale / std::max(std::abs(dCsr), 1e-300)}, what + " " + name));
  }
  // And against a host gold (catches a kernel shared by both paths).
  const HostVec gold = HostCsr(A).apply(mfsi::test::host(p));
  EXPECT_LE(mfsi::test::relDiff(mfsi::test::host(qLat), gold), 1e-14) << what << " vs host";
  L.spmv(exec, p, qLat2);
  EXPECT_LE(mfsi::test::relDiff(mfsi::test::host(qLat2), gold), 1e-14) << what << " spmv vs host";
}

TEST(CgLattice, ProductMatchesCsr3D) {
  for (const bool dirichlet : {true, false}) {
    const std::string bc = dirichlet ? "Dirichlet" : "Neumann";
    // Non-cubic extents (nx, ny, nz all different) and several blocks of rows with interior planes.
    for (const std::array<lid_t, 3> e : {std::array<lid_t, 3>{20, 17, 13}, std::array<lid_t, 3>{7, 5, 6},
                                         std::array<lid_t, 3>{3, 2, 2}}) {
      const auto A = latticeMatrix(e, dirichlet);
      expectLatticeProductMatchesCsr(A, e, bc + " " + std::to_string(e[0]) + "x" + std::to_string(e[1]) + "x" +
                                               std::to_string(e[2]));
    }
  }
}

TEST(CgLattice, ProductMatchesCsrOneCellThick) {
  for (const bool dirichlet : {true, false}) {
    const std::array<lid_t, 3> e{37, 29, 1};
    const auto A = latticeMatrix(e, dirichlet);
    expectLatticeProductMatchesCsr(A, e, std::string("5-point ") + (dirichlet ? "Dirichlet" : "Neumann"));
  }
}

/// The lattice adjacency renumbered by a fixed pseudo-random permutation.
Adjacency shuffledLattice(lid_t nx, lid_t ny, lid_t nz) {
  const lid_t n = nx * ny * nz;
  const std::vector<lid_t> perm = mfsi::test::randomPermutation(n, 4242u);
  Adjacency adj(n);
  for (lid_t z = 0; z < nz; ++z)
    for (lid_t y = 0; y < ny; ++y)
      for (lid_t x = 0; x < nx; ++x) {
        const lid_t i = x + nx * (y + ny * z);
        auto& a = adj[perm[i]];
        if (x > 0) a.push_back(perm[i - 1]);
        if (x + 1 < nx) a.push_back(perm[i + 1]);
        if (y > 0) a.push_back(perm[i - nx]);
        if (y + 1 < ny) a.push_back(perm[i + nx]);
        if (z > 0) a.push_back(perm[i - nx * ny]);
        if (z + 1 < nz) a.push_back(perm[i + nx * ny]);
      }
  return adj;
}

/// Unstructured-like: the lattice couplings plus a diagonal coupling (x+1, y+1) in every third
/// row, so rows have 7 to 9 entries.
Adjacency irregularLattice(lid_t nx, lid_t ny, lid_t nz) {
  Adjacency adj(nx * ny * nz);
  for (lid_t z = 0; z < nz; ++z)
    for (lid_t y = 0; y < ny; ++y)
      for (lid_t x = 0; x < nx; ++x) {
        const lid_t i = x + nx * (y + ny * z);
        if (x + 1 < nx) adj[i].push_back(i + 1), adj[i + 1].push_back(i);
        if (y + 1 < ny) adj[i].push_back(i + nx), adj[i + nx].push_back(i);
        if (z + 1 < nz) adj[i].push_back(i + nx * ny), adj[i + nx * ny].push_back(i);
        if (i % 3 == 0 && x + 1 < nx && y + 1 < ny) adj[i].push_back(i + nx + 1), adj[i + nx + 1].push_back(i);
      }
  return adj;
}

/// Solves A x = b by AMG-CG from x = 0 (AMG set up once per matrix by the caller), with or
/// without announcing A to the solver.
struct CgRun {
  mfsi::KrylovResult result;
  HostVec x;
  bool usedCopy = false;
};
CgRun solveCg(const mfsi::CsrMatrix& A, const mfsi::RealView& b, mfsi::Preconditioner& M, bool announce,
              bool neumann) {
  const mfsi::ExecSpace exec;
  mfsi::KrylovOptions o;
  o.relTol = 1e-10;
  o.maxIterations = 200;
  if (neumann) o.nullSpace = mfsi::NullSpace::Constant;
  mfsi::ConjugateGradient cg(o);
  if (announce) cg.matrixChanged(exec, A);
  mfsi::RealView x("test::x", A.nRows);
  CgRun run;
  run.usedCopy = cg.usesLatticeCopy(A);
  run.result = cg.solve(exec, A, b, x, M);
  run.x = mfsi::test::host(x);
  return run;
}

TEST(CgLattice, FallsBackToCsr) {
  const mfsi::ExecSpace exec;
  struct Case {
    std::string name;
    mfsi::CsrMatrix A;
  };
  std::vector<Case> cases;
  {
    // One coupling made asymmetric by one ulp: a_ij == a_ji is checked exactly.
    auto A = latticeMatrix({9, 8, 7}, true);
    HostCsr h(A);
    const lid_t i = 200, k = h.rowPtr[i + 1] - 1;  // row 200's +z coupling
    h.values[k] = std::nextafter(h.values[k], 0.0);
    Kokkos::deep_copy(A.values, mfsi::hostView(h.values));
    cases.push_back({"asymmetric by one ulp", A});
  }
  {
    auto A = mfsi::buildCsr(shuffledLattice(9, 8, 7));
    setSymmetricValues(A, true);
    cases.push_back({"shuffled numbering", A});
  }
  {
    auto A = mfsi::buildCsr(irregularLattice(9, 8, 7));
    setSymmetricValues(A, true);
    cases.push_back({"unstructured-like", A});
  }
  for (const auto& c : cases) {
    mfsi::SymmetricLatticeMatrix L;
    EXPECT_FALSE(L.update(exec, c.A)) << c.name;
    EXPECT_FALSE(L.matches(c.A)) << c.name;
    mfsi::AmgPreconditioner M;
    M.setup(exec, c.A);
    const mfsi::RealView b = mfsi::test::roughVector(c.A.nRows, false);
    const CgRun with = solveCg(c.A, b, M, true, false), without = solveCg(c.A, b, M, false, false);
    EXPECT_FALSE(with.usedCopy) << c.name;
    EXPECT_TRUE(with.result.converged) << c.name;
    EXPECT_GT(with.result.iterations, 2) << c.name;
    EXPECT_EQ(with.result.iterations, without.result.iterations) << c.name;
    EXPECT_EQ(with.x, without.x) << c.name << ": CSR either way, identical results";
  }
}

TEST(CgLattice, AmgCgSolveSameWithAndWithoutCopy) {
  const mfsi::ExecSpace exec;
  for (const bool dirichlet : {true, false}) {
    for (const std::array<lid_t, 3> e : {std::array<lid_t, 3>{18, 16, 14}, std::array<lid_t, 3>{48, 40, 1}}) {
      const std::string what = std::string(dirichlet ? "Dirichlet " : "Neumann ") + std::to_string(e[0]) + "x" +
                               std::to_string(e[1]) + "x" + std::to_string(e[2]);
      const auto A = latticeMatrix(e, dirichlet);
      mfsi::AmgPreconditioner M;
      M.setup(exec, A);
      const mfsi::RealView b = mfsi::test::roughVector(A.nRows, !dirichlet);
      const CgRun with = solveCg(A, b, M, true, !dirichlet), without = solveCg(A, b, M, false, !dirichlet);
      EXPECT_TRUE(with.usedCopy) << what;
      EXPECT_FALSE(without.usedCopy) << what;
      EXPECT_TRUE(with.result.converged) << what;
      EXPECT_GT(with.result.iterations, 3) << what;
      EXPECT_EQ(with.result.iterations, without.result.iterations) << what;
      EXPECT_LE(mfsi::test::relDiff(with.x, without.x), 1e-12) << what;
      // The solution solves A x = b (b's consistent part for Neumann) to the tolerance's order.
      HostVec r = HostCsr(A).apply(with.x);
      const HostVec bh = mfsi::test::host(b);
      double rr = 0.0, bb = 0.0;
      for (lid_t i = 0; i < A.nRows; ++i) {
        rr += (bh[i] - r[i]) * (bh[i] - r[i]);
        bb += bh[i] * bh[i];
      }
      EXPECT_LE(std::sqrt(rr / bb), 1e-9) << what;
    }
  }
}

TEST(CgLattice, CopyIsNotUsedForAnotherMatrix) {
  const mfsi::ExecSpace exec;
  const std::array<lid_t, 3> e{14, 12, 10};
  const auto A = latticeMatrix(e, true);
  // B: A's sparsity views with its own values, 3 A + I (also a symmetric lattice matrix).
  mfsi::CsrMatrix B = A;
  B.values = mfsi::RealView("test::B::values", A.nnz());
  {
    HostCsr h(A);
    for (lid_t i = 0; i < h.n; ++i)
      for (lid_t k = h.rowPtr[i]; k < h.rowPtr[i + 1]; ++k) h.values[k] = 3.0 * h.values[k] + (h.colIdx[k] == i);
    Kokkos::deep_copy(B.values, mfsi::hostView(h.values));
  }
  mfsi::KrylovOptions o;
  o.relTol = 1e-10;
  mfsi::ConjugateGradient cg(o);
  cg.matrixChanged(exec, A);
  EXPECT_TRUE(cg.usesLatticeCopy(A));
  EXPECT_FALSE(cg.usesLatticeCopy(B));
  mfsi::CsrMatrix deepCopyOfA = A;  // same values, different allocation
  deepCopyOfA.values = mfsi::RealView("test::A2::values", A.nnz());
  Kokkos::deep_copy(deepCopyOfA.values, A.values);
  EXPECT_FALSE(cg.usesLatticeCopy(deepCopyOfA));

  // Solving with B after announcing A must solve B's system, not A's.
  mfsi::AmgPreconditioner M;
  M.setup(exec, B);
  const mfsi::RealView b = mfsi::test::roughVector(B.nRows, false);
  mfsi::RealView x("test::x", B.nRows);
  const auto res = cg.solve(exec, B, b, x, M);
  ASSERT_TRUE(res.converged);
  const HostVec bx = HostCsr(B).apply(mfsi::test::host(x)), bh = mfsi::test::host(b);
  EXPECT_LE(mfsi::test::relDiff(bx, bh), 1e-8) << "B x = b";

  // Announcing B switches the copy to B (same sparsity: no new detection) and off A.
  cg.matrixChanged(exec, B);
  EXPECT_TRUE(cg.usesLatticeCopy(B));
  EXPECT_FALSE(cg.usesLatticeCopy(A));
  // An asymmetric refill of B's values in place, announced: no copy; restored: copy again.
  {
    HostCsr h(B);
    h.values[h.rowPtr[50] + 4] += 0.25;
    Kokkos::deep_copy(B.values, mfsi::hostView(h.values));
    cg.matrixChanged(exec, B);
    EXPECT_FALSE(cg.usesLatticeCopy(B));
    h.values[h.rowPtr[50] + 4] -= 0.25;
    Kokkos::deep_copy(B.values, mfsi::hostView(h.values));
    cg.matrixChanged(exec, B);
    EXPECT_TRUE(cg.usesLatticeCopy(B));
  }
}

/// u.v and |u|_1 by the lane reduction (a free function: nvcc compiles device lambdas only in
/// public or free functions, and a TEST body is a private member).
std::array<double, 2> laneSums(const mfsi::ExecSpace& exec, const mfsi::SolverComm& comm, lid_t n,
                               const mfsi::RealView& u, const mfsi::RealView& v) {
  return mfsi::blas::reduceLanes<2>(
      exec, comm, "test::lanes", n, KOKKOS_LAMBDA(lid_t i, mfsi::blas::Sums<2> & acc) {
        acc[0] += u(i) * v(i);
        acc[1] += mfsi::kmath::fabs(u(i));
      });
}

TEST(CgLattice, LaneReductionMatchesHostSum) {
  const mfsi::ExecSpace exec;
  const mfsi::SolverComm comm;
  for (const lid_t n : {1, 3, 256, 1027}) {  // partial lanes, one block, a partial last block
    const mfsi::RealView u = mfsi::test::roughVector(n, false, 0), v = mfsi::test::roughVector(n, false, 1);
    const auto s = laneSums(exec, comm, n, u, v);
    const HostVec uh = mfsi::test::host(u), vh = mfsi::test::host(v);
    long double d = 0, a = 0, scale = 0;
    for (lid_t i = 0; i < n; ++i) {
      d += static_cast<long double>(uh[i]) * vh[i];
      scale += std::abs(static_cast<long double>(uh[i]) * vh[i]);
      a += std::abs(static_cast<long double>(uh[i]));
    }
    EXPECT_TRUE(near(s[0], static_cast<double>(d), Tol{1e-15 * static_cast<double>(scale), 0}, "u.v"));
    EXPECT_TRUE(near(s[1], static_cast<double>(a), Tol{0, 1e-15}, "|u|_1"));
  }
}

}  // namespace

TEST(CgLattice, DirectAssemblyAndCsrRoundTrip) {
  // An assembly that writes the lattice itself (prepare, the arrays, markAssembled): the lattice
  // then stands for A although A's CSR values are stale, and writeCsr gives back the CSR values
  // bitwise (both halves of every coupling, in 3D and one cell thick).
  const mfsi::ExecSpace exec;
  for (const std::array<lid_t, 3> e : {std::array<lid_t, 3>{9, 8, 7}, std::array<lid_t, 3>{11, 6, 1}}) {
    const auto A = latticeMatrix(e, true);
    const HostVec want = HostCsr(A).values;
    mfsi::SymmetricLatticeMatrix copy;
    ASSERT_TRUE(copy.update(exec, A));
    // B: A's sparsity with zeroed values; its lattice is written from the copy's arrays.
    mfsi::CsrMatrix B = A;
    B.values = mfsi::RealView("test::B::values", A.nnz());
    mfsi::SymmetricLatticeMatrix L;
    EXPECT_THROW(L.markAssembled(B), std::exception) << "markAssembled before prepare";
    ASSERT_TRUE(L.prepare(B));
    EXPECT_FALSE(L.matches(B));
    Kokkos::deep_copy(L.diagonal(), copy.diagonal());
    Kokkos::deep_copy(L.upperX(), copy.upperX());
    Kokkos::deep_copy(L.upperY(), copy.upperY());
    if (e[2] > 1) Kokkos::deep_copy(L.upperZ(), copy.upperZ());
    L.markAssembled(B);
    EXPECT_TRUE(L.matches(B) && L.assembledFor(B));
    EXPECT_FALSE(copy.assembledFor(A)) << "a copy made by update is not an assembly";
    // The lattice stands for B: its product is A's although B's CSR values are still zero.
    const mfsi::RealView x = mfsi::test::roughVector(A.nRows, false);
    mfsi::RealView y("test::y", A.nRows);
    L.spmv(exec, x, y);
    EXPECT_LE(mfsi::test::relDiff(mfsi::test::host(y), HostCsr(A).apply(mfsi::test::host(x))), 1e-14);
    EXPECT_EQ(HostCsr(B).values, HostVec(A.nnz(), 0.0));
    L.writeCsr(exec, B);
    EXPECT_EQ(HostCsr(B).values, want) << e[0] << "x" << e[1] << "x" << e[2];
    // A new copy from CSR ends the assembly state.
    ASSERT_TRUE(L.update(exec, B));
    EXPECT_FALSE(L.assembledFor(B));
    EXPECT_TRUE(L.matches(B));
  }
}
