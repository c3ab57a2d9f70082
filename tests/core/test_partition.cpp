// Decomposition: METIS on the cell dual graph, cells kept together, and each rank's local mesh
// with its halo plans (checked here by carrying out every rank's exchange in one process; the MPI
// exchange itself is in tests/mpi/test_halo_np*.cpp).
#include "core/BlockMesh.hpp"
#include "core/Error.hpp"
#include "core/parallel/LocalMesh.hpp"
#include "core/parallel/MeshScatter.hpp"
#include "core/parallel/Partition.hpp"
#include "support/LocalParts.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <set>

using namespace mfsi;

namespace {

/// Global ids of a part's cells or nodes, on the host.
std::vector<mfsi::gid_t> hostIds(Kokkos::View<const mfsi::gid_t*, MemSpace> v) {
  auto h = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), v);
  return std::vector<mfsi::gid_t>(h.data(), h.data() + h.extent(0));
}

/// Carry out the exchange of every rank in one process: each ghost's value is the id its owner
/// sends for it. Checks that every ghost receives exactly its own global id.
void checkPlans(const std::vector<LocalMeshPart>& parts, bool nodes) {
  const int ranks = static_cast<int>(parts.size());
  std::vector<std::vector<mfsi::gid_t>> ids(ranks);
  for (int r = 0; r < ranks; ++r) ids[r] = nodes ? parts[r].input.nodeGlobalIds : parts[r].input.cellGlobalIds;
  for (int r = 0; r < ranks; ++r) {
    const HaloPlan& p = nodes ? parts[r].nodes : parts[r].cells;
    ASSERT_EQ(p.nLocal, static_cast<lid_t>(ids[r].size()));
    for (std::size_t k = 0; k < p.neighbours.size(); ++k) {
      const int s = p.neighbours[k];
      const HaloPlan& q = nodes ? parts[s].nodes : parts[s].cells;
      // What s sends to r, in order, must be r's ghosts from s.
      const auto it = std::find(q.neighbours.begin(), q.neighbours.end(), r);
      ASSERT_NE(it, q.neighbours.end()) << "rank " << s << " does not list rank " << r;
      const std::size_t j = it - q.neighbours.begin();
      const lid_t n = p.recvOffsets[k + 1] - p.recvOffsets[k];
      ASSERT_EQ(q.sendOffsets[j + 1] - q.sendOffsets[j], n);
      for (lid_t i = 0; i < n; ++i) {
        const lid_t sender = q.sendIndices[q.sendOffsets[j] + i];
        EXPECT_LT(sender, q.nOwned);
        EXPECT_EQ(ids[s][sender], ids[r][p.nOwned + p.recvOffsets[k] + i]);
      }
    }
  }
}

void checkParts(const HexMeshInput& in, const std::vector<int>& cellRank, int ranks) {
  const HexMesh global = buildHexMesh(in);
  std::vector<LocalMeshPart> parts;
  std::vector<int> ownedCount(global.nCells(), 0), ownedNodes(global.nNodes(), 0);
  MeshDecomposition decomposition(global, cellRank, ranks);
  for (int r = 0; r < ranks; ++r) {
    parts.push_back(decomposition.part(r));
    const HexMesh local = buildHexMesh(parts.back().input);  // a valid mesh of its own
    EXPECT_EQ(local.nOwnedCells(), parts.back().cells.nOwned);
    const auto cg = hostIds(local.cellGlobalIds());
    const auto ng = hostIds(local.nodeGlobalIds());
    for (lid_t c = 0; c < local.nOwnedCells(); ++c) {
      ++ownedCount[cg[c]];
      EXPECT_EQ(cellRank[cg[c]], r);
    }
    for (lid_t c = local.nOwnedCells(); c < local.nCells(); ++c) EXPECT_NE(cellRank[cg[c]], r);
    for (lid_t n = 0; n < local.nOwnedNodes(); ++n) ++ownedNodes[ng[n]];
    // Every patch keeps its name on every rank; the faces of the owned cells keep their patch.
    for (const auto& p : global.patches()) EXPECT_GE(local.findPatch(p.name), 0) << p.name;
  }
  for (lid_t c = 0; c < global.nCells(); ++c) EXPECT_EQ(ownedCount[c], 1) << "cell " << c;
  for (lid_t n = 0; n < global.nNodes(); ++n) EXPECT_EQ(ownedNodes[n], 1) << "node " << n;
  checkPlans(parts, false);
  checkPlans(parts, true);
}

}  // namespace

