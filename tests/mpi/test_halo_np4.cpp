// Halo exchange on 4 ranks (tests/support/HaloChecks.hpp): METIS on a long thin mesh with a
// baffle, a deliberately bad (random) partition, and the deterministic global sums; with them
// (from the header) the closed-chamber regions and a membrane cut on the parts.
#include "support/HaloChecks.hpp"

using namespace mfsi;

TEST(Halo, GlobalIdsSurviveTheExchangeMetis) {
  const HexMeshInput in = test::longBoxWithBaffle();
  test::checkExchange(in, partitionCells(in, test::keepPanelTogether(in, test::worldSize())).cellRank);
}

TEST(Halo, GlobalIdsSurviveTheExchangeBadPartition) {
  const HexMeshInput in = test::longBoxWithBaffle();
  test::checkExchange(in, test::randomPartition(in.cells.size(), test::worldSize()));
}

TEST(Halo, GlobalSumsAreExactAndTheSameOnEveryRank) {
  const HexMeshInput in = test::longBoxWithBaffle();
  test::checkGlobalSums(in, partitionCells(in, test::keepPanelTogether(in, test::worldSize())).cellRank);
}
