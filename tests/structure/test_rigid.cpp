// Rigid multi-body frame dynamics (structure/rigid/RigidBodySystem): every test compares against an
// analytic solution (damped oscillator, pendulum period, bead on a rotating rod, free fall, ...)
// or an exact conservation law.
#include "core/Error.hpp"
#include "structure/rigid/RigidBodySystem.hpp"
#include "structure/rigid/RigidCsvWriter.hpp"
#include "support/Approx.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

using mfsi::test::near;
using mfsi::test::Tol;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kG = 9.81;

mfsi::RigidBodyOptions body(const std::string& name, double mass, mfsi::RigidJointType joint) {
  mfsi::RigidBodyOptions b;
  b.name = name;
  b.mass = mass;
  b.joint.type = joint;
  return b;
}

/// Thin rod of length L along the body x axis, pivoting at the body origin.
mfsi::RigidBodyOptions rod(const std::string& name, double mass, double length) {
  auto b = body(name, mass, mfsi::RigidJointType::Rz);
  b.centreOfMass = {0.5 * length, 0, 0};
  b.inertia = Eigen::Vector3d(1e-4, mass * length * length / 12, mass * length * length / 12).asDiagonal();
  return b;
}

// --- spring-mass-damper ------------------------------------------------------------------------

struct Oscillator {
  double m = 2.0;
  double omega0 = 2 * kPi;  // 1 s period
  double zeta = 0.05;
  double y0 = 0.1;
  double k() const { return m * omega0 * omega0; }
  double c() const { return 2 * zeta * m * omega0; }
};

mfsi::RigidSystemOptions oscillatorSystem(const Oscillator& o, bool gravity) {
  mfsi::RigidSystemOptions opt;
  auto b = body("mass", o.m, mfsi::RigidJointType::Py);
  b.joint.q0 = {o.y0};
  opt.bodies.push_back(b);
  // Anchor far above so the spring stays vertical; rest length puts the unloaded equilibrium at y = 0.
  mfsi::RigidLinearSpringOptions s;
  s.name = "spring";
  s.body = "mass";
  s.anchor = {0, 10, 0};
  s.restLength = 10;
  s.stiffness = o.k();
  s.damping = o.c();
  opt.linearSprings.push_back(s);
  if (gravity) opt.gravity = {0, -kG, 0};
  return opt;
}

/// Analytic y(t) of m y'' + c y' + k y = -m g from rest at y0.
double oscillatorExact(const Oscillator& o, double g, double t) {
  const double yEq = -o.m * g / o.k();
  const double u0 = o.y0 - yEq;
  const double wd = o.omega0 * std::sqrt(1 - o.zeta * o.zeta);
  const double s = o.zeta * o.omega0;
  return yEq + std::exp(-s * t) * (u0 * std::cos(wd * t) + s * u0 / wd * std::sin(wd * t));
}

double runOscillator(const Oscillator& o, bool gravity, mfsi::RigidIteration iteration, int* maxIts = nullptr) {
  auto opt = oscillatorSystem(o, gravity);
  opt.solver.iteration = iteration;
  mfsi::RigidBodySystem sys(opt);
  const double g = gravity ? kG : 0.0;
  const double amplitude = std::abs(o.y0 + o.m * g / o.k());
  const double dt = 0.002;
  double maxErr = 0;
  for (int n = 0; n < 2500; ++n) {  // 5 periods
    sys.step(sys.time(), dt);
    maxErr = std::max(maxErr, std::abs(sys.q()[0] - oscillatorExact(o, g, sys.time())));
  }
  if (maxIts) *maxIts = static_cast<int>(sys.metrics().at("solver.maxIterations"));
  return maxErr / amplitude;
}

}  // namespace

TEST(Rigid, SpringMassDamperMatchesAnalyticSolution) {
  Oscillator o;
  for (bool gravity : {false, true}) {
    const double relErr = runOscillator(o, gravity, mfsi::RigidIteration::Newton);
    EXPECT_LT(relErr, 1e-3) << "gravity " << gravity;
    std::printf("spring-mass-damper (gravity %d): max |y - exact| / amplitude over 5 periods = %.3e\n", gravity,
                relErr);
  }
}

TEST(Rigid, FixedPointIterationAgreesWithNewton) {
  Oscillator o;
  int itsNewton = 0, itsFixed = 0;
  const double eN = runOscillator(o, true, mfsi::RigidIteration::Newton, &itsNewton);
  const double eF = runOscillator(o, true, mfsi::RigidIteration::FixedPoint, &itsFixed);
  EXPECT_TRUE(near(eF, eN, Tol{1e-8, 0}, "fixed point vs Newton error"));
  // Linear problem: Newton needs one update plus the convergence check.
  EXPECT_LE(itsNewton, 3);
  EXPECT_GT(itsFixed, itsNewton);
}

