// What a membrane time step needs inside an FSI coupling: the artificial interface mass and the
// line search.
//
// The artificial added mass of a coupling iteration (MembraneSolver::setInterfaceMass): a step
// solved from a start displacement u* adds m_a (a_1 - a_1*) to the inertia. On a pre-stressed
// square under a step pressure:
//  - started from the step's own answer, the solve returns it unchanged (the term vanishes there);
//  - started from the predictor, the answer moves by a visible amount (so the term does act);
//  - the fixed-point iteration "start the next solve from the last answer" converges to the plain
//    step's answer, with the contraction factor m_a / (m_s + m_a) of a mass-dominated step.
#include "support/Approx.hpp"

#include "structure/membrane/MembraneSolver.hpp"

#include <cmath>

using namespace mfsi;

namespace {

constexpr double kRho = 1000.0, kH = 1e-3;  // m_s = rho h = 1 kg/m^2

struct Square {
  MembraneMesh mesh;
  MembraneBoundary bc;
  MembraneOptions opt;
  MembraneLoads loads;
};

Square square() {
  MembraneRectangleSpec rect;
  rect.lx = rect.ly = 1.0;
  rect.nx = rect.ny = 8;
  Square s{buildMembraneMesh(generateRectangleMesh(rect)), {}, {}, {}};
  s.bc.clamps.push_back({s.mesh.nodeSet("boundary"), {}, {}});
  s.opt.material = {1e7, 0.3, kH, kRho, 100.0};  // E, nu, h, rho, T0
  s.opt.tolerance = 1e-12;
  s.loads.pressure = 50;
  return s;
}

std::vector<double> host(const ConstRealView& v) {
  auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), v);
  return std::vector<double>(h.data(), h.data() + h.extent(0));
}

double maxDifference(const std::vector<double>& a, const std::vector<double>& b) {
  double m = 0;
  for (std::size_t i = 0; i < a.size(); ++i) m = std::max(m, std::abs(a[i] - b[i]));
  return m;
}

double maxAbs(const std::vector<double>& a) {
  double m = 0;
  for (double x : a) m = std::max(m, std::abs(x));
  return m;
}

}  // namespace

TEST(MembraneInterfaceMass, VanishesAtItsStartAndActsElsewhere) {
  const double dt = 0.01;
  Square sq = square();
  MembraneSolver plain(sq.mesh, sq.opt, sq.bc, sq.loads);
  ASSERT_TRUE(plain.solveStep(dt).converged);
  const std::vector<double> uPlain = host(plain.trialDisplacement());
  const double scale = maxAbs(uPlain);
  ASSERT_GT(scale, 1e-4);

  MembraneSolver s(sq.mesh, sq.opt, sq.bc, sq.loads);
  s.setInterfaceMass(3.0);  // m_a = 3 m_s
  // From the predictor (no trial yet): the artificial mass holds the step back.
  ASSERT_TRUE(s.solveStep(dt).converged);
  const std::vector<double> uHeld = host(s.trialDisplacement());
  EXPECT_GT(maxDifference(uHeld, uPlain), 0.3 * scale) << "the interface mass must act away from its start";
  // From the plain answer: unchanged.
  RealView start("start", uPlain.size());
  auto h = Kokkos::create_mirror_view(start);
  for (std::size_t i = 0; i < uPlain.size(); ++i) h(i) = uPlain[i];
  Kokkos::deep_copy(start, h);
  s.setTrialDisplacement(start);
  ASSERT_TRUE(s.solveStep(dt).converged);
  EXPECT_LT(maxDifference(host(s.trialDisplacement()), uPlain), 1e-9 * scale);
}

TEST(MembraneInterfaceMass, RepeatedSolvesConvergeToThePlainStep) {
  const double dt = 0.01, ma = 3.0;
  Square sq = square();
  MembraneSolver plain(sq.mesh, sq.opt, sq.bc, sq.loads);
  ASSERT_TRUE(plain.solveStep(dt).converged);
  const std::vector<double> uPlain = host(plain.trialDisplacement());

  MembraneSolver s(sq.mesh, sq.opt, sq.bc, sq.loads);
  s.setInterfaceMass(ma);
  std::vector<double> errors;
  for (int k = 0; k < 12; ++k) {
    ASSERT_TRUE(s.solveStep(dt).converged) << "solve " << k;  // starts from the last answer
    errors.push_back(maxDifference(host(s.trialDisplacement()), uPlain));
  }
  // The error contracts by m_a / (m_s + m_a + the stiffness's share) per solve: 0.75 for
  // m_s = 1 kg/m^2 and a step this short (T0 dt^2 k^2 << m_s), a little less with the stiffness.
  for (std::size_t k = 4; k < errors.size(); ++k) {
    EXPECT_LT(errors[k], 0.76 * errors[k - 1]) << "solve " << k;
    EXPECT_GT(errors[k], 0.70 * errors[k - 1]) << "solve " << k;
  }
  EXPECT_LT(errors.back(), 0.05 * errors.front());
}

TEST(MembraneInterfaceMass, RefusesANegativeMass) {
  Square sq = square();
  MembraneSolver s(sq.mesh, sq.opt, sq.bc, sq.loads);
  EXPECT_THROW(s.setInterfaceMass(-1.0), std::exception);
  EXPECT_THROW(s.setInterfaceMass(std::nan("")), std::exception);
}

