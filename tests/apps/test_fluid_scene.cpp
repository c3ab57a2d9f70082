// The `fluid` scene section end to end: a cavity scene through SceneConfig + Simulation matches
// Ghia's table, bad fluid input is an InputError naming file:line and key, and the fluid module is
// built (and allocates) only when the scene names it.
#include "coupling/FluidModule.hpp"
#include "coupling/Simulation.hpp"
#include "support/AllocationRecorder.hpp"
#include "support/Approx.hpp"

#include <gtest/gtest.h>

#include <filesystem>

namespace {

// Unit cavity at Re 100 with N x N cells; `extra` is appended to the fluid section.
std::string cavityScene(int n, const std::string& extra = "", const std::string& boundary = "lid: {type: wall, velocity: [1, 0, 0]}") {
  return "name: cavity-test\n"
         "time: {endTime: 20, dt: 1}\n"
         "mesh:\n"
         "  blocks:\n"
         "    - min: [0, 0, 0]\n"
         "      max: [1, 1, 0.1]\n"
         "      cells: [" + std::to_string(n) + ", " + std::to_string(n) + ", 1]\n"
         "      patches: {xmin: walls, xmax: walls, ymin: walls, ymax: lid, zmin: frontBack, zmax: frontBack}\n"
         "  patchTypes: {walls: wall, lid: wall, frontBack: empty}\n"
         "fluid:\n"
         "  nu: 0.01\n"
         "  timeScheme: steady\n"
         "  pimple: {outerCorrectors: 100, correctors: 1, relaxVelocity: 0.9, relaxPressure: 0.2, outerTolerance: 1.0e-7}\n"
         "  solvers:\n"
         "    pressure: {tolerance: 1.0e-9, relTol: 0.01}\n"
         "    momentum: {tolerance: 1.0e-9, relTol: 0.01}\n"
         "  boundary:\n"
         "    " + boundary + "\n"
         "  ghia: {re: 100}\n" +
         extra;
}

std::map<std::string, double> runScene(const std::string& yaml, const std::vector<std::string>& sets = {}) {
  auto cfg = mfsi::SceneConfig::fromString(yaml, "cavity.yaml", mfsi::sceneSchema(), sets);
  mfsi::Simulation sim(cfg);
  const auto out = std::filesystem::temp_directory_path() / "mfsi_test_fluid_scene";
  std::filesystem::create_directories(out);
  return sim.run(out.string(), false).metrics;
}

// The InputError message of building a Simulation from `yaml`, or "" when it builds.
std::string inputError(const std::string& yaml) {
  try {
    auto cfg = mfsi::SceneConfig::fromString(yaml, "bad.yaml", mfsi::sceneSchema());
    mfsi::Simulation sim(cfg);
  } catch (const mfsi::InputError& e) {
    return e.what();
  }
  return "";
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

}  // namespace

TEST(FluidScene, CavityAtN16MatchesGhiaAndUpwindOverrideIsWorse) {
  const auto m = runScene(cavityScene(16));
  ASSERT_TRUE(m.count("fluid.ghia_u_max_err") && m.count("fluid.ghia_v_max_err"));
  const double eu = m.at("fluid.ghia_u_max_err"), ev = m.at("fluid.ghia_v_max_err");
  std::printf("cavity scene N=16: ghia u err %.4f v err %.4f, %g SIMPLE iterations\n", eu, ev,
              m.at("fluid.outer_iterations"));
  EXPECT_EQ(m.at("fluid.converged"), 1.0);
  EXPECT_LT(m.at("fluid.continuity_max"), 1e-6);
  // Measured 0.0241 / 0.0147 with linear convection (0.0035 / 0.0097 at N = 32, as
  // tests/fluid/test_cavity_ghia.cpp gets from the solver directly). Upwind convection (next
  // lines: more than twice as far), a wrong viscosity or a mis-read lid velocity break these bounds.
  EXPECT_LT(eu, 0.03);
  EXPECT_LT(ev, 0.02);
  // The extremes of the centreline profiles, against Ghia's extreme table entries (u -0.21090 at
  // y = 0.4531, v 0.17527 at x = 0.2344, -0.24533 at x = 0.8047); N = 16 is 0.019 off at most.
  std::printf("cavity scene N=16: centreline u min %.5f, v max %.5f, v min %.5f\n", m.at("fluid.centreline_u_min"),
              m.at("fluid.centreline_v_max"), m.at("fluid.centreline_v_min"));
  EXPECT_NEAR(m.at("fluid.centreline_u_min"), -0.21090, 0.025);  // measured -0.19222
  EXPECT_NEAR(m.at("fluid.centreline_v_max"), 0.17527, 0.025);  // 0.16195
  EXPECT_NEAR(m.at("fluid.centreline_v_min"), -0.24533, 0.025);  // -0.23909
  // The --set override reaches the solver: first-order upwind is clearly worse.
  const auto up = runScene(cavityScene(16), {"fluid.convection=upwind"});
  const double eUp = std::max(up.at("fluid.ghia_u_max_err"), up.at("fluid.ghia_v_max_err"));
  std::printf("cavity scene N=16 upwind: max ghia err %.4f\n", eUp);
  EXPECT_GT(eUp, 2.0 * std::max(eu, ev));
}

TEST(FluidScene, GhiaCheckRejectsAnotherReynoldsNumber) {
  // nu = 0.01 with a lid speed of 2 m/s is Re 200.
  std::string yaml = cavityScene(8);
  yaml.replace(yaml.find("ghia: {re: 100}"), 15, "ghia: {re: 100, lidSpeed: 2}");
  const std::string e = inputError(yaml);
  EXPECT_TRUE(contains(e, "bad.yaml:")) << e;
  EXPECT_TRUE(contains(e, "fluid.ghia")) << e;
  EXPECT_TRUE(contains(e, "differs from the table's 100")) << e;
}

TEST(FluidScene, UnknownPatchNamesFileLineKeyAndSuggestion) {
  const std::string e = inputError(cavityScene(8, "", "lidd: {type: wall, velocity: [1, 0, 0]}"));
  EXPECT_TRUE(contains(e, "bad.yaml:18:")) << e;
  EXPECT_TRUE(contains(e, "key 'fluid.boundary.lidd'")) << e;
  EXPECT_TRUE(contains(e, "did you mean 'lid'")) << e;
}

TEST(FluidScene, UnknownBoundaryTypeNamesFileLineKeyAndSuggestion) {
  const std::string e = inputError(cavityScene(8, "", "lid: {type: wal, velocity: [1, 0, 0]}"));
  EXPECT_TRUE(contains(e, "bad.yaml:18:")) << e;
  EXPECT_TRUE(contains(e, "key 'fluid.boundary.lid.type'")) << e;
  EXPECT_TRUE(contains(e, "did you mean 'wall'")) << e;
}

TEST(FluidScene, NegativeViscosityNamesFileLineAndKey) {
  std::string yaml = cavityScene(8);
  yaml.replace(yaml.find("nu: 0.01"), 8, "viscosity: -1e-3");
  const std::string e = inputError(yaml);
  EXPECT_TRUE(contains(e, "bad.yaml:11:")) << e;
  EXPECT_TRUE(contains(e, "key 'fluid.viscosity'")) << e;
}

TEST(FluidScene, MissingViscosityAndPlainPatchWithoutConditionAreErrors) {
  std::string yaml = cavityScene(8);
  yaml.erase(yaml.find("  nu: 0.01\n"), 11);
  std::string e = inputError(yaml);
  EXPECT_TRUE(contains(e, "bad.yaml:10:")) << e;
  EXPECT_TRUE(contains(e, "'viscosity'")) << e;
  // A plain patch (no wall/symmetry/empty kind) needs an entry under fluid.boundary.
  yaml = cavityScene(8, "", "walls: {type: wall}");
  yaml.replace(yaml.find("lid: wall, "), 11, "");
  e = inputError(yaml);
  EXPECT_TRUE(contains(e, "bad.yaml:17:")) << e;
  EXPECT_TRUE(contains(e, "fluid.boundary.lid")) << e;
}

TEST(FluidScene, SimplecNeedsSteadyAndRelaxedMomentum) {
  std::string yaml = cavityScene(8);
  yaml.replace(yaml.find("relaxPressure: 0.2"), 18, "relaxPressure: 1, consistent: true");
  EXPECT_EQ(inputError(yaml), "");
  std::string transient = yaml;
  transient.replace(transient.find("timeScheme: steady"), 18, "timeScheme: euler");
  std::string e = inputError(transient);
  EXPECT_TRUE(contains(e, "bad.yaml:13:")) << e;
  EXPECT_TRUE(contains(e, "key 'fluid.pimple.consistent'")) << e;
  EXPECT_TRUE(contains(e, "needs timeScheme: steady")) << e;
  std::string unrelaxed = yaml;
  unrelaxed.replace(unrelaxed.find("relaxVelocity: 0.9"), 18, "relaxVelocity: 1");
  e = inputError(unrelaxed);
  EXPECT_TRUE(contains(e, "key 'fluid.pimple.consistent'")) << e;
  EXPECT_TRUE(contains(e, "relaxVelocity < 1")) << e;
}

// A steady scene ends after the step whose residuals fell below outerTolerance (20 steps of 100
// SIMPLE iterations asked for), unless time.stopAtSteadyState is off.
TEST(FluidScene, SteadyRunStopsWhenConverged) {
  const auto out = std::filesystem::temp_directory_path() / "mfsi_test_steady_stop";
  std::filesystem::create_directories(out);
  auto cfg = mfsi::SceneConfig::fromString(cavityScene(16), "cavity.yaml", mfsi::sceneSchema());
  mfsi::Simulation sim(cfg);
  const mfsi::RunResult r = sim.run(out.string(), false);
  EXPECT_TRUE(r.steadyStateReached);
  EXPECT_EQ(r.metrics.at("time.steady_state_reached"), 1.0);
  EXPECT_EQ(r.metrics.at("fluid.converged"), 1.0);
  EXPECT_LT(r.steps, 20);  // measured 2 (the cavity converges within the second 100 iterations)
  auto all = mfsi::SceneConfig::fromString(cavityScene(16), "cavity.yaml", mfsi::sceneSchema(),
                                           {"time.stopAtSteadyState=false"});
  mfsi::Simulation simAll(all);
  const mfsi::RunResult rAll = simAll.run(out.string(), false);
  EXPECT_FALSE(rAll.steadyStateReached);
  EXPECT_EQ(rAll.steps, 20);
  EXPECT_EQ(rAll.metrics.count("time.steady_state_reached"), 0u);
}

TEST(FluidScene, FluidWithoutMeshIsAnError) {
  const std::string e = inputError("time: {endTime: 1, dt: 1}\nfluid: {nu: 0.01}\n");
  EXPECT_TRUE(contains(e, "bad.yaml:2:")) << e;
  EXPECT_TRUE(contains(e, "key 'fluid'")) << e;
  EXPECT_TRUE(contains(e, "mesh")) << e;
}

TEST(Effects, FluidSceneBuildsTheFluidModuleOnceAndAllocatesFluidViews) {
  mfsi::test::AllocationRecorder rec;
  auto before = mfsi::Module::constructionCounts();
  auto cfg = mfsi::SceneConfig::fromString(cavityScene(6), "cavity.yaml", mfsi::sceneSchema());
  mfsi::Simulation sim(cfg);
  auto after = mfsi::Module::constructionCounts();
  ASSERT_EQ(sim.modules().size(), 1u);
  EXPECT_EQ(sim.modules()[0]->name(), "fluid");
  EXPECT_NE(dynamic_cast<const mfsi::FluidModule*>(sim.modules()[0].get()), nullptr);
  EXPECT_EQ(after["fluid"], before["fluid"] + 1);
  after.erase("fluid");
  before.erase("fluid");
  EXPECT_EQ(after, before) << "a module other than 'fluid' was constructed";
  EXPECT_GT(rec.countWithPrefix("mfsi::fluid::"), 10);
  EXPECT_EQ(rec.countWithPrefix("mfsi::structure::"), 0);
  for (const auto& l : rec.all()) EXPECT_EQ(l.rfind("mfsi::", 0), 0u) << "unlabelled View '" << l << "'";
}
