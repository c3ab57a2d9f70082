// Linear-algebra kernels (single vectors and n x 3 multi-vectors) against simple serial host versions
// on random matrices and vectors.
#include "kernels/Blas.hpp"
#include "kernels/CsrBuild.hpp"
#include "support/Approx.hpp"

#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace {

using mfsi::lid_t;
using mfsi::test::allNear;
using mfsi::test::near;
using mfsi::test::Tol;
using HostVec = std::vector<double>;

/// A random sparse matrix (host gold copy + device CsrMatrix): 0..8 random columns per row plus
/// the diagonal, values in [-1, 1]. nCols > nRows gives ghost columns.
struct RandomMatrix {
  mfsi::CsrMatrix A;
  std::vector<lid_t> rowPtr, colIdx;
  HostVec values;
};

RandomMatrix randomMatrix(lid_t nRows, lid_t nCols, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_int_distribution<lid_t> col(0, nCols - 1), count(0, 8);
  std::uniform_real_distribution<double> val(-1.0, 1.0);
  std::vector<std::vector<lid_t>> adj(nRows);
  for (lid_t i = 0; i < nRows; ++i) {
    const lid_t c = count(gen);
    for (lid_t k = 0; k < c; ++k) adj[i].push_back(col(gen));
  }
  mfsi::CsrBuildOptions opt;
  opt.nCols = nCols;
  RandomMatrix m;
  m.A = mfsi::buildCsr(adj, opt);
  auto rp = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), m.A.rowPtr);
  auto ci = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), m.A.colIdx);
  m.rowPtr.assign(rp.data(), rp.data() + rp.extent(0));
  m.colIdx.assign(ci.data(), ci.data() + ci.extent(0));
  m.values.resize(m.colIdx.size());
  for (auto& v : m.values) v = val(gen);
  auto hv = Kokkos::create_mirror_view(m.A.values);
  for (std::size_t k = 0; k < m.values.size(); ++k) hv(k) = m.values[k];
  Kokkos::deep_copy(m.A.values, hv);
  return m;
}

HostVec randomVec(lid_t n, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> val(-1.0, 1.0);
  HostVec v(n);
  for (auto& x : v) x = val(gen);
  return v;
}

mfsi::RealView toDevice(const HostVec& v) {
  mfsi::RealView d("test::vec", v.size());
  auto h = Kokkos::create_mirror_view(d);
  for (std::size_t i = 0; i < v.size(); ++i) h(i) = v[i];
  Kokkos::deep_copy(d, h);
  return d;
}

HostVec toHost(const mfsi::RealView& d) {
  auto h = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), d);
  return HostVec(h.data(), h.data() + h.extent(0));
}

HostVec hostSpmv(const RandomMatrix& m, const HostVec& x) {
  HostVec y(m.rowPtr.size() - 1, 0.0);
  for (std::size_t i = 0; i + 1 < m.rowPtr.size(); ++i)
    for (lid_t k = m.rowPtr[i]; k < m.rowPtr[i + 1]; ++k) y[i] += m.values[k] * x[m.colIdx[k]];
  return y;
}

double hostDot(const HostVec& x, const HostVec& y, std::size_t n) {
  double s = 0;
  for (std::size_t i = 0; i < n; ++i) s += x[i] * y[i];
  return s;
}

constexpr lid_t kRows = 1234;  // not a multiple of the reduction block: exercises the tail
constexpr lid_t kCols = 1300;  // ghost columns
const Tol kTight{1e-13, 1e-13};

}  // namespace

TEST(Blas, SpmvMatchesHostGold) {
  const auto m = randomMatrix(kRows, kCols, 1);
  const HostVec x = randomVec(kCols, 2), y0 = randomVec(kRows, 3);
  auto dx = toDevice(x), dy = toDevice(y0);
  mfsi::ExecSpace exec;
  mfsi::blas::spmv(exec, m.A, dx, dy);
  const HostVec gold = hostSpmv(m, x);
  EXPECT_TRUE(allNear(toHost(dy), gold, kRows, kTight, "y = Ax"));

  // y = 2 A x - 0.5 y0
  Kokkos::deep_copy(dy, toDevice(y0));
  mfsi::blas::spmv(exec, 2.0, m.A, dx, -0.5, dy);
  HostVec gold2(kRows);
  for (lid_t i = 0; i < kRows; ++i) gold2[i] = 2.0 * gold[i] - 0.5 * y0[i];
  EXPECT_TRUE(allNear(toHost(dy), gold2, kRows, kTight, "y = 2Ax - y0/2"));

  // beta = 0 must not read y: NaN in y is overwritten.
  Kokkos::deep_copy(dy, std::numeric_limits<double>::quiet_NaN());
  mfsi::blas::spmv(exec, 1.0, m.A, dx, 0.0, dy);
  EXPECT_TRUE(allNear(toHost(dy), gold, kRows, kTight, "beta = 0 ignores NaN in y"));
}

