// AMG on structured lattices: the lattice detector (accepts 7- and 5-point lattices with their
// extents, rejects other numberings, wrap-around or extra couplings, several blocks), the
// hierarchy built from lattice-aligned cube aggregates (aggregate counts, pattern-compressed
// level 1, fallbacks), a symmetric preconditioner, and CG iterations no worse than greedy
// aggregation.
#include "kernels/Amg.hpp"

#include "kernels/CsrBuild.hpp"
#include "kernels/Krylov.hpp"
#include "support/AmgChecks.hpp"
#include "support/Approx.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

namespace {

using mfsi::lid_t;
using mfsi::test::near;
using mfsi::test::Tol;
using Adjacency = std::vector<std::vector<lid_t>>;

/// Neighbours of the nx x ny x nz lattice numbered x fastest, with per-axis coupling weights.
Adjacency latticeAdjacency(lid_t nx, lid_t ny, lid_t nz) {
  Adjacency adj(static_cast<std::size_t>(nx) * ny * nz);
  for (lid_t z = 0; z < nz; ++z)
    for (lid_t y = 0; y < ny; ++y)
      for (lid_t x = 0; x < nx; ++x) {
        const lid_t i = x + nx * (y + ny * z);
        if (x > 0) adj[i].push_back(i - 1);
        if (x + 1 < nx) adj[i].push_back(i + 1);
        if (y > 0) adj[i].push_back(i - nx);
        if (y + 1 < ny) adj[i].push_back(i + nx);
        if (z > 0) adj[i].push_back(i - nx * ny);
        if (z + 1 < nz) adj[i].push_back(i + nx * ny);
      }
  return adj;
}

void couple(Adjacency& adj, lid_t i, lid_t j) {
  adj[i].push_back(j);
  adj[j].push_back(i);
}

/// A symmetric matrix on the sparsity of `adj`: -weight(i, j) off the diagonal (weight = wx for
/// |i - j| == 1, 1 otherwise), diagonal = sum of the weights + shift (shift > 0: SPD).
mfsi::CsrMatrix laplacian(const Adjacency& adj, double shift, double wx = 1.0) {
  mfsi::CsrMatrix A = mfsi::buildCsr(adj);
  auto ptr = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), A.rowPtr);
  auto col = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), A.colIdx);
  auto val = Kokkos::create_mirror_view(A.values);
  for (lid_t i = 0; i < A.nRows; ++i) {
    double diag = shift;
    lid_t d = -1;
    for (lid_t k = ptr(i); k < ptr(i + 1); ++k) {
      if (col(k) == i) {
        d = k;
        continue;
      }
      const double w = std::abs(col(k) - i) == 1 ? wx : 1.0;
      val(k) = -w;
      diag += w;
    }
    val(d) = diag;
  }
  Kokkos::deep_copy(A.values, val);
  return A;
}

/// The matrix of `adj` renumbered: new index perm[i] for old row i.
Adjacency renumbered(const Adjacency& adj, const std::vector<lid_t>& perm) {
  Adjacency out(adj.size());
  for (std::size_t i = 0; i < adj.size(); ++i)
    for (lid_t j : adj[i]) out[perm[i]].push_back(perm[j]);
  return out;
}

mfsi::RealView roughRhs(lid_t n, bool zeroMean) { return mfsi::test::roughVector(n, zeroMean); }

mfsi::KrylovResult solveCg(const mfsi::CsrMatrix& A, const mfsi::RealView& b, mfsi::Preconditioner& M,
                           mfsi::NullSpace ns = mfsi::NullSpace::None) {
  mfsi::KrylovOptions opt;
  opt.relTol = 1e-8;
  opt.maxIterations = 500;
  opt.nullSpace = ns;
  mfsi::RealView x("test::x", A.nRows);
  return mfsi::ConjugateGradient(opt).solve(mfsi::ExecSpace(), A, b, x, M);
}

void expectLattice(const mfsi::AmgLattice& g, std::array<lid_t, 3> n, const std::string& what) {
  EXPECT_TRUE(g.valid()) << what;
  EXPECT_EQ(g.nx, n[0]) << what;
  EXPECT_EQ(g.ny, n[1]) << what;
  EXPECT_EQ(g.nz, n[2]) << what;
}

}  // namespace