TEST(Rigid, NewtonHandlesStiffSpringWhereFixedPointDiverges) {
  // omega dt = 4: beyond the fixed-point iteration's reach (beta (omega dt)^2 = 4 > 1), while the
  // implicit trapezoidal rule stays exact in energy for this linear oscillator.
  Oscillator o;
  o.omega0 = 400;
  o.zeta = 0;
  auto opt = oscillatorSystem(o, false);
  mfsi::RigidBodySystem sys(opt);
  const double E0 = sys.kineticEnergy() + sys.potentialEnergy();
  for (int n = 0; n < 100; ++n) sys.step(sys.time(), 0.01);
  EXPECT_TRUE(near(sys.kineticEnergy() + sys.potentialEnergy(), E0, Tol{0, 1e-9}, "discrete energy"));
  EXPECT_LE(sys.metrics().at("solver.maxIterations"), 3.0);
  opt.solver.iteration = mfsi::RigidIteration::FixedPoint;
  mfsi::RigidBodySystem fixedPoint(opt);
  EXPECT_THROW(fixedPoint.step(0.0, 0.01), mfsi::DivergenceError);
}

TEST(Rigid, SpringUnderGravitySettlesAtMgOverK) {
  Oscillator o;
  o.zeta = 0.7;
  mfsi::RigidBodySystem sys(oscillatorSystem(o, true));
  for (int n = 0; n < 1000; ++n) sys.step(sys.time(), 0.01);
  const auto m = sys.metrics();
  const double yEq = -o.m * kG / o.k();
  EXPECT_TRUE(near(m.at("body.mass.y"), yEq, Tol{1e-9, 0}, "static deflection -mg/k"));
  EXPECT_TRUE(near(m.at("restraint.spring.force"), o.m * kG, Tol{1e-7, 0}, "spring tension = m g"));
  EXPECT_TRUE(near(m.at("body.mass.Fy"), 0.0, Tol{1e-7, 0}, "net force at rest"));
  EXPECT_TRUE(near(m.at("kineticEnergy"), 0.0, Tol{1e-16, 0}, "kinetic energy at rest"));
}

TEST(Rigid, LinearAndAngularDampersDecayExponentially) {
  // Py body with a linear damper: v = v0 exp(-c t / m); Rz body with an angular damper about its
  // CoM: omega = w0 exp(-c t / I). Trapezoidal Newmark: relative error O((c dt / m)^2).
  const double m = 2.0, c = 1.5, v0 = 0.8, Izz = 0.25, ca = 0.2, w0 = 3.0;
  mfsi::RigidSystemOptions opt;
  auto slider = body("slider", m, mfsi::RigidJointType::Py);
  slider.joint.qdot0 = {v0};
  auto wheel = body("wheel", 1.0, mfsi::RigidJointType::Rz);
  wheel.inertia = Eigen::Vector3d(0.1, 0.1, Izz).asDiagonal();
  wheel.joint.origin = {5, 0, 0};
  wheel.joint.qdot0 = {w0};
  opt.bodies = {slider, wheel};
  opt.linearDampers.push_back({"drag", "slider", c});
  opt.angularDampers.push_back({"friction", "wheel", ca});
  mfsi::RigidBodySystem sys(opt);
  for (int n = 0; n < 1000; ++n) sys.step(sys.time(), 2e-3);
  const double t = sys.time();
  EXPECT_TRUE(near(sys.qdot()[0], v0 * std::exp(-c * t / m), Tol{0, 1e-5}, "damped velocity"));
  EXPECT_TRUE(near(sys.q()[0], v0 * m / c * (1 - std::exp(-c * t / m)), Tol{0, 1e-5}, "damped position"));
  EXPECT_TRUE(near(sys.qdot()[1], w0 * std::exp(-ca * t / Izz), Tol{0, 1e-5}, "damped spin"));
  EXPECT_TRUE(near(sys.bodyReport(1).moment[2], -ca * sys.qdot()[1], Tol{1e-14, 0}, "damper moment"));
}

// --- pendulums ---------------------------------------------------------------------------------

