// Effects composition: a module the scene does not name is never constructed and allocates nothing.
#include "coupling/Simulation.hpp"
#include "support/AllocationRecorder.hpp"

#include <gtest/gtest.h>

namespace {

const char* kMeshOnly = R"(
name: mesh-only
mesh:
  blocks:
    - {min: [0, 0, 0], max: [1, 1, 1], cells: [6, 5, 4]}
)";

}  // namespace

TEST(Effects, MeshOnlySceneBuildsNoModuleAndAllocatesOnlyCoreData) {
  mfsi::test::AllocationRecorder rec;
  const auto counts0 = mfsi::Module::constructionCounts();
  auto cfg = mfsi::SceneConfig::fromString(kMeshOnly, "mesh-only.yaml", mfsi::sceneSchema());
  mfsi::Simulation sim(cfg);
  EXPECT_TRUE(sim.modules().empty());
  EXPECT_EQ(mfsi::Module::constructionCounts(), counts0) << "a module was constructed for a mesh-only scene";
  // The recorder sees the mesh being built (so it works) ...
  EXPECT_GT(rec.countWithPrefix("mfsi::core::mesh::"), 5);
  EXPECT_GT(rec.countWithPrefix("mfsi::core::geometry::"), 3);
  // ... and nothing of any physics module.
  EXPECT_EQ(rec.countWithPrefix("mfsi::fluid::"), 0);
  EXPECT_EQ(rec.countWithPrefix("mfsi::structure::"), 0);
  EXPECT_EQ(rec.countWithPrefix("mfsi::coupling::"), 0);
  // Every allocation is labelled hierarchically.
  for (const auto& l : rec.all()) EXPECT_EQ(l.rfind("mfsi::", 0), 0u) << "unlabelled View '" << l << "'";
}

TEST(Effects, RigidOnlySceneBuildsOnlyTheBodiesModuleAndNoMesh) {
  const char* scene = R"(
time: {endTime: 0.01, dt: 0.001}
bodies:
  gravity: [0, -9.81, 0]
  members:
    bob: {mass: 2.0, joint: {type: Py}}
)";
  mfsi::test::AllocationRecorder rec;
  auto before = mfsi::Module::constructionCounts();
  auto cfg = mfsi::SceneConfig::fromString(scene, "rigid.yaml", mfsi::sceneSchema());
  mfsi::Simulation sim(cfg);
  auto after = mfsi::Module::constructionCounts();
  EXPECT_FALSE(sim.hasMesh());
  ASSERT_EQ(sim.modules().size(), 1u);
  EXPECT_EQ(sim.modules()[0]->name(), "bodies");
  EXPECT_EQ(after["bodies"], before["bodies"] + 1);
  after.erase("bodies");
  before.erase("bodies");
  EXPECT_EQ(after, before) << "a module other than 'bodies' was constructed";
  EXPECT_EQ(rec.countWithPrefix("mfsi::core::mesh::"), 0) << "a mesh was built for a scene without one";
  EXPECT_EQ(rec.countWithPrefix("mfsi::fluid::"), 0);
}
