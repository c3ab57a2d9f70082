// Coupling accelerations on fixed points with known answers: x = H(x) = A x + b.
#include "coupling/acceleration/Acceleration.hpp"
#include "coupling/acceleration/QuasiNewton.hpp"

#include "core/Error.hpp"
#include "core/io/Checkpoint.hpp"
#include "core/io/Hdf5File.hpp"
#include "support/Approx.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

using mfsi::coupling::AccelerationMethod;
using mfsi::coupling::AccelerationOptions;
using mfsi::coupling::AccelerationReport;
using mfsi::coupling::InterfaceBlock;
using mfsi::coupling::InterfaceVector;
using mfsi::coupling::makeAcceleration;
using mfsi::test::near;
using mfsi::test::Tol;

namespace {

/// An affine map whose plain fixed-point iteration diverges: A random with spectral radius ~1.5.
struct Affine {
  Eigen::MatrixXd A;
  InterfaceVector b;
  InterfaceVector operator()(const InterfaceVector& x) const { return A * x + b; }
  InterfaceVector solution() const {
    const Eigen::Index n = A.rows();
    return (Eigen::MatrixXd::Identity(n, n) - A).fullPivLu().solve(b);
  }
};

Affine randomAffine(int n, unsigned seed, double radius = 1.5) {
  std::mt19937 gen(seed);
  std::normal_distribution<double> nd;
  Affine h{Eigen::MatrixXd(n, n), InterfaceVector(n)};
  for (int i = 0; i < n; ++i) {
    h.b[i] = nd(gen);
    for (int j = 0; j < n; ++j) h.A(i, j) = nd(gen);
  }
  const double rho = h.A.eigenvalues().cwiseAbs().maxCoeff();
  h.A *= radius / rho;
  return h;
}

std::vector<InterfaceBlock> oneBlock(Eigen::Index n) { return {{"x", 0, n}}; }

AccelerationOptions iqn(int maxCols, double filter) {
  AccelerationOptions o;
  o.method = AccelerationMethod::IqnIls;
  o.iqnMaxCols = maxCols;
  o.iqnFilterEps = filter;
  o.omegaInit = 0.5;
  o.stallIterations = 0;  // the residual of a quasi-Newton sequence need not fall monotonically
  return o;
}

/// Aitken from omega 0.5, bounded below by 0.05.
AccelerationOptions aitken() {
  AccelerationOptions o;
  o.method = AccelerationMethod::Aitken;
  o.omegaInit = 0.5;
  o.omegaMin = 0.05;
  return o;
}

}  // namespace

TEST(Acceleration, PlainIterationOfTheTestMapDiverges) {
  // The test problem is hard on purpose: without acceleration the iterates grow.
  const Affine h = randomAffine(8, 1);
  AccelerationOptions o;
  o.method = AccelerationMethod::Constant;
  o.omegaInit = 1.0;
  auto acc = makeAcceleration(o, oneBlock(8));
  acc->beginStep();
  InterfaceVector x = InterfaceVector::Zero(8);
  for (int k = 0; k < 40; ++k) acc->update(h(x), x);
  EXPECT_GT((x - h.solution()).norm(), 1e3 * h.solution().norm());
}

TEST(Acceleration, IqnIlsSolvesAnAffineFixedPointInAtMostNPlusOnePasses) {
  for (const int n : {1, 3, 8, 12}) {
    const Affine h = randomAffine(n, 10 + n);
    const InterfaceVector xs = h.solution();
    auto acc = makeAcceleration(iqn(2 * n, 1e-10), oneBlock(n));
    acc->beginStep();
    InterfaceVector x = InterfaceVector::Zero(n);
    double errAfterTwo = 0;
    for (int k = 1; k <= n + 1; ++k) {
      const AccelerationReport rep = acc->update(h(x), x);
      EXPECT_EQ(rep.columns, k - 1) << "n " << n << " pass " << k;
      if (k == 2) errAfterTwo = (x - xs).norm() / xs.norm();
    }
    EXPECT_LT((x - xs).norm(), 1e-9 * xs.norm()) << "n = " << n << ": not at the fixed point after n + 1 passes";
    if (n > 2) {
      EXPECT_GT(errAfterTwo, 1e-3) << "n = " << n << ": the problem is too easy to show anything";
    }
  }
}

