// Running means of a whole run (`fluid.means`): on a converged steady flow the means equal the
// field; the field frames carry UMean and pMean (zero before the start time), and summary.json the
// time averaged. (The accumulation itself against analytic averages: tests/fluid/test_running_mean.cpp;
// bitwise restarts with means: tests/apps/test_restart.cpp.)
#include "core/io/Hdf5File.hpp"
#include "core/io/HostCopy.hpp"
#include "coupling/FluidModule.hpp"
#include "coupling/Simulation.hpp"

#include "support/Approx.hpp"
#include "support/FreshDir.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

using mfsi::io::Hdf5File;
using mfsi::test::allNear;
using mfsi::test::Tol;

namespace {

mfsi::SceneConfig cavity(std::vector<std::string> sets) {
  sets.insert(sets.begin(), "mesh.blocks.0.cells=[12,12,1]");
  return mfsi::SceneConfig::load(std::string(MFSI_CASES_DIR) + "/cavity.yaml", mfsi::sceneSchema(), sets);
}

mfsi::FluidModule* fluidOf(mfsi::Simulation& sim) {
  for (const auto& m : sim.modules())
    if (auto* f = dynamic_cast<mfsi::FluidModule*>(m.get())) return f;
  return nullptr;
}

}  // namespace

// The steady cavity converges (outerTolerance 1e-7) in its first chunk of SIMPLE iterations; the
// chunks ending at t = 6 ... 12 enter the means, whose fields then differ from the final ones by
// what the converged iterations still change (~1e-9 of the lid speed).
TEST(RunningMeans, OnASteadyFlowTheMeansAreTheField) {
  const std::string dir = mfsi::test::freshDir("running_means_steady");
  mfsi::Simulation sim(cavity({"time.endTime=12", "time.stopAtSteadyState=false", "fluid.means.start=6", "output.fields.initial=true"}));
  const mfsi::RunResult r = sim.run(dir, false);
  ASSERT_EQ(r.steps, 12);
  EXPECT_EQ(r.metrics.at("fluid.means_time"), 7.0);
  mfsi::FluidModule* fluid = fluidOf(sim);
  ASSERT_NE(fluid, nullptr);
  ASSERT_NE(fluid->means(), nullptr);
  const std::size_t n = static_cast<std::size_t>(sim.mesh().nCells());
  const std::vector<double> U = mfsi::io::hostValues(fluid->solver().velocity(), n);
  const std::vector<double> p = mfsi::io::hostValues(fluid->solver().pressure(), n);
  const std::vector<double> UMean = mfsi::io::hostValues(fluid->means()->velocity(), n);
  const std::vector<double> pMean = mfsi::io::hostValues(fluid->means()->pressure(), n);
  const double pRange = *std::max_element(p.begin(), p.end()) - *std::min_element(p.begin(), p.end());
  EXPECT_TRUE(allNear(UMean, U, 3 * n, Tol{1e-7, 0}, "UMean"));
  EXPECT_TRUE(allNear(pMean, p, n, Tol{1e-7 * pRange, 0}, "pMean"));
  // The final frame holds the means as they are; the initial one (before the start) zeros.
  const Hdf5File last = Hdf5File::openRead(dir + "/fields/fields_000012.h5");
  EXPECT_EQ(last.readDoubles("/mesh/cell/UMean"), UMean);
  EXPECT_EQ(last.readDoubles("/mesh/cell/pMean"), pMean);
  const Hdf5File first = Hdf5File::openRead(dir + "/fields/fields_000000.h5");
  EXPECT_EQ(first.readDoubles("/mesh/cell/UMean"), std::vector<double>(3 * n, 0.0));
}

// Without the key: no mean fields, no metric.
TEST(RunningMeans, AreOffUnlessTheSceneAsks) {
  const std::string dir = mfsi::test::freshDir("running_means_off");
  mfsi::Simulation sim(cavity({"time.endTime=1"}));
  const mfsi::RunResult r = sim.run(dir, false);
  EXPECT_EQ(r.metrics.count("fluid.means_time"), 0u);
  EXPECT_EQ(fluidOf(sim)->means(), nullptr);
  const Hdf5File last = Hdf5File::openRead(dir + "/fields/fields_000001.h5");
  const auto names = last.datasets();
  EXPECT_EQ(std::count(names.begin(), names.end(), "/mesh/cell/UMean"), 0);
}