TEST(Rigid, SmallAnglePendulumPeriod) {
  const double m = 1.5, l = 0.4, Izz = 0.03, theta0 = 0.02;
  mfsi::RigidSystemOptions opt;
  auto b = body("pendulum", m, mfsi::RigidJointType::Rz);
  b.centreOfMass = {0, -l, 0};
  b.inertia = Eigen::Vector3d(0.02, 0.02, Izz).asDiagonal();
  b.joint.q0 = {theta0};
  opt.bodies.push_back(b);
  opt.gravity = {0, -kG, 0};
  mfsi::RigidBodySystem sys(opt);

  const double Ipivot = Izz + m * l * l;
  const double T0 = 2 * kPi * std::sqrt(Ipivot / (m * kG * l));
  const double dt = T0 / 400;
  // Upward zero crossings of the angle, located by linear interpolation.
  std::vector<double> crossings;
  double prev = sys.q()[0], maxAngleLate = 0;
  for (int n = 0; n < 5 * 400 + 10; ++n) {
    const double t0 = sys.time();
    sys.step(t0, dt);
    const double cur = sys.q()[0];
    if (prev < 0 && cur >= 0) crossings.push_back(t0 + dt * (-prev) / (cur - prev));
    if (sys.time() > 4 * T0) maxAngleLate = std::max(maxAngleLate, std::abs(cur));
    prev = cur;
  }
  ASSERT_GE(crossings.size(), 4u);
  const double T = (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
  std::printf("pendulum: period %.6f s, analytic %.6f s, rel. diff %.2e\n", T, T0, T / T0 - 1);
  EXPECT_TRUE(near(T, T0, Tol{0, 5e-3}, "small-angle period 2 pi sqrt(I_pivot / (m g l))"));
  // Trapezoidal Newmark does not dissipate: the amplitude survives five periods.
  EXPECT_TRUE(near(maxAngleLate, theta0, Tol{0, 1e-3}, "amplitude after 4 periods"));
}

namespace {
struct DoublePendulum {
  double m1 = 1.0, L1 = 1.0, m2 = 0.8, L2 = 0.7;
  double I1c() const { return m1 * L1 * L1 / 12; }
  double I2c() const { return m2 * L2 * L2 / 12; }

  mfsi::RigidSystemOptions options(double th1, double th2) const {
    mfsi::RigidSystemOptions opt;
    auto a = rod("upper", m1, L1);
    a.joint.q0 = {th1};
    auto b = rod("lower", m2, L2);
    b.parent = "upper";
    b.joint.origin = {L1, 0, 0};
    b.joint.q0 = {th2};
    opt.bodies = {a, b};
    opt.gravity = {0, -kG, 0};
    return opt;
  }
  /// Analytic mass matrix in relative angles (th2 measured from rod 1).
  Eigen::Matrix2d mass(double th2) const {
    const double c1 = L1 / 2, c2 = L2 / 2;
    Eigen::Matrix2d M;
    M(0, 0) = I1c() + m1 * c1 * c1 + I2c() + m2 * (L1 * L1 + c2 * c2 + 2 * L1 * c2 * std::cos(th2));
    M(0, 1) = M(1, 0) = I2c() + m2 * (c2 * c2 + L1 * c2 * std::cos(th2));
    M(1, 1) = I2c() + m2 * c2 * c2;
    return M;
  }
  /// Analytic Lagrangian accelerations M qdd = -C - G (gravity along -y, angles from +x).
  Eigen::Vector2d accel(const Eigen::Vector2d& q, const Eigen::Vector2d& qd) const {
    const double c1 = L1 / 2, c2 = L2 / 2, h = m2 * L1 * c2 * std::sin(q[1]);
    const Eigen::Vector2d C(-h * (2 * qd[0] * qd[1] + qd[1] * qd[1]), h * qd[0] * qd[0]);
    const Eigen::Vector2d G(
        m1 * kG * c1 * std::cos(q[0]) + m2 * kG * (L1 * std::cos(q[0]) + c2 * std::cos(q[0] + q[1])),
        m2 * kG * c2 * std::cos(q[0] + q[1]));
    return mass(q[1]).ldlt().solve(-C - G);
  }
};
}  // namespace

TEST(Rigid, DoublePendulumMassMatrixIsAnalytic) {
  DoublePendulum p;
  mfsi::RigidBodySystem sys(p.options(0.3, 1.1));
  const Eigen::MatrixXd M = sys.massMatrix();
  const Eigen::Matrix2d Me = p.mass(1.1);
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) EXPECT_TRUE(near(M(i, j), Me(i, j), Tol{1e-12, 1e-12}, "M"));
}

TEST(Rigid, DoublePendulumFollowsLagrangianEquations) {
  // Reference: RK4 on the hand-derived Lagrange equations with a 20x smaller step.
  DoublePendulum p;
  const double th1 = 0.0, th2 = kPi / 2, tEnd = 0.5, dt = 5e-4;
  mfsi::RigidBodySystem sys(p.options(th1, th2));
  for (int n = 0; n < 1000; ++n) sys.step(sys.time(), dt);

  Eigen::Vector2d q(th1, th2), qd(0, 0);
  const double h = dt / 20;
  for (int n = 0; n < static_cast<int>(std::lround(tEnd / h)); ++n) {
    const Eigen::Vector2d k1q = qd, k1v = p.accel(q, qd);
    const Eigen::Vector2d k2q = qd + 0.5 * h * k1v, k2v = p.accel(q + 0.5 * h * k1q, qd + 0.5 * h * k1v);
    const Eigen::Vector2d k3q = qd + 0.5 * h * k2v, k3v = p.accel(q + 0.5 * h * k2q, qd + 0.5 * h * k2v);
    const Eigen::Vector2d k4q = qd + h * k3v, k4v = p.accel(q + h * k3q, qd + h * k3v);
    q += h / 6 * (k1q + 2 * k2q + 2 * k3q + k4q);
    qd += h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
  }
  std::printf("double pendulum at t=%.2f: Newmark (%.6f, %.6f) vs Lagrange RK4 (%.6f, %.6f)\n", sys.time(), sys.q()[0],
              sys.q()[1], q[0], q[1]);
  EXPECT_TRUE(near(sys.time(), tEnd, Tol{1e-12, 0}, "time"));
  EXPECT_TRUE(near(sys.q()[0], q[0], Tol{2e-4, 0}, "theta1"));
  EXPECT_TRUE(near(sys.q()[1], q[1], Tol{2e-4, 0}, "theta2"));
  EXPECT_GT(std::abs(q[1] - th2), 0.5);  // the reference itself moved a lot
}