TEST(Acceleration, IqnIlsWithTheDefaultFilterStillConverges) {
  const int n = 12;
  const Affine h = randomAffine(n, 99);
  const InterfaceVector xs = h.solution();
  auto acc = makeAcceleration(iqn(50, AccelerationOptions{}.iqnFilterEps), oneBlock(n));
  acc->beginStep();
  InterfaceVector x = InterfaceVector::Zero(n);
  int k = 0;
  while (k < 3 * n && (h(x) - x).norm() > 1e-10 * xs.norm()) {
    acc->update(h(x), x);
    ++k;
  }
  EXPECT_LT((h(x) - x).norm(), 1e-10 * xs.norm()) << "after " << k << " passes";
  EXPECT_LE(k, 2 * n);
}

TEST(Acceleration, AitkenFindsTheSecantOfAScalarStrongAddedMassMap) {
  // H(x) = a x + b with a = -9: the map of a structure 9x lighter than its added mass; plain
  // iteration diverges, the exact relaxation is 1 / (1 - a) = 0.1, which Aitken finds at its second
  // pass and which lands on the fixed point.
  const double a = -9, b = 2, xs = b / (1 - a);
  auto acc = makeAcceleration(aitken(), oneBlock(1));
  acc->beginStep();
  InterfaceVector x = InterfaceVector::Zero(1);
  auto H = [&](const InterfaceVector& y) { return InterfaceVector::Constant(1, a * y[0] + b); };
  EXPECT_DOUBLE_EQ(acc->update(H(x), x).omega, 0.5);
  const AccelerationReport second = acc->update(H(x), x);
  EXPECT_TRUE(near(second.omega, 0.1, Tol{1e-14, 0}, "omega"));
  EXPECT_TRUE(near(x[0], xs, Tol{1e-14, 0}, "x"));
}

TEST(Acceleration, AitkenOmegaStaysInItsBounds) {
  // H(x) = a x + b with a = -99: the exact relaxation 0.01 is below omegaMin = 0.05, so omega stops
  // at the bound (and the iteration, 1 - 0.05 * 100 = -4 per pass, diverges: the bound is honoured).
  auto acc = makeAcceleration(aitken(), oneBlock(1));
  acc->beginStep();
  InterfaceVector x = InterfaceVector::Zero(1);
  for (int k = 0; k < 5; ++k) {
    const auto rep = acc->update(InterfaceVector::Constant(1, -99 * x[0] + 1), x);
    EXPECT_GE(rep.omega, 0.05);
    EXPECT_LE(rep.omega, 1.0);
    if (k > 0) {
      EXPECT_DOUBLE_EQ(rep.omega, 0.05);
    }
  }
}

TEST(Acceleration, TheLimiterReplacesAnOversizedQuasiNewtonStepByRelaxation) {
  const int n = 6;
  const Affine h = randomAffine(n, 5);
  AccelerationOptions o = iqn(10, 1e-10);
  o.maxUpdate = 1e-6;  // every quasi-Newton step is larger than this
  auto acc = makeAcceleration(o, oneBlock(n));
  acc->beginStep();
  InterfaceVector x = InterfaceVector::Zero(n);
  acc->update(h(x), x);  // first pass: relaxation, no history
  const InterfaceVector before = x, xt = h(x);
  const AccelerationReport rep = acc->update(xt, x);
  EXPECT_TRUE(rep.fellBack);
  EXPECT_EQ(rep.columns, 0);
  EXPECT_GE(rep.omega, o.omegaMin);
  EXPECT_LT((x - (before + rep.omega * (xt - before))).norm(), 1e-14 * x.norm());
}

TEST(Acceleration, AStalledResidualRestartsTheHistory) {
  // H(x) = x + c: the residual is c whatever x is, so it never falls below its first value.
  const int n = 4;
  AccelerationOptions o = iqn(10, 1e-2);
  o.stallIterations = 3;  // (the default is 10)
  auto acc = makeAcceleration(o, oneBlock(n));
  acc->beginStep();
  InterfaceVector x = InterfaceVector::Zero(n);
  const InterfaceVector c = InterfaceVector::LinSpaced(n, 1, 2);
  std::vector<int> restarts;
  for (int k = 1; k <= 8; ++k)
    if (acc->update(x + c, x).restarted) restarts.push_back(k);
  EXPECT_EQ(restarts, (std::vector<int>{4, 7}));
}

