// Field output of whole runs (the `output.fields` section): what the HDF5 frames hold is the
// solvers' own state, bit for bit, and the frames come when the scene asks.
//  - the flexible cavity: the mesh grid (moved points, displacement from the reference mesh, each
//    cell's scaled Jacobian), the fluid's U and p on it, the membrane's deformed surface;
//  - the pendulum: the bodies' grid (centre of mass on its circle, velocity along it);
//  - frames by steps, by time, first and last.
#include "coupling/FluidModule.hpp"
#include "coupling/MembraneModule.hpp"
#include "coupling/Simulation.hpp"
#include "core/io/Hdf5File.hpp"
#include "core/io/HostCopy.hpp"

#include "support/FreshDir.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using mfsi::io::Hdf5File;

namespace {

std::vector<std::string> frameFiles(const std::string& dir) {
  std::vector<std::string> files;
  if (!fs::exists(dir + "/fields")) return files;
  for (const auto& e : fs::directory_iterator(dir + "/fields")) files.push_back(e.path().filename().string());
  std::sort(files.begin(), files.end());
  return files;
}

template <class T>
T* findModule(mfsi::Simulation& sim) {
  for (const auto& m : sim.modules()) {
    if (auto* t = dynamic_cast<T*>(m.get())) return t;
    for (mfsi::Module* p : m->parts())
      if (auto* t = dynamic_cast<T*>(p)) return t;
  }
  return nullptr;
}

}  // namespace

TEST(FieldOutputScene, TheCavitysFramesHoldTheSolversStateBitForBit) {
  const std::string dir = mfsi::test::freshDir("field_output_scene_cavity");
  auto cfg = mfsi::SceneConfig::load(std::string(MFSI_CASES_DIR) + "/flexible-cavity.yaml", mfsi::sceneSchema(),
                                     {"mesh.blocks.0.cells=[12,10,1]", "mesh.blocks.1.cells=[12,2,1]",
                                      "time.endTime=0.3", "output.fields.everySteps=2", "output.fields.initial=true"});
  mfsi::Simulation sim(cfg);
  const auto result = sim.run(dir, false);
  ASSERT_EQ(result.steps, 3);
  // Initial, step 2, and the final step 3.
  EXPECT_EQ(frameFiles(dir), (std::vector<std::string>{"fields_000000.h5", "fields_000002.h5", "fields_000003.h5"}));
  EXPECT_EQ(result.metrics.at("output.field_frames"), 3);

  const Hdf5File h5 = Hdf5File::openRead(dir + "/fields/fields_000003.h5");
  EXPECT_NEAR(h5.readAttribute("time"), 0.3, 1e-12);
  const auto& mesh = sim.mesh();
  const std::size_t nCells = static_cast<std::size_t>(mesh.nCells());
  const std::size_t nNodes = static_cast<std::size_t>(mesh.nNodes());
  auto* fluid = findModule<mfsi::FluidModule>(sim);
  auto* membrane = findModule<mfsi::MembraneModule>(sim);
  ASSERT_NE(fluid, nullptr);
  ASSERT_NE(membrane, nullptr);
  EXPECT_EQ(h5.readDoubles("/mesh/cell/p"), mfsi::io::hostValues(fluid->solver().pressure(), nCells));
  EXPECT_EQ(h5.readDoubles("/mesh/cell/U"), mfsi::io::hostValues(fluid->solver().velocity(), nCells));
  const std::vector<double> points = h5.readDoubles("/mesh/points");
  EXPECT_EQ(points, mfsi::io::hostValues(mesh.points(), nNodes));
  const std::vector<double> x0 = mfsi::io::hostValues(mesh.referencePoints(), nNodes);
  const std::vector<double> d = h5.readDoubles("/mesh/point/meshDisplacement");
  double maxMove = 0;
  for (std::size_t i = 0; i < d.size(); ++i) {
    EXPECT_EQ(d[i], points[i] - x0[i]);
    maxMove = std::max(maxMove, std::abs(d[i]));
  }
  EXPECT_GT(maxMove, 1e-6) << "the bottom has moved by t = 0.3 s, and the mesh with it";
  const std::vector<double> jac = h5.readDoubles("/mesh/cell/scaledJacobian");
  ASSERT_EQ(jac.size(), nCells);
  EXPECT_NEAR(*std::min_element(jac.begin(), jac.end()), result.metrics.at("mesh.min_scaled_jacobian"), 1e-15);
  EXPECT_GT(*std::min_element(jac.begin(), jac.end()), 0.9);

  // The membrane: its surface deformed by its own displacement, and that displacement.
  const std::string m = "/" + membrane->name();
  const auto& mm = membrane->solver().mesh();
  const std::vector<double> u = mfsi::io::hostValues(membrane->solver().displacement(), 3 * mm.nNodes());
  EXPECT_EQ(h5.readDoubles(m + "/point/displacement"), u);
  const std::vector<double> mp = h5.readDoubles(m + "/points");
  for (mfsi::lid_t i = 0; i < mm.nNodes(); ++i)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(mp[3 * i + k], mm.hostPoints()[i][k] + u[3 * i + k]);
  EXPECT_EQ(h5.readDoubles(m + "/cell/vonMises").size(), static_cast<std::size_t>(mm.nElements()));
  // All quads; the cells never change, so the first frame holds them for every frame.
  EXPECT_FALSE(h5.has(m + "/topology"));
  EXPECT_EQ(Hdf5File::openRead(dir + "/fields/fields_000000.h5").readInts(m + "/topology").size(),
            4u * mm.nElements());

  std::ifstream in(dir + "/fields.xdmf");
  std::stringstream x;
  x << in.rdbuf();
  EXPECT_NE(x.str().find("<Time Value=\"0.20000000000000001\"/>"), std::string::npos) << x.str().substr(0, 2000);
  EXPECT_NE(x.str().find("Name=\"" + membrane->name() + "\" GridType=\"Collection\""), std::string::npos);
}

