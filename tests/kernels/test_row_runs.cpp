// Row runs of a CSR sparsity (CsrRowRuns): their structure (runs tile the rows, share relative
// columns, never cross a reduction block), when they are built, and that the kernels that sweep
// them (host backends) give bitwise the results of the row kernels: spmv, the fused SpMV + dot
// of CG, and whole BiCGStab3 solves.
#include "kernels/Blas.hpp"
#include "kernels/CsrBuild.hpp"
#include "kernels/Krylov.hpp"
#include "support/HostVectors.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <vector>

namespace {

using mfsi::lid_t;
using mfsi::test::column;
using mfsi::test::device;
using mfsi::test::device3;
using mfsi::test::host;
using mfsi::test::HostVec;

std::vector<lid_t> hostIdx(const mfsi::IndexView& v) {
  auto h = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), v);
  return std::vector<lid_t>(h.data(), h.data() + h.extent(0));
}

/// 7-point sparsity on an nx x ny x nz grid with non-symmetric, row-varying values (an upwind
/// convection-diffusion-like M-matrix): a wrong column offset or value position changes results.
mfsi::CsrMatrix structuredMatrix(lid_t nx, lid_t ny, lid_t nz) {
  auto A = mfsi::buildPoisson7({nx, ny, nz}, mfsi::ModelBoundary::Dirichlet);
  const auto rowPtr = hostIdx(A.rowPtr), col = hostIdx(A.colIdx);
  auto v = Kokkos::create_mirror_view(A.values);
  for (lid_t i = 0; i < A.nRows; ++i) {
    double off = 0;
    for (lid_t k = rowPtr[i]; k < rowPtr[i + 1]; ++k) {
      if (col[k] == i) continue;
      v(k) = -(1.0 + 0.4 * (col[k] > i ? 1 : -1) + 0.01 * std::sin(0.3 * k));
      off += std::abs(v(k));
    }
    for (lid_t k = rowPtr[i]; k < rowPtr[i + 1]; ++k)
      if (col[k] == i) v(k) = off + 0.5 + 0.1 * std::cos(0.7 * i);
  }
  Kokkos::deep_copy(A.values, v);
  return A;
}

/// The same matrix without runs: the kernels take their row paths.
mfsi::CsrMatrix withoutRuns(mfsi::CsrMatrix A) {
  A.runs = mfsi::CsrRowRuns{};
  return A;
}

HostVec wave(lid_t n, double a, double b) {
  HostVec x(n);
  for (lid_t i = 0; i < n; ++i) x[i] = std::sin(a * i) + std::cos(b * i * i) + 0.2;
  return x;
}

}  // namespace

TEST(RowRuns, TileTheRowsWithOneRelativeColumnSetPerRun) {
  const auto A = structuredMatrix(40, 7, 5);
  ASSERT_GT(A.runs.count, 0);
  const auto rowPtr = hostIdx(A.rowPtr), col = hostIdx(A.colIdx);
  const auto start = hostIdx(A.runs.start), at = hostIdx(A.runs.offsetsAt), offsets = hostIdx(A.runs.offsets),
             blockStart = hostIdx(A.runs.blockStart);
  ASSERT_EQ(static_cast<lid_t>(start.size()), A.runs.count + 1);
  EXPECT_EQ(start.front(), 0);
  EXPECT_EQ(start.back(), A.nRows);
  // 40-cell lines: interior runs of 38 rows, split where they cross a block boundary.
  EXPECT_GT(static_cast<double>(A.nRows) / A.runs.count, 10.0);
  for (lid_t r = 0; r < A.runs.count; ++r) {
    ASSERT_LT(start[r], start[r + 1]) << "run " << r;
    EXPECT_EQ(start[r] / mfsi::kRowBlock, (start[r + 1] - 1) / mfsi::kRowBlock) << "run " << r << " crosses a block";
    const lid_t w = rowPtr[start[r] + 1] - rowPtr[start[r]];
    for (lid_t i = start[r]; i < start[r + 1]; ++i) {
      ASSERT_EQ(rowPtr[i + 1] - rowPtr[i], w) << "row " << i;
      for (lid_t k = 0; k < w; ++k) ASSERT_EQ(col[rowPtr[i] + k], i + offsets[at[r] + k]) << "row " << i;
    }
  }
  const lid_t nBlocks = (A.nRows + mfsi::kRowBlock - 1) / mfsi::kRowBlock;
  ASSERT_EQ(static_cast<lid_t>(blockStart.size()), nBlocks + 1);
  for (lid_t b = 0; b < nBlocks; ++b) EXPECT_EQ(start[blockStart[b]], b * mfsi::kRowBlock) << "block " << b;
  EXPECT_EQ(blockStart.back(), A.runs.count);
}

