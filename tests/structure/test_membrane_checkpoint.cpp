// Membrane checkpoints (MembraneSolver::saveState / loadState through an HDF5 checkpoint file): a
// run of 2N steps and a run of N steps, a checkpoint, a new solver that loads it and N more steps
// end bitwise equal (dynamics with generalized-alpha and Rayleigh damping; a static solve per step
// under a load ramp; an uncommitted FSI trial step with a pressure field). Leaving out the saved
// acceleration, or the static state, changes the answer; a checkpoint of another mesh is refused.
#include "core/Error.hpp"
#include "core/io/Checkpoint.hpp"
#include "structure/membrane/MembraneSolver.hpp"
#include "support/FreshDir.hpp"
#include "support/HostVectors.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

using namespace mfsi;
using mfsi::test::host;
using mfsi::test::HostVec;

namespace {

constexpr double kSide = 1.0, kT0 = 100.0, kRho = 1000.0, kH = 1e-3, kE = 1e7, kNu = 0.3, kPressure = 5.0;

/// Clamped pre-stressed square of n x n quads under a follower pressure, as a solver of its own.
/// `ramp` > 0: the pressure grows linearly over that time (static solves along a load path).
std::unique_ptr<MembraneSolver> makeSquare(int n, MembraneOptions opt, double ramp = 0) {
  MembraneRectangleSpec rect;
  rect.lx = rect.ly = kSide;
  rect.nx = rect.ny = n;
  const MembraneMesh mesh = buildMembraneMesh(generateRectangleMesh(rect));
  MembraneBoundary bc;
  bc.clamps.push_back({mesh.nodeSet("boundary"), {}, {}});
  MembraneLoads loads;
  loads.pressure = kPressure;
  if (ramp > 0) loads.pressureTime = [ramp](real t) { return std::min<real>(1, t / ramp); };
  return std::make_unique<MembraneSolver>(mesh, opt, bc, loads);
}

MembraneOptions dynamicOptions() {
  MembraneOptions opt;
  opt.material = {kE, kNu, kH, kRho, kT0};
  opt.tolerance = 1e-9;
  opt.dynamics.integrator = MembraneTimeIntegrator::GeneralizedAlpha;
  opt.dynamics.rhoInfinity = 0.6;
  opt.dynamics.rayleighAlpha = 0.5;
  opt.dynamics.rayleighBeta = 1e-4;
  return opt;
}

MembraneOptions staticOptions() {
  MembraneOptions opt;
  opt.material = {kE, kNu, kH, kRho, kT0};
  opt.tolerance = 1e-8;
  return opt;
}

void save(const MembraneSolver& s, const std::string& path) {
  io::Hdf5File file = io::Hdf5File::create(path);
  io::StateWriter w(file, "/m");
  s.saveState(w);
  file.commit();
}

void load(MembraneSolver& s, const std::string& path) {
  const io::Hdf5File file = io::Hdf5File::openRead(path);
  s.loadState(io::StateReader(file, "/m"));
}

/// Equal bit patterns (not only equal values: -0 and 0 differ); names the first different index.
::testing::AssertionResult bitwiseEqual(const HostVec& a, const HostVec& b, const std::string& what) {
  if (a.size() != b.size())
    return ::testing::AssertionFailure() << what << ": sizes " << a.size() << " and " << b.size();
  for (std::size_t i = 0; i < a.size(); ++i) {
    std::uint64_t x, y;
    std::memcpy(&x, &a[i], sizeof x);
    std::memcpy(&y, &b[i], sizeof y);
    if (x != y) {
      char buf[128];
      std::snprintf(buf, sizeof buf, "[%zu]: %.17g vs %.17g", i, a[i], b[i]);
      return ::testing::AssertionFailure() << what << buf;
    }
  }
  return ::testing::AssertionSuccess();
}

void steps(MembraneSolver& s, int n, double dt) {
  for (int k = 0; k < n; ++k) ASSERT_TRUE(s.step(dt).converged) << "step at t = " << s.time();
}

/// Period of the (1,1) mode of the square; the steps below resolve it with 40 per period.
double stepSize() { return 2.0 / (std::sqrt(kT0 / (kRho * kH)) * std::sqrt(2.0)) / 40; }

}  // namespace

