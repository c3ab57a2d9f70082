// Time series of a run (steps.csv, flushed every step): the fluid's force reports, pressure
// differences and probes per step, whose last row is the state summary.json reports.
#include "coupling/Simulation.hpp"

#include "support/FreshDir.hpp"
#include "support/StepsCsv.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

TEST(TimeSeries, ForcesPressureDifferencesAndProbesEveryStepEndAtTheSummarysValues) {
  const std::string dir = mfsi::test::freshDir("time_series_cylinder");
  auto cfg = mfsi::SceneConfig::load(
      std::string(MFSI_CASES_DIR) + "/cylinder.yaml", mfsi::sceneSchema(),
      {"time.endTime=6",
       "fluid.probes=[{name: wake, point: [0.27, 0.2, 0.005]}, {name: gap, point: [0.2, 0.29, 0.005]}]"});
  mfsi::Simulation sim(cfg);
  const mfsi::RunResult r = sim.run(dir, false);
  const auto steps = mfsi::test::readSteps(dir + "/steps.csv");
  ASSERT_EQ(steps.at("step").size(), static_cast<std::size_t>(r.steps));
  ASSERT_GE(r.steps, 2);
  for (const char* name : {"cylinder.force_x", "cylinder.force_y", "cylinder.moment_z", "cylinder.c_D", "cylinder.c_L",
                           "dp"}) {
    const std::vector<double>& column = steps.at(std::string("fluid.") + name);
    const double summary = r.metrics.at(std::string("fluid.") + name);
    EXPECT_NEAR(column.back(), summary, 1e-11 * std::abs(summary) + 1e-300) << name;
  }
  // c_D is the drag over q = rho U^2 A / 2 in every row, not only the last.
  const double q = 0.5 * 1.0 * 0.2 * 0.2 * 0.001;
  for (std::size_t i = 0; i < steps.at("step").size(); ++i)
    EXPECT_NEAR(steps.at("fluid.cylinder.c_D")[i], steps.at("fluid.cylinder.force_x")[i] / q,
                1e-10 * std::abs(steps.at("fluid.cylinder.c_D")[i]));
  // Just behind the cylinder the flow turns back (the recirculation bubble at Re = 20 is 1.7
  // diameters long); in the gap above it the flow is faster than the inflow's peak of 0.3.
  EXPECT_LT(steps.at("fluid.probe.wake.Ux").back(), 0.0);
  EXPECT_GT(steps.at("fluid.probe.gap.Ux").back(), 0.3);
  EXPECT_EQ(steps.count("fluid.probe.wake"), 1u);  // the pressure column keeps its name
}

TEST(TimeSeries, AProbeOnAMeshNodeIsInterpolatedNotTheNearestCell) {
  // Steady Poiseuille flow (cases/channel.yaml): the pressure falls linearly along x. A probe on
  // a mesh node (x = 3, y = 0.5: eight cell centres equally near) reads the linear field there,
  // halfway between the probes at the two cell centres beside it, not either cell's value (which
  // is what the nearest cell gave, the choice between the two decided by round-off).
  const std::string dir = mfsi::test::freshDir("time_series_probe_node");
  auto cfg = mfsi::SceneConfig::load(
      std::string(MFSI_CASES_DIR) + "/channel.yaml", mfsi::sceneSchema(),
      {"fluid.probes=[{name: node, point: [3.0, 0.5, 0.05]}, {name: before, point: [2.95, 0.55, 0.05]},"
       " {name: after, point: [3.05, 0.55, 0.05]}]"});
  mfsi::Simulation sim(cfg);
  const mfsi::RunResult r = sim.run(dir, false);
  ASSERT_TRUE(r.steadyStateReached) << r.steadyStateMissed;
  const auto steps = mfsi::test::readSteps(dir + "/steps.csv");
  const double node = steps.at("fluid.probe.node").back(), before = steps.at("fluid.probe.before").back(),
               after = steps.at("fluid.probe.after").back();
  const double jump = before - after;  // dp/dx times one cell
  ASSERT_GT(jump, 0.0);
  EXPECT_NEAR(node, 0.5 * (before + after), 0.02 * jump);
  EXPECT_GT(std::abs(node - before), 0.4 * jump);
  EXPECT_GT(std::abs(node - after), 0.4 * jump);
}

TEST(TimeSeries, PatchFlowsAndTheMeanPressure) {
  // Steady Poiseuille flow (cases/channel.yaml: Q = 0.1 m^3/s in, p = 0 out, dp/dx = -1.2 Pa/m
  // over 4 m): the inlet's flow is -Q exactly (a flow-rate condition), the outlet's +Q (continuity
  // at the solver's tolerance); the outlet's mean pressure is its prescribed 0, the inlet's the
  // 4.74 Pa the gradient builds from the outlet to the first cells' centres (the boundary value is
  // theirs: zero gradient), and the volume mean half of 4.8 (p linear in x). Measured 4.69 and
  // 2.35: the discrete gradient on 10 cells across is 1.7 % below the exact one.
  const std::string dir = mfsi::test::freshDir("time_series_flows");
  auto cfg = mfsi::SceneConfig::load(std::string(MFSI_CASES_DIR) + "/channel.yaml", mfsi::sceneSchema(),
                                     {"fluid.flows=[inlet, outlet]", "fluid.meanPressure=true"});
  mfsi::Simulation sim(cfg);
  const mfsi::RunResult r = sim.run(dir, false);
  ASSERT_TRUE(r.steadyStateReached) << r.steadyStateMissed;
  const auto steps = mfsi::test::readSteps(dir + "/steps.csv");
  EXPECT_NEAR(steps.at("fluid.inlet.flowRate").back(), -0.1, 1e-12);
  EXPECT_NEAR(steps.at("fluid.outlet.flowRate").back(), 0.1, 1e-7);
  EXPECT_NEAR(steps.at("fluid.outlet.pressure").back(), 0.0, 1e-12);
  EXPECT_NEAR(steps.at("fluid.inlet.pressure").back(), 4.74, 0.02 * 4.74);
  EXPECT_NEAR(steps.at("fluid.meanPressure").back(), 2.4, 0.03 * 2.4);
}