TEST(RowRuns, AreNotBuiltWhereRunsWouldBeShort) {
  // 6-cell lines: runs of 1, 4, 1 rows, mean 2 < 8.
  EXPECT_EQ(structuredMatrix(6, 6, 6).runs.count, 0);
}

TEST(RowRuns, SpmvAndSpmvDotEqualTheRowKernelsBitwise) {
  const auto A = structuredMatrix(40, 7, 5);
  ASSERT_GT(A.runs.count, 0);
  const auto B = withoutRuns(A);
  const auto x = device(wave(A.nRows, 0.37, 0.011)), w = device(wave(A.nRows, 0.13, 0.029));
  mfsi::ExecSpace exec;
  mfsi::RealView ya("ya", A.nRows), yb("yb", A.nRows);
  const double da = mfsi::blas::spmvDot(exec, mfsi::SolverComm(), A, x, ya, w);
  const double db = mfsi::blas::spmvDot(exec, mfsi::SolverComm(), B, x, yb, w);
  EXPECT_EQ(da, db);
  EXPECT_EQ(host(ya), host(yb));
  const auto y0 = wave(A.nRows, 0.5, 0.003);
  ya = device(y0);
  yb = device(y0);
  mfsi::blas::spmv(exec, 0.7, A, x, -1.3, ya);
  mfsi::blas::spmv(exec, 0.7, B, x, -1.3, yb);
  EXPECT_EQ(host(ya), host(yb));
  // And the product itself is right (a gold host SpMV).
  const auto rowPtr = hostIdx(A.rowPtr), col = hostIdx(A.colIdx);
  const auto val = host(A.values), hx = host(x), hy = host(ya);
  double worst = 0;
  for (lid_t i = 0; i < A.nRows; ++i) {
    double s = 0;
    for (lid_t k = rowPtr[i]; k < rowPtr[i + 1]; ++k) s += val[k] * hx[col[k]];
    worst = std::max(worst, std::abs(hy[i] - (0.7 * s - 1.3 * y0[i])));
  }
  EXPECT_LE(worst, 1e-12);
}

TEST(RowRuns, BiCGStab3SolvesEqualTheRowKernelsBitwise) {
  const auto A = structuredMatrix(40, 7, 5);
  ASSERT_GT(A.runs.count, 0);
  const auto B = withoutRuns(A);
  mfsi::ExecSpace exec;
  auto d = Kokkos::create_mirror_view(mfsi::RealView("inv", A.nRows));
  {
    const auto rowPtr = hostIdx(A.rowPtr), diag = hostIdx(A.diagIdx);
    const auto val = host(A.values);
    for (lid_t i = 0; i < A.nRows; ++i) d(i) = 1.0 / val[diag[i]];
  }
  mfsi::RealView inv("inv", A.nRows);
  Kokkos::deep_copy(inv, d);
  const std::array<HostVec, 3> b{wave(A.nRows, 0.3, 0.01), wave(A.nRows, 0.7, 0.002), wave(A.nRows, 0.11, 0.05)};
  mfsi::KrylovOptions opt;
  opt.relTol = 1e-10;
  mfsi::BiCGStab3 sa(opt), sb(opt);
  auto xa = device3({HostVec(A.nRows, 0.0), HostVec(A.nRows, 0.0), HostVec(A.nRows, 0.0)});
  auto xb = device3({HostVec(A.nRows, 0.0), HostVec(A.nRows, 0.0), HostVec(A.nRows, 0.0)});
  const auto ra = sa.solve(exec, A, device3(b), xa, inv);
  const auto rb = sb.solve(exec, B, device3(b), xb, inv);
  for (int c = 0; c < 3; ++c) {
    EXPECT_TRUE(ra[c].converged) << "column " << c;
    EXPECT_GT(ra[c].iterations, 3) << "column " << c;
    EXPECT_EQ(ra[c].iterations, rb[c].iterations) << "column " << c;
    EXPECT_EQ(ra[c].finalResidual, rb[c].finalResidual) << "column " << c;
    EXPECT_EQ(column(xa, c), column(xb, c)) << "column " << c;
  }
}
