// Runaway growth is divergence (issue 14): a cavity whose pressure-velocity coupling is unstable
// at its time step grows by orders of magnitude per step and stays finite for several steps; the
// run must stop as diverged at the first step whose max |U| exceeds 100 times the lid speed, with
// a message naming the value, the scale, the time and the remedy, long before NaN appears. The
// same cavity at a stable time step, and the scene's own under-relaxed iterations at any time
// step, run to the end untouched.
#include "core/Error.hpp"
#include "coupling/Simulation.hpp"

#include "support/FreshDir.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace {

/// cases/cavity.yaml on 12 x 12 cells, implicit Euler at `dt` for 20 steps, with `more` settings.
mfsi::SceneConfig cavity(double dt, std::vector<std::string> more = {}) {
  std::vector<std::string> sets = {"mesh.blocks.0.cells=[12,12,1]", "fluid.timeScheme=euler",
                                   "time.dt=" + std::to_string(dt), "time.endTime=" + std::to_string(20 * dt)};
  sets.insert(sets.end(), more.begin(), more.end());
  return mfsi::SceneConfig::load(std::string(MFSI_CASES_DIR) + "/cavity.yaml", mfsi::sceneSchema(), sets);
}

/// PISO-like coupling without under-relaxation: two outer iterations of one corrector each. At
/// dt = 1000 (a Courant number of 12000) it multiplies the velocity by ~300 in the first step.
const std::vector<std::string> kUnrelaxed = {"fluid.pimple.outerCorrectors=2", "fluid.pimple.correctors=1",
                                             "fluid.pimple.relaxVelocity=1", "fluid.pimple.relaxPressure=1"};

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

}  // namespace

TEST(Runaway, TheUnstableCavityStopsAsDivergedAtTheFirstRunawayStep) {
  mfsi::Simulation sim(cavity(1000, kUnrelaxed));
  try {
    sim.run(mfsi::test::freshDir("runaway_cavity"), false);
    FAIL() << "the cavity at dt = 1000 without relaxation ran to the end";
  } catch (const mfsi::DivergenceError& e) {
    const std::string m = e.what();
    EXPECT_TRUE(contains(m, "runaway growth in the step to t = 2000")) << m;
    EXPECT_TRUE(contains(m, "max |U| = 344.")) << m;  // 344.427 m/s, measured
    EXPECT_TRUE(contains(m, "velocity scale 1 m/s")) << m;
    EXPECT_TRUE(contains(m, "fluid.divergenceVelocityFactor = 100")) << m;
    EXPECT_TRUE(contains(m, "reduce time.dt")) << m;
  }
  // The first step (max |U| a few lid speeds) completed; the second is the runaway one.
  EXPECT_EQ(sim.completedSteps(), 1);
  EXPECT_EQ(sim.completedTime(), 1000.0);
}

// Without the guard the same run goes on growing (to |U| ~ 1e38 and a continuity error of 1e77)
// until the fields turn non-finite several steps later: what the guard saves.
TEST(Runaway, WithoutTheGuardTheSameRunOnlyStopsAtNonFiniteFields) {
  std::vector<std::string> sets = kUnrelaxed;
  sets.push_back("fluid.divergenceVelocityFactor=0");
  mfsi::Simulation sim(cavity(1000, sets));
  try {
    sim.run(mfsi::test::freshDir("runaway_cavity_unguarded"), false);
    FAIL() << "the cavity at dt = 1000 without relaxation ran to the end";
  } catch (const mfsi::DivergenceError& e) {
    EXPECT_TRUE(contains(e.what(), "non-finite")) << e.what();
  }
  EXPECT_GT(sim.completedSteps(), 4);
}

TEST(Runaway, TheCavityAtAStableTimeStepIsUntouched) {
  // Unrelaxed at a Courant number of 0.6, and the scene's own under-relaxed SIMPLE iterations at
  // dt = 1000, which converge to the steady flow.
  for (const auto& scene : {cavity(0.05, kUnrelaxed), cavity(1000)}) {
    mfsi::Simulation sim(scene);
    mfsi::RunResult r;
    ASSERT_NO_THROW(r = sim.run(mfsi::test::freshDir("runaway_cavity_stable"), false));
    EXPECT_EQ(r.steps, 20);
    EXPECT_EQ(r.metrics.at("fluid.velocity_scale"), 1.0);
    EXPECT_GT(r.metrics.at("fluid.max_velocity"), 0.1);
    EXPECT_LT(r.metrics.at("fluid.max_velocity"), 1.0);
  }
}
