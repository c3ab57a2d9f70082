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