TEST(Rigid, DoublePendulumConservesEnergy) {
  DoublePendulum p;
  const double th1 = 0.0, th2 = kPi / 2;
  mfsi::RigidSystemOptions opt = p.options(th1, th2);
  opt.solver.gamma = 0.5;
  opt.solver.beta = 0.25;
  mfsi::RigidBodySystem sys(opt);
  const double E0 = sys.kineticEnergy() + sys.potentialEnergy();
  double maxDrift = 0, maxKE = 0, maxSwing = 0;
  for (int n = 0; n < 1000; ++n) {
    sys.step(sys.time(), 0.002);
    maxDrift = std::max(maxDrift, std::abs(sys.kineticEnergy() + sys.potentialEnergy() - E0));
    maxKE = std::max(maxKE, sys.kineticEnergy());
    maxSwing = std::max(maxSwing, std::abs(sys.q()[1] - th2));
  }
  // Scale: the kinetic energy the motion reaches (independent of the potential's datum).
  std::printf("double pendulum: max |E - E0| / max KE = %.3e over 1000 steps, max KE %.3f J, max swing %.3f rad\n",
              maxDrift / maxKE, maxKE, maxSwing);
  EXPECT_GT(maxKE, 2.0);     // released from horizontal: several joules of motion
  EXPECT_GT(maxSwing, 1.0);  // the lower rod swings far: a genuinely large-angle run
  EXPECT_LT(maxDrift / maxKE, 1e-3);
  EXPECT_LE(sys.metrics().at("solver.maxIterations"), 5.0);  // Newton: quadratic convergence
}

TEST(Rigid, FreeTumblingBodyConservesAngularMomentumAndEnergy) {
  // Euler-angle composite joint about the CoM: torque-free rotation of an asymmetric body exercises
  // the 3-D Jacobians and the gyroscopic term omega x I omega.
  mfsi::RigidSystemOptions opt;
  auto b = body("tumbler", 2.0, mfsi::RigidJointType::Composite);
  b.joint.axes = {mfsi::RigidAxis::Rx, mfsi::RigidAxis::Ry, mfsi::RigidAxis::Rz};
  b.inertia = Eigen::Vector3d(1.0, 2.0, 3.0).asDiagonal();
  b.joint.q0 = {0.1, 0.2, 0.3};
  b.joint.qdot0 = {0.4, -0.3, 0.9};
  opt.bodies.push_back(b);
  mfsi::RigidBodySystem sys(opt);
  auto angularMomentum = [&] {
    const auto r = sys.bodyReport(0);
    return Eigen::Vector3d(r.orientation * opt.bodies[0].inertia * r.orientation.transpose() * r.angularVelocity);
  };
  const Eigen::Vector3d L0 = angularMomentum();
  const double E0 = sys.kineticEnergy();
  double maxDL = 0, maxDE = 0, maxPitch = 0;
  Eigen::Vector3d w0 = sys.bodyReport(0).angularVelocity;
  double maxDw = 0;
  for (int n = 0; n < 1000; ++n) {
    sys.step(sys.time(), 0.002);
    maxDL = std::max(maxDL, (angularMomentum() - L0).norm() / L0.norm());
    maxDE = std::max(maxDE, std::abs(sys.kineticEnergy() - E0) / E0);
    maxPitch = std::max(maxPitch, std::abs(sys.q()[1]));
    maxDw = std::max(maxDw, (sys.bodyReport(0).angularVelocity - w0).norm());
  }
  std::printf("tumbler: max |dL|/|L| = %.2e, max |dE|/E = %.2e, max pitch %.2f rad, max |d omega| %.2f\n", maxDL, maxDE,
              maxPitch, maxDw);
  EXPECT_LT(maxPitch, 1.3);  // stayed away from the Euler-angle singularity
  EXPECT_GT(maxDw, 0.1);     // the angular velocity really precesses (not a trivial spin)
  EXPECT_LT(maxDL, 1e-4);
  EXPECT_LT(maxDE, 1e-4);
  EXPECT_TRUE(near(sys.bodyReport(0).position.norm(), 0.0, Tol{1e-15, 0}, "CoM stays at the pivot"));
}

