// Rigid-body checkpoints (RigidBodySystem::saveState / loadState through an HDF5 checkpoint file):
// 2N steps in one system and N steps, a checkpoint, a new system that loads it and N more steps end
// bitwise equal (a double pendulum with a damped spring, an angular damper, a held external load and
// acceleration relaxation; a motor-driven arm). A restart from the coordinates and rates alone
// differs; a checkpoint of another system is refused.
#include "core/Error.hpp"
#include "core/io/Checkpoint.hpp"
#include "structure/rigid/RigidBodySystem.hpp"
#include "support/FreshDir.hpp"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

using namespace mfsi;

namespace {

constexpr double kG = 9.81;

RigidBodyOptions rod(const std::string& name, double mass, double length) {
  RigidBodyOptions b;
  b.name = name;
  b.mass = mass;
  b.joint.type = RigidJointType::Rz;
  b.centreOfMass = {0.5 * length, 0, 0};
  b.inertia = Eigen::Vector3d(1e-4, mass * length * length / 12, mass * length * length / 12).asDiagonal();
  return b;
}

/// The double pendulum of test_rigid.cpp, with a damped spring pulling the lower rod's tip towards a
/// point above the pivot, an angular damper on the upper rod and relaxed accelerations.
RigidSystemOptions pendulumOptions() {
  RigidSystemOptions opt;
  auto a = rod("upper", 1.0, 1.0);
  a.joint.q0 = {0.0};
  auto b = rod("lower", 0.8, 0.7);
  b.parent = "upper";
  b.joint.origin = {1.0, 0, 0};
  b.joint.q0 = {std::acos(-1.0) / 2};
  opt.bodies = {a, b};
  opt.gravity = {0, -kG, 0};
  RigidLinearSpringOptions s;
  s.name = "spring";
  s.body = "lower";
  s.anchor = {0.5, 1.5, 0};
  s.attachment = {0.7, 0, 0};
  s.stiffness = 40;
  s.damping = 2;
  s.restLength = 0.5;
  opt.linearSprings.push_back(s);
  opt.angularDampers.push_back({"hinge", "upper", 0.3});
  opt.solver.accelerationRelaxation = 0.9;
  return opt;
}

/// The motor-driven arm of test_rigid.cpp (a prescribed rotation: a constraint with a motor torque).
RigidSystemOptions motorOptions() {
  RigidSystemOptions opt;
  RigidBodyOptions b;
  b.name = "arm";
  b.mass = 1.5;
  b.joint.type = RigidJointType::Rz;
  b.centreOfMass = {0, -0.4, 0};
  b.inertia = Eigen::Vector3d(0.02, 0.02, 0.03).asDiagonal();
  opt.bodies.push_back(b);
  opt.gravity = {0, -kG, 0};
  RigidPrescribedRotationOptions p;
  p.name = "motor";
  p.body = "arm";
  p.angle = RigidTimeFunction::sine(0.3, 2.0);
  opt.prescribedRotations.push_back(p);
  return opt;
}

/// A force held across steps (set once, as a coupling leaves its last one).
void holdLoad(RigidBodySystem& sys) {
  if (sys.nBodies() > 1) sys.setExternalLoad(sys.bodyIndex("lower"), {0.5, 1.0, 0}, {0, 0, 0.1});
}

void save(const RigidBodySystem& s, const std::string& path) {
  io::Hdf5File file = io::Hdf5File::create(path);
  io::StateWriter w(file, "/m");
  s.saveState(w);
  file.commit();
}

void load(RigidBodySystem& s, const std::string& path) {
  const io::Hdf5File file = io::Hdf5File::openRead(path);
  s.loadState(io::StateReader(file, "/m"));
}

void steps(RigidBodySystem& s, int n, double dt) {
  for (int k = 0; k < n; ++k) s.step(s.time(), dt);
}

bool sameBits(double a, double b) {
  std::uint64_t x, y;
  std::memcpy(&x, &a, sizeof x);
  std::memcpy(&y, &b, sizeof y);
  return x == y;
}

/// Every value of the state and the body reports with equal bits; names the first one that differs.
::testing::AssertionResult bitwiseEqual(const RigidBodySystem& a, const RigidBodySystem& b) {
  std::vector<std::pair<std::string, std::pair<double, double>>> values;
  auto add = [&values](const std::string& what, const auto& x, const auto& y) {
    for (Eigen::Index i = 0; i < x.size(); ++i)
      values.push_back({what + "[" + std::to_string(i) + "]", {x.data()[i], y.data()[i]}});
  };
  values.push_back({"time", {a.time(), b.time()}});
  add("q", a.q(), b.q());
  add("qdot", a.qdot(), b.qdot());
  add("qddot", a.qddot(), b.qddot());
  for (int k = 0; k < a.nBodies(); ++k) {
    const RigidBodyReport ra = a.bodyReport(k), rb = b.bodyReport(k);
    const std::string p = "body " + ra.name + " ";
    add(p + "position", ra.position, rb.position);
    add(p + "orientation", ra.orientation, rb.orientation);
    add(p + "velocity", ra.velocity, rb.velocity);
    add(p + "angularVelocity", ra.angularVelocity, rb.angularVelocity);
    add(p + "force", ra.force, rb.force);
    add(p + "moment", ra.moment, rb.moment);
  }
  for (const auto& [what, v] : values)
    if (!sameBits(v.first, v.second)) {
      char buf[96];
      std::snprintf(buf, sizeof buf, ": %.17g vs %.17g", v.first, v.second);
      return ::testing::AssertionFailure() << what << buf;
    }
  return ::testing::AssertionSuccess();
}

/// 2N steps straight against N, checkpoint, a new system, N more.
void expectBitwiseRestart(const RigidSystemOptions& options, const std::string& tag, int half, double dt) {
  const std::string path = test::freshDir(tag) + "/state.h5";
  RigidBodySystem straight(options);
  holdLoad(straight);
  steps(straight, 2 * half, dt);

  RigidBodySystem first(options);
  holdLoad(first);
  steps(first, half, dt);
  save(first, path);
  RigidBodySystem resumed(options);  // no external load set: it comes from the checkpoint
  load(resumed, path);
  EXPECT_TRUE(bitwiseEqual(resumed, first)) << "right after loading";
  steps(resumed, half, dt);
  EXPECT_TRUE(bitwiseEqual(resumed, straight));
  // Running maxima, counters, energies, restraint and motor reports.
  EXPECT_EQ(resumed.metrics(), straight.metrics());
}

}  // namespace

