// A scene on 2 ranks: rank 0 alone reads and partitions the mesh, hands out the parts and frees
// it; the other rank never builds the whole mesh, and an error only rank 0 can find (in the mesh
// it reads) reaches both ranks with its message.
#include "support/SceneErrors.hpp"

#include <gtest/gtest.h>
#include <mpi.h>

#include <string>
#include <vector>

namespace {

const std::string kCavity = std::string(MFSI_CASES_DIR) + "/flexible-cavity.yaml";
const std::vector<std::string> kSmall = {"mesh.blocks.0.cells=[12,10,1]", "mesh.blocks.1.cells=[12,2,1]"};

int worldRank() {
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  return rank;
}

}  // namespace

TEST(SceneOnRanks, NoRankHoldsTheWholeMeshAfterSetUp) {
  const auto cfg = mfsi::SceneConfig::load(kCavity, mfsi::sceneSchema(), kSmall);
  const mfsi::Simulation sim(cfg);
  const int rank = worldRank();
  ASSERT_EQ(sim.ranks(), 2);
  EXPECT_EQ(sim.meshCounts().cells, 12 * 10 + 12 * 2) << "rank " << rank;
  EXPECT_EQ(sim.meshCounts().nodes, 13 * 13 * 2) << "rank " << rank;
  EXPECT_EQ(sim.mesh().nCells(), 0) << "rank " << rank << " (rank 0 frees the mesh it read)";
  ASSERT_EQ(sim.modules().size(), 1u) << "rank " << rank << ": the coupling, with its fluid and membrane";
  EXPECT_EQ(sim.modules()[0]->name(), "coupling");
}

TEST(SceneOnRanks, AMeshRankZeroCannotBuildStopsBothRanksWithItsMessage) {
  std::vector<std::string> sets = kSmall;
  sets[1] = "mesh.blocks.1.cells=[11,2,1]";
  const std::string e = mfsi::test::sceneInputError(kCavity, sets);
  EXPECT_NE(e.find("touch but their grids differ"), std::string::npos) << "rank " << worldRank() << ": " << e;
}