TEST(Blas, FusedResidualAndSpmvDotMatchHostGold) {
  const auto m = randomMatrix(kRows, kCols, 4);
  const HostVec x = randomVec(kCols, 5), b = randomVec(kRows, 6), w = randomVec(kRows, 7);
  auto dx = toDevice(x), db = toDevice(b), dw = toDevice(w);
  mfsi::RealView dr("r", kRows), dy("y", kRows);
  mfsi::ExecSpace exec;
  const mfsi::SolverComm comm;
  const double rr = mfsi::blas::residual(exec, comm, m.A, dx, db, dr);
  const HostVec ax = hostSpmv(m, x);
  HostVec r(kRows);
  for (lid_t i = 0; i < kRows; ++i) r[i] = b[i] - ax[i];
  EXPECT_TRUE(allNear(toHost(dr), r, kRows, kTight, "r = b - Ax"));
  EXPECT_TRUE(near(rr, hostDot(r, r, kRows), kTight, "r.r"));

  const double wy = mfsi::blas::spmvDot(exec, comm, m.A, dx, dy, dw);
  EXPECT_TRUE(allNear(toHost(dy), ax, kRows, kTight, "y = Ax"));
  EXPECT_TRUE(near(wy, hostDot(w, ax, kRows), kTight, "w.Ax"));
}

TEST(Blas, ReductionsMatchHostGold) {
  const HostVec x = randomVec(kRows, 8), y = randomVec(kRows, 9);
  auto dx = toDevice(x), dy = toDevice(y);
  mfsi::ExecSpace exec;
  const mfsi::SolverComm comm;
  double s = 0, mx = 0;
  for (lid_t i = 0; i < kRows; ++i) {
    s += x[i];
    mx = std::max(mx, std::abs(x[i]));
  }
  EXPECT_TRUE(near(mfsi::blas::dot(exec, comm, kRows, dx, dy), hostDot(x, y, kRows), kTight, "dot"));
  EXPECT_TRUE(near(mfsi::blas::norm2(exec, comm, kRows, dx), std::sqrt(hostDot(x, x, kRows)), kTight, "norm2"));
  EXPECT_TRUE(near(mfsi::blas::sum(exec, comm, kRows, dx), s, kTight, "sum"));
  EXPECT_TRUE(near(mfsi::blas::mean(exec, comm, kRows, dx), s / kRows, kTight, "mean"));
  EXPECT_EQ(mfsi::blas::normInf(exec, comm, kRows, dx), mx);
  // Partial range: only the first n entries count.
  EXPECT_TRUE(near(mfsi::blas::dot(exec, comm, 300, dx, dy), hostDot(x, y, 300), kTight, "dot over 300"));
  EXPECT_EQ(mfsi::blas::dot(exec, comm, 0, dx, dy), 0.0);
  EXPECT_EQ(mfsi::blas::normInf(exec, comm, 0, dx), 0.0);

  // A NaN is reported by the max norm (as +inf) and propagates through dots.
  auto h = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), dx);
  h(777) = std::numeric_limits<double>::quiet_NaN();
  Kokkos::deep_copy(dx, h);
  EXPECT_TRUE(std::isinf(mfsi::blas::normInf(exec, comm, kRows, dx)));
  EXPECT_TRUE(std::isnan(mfsi::blas::dot(exec, comm, kRows, dx, dy)));
}