TEST(Acceleration, ReusedColumnsChangeIterationsNotResults) {
  // A sequence of time steps: the same A, a slowly changing b. With the columns of earlier steps
  // reused, later steps need fewer passes; the converged answers agree to the tolerance.
  const int n = 10;
  const double tol = 1e-10;
  Affine h = randomAffine(n, 3, 0.9);
  const InterfaceVector b0 = h.b;
  auto run = [&](int reuse, std::vector<InterfaceVector>& answers) {
    AccelerationOptions o = iqn(30, 1e-2);
    o.iqnReuseCols = reuse;
    auto acc = makeAcceleration(o, oneBlock(n));
    InterfaceVector x = InterfaceVector::Zero(n);
    int passes = 0;
    for (int step = 0; step < 6; ++step) {
      h.b = b0 * (1.0 + 0.05 * step);
      acc->beginStep();
      for (int k = 0; k < 60 && (h(x) - x).norm() > tol * x.norm(); ++k, ++passes) acc->update(h(x), x);
      answers.push_back(x);
    }
    return passes;
  };
  std::vector<InterfaceVector> fresh, reused;
  const int passesFresh = run(0, fresh), passesReused = run(2, reused);
  EXPECT_LT(passesReused, passesFresh);
  for (std::size_t s = 0; s < fresh.size(); ++s)
    EXPECT_LT((fresh[s] - reused[s]).norm(), 10 * tol * fresh[s].norm()) << "step " << s;
}

TEST(Acceleration, TheKeptFactorisationStaysTheHistorysQr) {
  // The factorisation is updated, not rebuilt: columns enter at the front (Givens), the oldest
  // leave at the history's limit and at the reuse window, filtered ones leave from the middle.
  // After every pass it must still be a QR factorisation of the scaled history.
  const int n = 10;
  Affine h = randomAffine(n, 5, 0.9);
  const InterfaceVector b0 = h.b;
  AccelerationOptions o = iqn(7, 0.4);
  o.iqnReuseCols = 2;
  auto acc = makeAcceleration(o, oneBlock(n));
  auto* qn = dynamic_cast<mfsi::coupling::QuasiNewton*>(acc.get());
  ASSERT_NE(qn, nullptr);
  InterfaceVector x = InterfaceVector::Zero(n);
  int dropped = 0, limited = 0;
  for (int step = 0; step < 8; ++step) {
    h.b = b0 * (1.0 + 0.3 * step);
    acc->beginStep();
    for (int k = 0; k < 30 && (h(x) - x).norm() > 1e-10 * x.norm(); ++k) {
      const AccelerationReport rep = acc->update(h(x), x);
      dropped += rep.dropped;
      limited += qn->columns() == 7 ? 1 : 0;
      EXPECT_LT(qn->factorisationDefect(), 1e-11) << "step " << step << " pass " << k;
    }
  }
  EXPECT_GT(dropped, 0) << "the filter never acted: the test shows less than it should";
  EXPECT_GT(limited, 0) << "the history never reached its limit";
}

TEST(Acceleration, BlockScalingMakesIqnIlsIndependentOfUnits) {
  // Two blocks (say metres and radians); expressing the second in units 1e6 times smaller
  // (y2 = 1e6 x2) must not change the iteration: the same iterates up to the change of units.
  const int n = 8, n1 = 5;
  const Affine h = randomAffine(n, 21);
  Eigen::VectorXd d = Eigen::VectorXd::Ones(n);
  d.tail(n - n1).setConstant(1e6);
  const std::vector<InterfaceBlock> layout = {{"membrane", 0, n1}, {"body", n1, n - n1}};
  auto a1 = makeAcceleration(iqn(20, 1e-2), layout);
  auto a2 = makeAcceleration(iqn(20, 1e-2), layout);
  a1->beginStep();
  a2->beginStep();
  InterfaceVector x = InterfaceVector::Zero(n), y = InterfaceVector::Zero(n);
  for (int k = 0; k < n + 1; ++k) {
    a1->update(h(x), x);
    const InterfaceVector hy = d.asDiagonal() * h(d.cwiseInverse().asDiagonal() * y);
    a2->update(hy, y);
    const InterfaceVector back = d.cwiseInverse().asDiagonal() * y;
    EXPECT_LT((back - x).norm(), 1e-9 * x.norm()) << "pass " << k + 1;
  }
}

TEST(Acceleration, TheFactoryAndTheOptionChecks) {
  AccelerationOptions o;
  o.iqnMaxCols = 4;  // selects IQN-ILS whatever the method says
  auto acc = makeAcceleration(o, oneBlock(3));
  EXPECT_NE(dynamic_cast<mfsi::coupling::IqnIls*>(acc.get()), nullptr);
  o = AccelerationOptions{};
  o.omegaInit = 0;
  EXPECT_THROW(makeAcceleration(o, oneBlock(3)), mfsi::InputError);
  o = AccelerationOptions{};
  auto aitken = makeAcceleration(o, oneBlock(3));
  InterfaceVector x = InterfaceVector::Zero(3);
  const InterfaceVector wrong = InterfaceVector::Zero(4);
  EXPECT_THROW(aitken->update(wrong, x), mfsi::InputError);
}