TEST(Rigid, PlanarCompositeJointFreeFlightIsBallistic) {
  // Px+Py+Rz body with the CoM off the joint origin: the CoM must fly a parabola and the spin must
  // stay constant, whatever the coupling between the joint coordinates.
  mfsi::RigidSystemOptions opt;
  auto b = body("panel", 1.3, mfsi::RigidJointType::Composite);
  b.joint.axes = {mfsi::RigidAxis::Px, mfsi::RigidAxis::Py, mfsi::RigidAxis::Rz};
  b.centreOfMass = {0.3, 0.1, 0};
  b.inertia = Eigen::Vector3d(0.1, 0.1, 0.05).asDiagonal();
  b.joint.q0 = {0.0, 0.0, 0.2};
  b.joint.qdot0 = {1.0, 2.0, 3.0};
  opt.bodies.push_back(b);
  opt.gravity = {0, -kG, 0};
  mfsi::RigidBodySystem sys(opt);
  const auto r0 = sys.bodyReport(0);
  const Eigen::Vector3d c0 = r0.position, v0 = r0.velocity;
  // Initial CoM velocity = joint velocity + omega x offset.
  const Eigen::Vector3d d0 = r0.orientation * b.centreOfMass;
  EXPECT_TRUE(near(v0[0], 1.0 - 3.0 * d0[1], Tol{1e-14, 0}, "vx0"));
  EXPECT_TRUE(near(v0[1], 2.0 + 3.0 * d0[0], Tol{1e-14, 0}, "vy0"));
  for (int n = 0; n < 500; ++n) sys.step(sys.time(), 0.002);
  const double t = sys.time();
  const auto r = sys.bodyReport(0);
  const Eigen::Vector3d cExact = c0 + v0 * t + 0.5 * opt.gravity * t * t;
  std::printf("planar flight: |CoM - exact| = %.2e m after %.1f s\n", (r.position - cExact).norm(), t);
  EXPECT_LT((r.position - cExact).norm(), 1e-4);
  EXPECT_TRUE(near(r.angularVelocity[2], 3.0, Tol{1e-4, 0}, "spin rate"));
  EXPECT_TRUE(near(r.acceleration[1], -kG, Tol{1e-3, 0}, "CoM acceleration"));
}

TEST(Rigid, PolarJointFreeParticleMovesInAStraightLine) {
  // Rz then Px: polar coordinates of a point mass. With no force it must move on a straight line,
  // which needs the Coriolis coupling of the rotating prismatic axis (2 m r rdot thetadot).
  mfsi::RigidSystemOptions opt;
  auto b = body("particle", 0.7, mfsi::RigidJointType::Composite);
  b.joint.axes = {mfsi::RigidAxis::Rz, mfsi::RigidAxis::Px};
  b.joint.q0 = {0.0, 1.0};
  b.joint.qdot0 = {1.0, 0.0};  // velocity (0, 1) at (1, 0)
  opt.bodies.push_back(b);
  mfsi::RigidBodySystem sys(opt);
  for (int n = 0; n < 1000; ++n) sys.step(sys.time(), 1e-3);
  const Eigen::Vector3d x = sys.bodyReport(0).position;
  std::printf("polar particle: |x - (1, t)| = %.2e\n", (x - Eigen::Vector3d(1, sys.time(), 0)).norm());
  EXPECT_TRUE(near(x[0], 1.0, Tol{1e-5, 0}, "x"));
  EXPECT_TRUE(near(x[1], sys.time(), Tol{1e-5, 0}, "y"));
  EXPECT_TRUE(near(sys.q()[1], std::sqrt(1 + sys.time() * sys.time()), Tol{1e-5, 0}, "r"));
}

// --- OpenFOAM-style acceleration damping / relaxation -----------------------------------------

TEST(Rigid, AccelerationDampingZeroFreezesBodyAndScalesMotion) {
  for (double damping : {0.0, 0.5, 1.0}) {
    mfsi::RigidSystemOptions opt;
    opt.bodies.push_back(body("block", 2.0, mfsi::RigidJointType::Py));
    opt.gravity = {0, -kG, 0};
    opt.solver.accelerationDamping = damping;
    mfsi::RigidBodySystem sys(opt);
    for (int n = 0; n < 100; ++n) sys.step(sys.time(), 0.01);
    const double t = sys.time();
    // The damping factor multiplies the acceleration in the update: y = -d g t^2 / 2.
    EXPECT_TRUE(near(sys.q()[0], -damping * kG * t * t / 2, Tol{1e-12, 1e-12}, "y with damping"));
    EXPECT_TRUE(near(sys.qdot()[0], -damping * kG * t, Tol{1e-12, 1e-12}, "v with damping"));
    if (damping == 0.0) {
      EXPECT_EQ(sys.q()[0], 0.0);
      EXPECT_EQ(sys.metrics().at("body.block.maxDisplacement"), 0.0);
    }
  }
}