TEST(Blas, DotIsTheFixedBlockOrderSumBitForBit) {
  // The reduction adds rows in blocks of kReductionBlock in order, then the blocks in order. The
  // same order on the host gives the same bits, whatever the number of threads running the kernel.
  const lid_t n = 10 * mfsi::blas::kReductionBlock + 77;
  const HostVec x = randomVec(n, 10), y = randomVec(n, 11);
  auto dx = toDevice(x), dy = toDevice(y);
  double gold = 0.0;
  for (lid_t b0 = 0; b0 < n; b0 += mfsi::blas::kReductionBlock) {
    double block = 0.0;
    for (lid_t i = b0; i < std::min(n, b0 + mfsi::blas::kReductionBlock); ++i) block += x[i] * y[i];
    gold += block;
  }
  mfsi::ExecSpace exec;
  const mfsi::SolverComm comm;
  EXPECT_EQ(mfsi::blas::dot(exec, comm, n, dx, dy), gold);
  EXPECT_NE(gold, hostDot(x, y, n));  // the plain serial order rounds differently: the test has teeth
}

TEST(Blas, VectorUpdatesMatchHostGold) {
  const HostVec x = randomVec(kRows, 12), y = randomVec(kRows, 13);
  mfsi::ExecSpace exec;
  auto dx = toDevice(x), dy = toDevice(y);
  mfsi::blas::axpy(exec, kRows, 0.75, dx, dy);
  HostVec g(kRows);
  for (lid_t i = 0; i < kRows; ++i) g[i] = y[i] + 0.75 * x[i];
  EXPECT_TRUE(allNear(toHost(dy), g, kRows, kTight, "axpy"));

  dy = toDevice(y);
  mfsi::blas::axpby(exec, kRows, -2.0, dx, 0.5, dy);
  for (lid_t i = 0; i < kRows; ++i) g[i] = -2.0 * x[i] + 0.5 * y[i];
  EXPECT_TRUE(allNear(toHost(dy), g, kRows, kTight, "axpby"));

  Kokkos::deep_copy(dy, std::numeric_limits<double>::quiet_NaN());
  mfsi::blas::axpby(exec, kRows, 3.0, dx, 0.0, dy);
  for (lid_t i = 0; i < kRows; ++i) g[i] = 3.0 * x[i];
  EXPECT_TRUE(allNear(toHost(dy), g, kRows, kTight, "axpby beta = 0 ignores NaN"));

  dy = toDevice(y);
  mfsi::blas::shift(exec, 500, 1.5, dy);
  for (lid_t i = 0; i < kRows; ++i) g[i] = y[i] + (i < 500 ? 1.5 : 0.0);
  EXPECT_TRUE(allNear(toHost(dy), g, kRows, kTight, "shift of the first 500"));

  mfsi::blas::fill(exec, kRows, -4.0, dy);
  for (lid_t i = 0; i < kRows; ++i) g[i] = -4.0;
  EXPECT_TRUE(allNear(toHost(dy), g, kRows, Tol{0, 0}, "fill"));
}

namespace {

/// sum x, sum x^2 and the count in one fused reduction (a free function: nvcc compiles device
/// lambdas only in public or free functions, and a TEST body is a private member).
std::array<double, 3> sumsOf(const mfsi::ExecSpace& exec, const mfsi::RealView& dx) {
  return mfsi::blas::reduce<3>(
      exec, mfsi::SolverComm(), "test::reduce3", kRows, KOKKOS_LAMBDA(lid_t i, mfsi::blas::Sums<3> & acc) {
        acc[0] += dx(i);
        acc[1] += dx(i) * dx(i);
        acc[2] += 1.0;
      });
}

}  // namespace

TEST(Blas, FusedReduceReturnsSeveralSums) {
  const HostVec x = randomVec(kRows, 14);
  auto dx = toDevice(x);
  mfsi::ExecSpace exec;
  const auto s = sumsOf(exec, dx);
  double s0 = 0;
  for (double v : x) s0 += v;
  EXPECT_TRUE(near(s[0], s0, kTight, "sum"));
  EXPECT_TRUE(near(s[1], hostDot(x, x, kRows), kTight, "sum of squares"));
  EXPECT_EQ(s[2], static_cast<double>(kRows));
}

