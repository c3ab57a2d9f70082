// Distributed smoothed-aggregation AMG on 4 ranks (tests/support/DistributedAmgChecks.hpp).
#include "core/parallel/Partition.hpp"
#include "support/DistributedAmgChecks.hpp"
#include "support/LocalParts.hpp"

using namespace mfsi;

namespace {
HexMeshInput box(std::array<int, 3> n) {
  BlockMeshSpec spec = boxSpec({0, 0, 0}, {1, 1, 1}, n);
  spec.blocks[0].patches[0] = "xmin";
  return generateBlockMesh(spec);
}
}  // namespace

TEST(DistributedAmg, MetisPartsGiveTheOneProcessAnswerWithinTwoIterations) {
  const HexMeshInput in = box({24, 24, 24});
  PartitionOptions opt;
  opt.parts = 4;
  const test::AmgComparison c = test::checkDistributedAmg(in, partitionCells(in, opt).cellRank);
  EXPECT_LE(c.many, c.one + 2);
  EXPECT_LE(c.one, 30);  // Jacobi-CG takes over 100 here
}

TEST(DistributedAmg, ARandomPartitionStillConverges) {
  // Every cell on a random rank: aggregates are single cells, the hierarchy is poor, the answer
  // must still be the same.
  const HexMeshInput in = box({12, 12, 12});
  test::checkDistributedAmg(in, test::randomPartition(in.cells.size(), 4));
}

TEST(DistributedAmg, ALargeGatheredCoarseLevelIsSolvedByItsOwnAmg) {
  const HexMeshInput in = box({24, 24, 24});
  PartitionOptions opt;
  opt.parts = 4;
  test::checkGatheredCoarseAmg(in, partitionCells(in, opt).cellRank);
}

TEST(DistributedAmg, CoarseLevelsMoveOntoFewerRanksAsTheyShrink) {
  // 24^3 cells: 13,824 rows, about 1,900 on the second level, 80 on the third.
  const HexMeshInput in = box({24, 24, 24});
  PartitionOptions opt;
  opt.parts = 4;
  test::checkCoarseLevelsMoveOntoFewerRanks(in, partitionCells(in, opt).cellRank, {4, 2, 1});
}

TEST(DistributedAmg, OverlappedExchangesGiveTheSameBits) {
  test::checkOverlapOnBox(box({24, 24, 24}), 4);
}