TEST(RigidCheckpoint, PendulumWithSpringDamperAndLoadRestartsBitwise) {
  expectBitwiseRestart(pendulumOptions(), "rigid_checkpoint_pendulum", 40, 0.005);
}

TEST(RigidCheckpoint, PrescribedRotationRestartsBitwise) {
  expectBitwiseRestart(motorOptions(), "rigid_checkpoint_motor", 30, 0.01);
}

TEST(RigidCheckpoint, CoordinatesAndRatesAloneAreNotEnough) {
  // A restart that only restores q and qdot (at the checkpoint's time) recomputes the accelerations
  // from the equations of motion, losing the Newmark ones and the relaxation's memory.
  const int half = 40;
  const double dt = 0.005;
  RigidBodySystem straight(pendulumOptions());
  holdLoad(straight);
  steps(straight, 2 * half, dt);
  RigidBodySystem first(pendulumOptions());
  holdLoad(first);
  steps(first, half, dt);
  RigidSystemOptions later = pendulumOptions();
  later.startTime = first.time();
  RigidBodySystem partial(later);
  partial.setState(first.q(), first.qdot());
  holdLoad(partial);
  steps(partial, half, dt);
  EXPECT_FALSE(bitwiseEqual(partial, straight));
}

TEST(RigidCheckpoint, CheckpointOfAnotherSystemIsAnInputError) {
  const std::string path = test::freshDir("rigid_checkpoint_other") + "/state.h5";
  RigidBodySystem motor(motorOptions());
  save(motor, path);
  RigidBodySystem pendulum(pendulumOptions());
  try {
    load(pendulum, path);
    ADD_FAILURE() << "a checkpoint of a one-body system loaded into a two-body one";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("state.h5"), std::string::npos) << what;
    EXPECT_NE(what.find("/m/committed/q"), std::string::npos) << what;
  }
}
