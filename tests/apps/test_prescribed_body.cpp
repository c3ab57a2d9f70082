// A rigid body with prescribed motion moves the fluid patches it carries (coupling.bodyPatches with
// no free coordinate: one-way, one fluid solve per step): the bottom of the flexible-cavity scene
// made rigid and lifted as y(t) = 0.05 (1 - cos(2 pi t / 5)).
//  - the body is where its joint's function puts it, and so is its patch: the mesh volume is the
//    cavity's 1 x (1 - y) x 0.05 to round-off (the side walls' nodes slide, the bottom stays flat);
//  - one coupling iteration per step, the cells stay valid;
//  - the fluid sees the motion: the pressure force on the lifting bottom differs from a rigid one.
// perf/openfoam/flexible_cavity_fluid.sh compares this case's bottom force with OpenFOAM's dynamic mesh.
#include "coupling/Module.hpp"
#include "coupling/Simulation.hpp"
#include "core/Error.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace {

/// `bodies`: the meshMotion.bodies entry (distance-weighted rigid motion), "" for none.
std::map<std::string, double> runLiftedBottom(bool lifted, double endTime, const std::string& bodies = "") {
  std::ifstream in(std::string(MFSI_CASES_DIR) + "/flexible-cavity.yaml");
  std::stringstream s;
  s << in.rdbuf();
  std::string yaml = s.str();
  yaml = yaml.substr(0, yaml.find("\nmembranes:")) + "\n";
  const std::string from = "bottom: {type: membraneWall}";
  yaml.replace(yaml.find(from), from.size(), lifted ? "bottom: {type: movingWall}" : "bottom: {type: wall}");
  yaml +=
      "  forces:\n"
      "    - {patch: bottom}\n";
  if (lifted) {
    std::ostringstream b;
    b.precision(17);
    b << "bodies:\n"
         "  members:\n"
         "    plate:\n"
         "      mass: 1\n"
         "      joint:\n"
         "        type: prescribed\n"
         "        axes: [Py]\n"
         "        motion: [{type: sine, amplitude: 0.05, omega: "
      << 2 * M_PI / 5 << ", phase: " << -M_PI / 2
      << ", offset: 0.05}]\n"
         "coupling:\n"
         "  bodyPatches: {plate: [bottom]}\n"
         "  meshMotion: {slidingPatches: [walls]"
      << (bodies.empty() ? "" : ", bodies: " + bodies) << "}\n";
    yaml += b.str();
  }
  auto cfg = mfsi::SceneConfig::fromString(
      yaml, "lifted-bottom.yaml", mfsi::sceneSchema(),
      {"mesh.blocks.0.cells=[16,14,1]", "mesh.blocks.1.cells=[16,2,1]", "time.endTime=" + std::to_string(endTime)});
  mfsi::Simulation sim(cfg);
  // One folder per test: ctest runs the tests of this file side by side.
  const std::string dir = ::testing::TempDir() + "/" + ::testing::UnitTest::GetInstance()->current_test_info()->name() +
                          (lifted ? "_lifted_bottom" : "_rigid_bottom") + (bodies.empty() ? "" : "_reach");
  std::filesystem::create_directories(dir);
  return sim.run(dir, false).metrics;
}

}  // namespace

TEST(PrescribedBody, LiftsItsPatchAndTheMeshFollows) {
  const double t = 2.0;
  const auto m = runLiftedBottom(true, t);
  const double y = 0.05 * (1 - std::cos(2 * M_PI * t / 5));
  EXPECT_NEAR(m.at("bodies.body.plate.y"), y, 1e-12);
  EXPECT_NEAR(m.at("mesh.total_volume"), (1 - y) * 0.05, 1e-13) << "the bottom patch is at y = " << y;
  EXPECT_EQ(m.at("coupling.mean_iterations"), 1.0);
  EXPECT_GT(m.at("coupling.min_scaled_jacobian"), 0.5);
  // The lifting bottom pushes fluid out through the outlet: its pressure load differs from the
  // rigid bottom's by far more than round-off (16 x 16, t = 2 s: -0.0070 against +0.0104 N).
  const auto rigid = runLiftedBottom(false, t);
  const double lifted = m.at("fluid.bottom.pressure_force_y"), still = rigid.at("fluid.bottom.pressure_force_y");
  std::printf("bottom pressure force y at t = %g: lifted %.6e, rigid %.6e\n", t, lifted, still);
  EXPECT_GT(std::abs(lifted - still), 0.5 * std::abs(still));
}

// The same lift with the mesh near the plate carried rigidly (coupling.meshMotion.bodies): the
// volume is still exact (the sliding walls' nodes keep to their walls under the blended motion),
// the cells stay valid, and the fluid's answer is the same to the mesh's difference.
TEST(PrescribedBody, TheMeshNearItMovesRigidlyWithMeshMotionBodies) {
  const double t = 2.0, y = 0.05 * (1 - std::cos(2 * M_PI * t / 5));
  const auto m = runLiftedBottom(true, t, "{plate: {innerDistance: 0.1, outerDistance: 0.6}}");
  EXPECT_NEAR(m.at("bodies.body.plate.y"), y, 1e-12);
  EXPECT_NEAR(m.at("mesh.total_volume"), (1 - y) * 0.05, 1e-13);
  EXPECT_EQ(m.at("coupling.mean_iterations"), 1.0);
  EXPECT_GT(m.at("coupling.min_scaled_jacobian"), 0.9) << "a lift, uniform near the plate";
  const auto plain = runLiftedBottom(true, t);
  const double a = m.at("fluid.bottom.pressure_force_y"), b = plain.at("fluid.bottom.pressure_force_y");
  std::printf("bottom pressure force y: %.6e blended, %.6e Laplacian alone\n", a, b);
  EXPECT_NEAR(a, b, 0.01 * std::abs(b));
}

TEST(PrescribedBody, MeshMotionBodiesNamesItsKeyOnBadInput) {
  for (const auto& [entry, message] : std::vector<std::pair<std::string, std::string>>{
           {"{plank: {innerDistance: 0.1, outerDistance: 0.6}}", "is not one of coupling.bodyPatches"},
           {"{plate: {innerDistance: 0.6, outerDistance: 0.1}}", "outerDistance must exceed innerDistance"}}) {
    try {
      runLiftedBottom(true, 0.2, entry);
      ADD_FAILURE() << "accepted " << entry;
    } catch (const mfsi::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("coupling.meshMotion.bodies.pla"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  }
}