TEST(Partition, DualGraphHasOneEdgePerInternalFace) {
  const HexMeshInput in = generateBlockMesh(boxSpec({0, 0, 0}, {1, 1, 1}, {5, 4, 3}));
  const CellGraph g = cellDualGraph(in);
  // (5-1)*4*3 + 5*(4-1)*3 + 5*4*(3-1) = 48 + 45 + 40 internal faces, each seen from both cells.
  EXPECT_EQ(g.neighbours.size(), 2u * 133u);
}

TEST(Partition, MetisBalancesAndCutsLessThanSlabs) {
  const HexMeshInput in = generateBlockMesh(boxSpec({0, 0, 0}, {1, 1, 1}, {16, 16, 16}));
  PartitionOptions opt;
  opt.parts = 4;
  const Partition p = partitionCells(in, opt);
  ASSERT_EQ(p.cellsPerRank.size(), 4u);
  EXPECT_LE(p.imbalance, 1.03);
  // Four slabs along x cut 3 * 16 * 16 = 768 faces, 2 x 2 columns 512; METIS's k-way answer (572
  // here) lies between.
  EXPECT_LT(p.edgeCut, 768);
  EXPECT_GT(p.edgeCut, 0);
  // Deterministic: the same answer again.
  EXPECT_EQ(partitionCells(in, opt).cellRank, p.cellRank);
}

TEST(Partition, KeepsGroupsOnOneRank) {
  const HexMeshInput in = generateBlockMesh(boxSpec({0, 0, 0}, {1, 1, 0.1}, {20, 20, 1}));
  PartitionOptions opt;
  opt.parts = 4;
  // The bottom row of cells (a membrane's wall) and a diagonal of scattered cells.
  std::vector<lid_t> row, diagonal;
  for (lid_t i = 0; i < 20; ++i) {
    row.push_back(i);
    diagonal.push_back(i * 20 + i);
  }
  opt.keepTogether = {row, diagonal};
  const Partition p = partitionCells(in, opt);
  for (const auto& g : opt.keepTogether)
    for (lid_t c : g) EXPECT_EQ(p.cellRank[c], p.cellRank[g[0]]);
  EXPECT_LE(p.imbalance, 1.25);
}

TEST(Partition, RefusesMoreRanksThanCells) {
  const HexMeshInput in = generateBlockMesh(boxSpec({0, 0, 0}, {1, 1, 1}, {2, 1, 1}));
  PartitionOptions opt;
  opt.parts = 3;
  try {
    partitionCells(in, opt);
    FAIL() << "3 ranks for 2 cells accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("use at most 2 ranks"), std::string::npos) << e.what();
  }
}

TEST(LocalMesh, MetisPartsOwnEverythingOnceAndTheirPlansMatch) {
  const HexMeshInput in = test::longBoxWithBaffle();
  for (int ranks : {2, 3, 4}) {
    const Partition p = partitionCells(in, test::keepPanelTogether(in, ranks));
    checkParts(in, p.cellRank, ranks);
  }
}

TEST(LocalMesh, ABadPartitionStillGivesConsistentPlans) {
  const HexMeshInput in = test::longBoxWithBaffle();
  checkParts(in, test::randomPartition(in.cells.size(), 4), 4);
}

