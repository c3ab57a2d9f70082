// Conjugate gradients on 4 ranks (tests/support/DistributedLaplacian.hpp): the cell Laplacian of
// a box decomposed by METIS and by a random partition gives the one-process answer to 1e-10.
#include "core/parallel/Partition.hpp"
#include "support/DistributedLaplacian.hpp"
#include "support/LocalParts.hpp"

using namespace mfsi;

namespace {
/// A 24 x 12 x 6 box whose x = 0 side is the patch "xmin" (the Dirichlet side).
HexMeshInput box() {
  BlockMeshSpec spec = boxSpec({0, 0, 0}, {2, 1, 0.5}, {24, 12, 6});
  spec.blocks[0].patches[0] = "xmin";
  return generateBlockMesh(spec);
}
}  // namespace

TEST(DistributedCg, MetisPartsGiveTheWholeMeshAnswer) {
  const HexMeshInput in = box();
  PartitionOptions opt;
  opt.parts = 4;
  test::checkDistributedCg(in, partitionCells(in, opt).cellRank);
}

TEST(DistributedCg, ARandomPartitionGivesTheWholeMeshAnswer) {
  const HexMeshInput in = box();
  test::checkDistributedCg(in, test::randomPartition(in.cells.size(), 4));
}
