// Jacobi point-Laplacian smoothing: the kernel against a serial host sweep, fixed nodes, weights,
// and the discrete harmonic property (a linear field is reproduced on a uniform grid).
#include "kernels/JacobiSmoothing.hpp"
#include "kernels/LaplacianCg.hpp"

#include "core/BlockMesh.hpp"
#include "support/Approx.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdint>
#include <vector>

using mfsi::lid_t;
using mfsi::test::near;
using mfsi::test::Tol;

namespace {

struct Graph {
  mfsi::HexMesh mesh;
  Kokkos::View<std::uint8_t*, mfsi::MemSpace> fixed;
  mfsi::SmoothingGraph g;
};

/// A box mesh graph whose boundary nodes (any coordinate at 0 or 1) are fixed.
Graph boxGraph(int n, std::array<double, 3> grading = {1, 1, 1}) {
  mfsi::BlockMeshSpec spec = mfsi::boxSpec({0, 0, 0}, {1, 1, 1}, {n, n, n});
  spec.blocks[0].grading = grading;
  Graph r{mfsi::buildHexMesh(mfsi::generateBlockMesh(spec)), {}, {}};
  const lid_t nn = r.mesh.nNodes();
  r.fixed = Kokkos::View<std::uint8_t*, mfsi::MemSpace>("test::fixed", nn);
  auto hf = Kokkos::create_mirror_view(r.fixed);
  auto hx = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), r.mesh.points());
  for (lid_t i = 0; i < nn; ++i) {
    bool b = false;
    for (int c = 0; c < 3; ++c) b = b || std::abs(hx(i, c)) < 1e-12 || std::abs(hx(i, c) - 1) < 1e-12;
    hf(i) = b ? 1 : 0;
  }
  Kokkos::deep_copy(r.fixed, hf);
  r.g.offsets = r.mesh.nodeNodeOffsets();
  r.g.neighbours = r.mesh.nodeNodes();
  r.g.fixed = r.fixed;
  return r;
}

mfsi::Real3View field(lid_t n, double (*f)(double, double, double, int), const mfsi::ConstReal3View& x) {
  mfsi::Real3View d("test::d", n);
  auto hd = Kokkos::create_mirror_view(d);
  auto hx = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), x);
  for (lid_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) hd(i, c) = f(hx(i, 0), hx(i, 1), hx(i, 2), c);
  Kokkos::deep_copy(d, hd);
  return d;
}

double rough(double x, double y, double z, int c) { return std::sin(7 * x + c) * std::cos(5 * y) + z * z * (c + 1); }
double linear(double x, double y, double z, int c) { return 0.3 * x - 0.2 * y + 0.1 * z + 0.05 * c; }

}  // namespace

TEST(JacobiSmoothing, OneSweepEqualsASerialHostSweep) {
  Graph b = boxGraph(5, {1, 1, 4});
  const lid_t n = b.mesh.nNodes();
  auto in = field(n, rough, b.mesh.points());
  mfsi::Real3View out("test::out", n);
  // Weighted too: w_ij = 1 + (i + j) % 3, one per adjacency entry.
  auto hoff = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), b.g.offsets);
  auto hnb = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), b.g.neighbours);
  auto hfix = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), b.fixed);
  auto hin = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), in);
  mfsi::RealView w("test::w", hnb.extent(0));
  auto hw = Kokkos::create_mirror_view(w);
  for (lid_t i = 0; i < n; ++i)
    for (lid_t k = hoff(i); k < hoff(i + 1); ++k) hw(k) = 1 + (i + hnb(k)) % 3;
  Kokkos::deep_copy(w, hw);
  for (const bool weighted : {false, true}) {
    mfsi::SmoothingGraph g = b.g;
    if (weighted) g.weights = w;
    mfsi::ExecSpace exec;
    mfsi::jacobiSweep(exec, g, in, out);
    exec.fence();
    auto hout = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), out);
    int interior = 0;
    for (lid_t i = 0; i < n; ++i) {
      for (int c = 0; c < 3; ++c) {
        double expect = hin(i, c);
        if (hfix(i) == 0) {
          double s = 0, ws = 0;
          for (lid_t k = hoff(i); k < hoff(i + 1); ++k) {
            const double wk = weighted ? hw(k) : 1.0;
            s += wk * hin(hnb(k), c);
            ws += wk;
          }
          expect = s / ws;
        }
        ASSERT_TRUE(near(hout(i, c), expect, Tol{1e-15, 1e-14}, "node " + std::to_string(i)));
      }
      interior += hfix(i) == 0;
    }
    EXPECT_EQ(interior, 4 * 4 * 4);
    for (lid_t i = 0; i < n; ++i)
      if (hfix(i) != 0) {
        for (int c = 0; c < 3; ++c) ASSERT_EQ(hout(i, c), hin(i, c)) << "fixed node " << i << " moved";
      }
  }
}

