// Checkpoint and restart (issue 14): a run of 2N steps and a run of N steps continued from its
// checkpoint for N more end in the same state, bit for bit — every dataset of their step-2N
// checkpoints (fields, old time levels, solver guesses, preconditioner history, structure and
// coupling state) and every column of steps.csv but the wall time.
#include "coupling/Simulation.hpp"
#include "core/Error.hpp"
#include "core/io/Hdf5File.hpp"

#include "support/CubeCavity.hpp"
#include "support/FreshDir.hpp"
#include "support/StepsCsv.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

using mfsi::io::Hdf5File;

namespace {

const std::string kCavity3d = mfsi::test::cubeCavityScene(12, 10);

mfsi::SceneConfig scene(const std::string& source, std::vector<std::string> sets) {
  if (source.find('\n') != std::string::npos)
    return mfsi::SceneConfig::fromString(source, "inline.yaml", mfsi::sceneSchema(), sets);
  return mfsi::SceneConfig::load(std::string(MFSI_CASES_DIR) + "/" + source + ".yaml", mfsi::sceneSchema(), sets);
}

std::vector<std::string> with(std::vector<std::string> sets, std::initializer_list<std::string> more) {
  sets.insert(sets.end(), more);
  return sets;
}

/// Wall-clock measurements (a solve's seconds, a phase's time and share): the only values a
/// restarted run may differ in.
bool isTiming(const std::string& name) {
  const auto ends = [&](const std::string& e) {
    return name.size() >= e.size() && name.compare(name.size() - e.size(), e.size(), e) == 0;
  };
  return ends("/seconds") || ends("_s") || name.find(".share_") != std::string::npos;
}

/// Every dataset of two checkpoints holds the same bits (the wall time, /run/time[4], aside).
void expectSameCheckpoints(const std::string& a, const std::string& b) {
  const Hdf5File fa = Hdf5File::openRead(a), fb = Hdf5File::openRead(b);
  const auto names = fa.datasets();
  ASSERT_EQ(names, fb.datasets());
  ASSERT_GT(names.size(), 10u);
  int compared = 0;
  for (const auto& n : names) {
    if (isTiming(n)) continue;
    std::vector<std::size_t> da, db;
    const auto ia = fa.readInts(n, &da), ib = fb.readInts(n, &db);  // exact for integer datasets
    ASSERT_EQ(da, db) << n;
    auto xa = fa.readDoubles(n), xb = fb.readDoubles(n);
    if (n == "/run/time") xa.resize(4), xb.resize(4);
    ASSERT_EQ(xa.size(), xb.size()) << n;
    std::size_t differ = 0, first = 0;
    for (std::size_t i = 0; i < xa.size(); ++i)
      if (std::memcmp(&xa[i], &xb[i], sizeof(double)) != 0 && differ++ == 0) first = i;
    EXPECT_EQ(differ, 0u) << n << ": " << differ << " of " << xa.size() << " values differ, the first at " << first
                          << " (" << xa[first] << " against " << xb[first] << ")";
    EXPECT_EQ(ia == ib || n == "/run/time", true) << n;
    ++compared;
  }
  EXPECT_GT(compared, static_cast<int>(names.size()) * 9 / 10);
}

/// 2N steps in one run against N steps, restart, N steps (continuing the first folder).
void expectRestartIsBitwise(const std::string& tag, const std::string& source, const std::vector<std::string>& sets,
                            int n) {
  const std::string whole = mfsi::test::freshDir("restart_" + tag + "_whole");
  const std::string split = mfsi::test::freshDir("restart_" + tag + "_split");
  const std::string ck = "output.checkpoint.final=true";
  mfsi::RunResult a;
  {
    mfsi::Simulation sim(scene(source, with(sets, {"time.maxSteps=" + std::to_string(2 * n), ck})));
    a = sim.run(whole, false);
  }
  ASSERT_EQ(a.steps, 2 * n);
  {
    mfsi::Simulation sim(scene(source, with(sets, {"time.maxSteps=" + std::to_string(n), ck})));
    ASSERT_EQ(sim.run(split, false).steps, n);
  }
  mfsi::RunResult b;
  {
    mfsi::Simulation sim(scene(source, with(sets, {"time.maxSteps=" + std::to_string(2 * n), ck})));
    const std::string checkpoint = mfsi::Simulation::findCheckpoint(split);
    char name[64];
    std::snprintf(name, sizeof name, "checkpoint_%09d.h5", n);
    EXPECT_EQ(std::filesystem::path(checkpoint).filename().string(), name);
    sim.restore(checkpoint);
    EXPECT_EQ(sim.completedSteps(), n);
    b = sim.run(split, false, /*continueFiles=*/true);
  }
  ASSERT_EQ(b.steps, 2 * n);
  char last[64];
  std::snprintf(last, sizeof last, "/checkpoints/checkpoint_%09d.h5", 2 * n);
  expectSameCheckpoints(whole + last, split + last);
  EXPECT_EQ(mfsi::test::stepsWithoutWallTime(whole + "/steps.csv"),
            mfsi::test::stepsWithoutWallTime(split + "/steps.csv"));
  for (const auto& [key, value] : a.metrics) {
    ASSERT_TRUE(b.metrics.count(key)) << key;
    if (isTiming(key)) continue;
    EXPECT_EQ(std::memcmp(&value, &b.metrics.at(key), sizeof(double)), 0) << key << ": " << value << " against "
                                                                           << b.metrics.at(key);
  }
}

}  // namespace

