// The `membranes` scene section end to end (SceneConfig -> Simulation -> MembraneModule):
//  - cases/hencky.yaml meets Hencky's exact centre deflection within 1 %;
//  - two panels in one scene are two modules with their own materials (w0 ~ E^(-1/3));
//  - bad input names file:line and the key;
//  - a membrane-only scene builds membrane modules only and allocates no fluid or mesh data.
#include "support/TextFiles.hpp"
#include "support/AllocationRecorder.hpp"
#include "support/Approx.hpp"

#include "coupling/MembraneModule.hpp"
#include "coupling/Simulation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

using mfsi::test::near;
using mfsi::test::Tol;

namespace {

using mfsi::test::readFile;

mfsi::RunResult runScene(const std::string& yaml, const std::string& file, const std::string& out) {
  auto cfg = mfsi::SceneConfig::fromString(yaml, file, mfsi::sceneSchema());
  mfsi::Simulation sim(cfg);
  const std::string dir = ::testing::TempDir() + "/membrane_scene_" + out;
  std::filesystem::create_directories(dir);
  return sim.run(dir, false);
}

/// The InputError message of building a scene, or "" when none is thrown.
std::string inputError(const std::string& yaml) {
  try {
    auto cfg = mfsi::SceneConfig::fromString(yaml, "bad.yaml", mfsi::sceneSchema());
    mfsi::Simulation sim(cfg);
  } catch (const mfsi::InputError& e) {
    return e.what();
  }
  return "";
}

// Line numbers matter in the bad-input tests: the scene starts on line 1.
// clang-format off
std::string panel(const std::string& wrinkling, const std::string& thickness, const std::string& clamp) {
  return "membranes:\n"                                                   // 1
         "  - mesh: {disc: {core: 2, rings: 2}}\n"                        // 2
         "    material: {E: 1.0e6, thickness: " + thickness + "}\n"       // 3
         "    wrinkling: " + wrinkling + "\n"                             // 4
         "    loads: {pressure: 1.0}\n"                                   // 5
         "    boundary: {clamp: [" + clamp + "]}\n";                      // 6
}
// clang-format on

}  // namespace

TEST(MembraneScene, HenckyCaseWithinOnePercent) {
  const auto r = runScene(readFile(std::string(MFSI_CASES_DIR) + "/hencky.yaml"), "hencky.yaml", "hencky");
  // Independent of the module's series: C_w(0.3) = 0.65344334 (Hencky's series summed in Python,
  // Chien's table: 0.6535), a = 1, p a / (E h) = 1e-5.
  const double exact = 0.65344334469 * std::cbrt(1e-5);
  const double w0 = r.metrics.at("membrane.centreDeflection");
  std::printf("hencky scene: w0 = %.6e, exact %.6e, rel.err %.3e (metric %.3e)\n", w0, exact, w0 / exact - 1,
              r.metrics.at("membrane.hencky_rel_err"));
  EXPECT_TRUE(near(w0, exact, Tol{0, 0.01}, "Hencky centre deflection"));
  EXPECT_TRUE(near(r.metrics.at("membrane.hencky_w0_exact"), exact, Tol{0, 1e-9}, "reported exact value"));
  EXPECT_EQ(r.metrics.at("membrane.hencky_w0"), w0);
  EXPECT_LT(r.metrics.at("membrane.hencky_rel_err"), 0.01);
  EXPECT_TRUE(near(r.metrics.at("membrane.hencky_rel_err"),
                   std::abs(w0 / r.metrics.at("membrane.hencky_w0_exact") - 1), Tol{1e-12, 1e-9}, "metric"));
}

TEST(MembraneScene, TwoPanelsAreTwoModulesWithTheirOwnMaterials) {
  // Same disc and pressure, E differs by 8: Hencky scaling w0 ~ (p a / (E h))^(1/3) gives a ratio of 2.
  const char* scene = R"(
membranes:
  - name: soft
    mesh: {disc: {core: 4, rings: 4}}
    material: {E: 1.0e9, thickness: 1.0e-3}
    solver: {tolerance: 1.0e-9}
    loads: {pressure: 10.0, direction: dead}
  - name: stiff
    mesh: {disc: {core: 4, rings: 4, centre: [3, 0, 0]}}
    material: {E: 8.0e9, thickness: 1.0e-3}
    solver: {tolerance: 1.0e-9}
    loads: {pressure: 10.0, direction: dead}
)";
  auto cfg = mfsi::SceneConfig::fromString(scene, "two.yaml", mfsi::sceneSchema());
  mfsi::Simulation sim(cfg);
  ASSERT_EQ(sim.modules().size(), 2u);
  EXPECT_EQ(sim.modules()[0]->name(), "membrane.soft");
  EXPECT_EQ(sim.modules()[1]->name(), "membrane.stiff");
  auto* soft = dynamic_cast<mfsi::MembraneModule*>(sim.modules()[0].get());
  auto* stiff = dynamic_cast<mfsi::MembraneModule*>(sim.modules()[1].get());
  ASSERT_TRUE(soft && stiff);
  EXPECT_EQ(soft->solver().options().material.youngsModulus, 1e9);
  EXPECT_EQ(stiff->solver().options().material.youngsModulus, 8e9);
  const std::string dir = ::testing::TempDir() + "/membrane_scene_two";
  std::filesystem::create_directories(dir);
  const auto r = sim.run(dir, false);
  const double ws = r.metrics.at("membrane.soft.centreDeflection"),
               wt = r.metrics.at("membrane.stiff.centreDeflection");
  std::printf("two panels: w0 soft %.6e stiff %.6e ratio %.6f\n", ws, wt, ws / wt);
  EXPECT_GT(wt, 0);
  EXPECT_TRUE(near(ws / wt, 2.0, Tol{0, 1e-3}, "deflection ratio E^(-1/3)"));
}