TEST(MembraneCheckpoint, DynamicRestartIsBitwise) {
  const std::string path = test::freshDir("membrane_checkpoint_dynamic") + "/state.h5";
  const int n = 8, half = 6;
  const double dt = stepSize();
  auto straight = makeSquare(n, dynamicOptions());
  steps(*straight, 2 * half, dt);

  auto first = makeSquare(n, dynamicOptions());
  steps(*first, half, dt);
  save(*first, path);
  first.reset();
  auto resumed = makeSquare(n, dynamicOptions());
  load(*resumed, path);
  steps(*resumed, half, dt);

  EXPECT_EQ(resumed->time(), straight->time());
  EXPECT_TRUE(bitwiseEqual(host(resumed->displacement()), host(straight->displacement()), "displacement"));
  EXPECT_TRUE(bitwiseEqual(host(resumed->velocity()), host(straight->velocity()), "velocity"));
  EXPECT_TRUE(bitwiseEqual(host(resumed->acceleration()), host(straight->acceleration()), "acceleration"));
  EXPECT_EQ(resumed->lastReport().iterations, straight->lastReport().iterations);
  EXPECT_EQ(resumed->lastReport().relativeResidual, straight->lastReport().relativeResidual);

  // Without the saved acceleration (recomputed from M a = R - C v, which is not the
  // generalized-alpha a_n) the run continues differently: the test can tell.
  auto forgetful = makeSquare(n, dynamicOptions());
  load(*forgetful, path);
  forgetful->resetDynamics();
  steps(*forgetful, half, dt);
  EXPECT_FALSE(bitwiseEqual(host(forgetful->displacement()), host(straight->displacement()), "displacement"));
}

TEST(MembraneCheckpoint, StaticLoadPathRestartIsBitwise) {
  // One static solve per step at the end time of the step, under a pressure ramp over 8 steps:
  // each solve starts from the last equilibrium, which is therefore state.
  const std::string path = test::freshDir("membrane_checkpoint_static") + "/state.h5";
  const int n = 8, half = 3;
  const double dt = 0.1, ramp = 8 * dt;
  auto solveSteps = [dt](MembraneSolver& s, int from, int count) {
    for (int k = from; k < from + count; ++k) ASSERT_TRUE(s.solveStatic((k + 1) * dt).converged) << "step " << k;
  };
  auto straight = makeSquare(n, staticOptions(), ramp);
  solveSteps(*straight, 0, 2 * half);

  auto first = makeSquare(n, staticOptions(), ramp);
  solveSteps(*first, 0, half);
  save(*first, path);
  auto resumed = makeSquare(n, staticOptions(), ramp);
  load(*resumed, path);
  EXPECT_EQ(resumed->time(), first->time());
  solveSteps(*resumed, half, half);
  EXPECT_TRUE(bitwiseEqual(host(resumed->displacement()), host(straight->displacement()), "displacement"));
  EXPECT_EQ(resumed->lastReport().iterations, straight->lastReport().iterations);

  // A new solver that starts the second half from the flat state converges to another iterate.
  auto fresh = makeSquare(n, staticOptions(), ramp);
  solveSteps(*fresh, half, half);
  EXPECT_FALSE(bitwiseEqual(host(fresh->displacement()), host(straight->displacement()), "displacement"));
}

TEST(MembraneCheckpoint, UncommittedTrialStepAndLoadFieldSurvive) {
  // The FSI path: a pressure field the coupling owns and refills (loads().elementPressure), a step
  // solved (solveStep) but not committed, then solved again on new loads from its trial state.
  const std::string path = test::freshDir("membrane_checkpoint_trial") + "/state.h5";
  const int n = 6;
  const double dt = stepSize();
  auto withField = [n](double value) {
    auto s = makeSquare(n, dynamicOptions());
    s->loads().elementPressure = test::device(HostVec(static_cast<std::size_t>(s->mesh().nElements()), value));
    return s;
  };
  auto straight = withField(2.0);
  auto first = withField(2.0);
  for (MembraneSolver* s : {straight.get(), first.get()}) {
    steps(*s, 2, dt);
    ASSERT_TRUE(s->solveStep(dt).converged);
    Kokkos::deep_copy(s->loads().elementPressure, 3.0);  // the next coupling iteration's loads
  }
  save(*first, path);
  auto resumed = withField(0.0);  // its own field, as a coupling built on restart would give it
  const RealView shared = resumed->loads().elementPressure;
  load(*resumed, path);
  EXPECT_EQ(resumed->loads().elementPressure.data(), shared.data()) << "loaded into the View the loads hold";
  EXPECT_TRUE(bitwiseEqual(host(shared), host(straight->loads().elementPressure), "elementPressure"));
  EXPECT_TRUE(bitwiseEqual(host(resumed->trialVelocity()), host(straight->trialVelocity()), "trial velocity"));
  for (MembraneSolver* s : {straight.get(), resumed.get()}) {
    ASSERT_TRUE(s->solveStep(dt).converged);
    s->commitStep();
  }
  EXPECT_TRUE(bitwiseEqual(host(resumed->displacement()), host(straight->displacement()), "displacement"));
  EXPECT_TRUE(bitwiseEqual(host(resumed->velocity()), host(straight->velocity()), "velocity"));
}

TEST(MembraneCheckpoint, CheckpointOfAnotherMeshIsAnInputError) {
  const std::string path = test::freshDir("membrane_checkpoint_mesh") + "/state.h5";
  auto small = makeSquare(6, dynamicOptions());
  save(*small, path);
  auto other = makeSquare(8, dynamicOptions());
  try {
    load(*other, path);
    ADD_FAILURE() << "a checkpoint of a 6 x 6 membrane loaded into an 8 x 8 one";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("state.h5"), std::string::npos) << what;
    EXPECT_NE(what.find("/m/displacement"), std::string::npos) << what;
  }
}