TEST(Rigid, AccelerationRelaxationBlendsWithPreviousIterate) {
  mfsi::RigidSystemOptions opt;
  opt.bodies.push_back(body("block", 2.0, mfsi::RigidJointType::Px));
  opt.solver.accelerationRelaxation = 0.5;
  mfsi::RigidBodySystem sys(opt);
  const double F1 = 4.0, F2 = 10.0, m = 2.0;
  sys.setExternalLoad(0, {F1, 0, 0}, Eigen::Vector3d::Zero());
  sys.step(0.0, 0.01);
  EXPECT_TRUE(near(sys.qddot()[0], F1 / m, Tol{1e-12, 0}, "steady load: no relaxation effect"));
  // Coupling iterations of one step: each call relaxes against the previous iterate.
  sys.setExternalLoad(0, {F2, 0, 0}, Eigen::Vector3d::Zero());
  sys.solveStep(sys.time(), 0.01);
  EXPECT_TRUE(near(sys.qddot()[0], 0.5 * F2 / m + 0.5 * F1 / m, Tol{1e-12, 0}, "first relaxed iterate"));
  sys.solveStep(sys.time(), 0.01);
  EXPECT_TRUE(near(sys.qddot()[0], 0.75 * F2 / m + 0.25 * F1 / m, Tol{1e-12, 0}, "second relaxed iterate"));
  for (int it = 0; it < 60; ++it) sys.solveStep(sys.time(), 0.01);
  EXPECT_TRUE(near(sys.qddot()[0], F2 / m, Tol{1e-12, 0}, "iterates converge to the unrelaxed solution"));
  EXPECT_TRUE(near(sys.time(), 0.01, Tol{1e-15, 0}, "solveStep does not commit"));
  sys.commitStep();
  EXPECT_TRUE(near(sys.time(), 0.02, Tol{1e-15, 0}, "commit advances time"));
  EXPECT_THROW(sys.commitStep(), mfsi::InputError);
}

// --- prescribed motion -------------------------------------------------------------------------

TEST(Rigid, PrescribedRotationFollowsFunctionAndReportsMotorTorque) {
  const double m = 1.5, l = 0.4, Izz = 0.03, A = 0.3, W = 2.0;
  mfsi::RigidSystemOptions opt;
  auto b = body("arm", m, mfsi::RigidJointType::Rz);
  b.centreOfMass = {0, -l, 0};
  b.inertia = Eigen::Vector3d(0.02, 0.02, Izz).asDiagonal();
  opt.bodies.push_back(b);
  opt.gravity = {0, -kG, 0};
  mfsi::RigidPrescribedRotationOptions p;
  p.name = "motor";
  p.body = "arm";
  p.angle = mfsi::RigidTimeFunction::sine(A, W);
  opt.prescribedRotations.push_back(p);
  mfsi::RigidBodySystem sys(opt);
  const double Ip = Izz + m * l * l;
  double maxErr = 0, maxTorqueErr = 0, maxTorque = 0;
  for (int n = 0; n < 2000; ++n) {
    sys.step(sys.time(), 1e-3);
    const double t = sys.time(), th = A * std::sin(W * t);
    maxErr = std::max(maxErr, std::abs(sys.q()[0] - th));
    // Torque the motor must supply: I_pivot theta'' + m g l sin(theta).
    const double tau = Ip * (-A * W * W * std::sin(W * t)) + m * kG * l * std::sin(th);
    maxTorqueErr = std::max(maxTorqueErr, std::abs(sys.metrics().at("restraint.motor.torque") - tau));
    maxTorque = std::max(maxTorque, std::abs(tau));
  }
  std::printf("prescribed rotation: max angle error %.2e rad, max torque error %.2e of %.3f N m\n", maxErr,
              maxTorqueErr, maxTorque);
  EXPECT_LT(maxErr, 1e-6 * A);
  EXPECT_LT(maxTorqueErr, 1e-3 * maxTorque);
}

TEST(Rigid, BeadOnPrescribedRotatingRod) {
  // Rod turning at a prescribed constant rate Omega, bead sliding freely along it: r = r0 cosh(Omega t).
  const double Omega = 1.5, r0 = 0.1;
  mfsi::RigidSystemOptions opt;
  auto rodBody = body("rod", 1.0, mfsi::RigidJointType::Prescribed);
  rodBody.inertia = Eigen::Vector3d(0.01, 0.1, 0.1).asDiagonal();
  rodBody.joint.axes = {mfsi::RigidAxis::Rz};
  mfsi::RigidTimeFunction angle;
  angle.value = [Omega](double t) { return Omega * t; };  // derivatives by finite differences
  rodBody.joint.motion = {angle};
  auto bead = body("bead", 0.2, mfsi::RigidJointType::Px);
  bead.parent = "rod";
  bead.joint.q0 = {r0};
  opt.bodies = {rodBody, bead};
  mfsi::RigidBodySystem sys(opt);
  ASSERT_EQ(sys.nDof(), 1);
  for (int n = 0; n < 1000; ++n) sys.step(sys.time(), 1e-3);
  const double t = sys.time(), r = r0 * std::cosh(Omega * t);
  std::printf("bead on rod: r = %.8f, exact %.8f\n", sys.q()[0], r);
  EXPECT_TRUE(near(sys.q()[0], r, Tol{0, 1e-5}, "bead radius"));
  const auto beadReport = sys.bodyReport(1);
  EXPECT_TRUE(near(beadReport.position[0], r * std::cos(Omega * t), Tol{1e-5, 0}, "bead x"));
  EXPECT_TRUE(near(beadReport.position[1], r * std::sin(Omega * t), Tol{1e-5, 0}, "bead y"));
  EXPECT_TRUE(near(sys.bodyReport(0).eulerAngles[2], Omega * t, Tol{1e-12, 0}, "rod yaw"));
  EXPECT_TRUE(near(sys.bodyReport(0).angularVelocity[2], Omega, Tol{1e-8, 0}, "rod rate"));
}