namespace {

mfsi::Real3View toDevice3(const HostVec& a, const HostVec& b, const HostVec& c) {
  mfsi::Real3View d("test::vec3", a.size());
  auto h = Kokkos::create_mirror_view(d);
  for (std::size_t i = 0; i < a.size(); ++i) {
    h(i, 0) = a[i];
    h(i, 1) = b[i];
    h(i, 2) = c[i];
  }
  Kokkos::deep_copy(d, h);
  return d;
}

HostVec column(const mfsi::Real3View& d, int c) {
  auto h = Kokkos::create_mirror_view_and_copy(mfsi::HostSpace(), d);
  HostVec out(h.extent(0));
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = h(i, c);
  return out;
}

}  // namespace

TEST(Blas, ResidualNormsMatchHostGold) {
  const auto m = randomMatrix(kRows, kCols, 15);
  const HostVec x = randomVec(kCols, 16), b = randomVec(kRows, 17);
  auto dx = toDevice(x), db = toDevice(b);
  mfsi::RealView dr("r", kRows), dr2("r2", kRows);
  mfsi::ExecSpace exec;
  const mfsi::SolverComm comm;
  const auto norms = mfsi::blas::residualNorms(exec, comm, m.A, dx, db, dr);
  const HostVec ax = hostSpmv(m, x);
  HostVec r(kRows);
  double l1 = 0;
  for (lid_t i = 0; i < kRows; ++i) {
    r[i] = b[i] - ax[i];
    l1 += std::abs(r[i]);
  }
  EXPECT_TRUE(allNear(toHost(dr), r, kRows, kTight, "r = b - Ax"));
  EXPECT_TRUE(near(norms.rr, hostDot(r, r, kRows), kTight, "r.r"));
  EXPECT_TRUE(near(norms.l1, l1, kTight, "|r|_1"));
  // Same r.r bits as the r.r-only kernel (solvers mixing the two stay bitwise repeatable).
  EXPECT_EQ(norms.rr, mfsi::blas::residual(exec, comm, m.A, dx, db, dr2));
}

TEST(Blas, ThreeColumnKernelsMatchHostGoldAndTheSingleColumnKernels) {
  const auto m = randomMatrix(kRows, kCols, 18);
  const HostVec x[3] = {randomVec(kCols, 19), randomVec(kCols, 20), randomVec(kCols, 21)};
  const HostVec b[3] = {randomVec(kRows, 22), randomVec(kRows, 23), randomVec(kRows, 24)};
  const auto x3 = toDevice3(x[0], x[1], x[2]), b3 = toDevice3(b[0], b[1], b[2]);
  mfsi::Real3View y3("y3", kRows), r3("r3", kRows);
  mfsi::ExecSpace exec;
  const mfsi::SolverComm comm;
  mfsi::blas::spmv(exec, m.A, x3, y3);
  const auto norms = mfsi::blas::residualNorms(exec, comm, m.A, x3, b3, r3);
  for (int c = 0; c < 3; ++c) {
    const std::string col = " column " + std::to_string(c);
    const HostVec ax = hostSpmv(m, x[c]);
    EXPECT_TRUE(allNear(column(y3, c), ax, kRows, kTight, "Y = AX" + col));
    HostVec r(kRows);
    double l1 = 0;
    for (lid_t i = 0; i < kRows; ++i) {
      r[i] = b[c][i] - ax[i];
      l1 += std::abs(r[i]);
    }
    EXPECT_TRUE(allNear(column(r3, c), r, kRows, kTight, "R = B - AX" + col));
    EXPECT_TRUE(near(norms[c].rr, hostDot(r, r, kRows), kTight, "r.r" + col));
    EXPECT_TRUE(near(norms[c].l1, l1, kTight, "|r|_1" + col));
    // Bitwise the single-column kernels: the same operations in the same order.
    mfsi::RealView y("y", kRows), r1("r1", kRows);
    mfsi::blas::spmv(exec, m.A, toDevice(x[c]), y);
    EXPECT_EQ(column(y3, c), toHost(y)) << col;
    const auto single = mfsi::blas::residualNorms(exec, comm, m.A, toDevice(x[c]), toDevice(b[c]), r1);
    EXPECT_EQ(column(r3, c), toHost(r1)) << col;
    EXPECT_EQ(norms[c].rr, single.rr) << col;
    EXPECT_EQ(norms[c].l1, single.l1) << col;
  }
}