TEST(Restart, TheTransientCubeCavityContinuesBitwise) {
  expectRestartIsBitwise("cavity3d", kCavity3d, {}, 10);
}

// Running means that started before the checkpoint (t = 0.1, step 5 of 20) continue from it: the
// means, the time they average and the runaway guard's running maximum are part of the state.
TEST(Restart, TheCubeCavityWithRunningMeansContinuesBitwise) {
  expectRestartIsBitwise("cavity3d_means", kCavity3d, {"fluid.means.start=0.1"}, 10);
}

TEST(Restart, AChangedSceneIsRefusedWithWhatChanged) {
  const std::string dir = mfsi::test::freshDir("restart_changed");
  {
    mfsi::Simulation sim(scene(kCavity3d, {"time.maxSteps=2", "output.checkpoint.final=true"}));
    sim.run(dir, false);
  }
  mfsi::Simulation changed(scene(kCavity3d, {"fluid.nu=0.02", "time.maxSteps=4"}));
  try {
    changed.restore(mfsi::Simulation::findCheckpoint(dir));
    FAIL() << "a restart with another viscosity was accepted";
  } catch (const mfsi::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("fluid.nu: 0.01 -> 0.02"), std::string::npos) << e.what();
  }
  // What a restart may change: the end and the output.
  mfsi::Simulation longer(scene(kCavity3d, {"time.maxSteps=4", "output.fields.everySteps=1"}));
  EXPECT_NO_THROW(longer.restore(mfsi::Simulation::findCheckpoint(dir)));
  EXPECT_EQ(longer.completedSteps(), 2);
}

// --allow-changes: other settings may change (to go on from a diverged run's last good state),
// listed back; the mesh and the time step may not.
TEST(Restart, AllowedChangesAreListedButNotTheMeshNorTheTimeStep) {
  const std::string dir = mfsi::test::freshDir("restart_allowed_changes");
  {
    mfsi::Simulation sim(scene(kCavity3d, {"time.maxSteps=2", "output.checkpoint.final=true"}));
    sim.run(dir, false);
  }
  const std::string checkpoint = mfsi::Simulation::findCheckpoint(dir);
  mfsi::Simulation changed(scene(kCavity3d, {"fluid.nu=0.02", "fluid.pimple.outerCorrectors=3", "time.maxSteps=4"}));
  const std::vector<std::string> changes = changed.restore(checkpoint, true);
  ASSERT_EQ(changes.size(), 2u);
  EXPECT_NE(changes[0].find("0.02"), std::string::npos) << changes[0];
  EXPECT_EQ(changed.completedSteps(), 2);
  const std::string out = mfsi::test::freshDir("restart_allowed_changes_out");
  EXPECT_EQ(changed.run(out, false).steps, 4);
  for (const std::string& set : {std::string("mesh.blocks.0.cells=[10, 10, 10]"), std::string("time.dt=0.01")}) {
    mfsi::Simulation refused(scene(kCavity3d, {set, "time.maxSteps=4"}));
    EXPECT_THROW(refused.restore(checkpoint, true), mfsi::InputError) << set;
  }
}