TEST(AmgLattice, DetectorAcceptsLatticesWithTheirExtents) {
  expectLattice(mfsi::detectLattice(mfsi::buildPoisson7({7, 5, 4}, mfsi::ModelBoundary::Dirichlet)), {7, 5, 4},
                "7x5x4 7-point");
  expectLattice(mfsi::detectLattice(mfsi::buildPoisson7({9, 6, 1}, mfsi::ModelBoundary::Neumann)), {9, 6, 1},
                "9x6x1 5-point");
  expectLattice(mfsi::detectLattice(mfsi::buildPoisson7({2, 3, 2}, mfsi::ModelBoundary::Dirichlet)), {2, 3, 2},
                "2x3x2");
  expectLattice(mfsi::detectLattice(laplacian(latticeAdjacency(6, 4, 3), 0.1)), {6, 4, 3}, "adjacency 6x4x3");
}

TEST(AmgLattice, DetectorRejectsEverythingElse) {
  const lid_t nx = 6, ny = 5, nz = 4, n = nx * ny * nz;
  auto rejects = [](const Adjacency& adj, const std::string& what) {
    EXPECT_FALSE(mfsi::detectLattice(laplacian(adj, 0.1)).valid()) << what;
  };
  // Two rows swapped: every row but a handful is still a lattice row.
  {
    std::vector<lid_t> perm(n);
    for (lid_t i = 0; i < n; ++i) perm[i] = i;
    std::swap(perm[37], perm[38 + nx]);
    rejects(renumbered(latticeAdjacency(nx, ny, nz), perm), "two rows swapped");
  }
  // y fastest numbering of a cube with a different x and y extent would be another lattice; a
  // pseudo-random numbering is none.
  {
    rejects(renumbered(latticeAdjacency(nx, ny, nz), mfsi::test::randomPermutation(n, 4321u)), "random numbering");
  }
  // Periodic in x: the first and last cell of every x line coupled.
  {
    Adjacency adj = latticeAdjacency(nx, ny, nz);
    for (lid_t l = 0; l < ny * nz; ++l) couple(adj, l * nx, l * nx + nx - 1);
    rejects(adj, "periodic in x");
  }
  // Wrap-around of one x line into the next (offset +1 across a line end), one row pair only.
  {
    Adjacency adj = latticeAdjacency(nx, ny, nz);
    couple(adj, 2 * nx + nx - 1, 3 * nx);
    rejects(adj, "line wrap-around");
  }
  // One extra (diagonal) coupling in the interior; one missing coupling.
  {
    Adjacency adj = latticeAdjacency(nx, ny, nz);
    const lid_t c = 2 + nx * (2 + ny * 2);
    couple(adj, c, c + nx + 1);
    rejects(adj, "extra diagonal coupling");
    Adjacency cut = latticeAdjacency(nx, ny, nz);
    auto drop = [&](lid_t i, lid_t j) { cut[i].erase(std::find(cut[i].begin(), cut[i].end(), j)); };
    drop(c, c + nx);
    drop(c + nx, c);
    rejects(cut, "missing coupling");
  }
  // Two blocks numbered one after the other, side by side in x (4x5x4 and 3x5x4), coupled
  // across their interface: one lattice geometrically, but not numbered as one.
  {
    const Adjacency a = latticeAdjacency(4, ny, nz), b = latticeAdjacency(3, ny, nz);
    const lid_t na = static_cast<lid_t>(a.size());
    Adjacency adj = a;
    for (const auto& row : b) {
      adj.emplace_back();
      for (lid_t j : row) adj.back().push_back(j + na);
    }
    for (lid_t l = 0; l < ny * nz; ++l) couple(adj, l * 4 + 3, na + l * 3);
    rejects(adj, "two blocks");
  }
  // A 1D chain (a lattice, but not a 2D or 3D one: cube aggregation would halve it only).
  rejects(latticeAdjacency(40, 1, 1), "1D chain");
}