TEST(JacobiSmoothing, ZeroDisplacementStaysExactlyZero) {
  Graph b = boxGraph(6, {1, 3, 8});
  const lid_t n = b.mesh.nNodes();
  mfsi::Real3View d("test::d", n), work("test::work", n);
  mfsi::ExecSpace exec;
  mfsi::jacobiSmooth(exec, b.g, d, work, 51);
  exec.fence();
  auto hd = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), d);
  for (lid_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) ASSERT_EQ(hd(i, c), 0.0);
}

TEST(JacobiSmoothing, ConvergesToTheLinearFieldItsBoundaryPrescribes) {
  // On a uniform grid the 6-neighbour mean of a linear field is its value: the linear field is
  // the smoother's fixed point, and Jacobi from zero interior values converges to it.
  Graph b = boxGraph(6);
  const lid_t n = b.mesh.nNodes();
  auto exact = field(n, linear, b.mesh.points());
  mfsi::Real3View d("test::d", n), work("test::work", n);
  auto he = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), exact);
  auto hfix = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), b.fixed);
  auto hd = Kokkos::create_mirror_view(d);
  for (lid_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) hd(i, c) = hfix(i) ? he(i, c) : 0.0;
  Kokkos::deep_copy(d, hd);
  mfsi::ExecSpace exec;
  mfsi::jacobiSmooth(exec, b.g, d, work, 1);  // one sweep: still far from it
  exec.fence();
  Kokkos::deep_copy(hd, d);
  double err1 = 0;
  for (lid_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) err1 = std::max(err1, std::abs(hd(i, c) - he(i, c)));
  mfsi::jacobiSmooth(exec, b.g, d, work, 299);
  exec.fence();
  Kokkos::deep_copy(hd, d);
  double err = 0;
  for (lid_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) err = std::max(err, std::abs(hd(i, c) - he(i, c)));
  EXPECT_GT(err1, 0.05);
  EXPECT_LT(err, 1e-10);
}

namespace {
/// d = f on fixed nodes, 0 elsewhere.
mfsi::Real3View boundaryOnly(const Graph& b, double (*f)(double, double, double, int)) {
  const lid_t n = b.mesh.nNodes();
  auto d = field(n, f, b.mesh.points());
  auto hd = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), d);
  auto hfix = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), b.fixed);
  for (lid_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c)
      if (!hfix(i)) hd(i, c) = 0;
  Kokkos::deep_copy(d, hd);
  return d;
}

/// Edge weights 1 / L^2 (L the edge length), as the stiffened smoother uses.
void weightByInverseSquareLength(Graph& b) {
  const lid_t n = b.mesh.nNodes();
  mfsi::RealView w("test::w", b.mesh.nodeNodes().extent(0));
  auto hw = Kokkos::create_mirror_view(w);
  auto off = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), b.mesh.nodeNodeOffsets());
  auto nb = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), b.mesh.nodeNodes());
  auto x = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), b.mesh.points());
  for (lid_t i = 0; i < n; ++i)
    for (lid_t k = off(i); k < off(i + 1); ++k) {
      double l2 = 0;
      for (int c = 0; c < 3; ++c) l2 += (x(nb(k), c) - x(i, c)) * (x(nb(k), c) - x(i, c));
      hw(k) = 1 / l2;
    }
  Kokkos::deep_copy(w, hw);
  b.g.weights = w;
}

double maxDiff(const mfsi::Real3View& a, const mfsi::Real3View& b) {
  Kokkos::View<double* [3], Kokkos::HostSpace> ha("a", a.extent(0)), hb("b", b.extent(0));
  Kokkos::deep_copy(ha, a);
  Kokkos::deep_copy(hb, b);
  double e = 0;
  for (std::size_t i = 0; i < ha.extent(0); ++i)
    for (int c = 0; c < 3; ++c) e = std::max(e, std::abs(ha(i, c) - hb(i, c)));
  return e;
}
}  // namespace