// The time step's line search (MembraneNewtonOptions::maxLineSearchSteps): a stress-free dome of
// tension-field membrane (the pump's: radius 4 cm, 1.5 cm high, E h = 1.4e5 N/m, rho h = 0.275
// kg/m^2) pushed from its convex side, with the exact tangent (no safeguard stiffness, no stress
// floor). The push compresses the dome: it goes slack, snaps through and stiffens again where it
// stretches, and the tangent jumps between the mass alone and E h. With the line search ten steps
// of 1 ms converge and carry the dome through (the centre past the dome's mirror image, below
// -1.5 cm, and not beyond -3.5 cm); with full Newton steps the first step already fails.
TEST(MembraneStepLineSearch, DomeSnapsThroughUnderPressureOnItsConvexSide) {
  for (double P : {100.0, 1000.0}) {
    for (int steps : {0, 12}) {
      MembraneDiscSpec disc;
      disc.radius = 0.04;
      disc.nCore = disc.nRing = 6;
      MembraneMeshInput in = generateDiscMesh(disc);
      for (auto& X : in.points) X[2] = 0.015 * std::cos(0.5 * M_PI * std::hypot(X[0], X[1]) / disc.radius);
      const MembraneMesh mesh = buildMembraneMesh(in);
      MembraneBoundary bc;
      bc.clamps.push_back({mesh.nodeSet("boundary"), {}, {}});
      MembraneOptions opt;
      opt.material = {5.5e8, 0.3, 2.5e-4, 1100, 0};  // E, nu, h, rho, T0
      opt.wrinkling = MembraneWrinklingModel::TensionField;
      opt.wrinklingStiffnessFraction = 0;
      opt.newton.tangentStressFloor = 0;
      opt.newton.maxLineSearchSteps = steps;
      opt.tolerance = 1e-9;
      MembraneLoads loads;
      loads.pressure = -P;  // against the normal (+z at the apex): onto the convex side
      MembraneSolver s(mesh, opt, bc, loads);
      int done = 0;
      for (; done < 10; ++done)
        if (!s.step(0.001).converged) break;
      if (steps == 0) {
        EXPECT_LT(done, 10) << P << " Pa: full Newton steps got through (the case no longer proves the search)";
      } else {
        EXPECT_EQ(done, 10) << P << " Pa";
        const double w = s.summary().at("centreDeflection");
        EXPECT_LT(w, -0.015) << P << " Pa";
        EXPECT_GT(w, -0.035) << P << " Pa";
      }
    }
  }
}

// A membrane solved on another rank (MembraneSolver::stepResult / adoptStep): a solver that did
// not run the solves but receives each one's four Views holds the solving one's state bit for bit,
// through relaxed trial displacements and commits over several steps, and its next own solve
// gives the same answer. A mirror that received nothing is wrong (the check can fail).
TEST(MembraneAdoptStep, AMirrorThatReceivesEachAnswerHoldsTheSolversState) {
  const double dt = 0.01;
  Square sq = square();
  MembraneSolver owner(sq.mesh, sq.opt, sq.bc, sq.loads), mirror(sq.mesh, sq.opt, sq.bc, sq.loads),
      unfed(sq.mesh, sq.opt, sq.bc, sq.loads);
  RealView relaxed("relaxed", 3 * sq.mesh.nNodes());
  for (int step = 0; step < 3; ++step) {
    for (int iteration = 0; iteration < 2; ++iteration) {
      const MembraneSolveReport rep = owner.solveStep(dt);
      ASSERT_TRUE(rep.converged);
      const auto from = owner.stepResult(), to = mirror.stepResult();
      for (std::size_t k = 0; k < from.size(); ++k) Kokkos::deep_copy(to[k], from[k]);
      mirror.adoptStep(dt, rep, owner.volumeConstraint().lambda);
      EXPECT_EQ(mirror.lastReport().iterations, rep.iterations);
      // The coupling relaxes the answer (here: 0.7 of it) and sets it on both.
      Kokkos::deep_copy(relaxed, owner.trialDisplacement());
      auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), relaxed);
      for (std::size_t i = 0; i < h.extent(0); ++i) h(i) *= 0.7 + 0.1 * iteration;
      Kokkos::deep_copy(relaxed, h);
      owner.setTrialDisplacement(relaxed);
      mirror.setTrialDisplacement(relaxed);
      EXPECT_EQ(host(mirror.trialVelocity()), host(owner.trialVelocity()));
      EXPECT_EQ(host(mirror.trialAcceleration()), host(owner.trialAcceleration()));
    }
    owner.commitStep();
    mirror.commitStep();
    EXPECT_EQ(mirror.time(), owner.time());
    EXPECT_EQ(host(mirror.displacement()), host(owner.displacement()));
    EXPECT_EQ(host(mirror.velocity()), host(owner.velocity()));
    EXPECT_EQ(host(mirror.acceleration()), host(owner.acceleration()));
  }
  // Its own solve from the adopted state: the owner's answer.
  ASSERT_TRUE(owner.solveStep(dt).converged);
  ASSERT_TRUE(mirror.solveStep(dt).converged);
  EXPECT_EQ(host(mirror.trialDisplacement()), host(owner.trialDisplacement()));
  // A solver that received nothing is not there.
  EXPECT_GT(maxDifference(host(unfed.displacement()), host(owner.displacement())),
            0.1 * maxAbs(host(owner.displacement())));
}