TEST(Rigid, PrescribedJointOnlySystemFollowsItsMotion) {
  // No free coordinate at all: a frame driven entirely by a prescribed Py + Rz joint.
  const double A = 0.05, W = 3.0, Omega = 0.7;
  mfsi::RigidSystemOptions opt;
  auto frame = body("frame", 4.0, mfsi::RigidJointType::Prescribed);
  frame.centreOfMass = {0.2, 0, 0};
  frame.inertia = Eigen::Vector3d(0.1, 0.1, 0.2).asDiagonal();
  frame.joint.axes = {mfsi::RigidAxis::Py, mfsi::RigidAxis::Rz};
  frame.joint.motion = {mfsi::RigidTimeFunction::sine(A, W), mfsi::RigidTimeFunction::linear(0.0, Omega)};
  opt.bodies.push_back(frame);
  opt.gravity = {0, -kG, 0};
  mfsi::RigidBodySystem sys(opt);
  ASSERT_EQ(sys.nDof(), 0);
  for (int n = 0; n < 50; ++n) sys.step(sys.time(), 0.01);
  const double t = sys.time(), th = Omega * t;
  const auto r = sys.bodyReport(0);
  EXPECT_TRUE(near(r.position[0], 0.2 * std::cos(th), Tol{1e-14, 0}, "x"));
  EXPECT_TRUE(near(r.position[1], A * std::sin(W * t) + 0.2 * std::sin(th), Tol{1e-14, 0}, "y"));
  EXPECT_TRUE(near(r.velocity[1], A * W * std::cos(W * t) + 0.2 * Omega * std::cos(th), Tol{1e-12, 0}, "vy"));
  EXPECT_TRUE(near(r.acceleration[0], -0.2 * Omega * Omega * std::cos(th), Tol{1e-12, 0}, "ax (centripetal)"));
  EXPECT_TRUE(near(r.angularVelocity[2], Omega, Tol{1e-14, 0}, "omega"));
}

// --- external loads ----------------------------------------------------------------------------

TEST(Rigid, ConstantExternalForceGivesUniformAcceleration) {
  const double m = 3.0, F = 4.5, dt = 0.01;
  mfsi::RigidSystemOptions opt;
  opt.bodies.push_back(body("slider", m, mfsi::RigidJointType::Px));
  mfsi::RigidBodySystem sys(opt);
  const int b = sys.bodyIndex("slider");
  // The y component is carried by the joint and must not move the body.
  sys.setExternalLoad(b, {F, 7.0, 0}, Eigen::Vector3d::Zero());
  for (int n = 0; n < 200; ++n) sys.step(sys.time(), dt);
  const double t = sys.time();
  EXPECT_TRUE(near(sys.q()[0], F * t * t / (2 * m), Tol{1e-12, 1e-12}, "x = F t^2 / (2 m)"));
  EXPECT_TRUE(near(sys.bodyReport(b).position[1], 0.0, Tol{0, 0}, "y held by the joint"));
  EXPECT_TRUE(near(sys.bodyReport(b).force[0], F, Tol{1e-14, 0}, "reported force"));
  // The same push as a generalised (joint-space) force.
  mfsi::RigidBodySystem viaTau(opt);
  viaTau.setGeneralisedForce(Eigen::VectorXd::Constant(1, F));
  for (int n = 0; n < 200; ++n) viaTau.step(viaTau.time(), dt);
  EXPECT_TRUE(near(viaTau.q()[0], sys.q()[0], Tol{1e-14, 1e-12}, "generalised force"));
}

