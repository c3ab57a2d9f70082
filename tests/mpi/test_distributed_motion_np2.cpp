// Mesh motion on 2 ranks: the cases of tests/support/DistributedMotionTests.hpp.
constexpr int kRanks = 2;
#include "support/DistributedMotionTests.hpp"

namespace {

/// A 2 x 2 x 2 box whose bottom (y = 0) slides, but for one quarter of it, the face under the
/// cell at x, z > 1/2, which is a wall (prescribed).
mfsi::HexMeshInput boxWithAFixedQuarter() {
  using namespace mfsi;
  BlockMeshSpec spec = boxSpec({0, 0, 0}, {1, 1, 1}, {2, 2, 2});
  spec.blocks[0].patches = {"rest", "rest", "bottom", "rest", "rest", "rest"};
  spec.patchKinds = {{"rest", PatchKind::Wall}, {"bottom", PatchKind::Wall}};
  HexMeshInput in = generateBlockMesh(spec);
  for (auto& p : in.patches) {
    if (p.name != "bottom") continue;
    for (std::size_t f = 0; f < p.faces.size(); ++f) {
      bool quarter = true;
      for (lid_t v : p.faces[f]) quarter = quarter && in.points[v][0] > 0.25 && in.points[v][2] > 0.25;
      if (!quarter) continue;
      const std::array<lid_t, 4> face = p.faces[f];
      p.faces.erase(p.faces.begin() + static_cast<std::ptrdiff_t>(f));
      in.patches.push_back({"foot", PatchKind::Wall, {face}});  // after the erase: p is invalid now
      return in;
    }
  }
  return in;
}

}  // namespace

TEST(DistributedMotion, ACopyOfANodeTellsItsOwnerOfAFaceTheOwnerLacks) {
  // The cells at x, z < 1/2 on rank 0, the rest on rank 1. The bottom's centre node is rank 0's
  // (the lower rank), but the wall face at it belongs to the cell diagonally across, which meets
  // rank 0's cells at that node's edge alone and is not in rank 0's part: only rank 1 sees it.
  // The node must be prescribed on both ranks, as on the whole mesh (a rank that slid it would
  // pull the wall's corner along the bottom).
  using namespace mfsi;
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  const HexMeshInput in = boxWithAFixedQuarter();
  const HexMesh whole = buildHexMesh(in);
  ASSERT_GE(whole.findPatch("foot"), 0);
  std::vector<int> cellRank;
  for (const auto& c : in.cells) {
    double x = 0, z = 0;
    for (lid_t v : c) {
      x += in.points[v][0] / 8;
      z += in.points[v][2] / 8;
    }
    cellRank.push_back(x < 0.5 && z < 0.5 ? 0 : 1);
  }
  const LocalMeshPart part = localMeshPart(whole, cellRank, 2, rank);
  const RankDomain domain = test::worldDomain(part);
  const HexMesh local = buildHexMesh(part.input);
  coupling::MeshSmootherOptions o = test::jacobiMotion();
  o.slidingPatches = {"bottom"};
  const coupling::MeshSmoother one(whole, o), many(local, o, domain);
  auto a = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), one.prescribed());
  auto b = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), many.prescribed());
  auto gid = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), local.nodeGlobalIds());
  auto X = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), local.referencePoints());
  int centre = 0, differ = 0;
  for (lid_t i = 0; i < local.nNodes(); ++i) {
    differ += a(gid(i)) != b(i) ? 1 : 0;
    if (std::abs(X(i, 0) - 0.5) + std::abs(X(i, 1)) + std::abs(X(i, 2) - 0.5) < 1e-12) {
      ++centre;
      EXPECT_EQ(b(i), 1) << "rank " << rank << ": the bottom's centre node";
      EXPECT_EQ(i < part.nodes.nOwned, rank == 0) << "rank 0 owns the centre node";
    }
  }
  EXPECT_EQ(centre, 1) << "rank " << rank;
  EXPECT_EQ(differ, 0) << "rank " << rank << ": nodes prescribed otherwise than on the whole mesh";
}