TEST(MembraneScene, BadInputNamesFileLineAndKey) {
  const std::string wrinkling = inputError(panel("tensionFeild", "1.0e-3", "boundary"));
  EXPECT_NE(wrinkling.find("bad.yaml:4:"), std::string::npos) << wrinkling;
  EXPECT_NE(wrinkling.find("membranes.0.wrinkling"), std::string::npos) << wrinkling;
  EXPECT_NE(wrinkling.find("did you mean 'tensionField'"), std::string::npos) << wrinkling;

  const std::string thickness = inputError(panel("none", "-1.0e-3", "boundary"));
  EXPECT_NE(thickness.find("bad.yaml:3:"), std::string::npos) << thickness;
  EXPECT_NE(thickness.find("membranes.0.material.thickness"), std::string::npos) << thickness;
  EXPECT_NE(thickness.find("> 0"), std::string::npos) << thickness;

  const std::string nodeSet = inputError(panel("none", "1.0e-3", "boundry"));
  EXPECT_NE(nodeSet.find("bad.yaml:6:"), std::string::npos) << nodeSet;
  EXPECT_NE(nodeSet.find("membranes.0.boundary.clamp.0"), std::string::npos) << nodeSet;
  EXPECT_NE(nodeSet.find("unknown node set 'boundry'"), std::string::npos) << nodeSet;
  EXPECT_NE(nodeSet.find("did you mean 'boundary'"), std::string::npos) << nodeSet;

  // The same panel with valid values builds (so the three errors above come from those values).
  EXPECT_EQ(inputError(panel("tensionField", "1.0e-3", "boundary")), "");
}

TEST(MembraneScene, MembraneOnlySceneBuildsMembranesOnlyAndNoFluidData) {
  const char* scene = R"(
membranes:
  - mesh: {rectangle: {cells: [4, 4]}}
    material: {E: 1.0e6, thickness: 1.0e-3, preStress: 10}
    loads: {pressure: 1.0}
)";
  mfsi::test::AllocationRecorder rec;
  auto before = mfsi::Module::constructionCounts();
  auto cfg = mfsi::SceneConfig::fromString(scene, "membrane-only.yaml", mfsi::sceneSchema());
  mfsi::Simulation sim(cfg);
  const std::string dir = ::testing::TempDir() + "/membrane_scene_only";
  std::filesystem::create_directories(dir);
  const auto r = sim.run(dir, false);
  auto after = mfsi::Module::constructionCounts();
  EXPECT_FALSE(sim.hasMesh());
  ASSERT_EQ(sim.modules().size(), 1u);
  EXPECT_EQ(sim.modules()[0]->name(), "membrane");
  EXPECT_EQ(after["membrane"], before["membrane"] + 1);
  after.erase("membrane");
  before.erase("membrane");
  EXPECT_EQ(after, before) << "a module other than the membrane was constructed";
  EXPECT_GT(r.metrics.at("membrane.centreDeflection"), 0) << "the panel was solved";
  // The recorder sees the membrane (so it works) ...
  EXPECT_GT(rec.countWithPrefix("mfsi::structure::"), 10);
  // ... and nothing of the fluid or of a fluid mesh.
  EXPECT_EQ(rec.countWithPrefix("mfsi::fluid::"), 0);
  EXPECT_EQ(rec.countWithPrefix("mfsi::core::mesh::"), 0);
  EXPECT_EQ(rec.countWithPrefix("mfsi::core::geometry::"), 0);
  EXPECT_EQ(rec.countWithPrefix("mfsi::coupling::"), 0);
  // Every allocation is labelled hierarchically.
  for (const auto& l : rec.all()) EXPECT_EQ(l.rfind("mfsi::", 0), 0u) << "unlabelled View '" << l << "'";
}