TEST(AmgLattice, HierarchyUsesCubeAggregatesAndPatternedLevel1) {
  mfsi::ExecSpace exec;
  struct Case {
    std::array<lid_t, 3> n;
    lid_t level1Rows, level2Rows;
    int level1Width;
  };
  // 3D: 2x2x2 cubes, then 3x3x3 cubes; extents that do not divide end with narrower aggregates
  // (ceil(n / 2), then ceil(n / 6) per axis). 2D: 2x2, then 3x3 squares.
  for (const Case& c : {Case{{16, 16, 16}, 512, 27, 32}, Case{{15, 14, 13}, 8 * 7 * 7, 3 * 3 * 3, 32},
                        Case{{30, 30, 1}, 225, 25, 12}}) {
    const std::string what = std::to_string(c.n[0]) + "x" + std::to_string(c.n[1]) + "x" + std::to_string(c.n[2]);
    const auto A = mfsi::buildPoisson7(c.n, mfsi::ModelBoundary::Dirichlet);
    for (auto precision : {mfsi::AmgPrecision::Double, mfsi::AmgPrecision::Mixed}) {
      mfsi::AmgOptions o;
      o.precision = precision;
      o.coarseSize = 50;
      mfsi::AmgPreconditioner amg(o);
      amg.setup(exec, A);
      const auto info = amg.info();
      ASSERT_EQ(info.levels.size(), 3u) << what;
      expectLattice(info.levels[0].lattice, c.n, what);
      expectLattice(info.levels[1].lattice, {(c.n[0] + 1) / 2, (c.n[1] + 1) / 2, (c.n[2] + 1) / 2}, what);
      EXPECT_EQ(info.levels[1].rows, c.level1Rows) << what;
      EXPECT_EQ(info.levels[2].rows, c.level2Rows) << what;
      EXPECT_EQ(info.levels[1].cycleWidth, c.level1Width) << what;
      EXPECT_TRUE(info.levels[1].cyclePatterned) << what;
      EXPECT_TRUE(info.levels[0].cyclePatterned) << what;
      // latticeLevels = 1: cubes on the finest level only, greedy aggregation below.
      o.latticeLevels = 1;
      mfsi::AmgPreconditioner one(o);
      one.setup(exec, A);
      const auto info1 = one.info();
      EXPECT_TRUE(info1.levels[0].lattice.valid()) << what;
      EXPECT_EQ(info1.levels[1].rows, c.level1Rows) << what;
      EXPECT_FALSE(info1.levels[1].lattice.valid()) << what;
    }
    // The aggregates: the unsmoothed prolongator maps fine cell (x, y, z) to coarse cell
    // (x / 2, y / 2, z / 2) of the ceil(n / 2) lattice, and only to it.
    mfsi::AmgOptions o;
    o.prolongation = mfsi::AmgProlongation::Unsmoothed;
    o.coarseSize = 50;
    mfsi::AmgPreconditioner amg(o);
    amg.setup(exec, A);
    const auto P = amg.prolongator(0);
    ASSERT_EQ(P.nCols, c.level1Rows) << what;
    auto ptr = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), P.rowPtr);
    auto col = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), P.colIdx);
    const lid_t cx = (c.n[0] + 1) / 2, cy = (c.n[1] + 1) / 2;
    lid_t wrong = 0;
    for (lid_t z = 0, i = 0; z < c.n[2]; ++z)
      for (lid_t y = 0; y < c.n[1]; ++y)
        for (lid_t x = 0; x < c.n[0]; ++x, ++i)
          wrong += ptr(i + 1) - ptr(i) == 1 && col(ptr(i)) == x / 2 + cx * (y / 2 + cy * (z / 2)) ? 0 : 1;
    EXPECT_EQ(wrong, 0) << what;
  }
}

TEST(AmgLattice, FallsBackToGreedyAggregation) {
  mfsi::ExecSpace exec;
  const auto lattice = mfsi::buildPoisson7({16, 16, 16}, mfsi::ModelBoundary::Dirichlet);
  mfsi::AmgOptions greedy;
  greedy.aggregation = mfsi::AmgAggregation::Greedy;
  mfsi::AmgPreconditioner g(greedy), a;
  g.setup(exec, lattice);
  a.setup(exec, lattice);
  EXPECT_FALSE(g.info().levels[0].lattice.valid());
  EXPECT_TRUE(a.info().levels[0].lattice.valid());
  // Greedy "star" aggregates (~7 rows) and their irregular numbering: no patterned level 1.
  EXPECT_GT(g.info().levels[1].rows, a.info().levels[1].rows);
  EXPECT_FALSE(g.info().levels[1].cyclePatterned);

  // Anisotropic lattice (x couplings 50x weaker: weak under the strength threshold): greedy.
  const auto aniso = laplacian(latticeAdjacency(12, 12, 12), 0.1, 0.02);
  ASSERT_TRUE(mfsi::detectLattice(aniso).valid());
  mfsi::AmgPreconditioner an;
  an.setup(exec, aniso);
  EXPECT_FALSE(an.info().levels[0].lattice.valid());
  EXPECT_TRUE(solveCg(aniso, roughRhs(aniso.nRows, false), an).converged);
}