TEST(Rigid, ExternalMomentAndOffsetForceTurnARevoluteBody) {
  const double m = 2.0, Izz = 0.1, l = 0.5;
  mfsi::RigidSystemOptions opt;
  auto b = body("flap", m, mfsi::RigidJointType::Rz);
  b.centreOfMass = {l, 0, 0};
  b.inertia = Eigen::Vector3d(0.1, 0.1, Izz).asDiagonal();
  opt.bodies.push_back(b);
  const double Ip = Izz + m * l * l;
  {
    mfsi::RigidBodySystem sys(opt);
    const double Mz = 0.8;
    sys.setExternalLoad(0, Eigen::Vector3d::Zero(), {0, 0, Mz});
    for (int n = 0; n < 100; ++n) sys.step(sys.time(), 0.01);
    const double t = sys.time();
    EXPECT_TRUE(near(sys.q()[0], Mz * t * t / (2 * Ip), Tol{1e-12, 1e-12}, "theta = M t^2 / (2 I_pivot)"));
  }
  {
    // Force Fy at world point (d, 0, 0): torque d Fy about the pivot.
    mfsi::RigidBodySystem sys(opt);
    const double Fy = 3.0, d = 0.9;
    sys.setExternalLoad(0, {0, Fy, 0}, Eigen::Vector3d::Zero(), {d, 0, 0});
    sys.step(0.0, 1e-7);
    EXPECT_TRUE(near(sys.bodyReport(0).angularAcceleration[2], d * Fy / Ip, Tol{0, 1e-9}, "alpha = d F / I_pivot"));
  }
}

// --- reporting and input checks ----------------------------------------------------------------

TEST(Rigid, CsvReportAndMetrics) {
  DoublePendulum p;
  mfsi::RigidBodySystem sys(p.options(0.2, 0.1));
  std::ostringstream os;
  mfsi::RigidCsvWriter writer(os);
  for (int n = 0; n < 3; ++n) {
    sys.step(sys.time(), 0.01);
    writer.write(sys);
  }
  std::istringstream is(os.str());
  std::string line;
  int lines = 0;
  std::vector<std::string> rows;
  while (std::getline(is, line)) {
    rows.push_back(line);
    ++lines;
    EXPECT_EQ(std::count(line.begin(), line.end(), ','), 34) << line;
  }
  EXPECT_EQ(lines, 1 + 3 * 2);  // header once, one line per body per step
  EXPECT_EQ(rows[0].rfind("time,body,x,y,z,", 0), 0u);
  EXPECT_EQ(rows[6].find(",lower,"), rows[6].find(','));
  const auto m = sys.metrics();
  const auto lower = sys.bodyReport(sys.bodyIndex("lower"));
  EXPECT_TRUE(near(m.at("body.lower.x"), lower.position[0], Tol{0, 0}, "metric x"));
  EXPECT_TRUE(near(m.at("body.upper.q0"), sys.q()[0], Tol{0, 0}, "metric q"));
  EXPECT_TRUE(near(m.at("time"), 0.03, Tol{1e-15, 0}, "metric time"));
  EXPECT_TRUE(near(m.at("maxDisplacement"),
                   std::max(m.at("body.upper.maxDisplacement"), m.at("body.lower.maxDisplacement")), Tol{0, 0}, "max"));
  EXPECT_GT(m.at("body.lower.maxDisplacement"), 0.0);
  // Report consistency: the CoM of the lower rod sits at the end of the upper rod plus half its own.
  const double a1 = sys.q()[0], a12 = sys.q()[0] + sys.q()[1];
  EXPECT_TRUE(near(lower.position[0], p.L1 * std::cos(a1) + 0.5 * p.L2 * std::cos(a12), Tol{1e-14, 0}, "x"));
  EXPECT_TRUE(near(lower.eulerAngles[2], a12, Tol{1e-14, 0}, "yaw"));
}

TEST(Rigid, InvalidInputIsRejected) {
  DoublePendulum p;
  auto opt = p.options(0, 0);
  opt.bodies[1].parent = "nosuchbody";
  EXPECT_THROW(mfsi::RigidBodySystem{opt}, mfsi::InputError);
  opt = p.options(0, 0);
  std::swap(opt.bodies[0], opt.bodies[1]);  // child before parent
  EXPECT_THROW(mfsi::RigidBodySystem{opt}, mfsi::InputError);
  opt = oscillatorSystem(Oscillator{}, false);
  mfsi::RigidPrescribedRotationOptions pr;
  pr.name = "bad";
  pr.body = "mass";  // a prismatic joint cannot take a prescribed rotation
  pr.angle = mfsi::RigidTimeFunction::constant(0);
  opt.prescribedRotations.push_back(pr);
  EXPECT_THROW(mfsi::RigidBodySystem{opt}, mfsi::InputError);
  EXPECT_THROW(mfsi::parseRigidAxis("Qz"), mfsi::InputError);
  EXPECT_EQ(mfsi::parseRigidJointType("Rz"), mfsi::RigidJointType::Rz);
  EXPECT_EQ(mfsi::parseRigidJointType("composite"), mfsi::RigidJointType::Composite);
  mfsi::RigidBodySystem sys(p.options(0, 0));
  EXPECT_THROW(sys.step(1.0, 0.01), mfsi::InputError);  // not the committed time
}