TEST(MembraneScene, GeneratorGmshSurfaceAndFluidBaffleGiveTheSamePanel) {
  // One clamped, pre-tensioned unit square under pressure, meshed three ways with the same 4x4
  // quads: the generator, a Gmsh surface file, and the baffle of the scene's fluid mesh.
  const std::string scene = R"(
mesh:
  blocks:
    - {min: [0, 0, 0], max: [1, 1, 1], cells: [4, 4, 2]}
  baffles:
    - {name: sail, axis: z, position: 0.5, min: [0, 0, 0], max: [1, 1, 0]}
membranes:
  - name: generated
    mesh: {rectangle: {origin: [0, 0, 0], size: [1, 1], cells: [4, 4]}}
    material: {E: 1.0e6, thickness: 1.0e-3, preStress: 10.0}
    solver: {tolerance: 1.0e-10}
    loads: {pressure: 5.0, direction: dead}
  - name: gmsh
    mesh: {gmsh: {file: ../meshes/membrane_square_quads.msh, group: membrane}}
    material: {E: 1.0e6, thickness: 1.0e-3, preStress: 10.0}
    solver: {tolerance: 1.0e-10}
    loads: {pressure: 5.0, direction: dead}
  - name: baffle
    mesh: {baffles: {patch: sail}}
    material: {E: 1.0e6, thickness: 1.0e-3, preStress: 10.0}
    solver: {tolerance: 1.0e-10}
    loads: {pressure: 5.0, direction: dead}
)";
  const auto r = runScene(scene, std::string(MFSI_TEST_DATA_DIR) + "/scenes/three_panels.yaml", "three");
  const double wg = r.metrics.at("membrane.generated.maxDisplacement");
  const double wm = r.metrics.at("membrane.gmsh.maxDisplacement");
  const double wb = r.metrics.at("membrane.baffle.maxDisplacement");
  EXPECT_GT(wg, 1e-3);
  EXPECT_TRUE(near(wm, wg, Tol{0, 1e-8}, "gmsh surface vs generator"));
  EXPECT_TRUE(near(wb, wg, Tol{0, 1e-8}, "fluid baffle vs generator"));

  // A baffle name the fluid mesh does not have is an input error with a suggestion.
  const std::string bad = scene.substr(0, scene.find("membranes:")) + R"(membranes:
  - mesh: {baffles: {patch: sial}}
    material: {E: 1.0e6, thickness: 1.0e-3}
    loads: {pressure: 5.0}
)";
  const std::string msg = inputError(bad);
  EXPECT_NE(msg.find("did you mean 'sail'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("membranes.0.mesh.baffles.patch"), std::string::npos) << msg;
}

TEST(MembraneScene, ClampedStripUnderPressureIsTheExactCircularArc) {
  // A strip clamped at x = 0 and 1 that stays in its (x, z) planes (the membrane of a 2D FSI scene),
  // under a uniform follower pressure p: a circular arc of radius R and half-angle theta with
  // L / 2 = R sin theta, stretch lambda = theta / sin theta, and the tension of St. Venant-Kirchhoff
  // per unit width, lambda E h (lambda^2 - 1) / 2, equal to p R. Deflections up to 0.27 L.
  const double E = 250, h = 0.002, L = 1;
  for (const double p : {0.01, 0.2}) {
    double lo = 1e-6, hi = 1.5;
    for (int i = 0; i < 200; ++i) {
      const double th = 0.5 * (lo + hi), lam = th / std::sin(th), R = L / (2 * std::sin(th));
      (lam * E * h * (lam * lam - 1) / 2 > p * R ? hi : lo) = th;
    }
    const double th = 0.5 * (lo + hi), R = L / (2 * std::sin(th)), exact = R * (1 - std::cos(th));
    std::ostringstream y;
    y << "membranes:\n"
         "  - mesh: {rectangle: {size: [1.0, 0.05], cells: [64, 1]}}\n"
         "    material: {E: 250, nu: 0, thickness: 0.002, density: 500}\n"
         "    loads: {pressure: "
      << p
      << "}\n"
         "    solver: {tolerance: 1.0e-10, loadSteps: 10}\n"
         "    boundary: {clamp: [xmin, xmax], motionPlaneNormal: [0, 1, 0]}\n";
    const auto r = runScene(y.str(), "strip.yaml", "strip");
    const double w = r.metrics.at("membrane.centreDeflection");
    std::printf("p = %.2f Pa: mid-point deflection %.6f, exact arc %.6f\n", p, w, exact);
    EXPECT_TRUE(near(w, exact, Tol{0, 2e-4})) << "p = " << p;
  }
}