TEST(LocalMesh, ADecompositionGivesEachPartAloneInAnyOrder) {
  // Each part reuses the decomposition's scratch maps: a part must not see what an earlier one
  // left there (a baffle face is kept only when the cells on both sides are the part's).
  const HexMeshInput in = test::longBoxWithBaffle();
  const HexMesh global = buildHexMesh(in);
  const std::vector<int> cellRank = test::randomPartition(in.cells.size(), 4);
  MeshDecomposition decomposition(global, cellRank, 4, 2);
  std::vector<std::vector<char>> forward, backward(4);
  for (int r = 0; r < 4; ++r) forward.push_back(packPart(decomposition.part(r)));
  for (int r = 3; r >= 0; --r) backward[r] = packPart(decomposition.part(r));
  for (int r = 0; r < 4; ++r) {
    EXPECT_EQ(forward[r], backward[r]) << "rank " << r;
    EXPECT_EQ(forward[r], packPart(localMeshPart(global, cellRank, 4, r, 2))) << "rank " << r;
  }
  std::size_t baffleFaces = 0;
  for (int r = 0; r < 4; ++r)
    for (const auto& b : unpackPart(forward[r]).input.baffles) baffleFaces += b.faces.size();
  EXPECT_GT(baffleFaces, 0u) << "some baffle faces lie with both cells on one rank";
  EXPECT_THROW(decomposition.part(4), InputError);
}

TEST(LocalMesh, OneRankIsTheWholeMeshWithoutGhosts) {
  const HexMeshInput in = test::longBoxWithBaffle();
  const HexMesh global = buildHexMesh(in);
  const LocalMeshPart part = localMeshPart(global, std::vector<int>(global.nCells(), 0), 1, 0);
  EXPECT_EQ(part.cells.nOwned, global.nCells());
  EXPECT_EQ(part.cells.nLocal, global.nCells());
  EXPECT_TRUE(part.cells.neighbours.empty());
  const HexMesh local = buildHexMesh(part.input);
  EXPECT_EQ(local.nInternalFaces(), global.nInternalFaces());
  EXPECT_EQ(local.patches().size(), global.patches().size());
}

TEST(LocalMesh, NamesAnOwnedNodeWhoseEdgesLieInCellsThePartLacks) {
  // Two unit cubes that touch at one corner, the node (1, 1, 1): on 2 ranks, one cube each, no
  // face joins them, so neither part holds the other cube, and the corner's three edges in it
  // are missing from the rank that owns the corner (rank 0, the lower).
  HexMeshInput in;
  in.source = "two cubes meeting at a corner";
  auto cube = [&](double o) {
    std::array<lid_t, 8> c;
    const double x[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
    for (int k = 0; k < 8; ++k) {
      const std::array<real, 3> p = {x[k][0] + o, x[k][1] + o, x[k][2] + o};
      auto it = std::find(in.points.begin(), in.points.end(), p);
      c[k] = static_cast<lid_t>(it - in.points.begin());
      if (it == in.points.end()) in.points.push_back(p);
    }
    in.cells.push_back(c);
  };
  cube(0);
  cube(1);
  const HexMesh global = buildHexMesh(in);
  ASSERT_EQ(global.nNodes(), 15);
  const LocalMeshPart zero = localMeshPart(global, {0, 1}, 2, 0), one = localMeshPart(global, {0, 1}, 2, 1);
  EXPECT_EQ(zero.incompleteNode, 6) << "the shared corner, owned by rank 0";
  EXPECT_EQ(one.incompleteNode, -1) << "rank 1 owns only its own cube's other nodes";
  // A box's parts are complete, even under a random partition (without a baffle: cells across a
  // baffle share nodes but no face, which is why a baffle's cells stay on one rank).
  const HexMeshInput box = generateBlockMesh(boxSpec({0, 0, 0}, {1, 1, 1}, {6, 5, 4}));
  const HexMesh boxMesh = buildHexMesh(box);
  const std::vector<int> random = test::randomPartition(box.cells.size(), 4);
  for (int r = 0; r < 4; ++r) EXPECT_EQ(localMeshPart(boxMesh, random, 4, r).incompleteNode, -1) << "rank " << r;
}

TEST(Partition, BuiltMeshGraphEqualsTheInputGraph) {
  // Baffle faces are boundary faces of the built mesh; its graph joins their two cells all the same.
  const HexMeshInput in = test::longBoxWithBaffle();
  const CellGraph a = cellDualGraph(in), b = cellDualGraph(buildHexMesh(in));
  EXPECT_EQ(a.offsets, b.offsets);
  EXPECT_EQ(a.neighbours, b.neighbours);
}