namespace {

/// Passes until |H(x) - x| < 1e-10 |x*| (at most `limit`), from x, within one step of `acc`;
/// `firstError`: |x - x*| / |x*| after the first pass.
int solveStep(mfsi::coupling::Acceleration& acc, const Affine& h, InterfaceVector& x, int limit,
              double* firstError = nullptr) {
  const double scale = h.solution().norm();
  acc.beginStep();
  int k = 0;
  while (k < limit && (h(x) - x).norm() > 1e-10 * scale) {
    acc.update(h(x), x);
    if (++k == 1 && firstError) *firstError = (x - h.solution()).norm() / scale;
  }
  acc.endStep();
  return k;
}

AccelerationOptions imvj(int maxCols) {
  AccelerationOptions o = iqn(maxCols, 1e-10);
  o.iqnJacobian = mfsi::coupling::IqnJacobian::MultiVector;
  return o;
}

}  // namespace

// IQN-IMVJ keeps the inverse Jacobian of past steps. On steps of one affine map with a new b each
// step (the same Jacobian, other loads), the first step takes about n + 1 passes like IQN-ILS;
// from then on the Jacobian is exact and its first quasi-Newton pass lands on the fixed point to
// 1e-8 (measured 1e-12 to 5e-12), where IQN-ILS without reused columns learns it anew every step.
TEST(Acceleration, IqnImvjCarriesTheJacobianToTheNextSteps) {
  const int n = 8;
  Affine h = randomAffine(n, 5);
  const InterfaceVector b0 = h.b;
  auto multi = makeAcceleration(imvj(2 * n), oneBlock(n));
  auto ils = makeAcceleration(iqn(2 * n, 1e-10), oneBlock(n));
  ASSERT_NE(dynamic_cast<mfsi::coupling::IqnImvj*>(multi.get()), nullptr);
  InterfaceVector xm = InterfaceVector::Zero(n), xi = InterfaceVector::Zero(n);
  for (int step = 0; step < 4; ++step) {
    h.b = b0 * (1 + 0.3 * step);
    h.b[step % n] += 1;
    double first = 0;
    const int pm = solveStep(*multi, h, xm, 4 * n, &first), pi = solveStep(*ils, h, xi, 4 * n);
    std::printf("step %d: IQN-IMVJ %d passes (error %.1e after the first), IQN-ILS %d\n", step, pm, first, pi);
    EXPECT_LT((h(xm) - xm).norm(), 1e-10 * h.solution().norm()) << "step " << step;
    if (step == 0) {
      EXPECT_LE(pm, n + 2);
    } else {
      EXPECT_LT(first, 1e-8) << "step " << step << ": the carried Jacobian is exact";
      EXPECT_LE(pm, 3);
      EXPECT_GE(pi, n / 2) << "IQN-ILS without reuse starts over";
    }
  }
  // What it carries is the exact inverse Jacobian of the residual map, J* = A (A - I)^-1.
  const Eigen::MatrixXd exact = h.A * (h.A - Eigen::MatrixXd::Identity(n, n)).inverse();
  const Eigen::MatrixXd j = dynamic_cast<mfsi::coupling::IqnImvj&>(*multi).jacobian();
  EXPECT_LT((j - exact).norm(), 1e-8 * exact.norm());
}

