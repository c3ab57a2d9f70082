// Distributed smoothed-aggregation AMG on 2 ranks (tests/support/DistributedAmgChecks.hpp).
#include "core/parallel/Partition.hpp"
#include "support/DistributedAmgChecks.hpp"
#include "support/LocalParts.hpp"

#include <algorithm>
#include <cstdio>
#include <random>

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
  opt.parts = 2;
  const test::AmgComparison c = test::checkDistributedAmg(in, partitionCells(in, opt).cellRank);
  EXPECT_LE(c.many, c.one + 2);
  EXPECT_LE(c.one, 30);  // Jacobi-CG takes over 100 here
}

TEST(DistributedAmg, ARandomPartitionStillConverges) {
  // Every cell on a random rank: aggregates are single cells, the hierarchy is poor, the answer
  // must still be the same.
  const HexMeshInput in = box({12, 12, 12});
  test::checkDistributedAmg(in, test::randomPartition(in.cells.size(), 2));
}

TEST(DistributedAmg, ALargeGatheredCoarseLevelIsSolvedByItsOwnAmg) {
  const HexMeshInput in = box({24, 24, 24});
  PartitionOptions opt;
  opt.parts = 2;
  test::checkGatheredCoarseAmg(in, partitionCells(in, opt).cellRank);
}

TEST(DistributedAmg, LatticeCubesPerRankKeepTheOneProcessIterations) {
  // A box numbered x fastest is a lattice: 2x2x2 cubes, then 3x3x3, each cut where METIS cuts.
  // Greedy aggregates on the same parts need more iterations (at 64^3 on 2 ranks: 13 against 9).
  const HexMeshInput in = box({32, 32, 32});
  PartitionOptions opt;
  opt.parts = 2;
  const std::vector<int> parts = partitionCells(in, opt).cellRank;
  const test::AmgComparison lattice = test::checkDistributedAmg(in, parts);
  EXPECT_LE(lattice.many, lattice.one + 1);
  DistributedAmgOptions greedy;
  greedy.latticeAggregation = false;
  const test::AmgComparison greedily = test::checkDistributedAmg(in, parts, greedy);
  EXPECT_EQ(greedily.one, lattice.one);
  EXPECT_GE(greedily.many, lattice.many + 2);
  EXPECT_FALSE(greedily.levels[0].lattice);
  // The hierarchy: the finest level and the next aggregated into cubes; about 32^3 / 8 (plus the
  // cubes the cut splits) rows on level 1.
  ASSERT_GE(lattice.levels.size(), 3u);
  EXPECT_TRUE(lattice.levels[0].lattice);
  EXPECT_TRUE(lattice.levels[1].lattice);
  EXPECT_GE(lattice.levels[1].rows, 4096);
  EXPECT_LE(lattice.levels[1].rows, 4096 + 600);
}

TEST(DistributedAmg, CellsOutOfLatticeOrderAreAggregatedGreedily) {
  // The same box with its cells in a shuffled order: no longer a lattice by its ids.
  HexMeshInput in = box({12, 12, 12});
  std::mt19937 rng(7);
  std::shuffle(in.cells.begin(), in.cells.end(), rng);
  PartitionOptions opt;
  opt.parts = 2;
  const std::vector<int> parts = partitionCells(in, opt).cellRank;
  EXPECT_FALSE(test::checkDistributedAmg(in, parts).levels[0].lattice);
}

TEST(DistributedAmg, TheFloatCycleTakesTheIterationsOfTheDoubleOne) {
  // The default V-cycle runs in float; rounding it must not cost CG iterations, and both reach the
  // one-process answer (checked inside to 1e-9 relative).
  const HexMeshInput in = box({24, 24, 24});
  PartitionOptions opt;
  opt.parts = 2;
  const std::vector<int> parts = partitionCells(in, opt).cellRank;
  DistributedAmgOptions inDouble;
  inDouble.mixedPrecision = false;
  const test::AmgComparison withFloat = test::checkDistributedAmg(in, parts);
  const test::AmgComparison withDouble = test::checkDistributedAmg(in, parts, inDouble);
  EXPECT_LE(std::abs(withFloat.many - withDouble.many), 1);
  // After set-up the hierarchy holds what its cycle uses, in the cycle's precision: a float cycle
  // about two thirds of a double one's bytes (the sparsity is shared; values, inverse diagonals
  // and work vectors halve). It held more than the double cycle while it kept the set-up's
  // double matrices and vectors beside the float copies.
  const double perRow = static_cast<double>(withFloat.bytes) / withFloat.levels.front().ownedRows;
  std::printf("distributed AMG on this rank: float cycle %zu bytes (%.0f per fine row), double %zu\n",
              withFloat.bytes, perRow, withDouble.bytes);
  EXPECT_LT(static_cast<double>(withFloat.bytes), 0.7 * static_cast<double>(withDouble.bytes));
  EXPECT_GT(static_cast<double>(withFloat.bytes), 0.5 * static_cast<double>(withDouble.bytes));
}

TEST(DistributedAmg, CoarseLevelsMoveOntoFewerRanksAsTheyShrink) {
  // 24^3 cells: 13,824 rows, about 1,900 on the second level, 80 on the third.
  const HexMeshInput in = box({24, 24, 24});
  PartitionOptions opt;
  opt.parts = 2;
  test::checkCoarseLevelsMoveOntoFewerRanks(in, partitionCells(in, opt).cellRank, {2, 2, 1});
}

TEST(DistributedAmg, OverlappedExchangesGiveTheSameBits) {
  test::checkOverlapOnBox(box({24, 24, 24}), 2);
}