TEST(FieldOutputScene, ThePendulumsBodyStaysOnItsCircleInEveryFrame) {
  const std::string dir = mfsi::test::freshDir("field_output_scene_pendulum");
  auto cfg = mfsi::SceneConfig::load(std::string(MFSI_CASES_DIR) + "/pendulum.yaml", mfsi::sceneSchema(),
                                     {"time.endTime=0.5", "output.fields.interval=0.1", "output.fields.initial=true"});
  mfsi::Simulation sim(cfg);
  sim.run(dir, false);
  const std::vector<std::string> files = frameFiles(dir);
  ASSERT_EQ(files.size(), 6u) << "t = 0, 0.1, ..., 0.5";
  EXPECT_EQ(files.back(), "fields_000500.h5");
  for (const auto& f : files) {
    const Hdf5File h5 = Hdf5File::openRead(dir + "/fields/" + f);
    const std::vector<double> x = h5.readDoubles("/bodies/points");
    const std::vector<double> v = h5.readDoubles("/bodies/point/velocity");
    ASSERT_EQ(x.size(), 3u);
    EXPECT_NEAR(std::hypot(x[0], x[1]), 0.5, 1e-12) << f;
    EXPECT_NEAR(x[0] * v[0] + x[1] * v[1], 0.0, 1e-12) << f;
  }
  const Hdf5File first = Hdf5File::openRead(dir + "/fields/" + files.front());
  const std::vector<double> x = first.readDoubles("/bodies/points");
  EXPECT_NEAR(x[0], 0.5 * std::sin(0.1), 1e-12);
  EXPECT_NEAR(x[1], -0.5 * std::cos(0.1), 1e-12);
}

TEST(FieldOutputScene, NoFramesWhenTheSceneAsksForNone) {
  const std::string dir = mfsi::test::freshDir("field_output_scene_none");
  auto cfg = mfsi::SceneConfig::load(std::string(MFSI_CASES_DIR) + "/pendulum.yaml", mfsi::sceneSchema(),
                                     {"time.endTime=0.01", "output.fields.final=false"});
  mfsi::Simulation sim(cfg);
  EXPECT_EQ(sim.run(dir, false).metrics.at("output.field_frames"), 0);
  EXPECT_TRUE(frameFiles(dir).empty());
  EXPECT_FALSE(fs::exists(dir + "/fields.xdmf"));
}

TEST(FieldOutputScene, AMountedPanelIsWrittenWhereItsFrameCarriesIt) {
  const std::string dir = mfsi::test::freshDir("field_output_scene_mounted");
  auto cfg = mfsi::SceneConfig::load(std::string(MFSI_CASES_DIR) + "/membrane-channel.yaml", mfsi::sceneSchema(),
                                     {"time.endTime=0.06", "mesh.blocks.0.cells=[24,8,16]"});
  mfsi::Simulation sim(cfg);
  sim.run(dir, false);
  const std::vector<std::string> files = frameFiles(dir);
  ASSERT_EQ(files.size(), 1u);
  const Hdf5File h5 = Hdf5File::openRead(dir + "/fields/" + files[0]);
  const std::vector<double> mesh = h5.readDoubles("/mesh/points");
  const std::vector<double> bodies = h5.readDoubles("/bodies/points");
  auto* membrane = findModule<mfsi::MembraneModule>(sim);
  ASSERT_NE(membrane, nullptr);
  const std::vector<double> points = h5.readDoubles("/" + membrane->name() + "/points");
  const std::vector<double> relative = h5.readDoubles("/" + membrane->name() + "/point/displacement");
  const auto& reference = membrane->solver().mesh().hostPoints();
  // Every panel point is a fluid mesh node (frame and membrane never gap), and the frame's motion
  // (it slides in x on its spring) is in the points but not in the frame-relative displacement.
  double maxFrameShift = 0;
  for (std::size_t i = 0; i < points.size() / 3; ++i) {
    bool onMesh = false;
    for (std::size_t j = 0; j < mesh.size() / 3 && !onMesh; ++j)
      onMesh = points[3 * i] == mesh[3 * j] && points[3 * i + 1] == mesh[3 * j + 1] &&
               points[3 * i + 2] == mesh[3 * j + 2];
    EXPECT_TRUE(onMesh) << "panel point " << i;
    maxFrameShift = std::max(maxFrameShift, std::abs(points[3 * i] - reference[i][0] - relative[3 * i]));
  }
  ASSERT_EQ(bodies.size(), 3u);
  EXPECT_GT(maxFrameShift, 1e-9) << "the frame has moved by t = 0.06 s";
}