// The carried Jacobian is (1 - omegaInit) I plus a low-rank part that a truncated SVD compresses
// past iqnJacobianRank columns. On an affine map whose inverse Jacobian is (1 - omegaInit) I plus
// a rank-2 matrix, every update W - J V lies in that matrix's column space, so however many
// columns the part holds its rank is 2: compressed to 2 columns (cap 4) the Jacobian is the one of
// a twin that never compresses, step after step, on two blocks of very different scale (the
// compression works in the block-scaled space and maps back); compressed to 1 column (cap 2) it is
// not, and the steps still converge (the least-squares part of each step makes up for it).
TEST(Acceleration, IqnImvjCompressesItsJacobianWithoutLosingALowRankOne) {
  const int n = 12;
  std::mt19937 gen(23);
  std::normal_distribution<double> nd;
  Eigen::MatrixXd u(n, 2), v(n, 2);
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < 2; ++c) {
      u(i, c) = nd(gen);
      v(i, c) = nd(gen);
    }
  const std::vector<InterfaceBlock> blocks = {{"membrane", 0, n / 2}, {"body", n / 2, n / 2}};
  AccelerationOptions o = imvj(2 * n);
  o.iqnFilterEps = AccelerationOptions{}.iqnFilterEps;  // nearly dependent columns would amplify round-off
  // J* = A (A - I)^-1 for A = (J* - I)^-1 J*, since J* and J* - I commute.
  const Eigen::MatrixXd exact = (1 - o.omegaInit) * Eigen::MatrixXd::Identity(n, n) + 0.3 * u * v.transpose();
  Affine h{(exact - Eigen::MatrixXd::Identity(n, n)).inverse() * exact, InterfaceVector(n)};
  std::vector<InterfaceVector> loads;
  for (int step = 0; step < 10; ++step) {
    InterfaceVector b(n);
    for (int i = 0; i < n; ++i) b[i] = (i < n / 2 ? 10.0 : 0.1) * nd(gen);
    loads.push_back(b);
  }
  auto twin = makeAcceleration(o, blocks);
  std::vector<Eigen::MatrixXd> twinJacobians;
  InterfaceVector xt = InterfaceVector::Zero(n);
  for (const InterfaceVector& b : loads) {
    h.b = b;
    solveStep(*twin, h, xt, 4 * n);
    twinJacobians.push_back(dynamic_cast<mfsi::coupling::IqnImvj&>(*twin).jacobian());
  }
  ASSERT_EQ(dynamic_cast<mfsi::coupling::IqnImvj&>(*twin).compressions(), 0);
  ASSERT_GT(dynamic_cast<mfsi::coupling::IqnImvj&>(*twin).rank(), 4);
  for (int rankCap : {4, 2}) {
    o.iqnJacobianRank = rankCap;
    auto acc = makeAcceleration(o, blocks);
    auto& multi = dynamic_cast<mfsi::coupling::IqnImvj&>(*acc);
    InterfaceVector x = InterfaceVector::Zero(n);
    double largest = 0;
    for (std::size_t step = 0; step < loads.size(); ++step) {
      h.b = loads[step];
      const int passes = solveStep(*acc, h, x, 4 * n);
      EXPECT_LT((h(x) - x).norm(), 1e-10 * h.solution().norm()) << "rank cap " << rankCap << ", step " << step;
      EXPECT_LE(passes, 2 * n) << "rank cap " << rankCap << ", step " << step;
      EXPECT_LE(multi.rank(), rankCap);
      const Eigen::MatrixXd& j = twinJacobians[step];
      largest = std::max(largest, (multi.jacobian() - j).norm() / j.norm());
    }
    EXPECT_GE(multi.compressions(), 2);
    if (rankCap == 4)
      EXPECT_LT(largest, 1e-9) << "a rank-2 part survives compressions to 2 columns";
    else
      EXPECT_GT(largest, 1e-3) << "one column cannot hold a rank-2 part";
  }
}

// A checkpoint of IQN-IMVJ between steps (columns, factorisation and the carried Jacobian): a new
// acceleration loaded from it takes the next step's passes bit for bit as the continued one, also
// right after a compression of the Jacobian (rank cap 2).
TEST(Acceleration, IqnImvjContinuesFromItsCheckpointBitwise) {
  const int n = 6;
  for (int rankCap : {200, 2}) {
    Affine h = randomAffine(n, 17);
    AccelerationOptions o = imvj(3 * n);
    o.iqnReuseCols = 1;
    o.iqnJacobianRank = rankCap;
    auto a = makeAcceleration(o, oneBlock(n));
    InterfaceVector x = InterfaceVector::Zero(n);
    solveStep(*a, h, x, 4 * n);
    EXPECT_EQ(dynamic_cast<mfsi::coupling::IqnImvj&>(*a).compressions(), rankCap == 2 ? 1 : 0);
    const std::string path = ::testing::TempDir() + "/imvj_state.h5";
    {
      mfsi::io::Hdf5File file = mfsi::io::Hdf5File::create(path);
      mfsi::io::StateWriter w(file, "/acceleration");
      a->saveState(w);
      file.commit();
    }
    auto b = makeAcceleration(o, oneBlock(n));
    {
      const mfsi::io::Hdf5File file = mfsi::io::Hdf5File::openRead(path);
      b->loadState(mfsi::io::StateReader(file, "/acceleration"));
    }
    h.b *= 1.7;
    InterfaceVector xa = x, xb = x;
    for (int step = 0; step < 2; ++step) {
      a->beginStep();
      b->beginStep();
      for (int k = 0; k < 4; ++k) {
        a->update(h(xa), xa);
        b->update(h(xb), xb);
        for (int i = 0; i < n; ++i) ASSERT_EQ(xa[i], xb[i]) << "rank cap " << rankCap << ", pass " << k;
      }
      a->endStep();
      b->endStep();
    }
  }
}