TEST(LaplacianCg, ReachesTheLinearFieldInFarFewerIterationsThanJacobiSweeps) {
  Graph b = boxGraph(6);
  auto exact = field(b.mesh.nNodes(), linear, b.mesh.points());
  auto d = boundaryOnly(b, linear);
  mfsi::LaplacianCgWork work;
  mfsi::LaplacianCgOptions opt;
  opt.relTol = 1e-13;
  const auto r = mfsi::laplacianCg(mfsi::ExecSpace(), b.g, d, work, opt);
  EXPECT_TRUE(r.converged);
  EXPECT_LT(r.iterations, 30) << "Jacobi needs ~300 sweeps for 1e-10 on this grid";
  EXPECT_GT(r.initialResidual, 0.1);
  EXPECT_LT(maxDiff(d, exact), 1e-12);
}

TEST(LaplacianCg, SolvesWhatTheSweepsConvergeToOnAGradedMeshAndLeavesASolvedFieldAlone) {
  // Graded cells and edge weights 1/L^2: the same weighted harmonic field as Jacobi converged.
  Graph b = boxGraph(7, {4, 1, 0.5});
  const lid_t n = b.mesh.nNodes();
  weightByInverseSquareLength(b);
  auto byCg = boundaryOnly(b, rough), bySweeps = boundaryOnly(b, rough);
  mfsi::Real3View work3("test::work", n);
  mfsi::ExecSpace exec;
  mfsi::jacobiSmooth(exec, b.g, bySweeps, work3, 20000);
  mfsi::LaplacianCgWork work;
  mfsi::LaplacianCgOptions opt;
  opt.relTol = 1e-12;
  const auto r = mfsi::laplacianCg(exec, b.g, byCg, work, opt);
  EXPECT_TRUE(r.converged);
  EXPECT_LT(maxDiff(byCg, bySweeps), 1e-9);
  EXPECT_GT(maxDiff(byCg, boundaryOnly(b, rough)), 0.05) << "the interior did move";
  // A solved field is (nearly) its own answer: the warm start needs at most a few iterations to
  // the round-off floor and moves nothing beyond the first solve's tolerance.
  mfsi::Real3View again("test::again", n);
  Kokkos::deep_copy(again, byCg);
  const auto r2 = mfsi::laplacianCg(exec, b.g, again, work, opt);
  EXPECT_LE(r2.iterations, 3);
  EXPECT_LT(maxDiff(again, byCg), 1e-10);
  // Zero data: zero iterations, exactly zero.
  mfsi::Real3View zero("test::zero", n);
  const auto r3 = mfsi::laplacianCg(exec, b.g, zero, work, opt);
  EXPECT_EQ(r3.iterations, 0);
  EXPECT_EQ(maxDiff(zero, mfsi::Real3View("test::zeros", n)), 0.0);
}

TEST(LaplacianCg, AFieldScaledToleranceLetsAGoodWarmStartEndEarly) {
  // The coupling's motions: the last solution, its boundary moved a little. Reducing the warm
  // start's (small) residual by relTol costs as many iterations as a cold solve; a tolerance on
  // the field's scale stops as soon as the residual is small against the field itself.
  Graph b = boxGraph(8, {4, 1, 0.5});
  const lid_t n = b.mesh.nNodes();
  weightByInverseSquareLength(b);
  mfsi::ExecSpace exec;
  mfsi::LaplacianCgWork work;
  mfsi::LaplacianCgOptions tight;
  tight.relTol = 1e-13;
  auto solved = boundaryOnly(b, rough);
  mfsi::laplacianCg(exec, b.g, solved, work, tight);
  // The next motion: every boundary value 0.1 % larger (the boundary of `rough` scaled).
  auto exactNext = boundaryOnly(b, rough);
  {
    auto h = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), exactNext);
    for (lid_t i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c) h(i, c) *= 1.001;
    Kokkos::deep_copy(exactNext, h);
  }
  auto warm = [&]() {
    // Interior from the last solution, boundary from the next motion.
    mfsi::Real3View w("test::warm", n);
    auto hw = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), solved);
    auto hb = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), exactNext);
    auto fixed = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), b.g.fixed);
    for (lid_t i = 0; i < n; ++i)
      if (fixed(i) != 0)
        for (int c = 0; c < 3; ++c) hw(i, c) = hb(i, c);
    Kokkos::deep_copy(w, hw);
    return w;
  };
  mfsi::laplacianCg(exec, b.g, exactNext, work, tight);
  mfsi::LaplacianCgOptions reduce, scaled;
  reduce.relTol = scaled.relTol = 1e-5;
  scaled.fieldScaled = true;
  auto byReduction = warm(), byScale = warm();
  const auto rr = mfsi::laplacianCg(exec, b.g, byReduction, work, reduce);
  const auto rs = mfsi::laplacianCg(exec, b.g, byScale, work, scaled);
  EXPECT_TRUE(rs.converged);
  EXPECT_LT(rs.iterations, rr.iterations / 2) << rs.iterations << " against " << rr.iterations;
  // It still solves: the warm start's error (the 0.1 % boundary change not yet carried inside)
  // falls tenfold, to the order of relTol times the grid's condition number (~ 8^2).
  EXPECT_LT(maxDiff(byScale, exactNext), 0.1 * maxDiff(warm(), exactNext));
  EXPECT_LT(maxDiff(byScale, exactNext), 1e-3);
}

