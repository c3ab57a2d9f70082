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