// The membrane load's filter switched on or off at a restart: switched on, it starts as at a
// run's start (the first step after the restart is the unfiltered run's, bit for bit; the next
// is filtered); switched off, its state is left behind.
TEST(Restart, ALoadFilterSwitchedOnOrOffAtARestartStartsAfresh) {
  const std::vector<std::string> cavity = {"mesh.blocks.0.cells=[12,10,1]", "mesh.blocks.1.cells=[12,2,1]",
                                           "output.checkpoint.final=true"};
  const std::string plain = mfsi::test::freshDir("restart_filter_plain");
  const std::string filtered = mfsi::test::freshDir("restart_filter_filtered");
  for (const std::string& dir : {plain, filtered}) {
    const std::string tau = dir == filtered ? "coupling.pNetFilterTau=0.5" : "coupling.pNetFilterTau=0";
    mfsi::Simulation sim(scene("flexible-cavity", with(cavity, {"time.maxSteps=6", tau})));
    ASSERT_EQ(sim.run(dir, false).steps, 6);
  }
  // The unfiltered run's checkpoint at step 6 is 6 steps in; run 6 .. 8 with the filter on.
  const std::string on = mfsi::test::freshDir("restart_filter_on");
  {
    mfsi::Simulation sim(scene("flexible-cavity", with(cavity, {"time.maxSteps=8", "coupling.pNetFilterTau=0.5"})));
    ASSERT_NO_THROW(sim.restore(mfsi::Simulation::findCheckpoint(plain), true));
    ASSERT_EQ(sim.run(on, false).steps, 8);
  }
  const std::string off = mfsi::test::freshDir("restart_filter_plain_on");
  {
    mfsi::Simulation sim(scene("flexible-cavity", with(cavity, {"time.maxSteps=8", "coupling.pNetFilterTau=0"})));
    sim.restore(mfsi::Simulation::findCheckpoint(plain), true);
    ASSERT_EQ(sim.run(off, false).steps, 8);
  }
  const auto a = mfsi::test::readSteps(on + "/steps.csv"), b = mfsi::test::readSteps(off + "/steps.csv");
  const std::string y = "membrane.bottom.centreUy";
  ASSERT_EQ(a.at(y).size(), 2u);
  EXPECT_EQ(a.at(y)[0], b.at(y)[0]) << "the first step after switching the filter on is unfiltered";
  EXPECT_NE(a.at(y)[1], b.at(y)[1]) << "the second is filtered";
  // And the filtered run's checkpoint continues with the filter off.
  mfsi::Simulation sim(scene("flexible-cavity", with(cavity, {"time.maxSteps=8", "coupling.pNetFilterTau=0"})));
  ASSERT_NO_THROW(sim.restore(mfsi::Simulation::findCheckpoint(filtered), true));
  EXPECT_EQ(sim.run(mfsi::test::freshDir("restart_filter_off"), false).steps, 8);
}

TEST(Restart, TheMembraneSquaresDynamicsContinueBitwise) {
  expectRestartIsBitwise("membrane_square", "membrane-square", {"membranes.0.mesh.rectangle.cells=[6,6]"}, 6);
}

TEST(Restart, TheDoublePendulumContinuesBitwise) {
  expectRestartIsBitwise("double_pendulum", "double-pendulum", {}, 40);
}

// FSI with IQN-ILS whose columns are reused across steps: the restarted run must carry them.
TEST(Restart, TheFlexibleCavityWithIqnIlsReuseContinuesBitwise) {
  expectRestartIsBitwise("flexible_cavity", "flexible-cavity",
                         {"mesh.blocks.0.cells=[12,10,1]", "mesh.blocks.1.cells=[12,2,1]"}, 4);
}

// The extrapolated predictor reads the load of the step before the checkpoint's: it must be in it.
TEST(Restart, TheExtrapolatedPredictorContinuesBitwise) {
  expectRestartIsBitwise("flexible_cavity_extrapolated", "flexible-cavity",
                         {"mesh.blocks.0.cells=[12,10,1]", "mesh.blocks.1.cells=[12,2,1]",
                          "coupling.predictor=extrapolatedLoad"},
                         4);
}

// A membrane mounted on a sprung rigid frame in a 3D channel: fluid, membrane, bodies and coupling.
TEST(Restart, TheMembraneChannelContinuesBitwise) {
  expectRestartIsBitwise("membrane_channel", "membrane-channel", {"mesh.blocks.0.cells=[24,8,16]"}, 2);
}

// IQN-IMVJ carries its inverse Jacobian from step to step: it must be in the checkpoint.
TEST(Restart, IqnImvjContinuesBitwise) {
  expectRestartIsBitwise("flexible_cavity_imvj", "flexible-cavity",
                         {"mesh.blocks.0.cells=[12,10,1]", "mesh.blocks.1.cells=[12,2,1]",
                          "coupling.iqnJacobian=multiVector"},
                         4);
}

// The mesh carried rigidly near the frame (meshMotion.bodies): the motion's warm start, the last
// rigid part, must be in the checkpoint.
TEST(Restart, TheRigidBlendContinuesBitwise) {
  expectRestartIsBitwise("membrane_channel_blend", "membrane-channel",
                         {"mesh.blocks.0.cells=[24,8,16]", "coupling.meshMotion.bodies={frame: {innerDistance: 0.2, "
                                                           "outerDistance: 1.0}}"},
                         2);
}