TEST(AmgLattice, PreconditionerIsSymmetricAndPositive) {
  // <M u, v> = <u, M v> and <M u, u> > 0 on cube hierarchies (with narrower aggregates where the
  // extents do not divide; cubes on every level, or on the finest only), Dirichlet and Neumann
  // (zero-mean vectors).
  mfsi::ExecSpace exec;
  for (auto bc : {mfsi::ModelBoundary::Dirichlet, mfsi::ModelBoundary::Neumann}) {
    for (std::array<lid_t, 3> dims : {std::array<lid_t, 3>{17, 14, 13}, std::array<lid_t, 3>{40, 33, 1}}) {
      const auto A = mfsi::buildPoisson7(dims, bc);
      const bool neumann = bc == mfsi::ModelBoundary::Neumann;
      for (int latticeLevels : {1, 12})
        for (auto precision : {mfsi::AmgPrecision::Double, mfsi::AmgPrecision::Mixed}) {
          mfsi::AmgOptions o;
          o.precision = precision;
          o.latticeLevels = latticeLevels;
          o.coarseSize = 30;
          mfsi::AmgPreconditioner amg(o);
          amg.setup(exec, A);
          const std::string what = std::to_string(dims[0]) + "x" + std::to_string(dims[1]) + "x" +
                                   std::to_string(dims[2]) + (neumann ? " Neumann" : " Dirichlet") +
                                   (precision == mfsi::AmgPrecision::Double ? " double" : " mixed") +
                                   " latticeLevels " + std::to_string(latticeLevels);
          ASSERT_TRUE(amg.info().levels[0].lattice.valid()) << what;
          const double rel = precision == mfsi::AmgPrecision::Double ? 1e-12 : 1e-5;
          mfsi::test::expectSymmetricPositive(amg, A.nRows, neumann, rel, what);
        }
    }
  }
}

TEST(AmgLattice, CgIterationsNoWorseThanGreedy) {
  mfsi::ExecSpace exec;
  struct Case {
    std::array<lid_t, 3> n;
    mfsi::ModelBoundary bc;
  };
  for (const Case& c : {Case{{32, 32, 32}, mfsi::ModelBoundary::Dirichlet}, Case{{24, 22, 20}, mfsi::ModelBoundary::Neumann},
                        Case{{96, 96, 1}, mfsi::ModelBoundary::Dirichlet}}) {
    const bool neumann = c.bc == mfsi::ModelBoundary::Neumann;
    const auto A = mfsi::buildPoisson7(c.n, c.bc);
    const auto b = roughRhs(A.nRows, neumann);
    const mfsi::NullSpace ns = neumann ? mfsi::NullSpace::Constant : mfsi::NullSpace::None;
    mfsi::AmgOptions greedy;
    greedy.aggregation = mfsi::AmgAggregation::Greedy;
    mfsi::AmgPreconditioner g(greedy), a;
    g.setup(exec, A);
    a.setup(exec, A);
    ASSERT_TRUE(a.info().levels[0].lattice.valid());
    const auto rg = solveCg(A, b, g, ns), ra = solveCg(A, b, a, ns);
    ASSERT_TRUE(rg.converged && ra.converged);
    const std::string what = std::to_string(c.n[0]) + "x" + std::to_string(c.n[1]) + "x" + std::to_string(c.n[2]);
    std::cout << "[ amg      ] " << what << (neumann ? " Neumann" : " Dirichlet") << ": greedy " << rg.iterations
              << " its (operator complexity " << g.info().operatorComplexity << "), lattice cubes " << ra.iterations
              << " its (" << a.info().operatorComplexity << ")\n";
    EXPECT_LE(ra.iterations, rg.iterations + 1) << what;
  }
}