TEST(LaplacianCg, TheAmgPreconditionerSolvesTheSameFieldInAFewIterationsWithSlidingNodes) {
  // A 16^3 box graded 8:1 with 1/L^2 weights; the nodes of the x = 0 face (not on other faces)
  // slide in that face. Jacobi-preconditioned and AMG-preconditioned CG must land on the same
  // field, the sliding nodes keep their normal (x) component, and AMG needs far fewer iterations.
  Graph b = boxGraph(16, {8, 1, 1});
  const lid_t n = b.mesh.nNodes();
  auto x = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), b.mesh.points());
  auto hfix = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), b.fixed);
  mfsi::Real3View slide("test::slide", n);
  auto hs = Kokkos::create_mirror_view(slide);
  for (lid_t i = 0; i < n; ++i) {
    bool onOther = false;
    for (int c = 1; c < 3; ++c) onOther = onOther || std::abs(x(i, c)) < 1e-12 || std::abs(x(i, c) - 1) < 1e-12;
    if (std::abs(x(i, 0)) < 1e-12 && !onOther) {
      hfix(i) = 0;
      hs(i, 0) = 1;
    }
  }
  Kokkos::deep_copy(b.fixed, hfix);
  Kokkos::deep_copy(slide, hs);
  b.g.slideNormal = slide;
  weightByInverseSquareLength(b);
  auto byJacobi = boundaryOnly(b, rough), byAmg = boundaryOnly(b, rough);
  const auto start = boundaryOnly(b, rough);
  mfsi::ExecSpace exec;
  mfsi::LaplacianCgOptions opt;
  opt.relTol = 1e-10;
  mfsi::LaplacianCgWork jw, aw;
  const auto rj = mfsi::laplacianCg(exec, b.g, byJacobi, jw, opt);
  opt.preconditioner = mfsi::LaplacianPreconditioner::Amg;
  const auto ra = mfsi::laplacianCg(exec, b.g, byAmg, aw, opt);
  ASSERT_TRUE(rj.converged);
  ASSERT_TRUE(ra.converged);
  EXPECT_LT(maxDiff(byAmg, byJacobi), 1e-8);
  EXPECT_GT(maxDiff(byAmg, start), 0.05) << "the interior did move";
  EXPECT_LE(ra.iterations * 4, rj.iterations) << "AMG " << ra.iterations << ", Jacobi " << rj.iterations;
  std::printf("CG iterations to 1e-10: AMG %d, Jacobi %d\n", ra.iterations, rj.iterations);
  auto ha = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), byAmg);
  auto h0 = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), start);
  double normalDrift = 0;
  for (lid_t i = 0; i < n; ++i)
    if (hs(i, 0) == 1) normalDrift = std::max(normalDrift, std::abs(ha(i, 0) - h0(i, 0)));
  EXPECT_EQ(normalDrift, 0.0) << "sliding nodes keep their normal component";
  // The set-up is kept: a second solve from the answer needs at most a couple of iterations.
  const auto again = mfsi::laplacianCg(exec, b.g, byAmg, aw, opt);
  EXPECT_LE(again.iterations, 2);
}
