#pragma once
/// \file
/// \brief The MPI halo tests, shared by tests/mpi/test_halo_np2.cpp and _np4.cpp: a field of
/// global ids survives an exchange exactly, under METIS and under a deliberately bad partition,
/// and global sums are bitwise the same on every rank.
#include "core/Error.hpp"
#include "core/parallel/Halo.hpp"
#include "core/parallel/LocalMesh.hpp"
#include "core/parallel/Partition.hpp"
#include "core/MeshRegions.hpp"
#include "structure/membrane/MembraneOnRanks.hpp"
#include "kernels/Blas.hpp"
#include "support/LocalParts.hpp"

#include <gtest/gtest.h>
#include <mpi.h>

#include <cmath>

namespace mfsi::test {

inline int worldRank() {
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}
inline int worldSize() {
  int s = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &s);
  return s;
}

/// Ghosts start at -1; after one exchange every entry must hold its global id (and its id + 0.25
/// and a third column for the 3-column exchange).
inline void checkExchange(const HexMeshInput& in, const std::vector<int>& cellRank) {
  const int ranks = worldSize(), rank = worldRank();
  const HexMesh global = buildHexMesh(in);
  const LocalMeshPart part = localMeshPart(global, cellRank, ranks, rank);
  const HexMesh local = buildHexMesh(part.input);
  for (const bool nodes : {false, true}) {
    const HaloPlan& plan = nodes ? part.nodes : part.cells;
    const Halo halo(MPI_COMM_WORLD, plan);
    const auto gid = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(),
                                                         nodes ? local.nodeGlobalIds() : local.cellGlobalIds());
    RealView x("x", plan.nLocal);
    Real3View x3("x3", plan.nLocal);
    auto hx = Kokkos::create_mirror_view(x);
    auto hx3 = Kokkos::create_mirror_view(x3);
    for (lid_t i = 0; i < plan.nLocal; ++i) {
      const bool owned = i < plan.nOwned;
      hx(i) = owned ? static_cast<double>(gid(i)) : -1.0;
      for (int k = 0; k < 3; ++k) hx3(i, k) = owned ? static_cast<double>(gid(i)) + 0.25 * k : -1.0;
    }
    Kokkos::deep_copy(x, hx);
    Kokkos::deep_copy(x3, hx3);
    const ExecSpace exec;
    halo.exchange(exec, x);
    halo.exchange(exec, x3);
    halo.exchange(exec, x);  // the persistent requests run again
    // In two halves: the ghosts arrive at `end`; a second `begin` before it is refused.
    Kokkos::deep_copy(hx, x);
    for (lid_t i = plan.nOwned; i < plan.nLocal; ++i) hx(i) = -1.0;
    Kokkos::deep_copy(x, hx);
    halo.begin(exec, x);
    if (halo.neighbours() > 0) {
      EXPECT_THROW(halo.begin(exec, x), InputError);
    }
    halo.end(exec, x);
    Kokkos::deep_copy(hx, x);
    Kokkos::deep_copy(hx3, x3);
    int bad = 0;
    for (lid_t i = 0; i < plan.nLocal; ++i) {
      bad += hx(i) != static_cast<double>(gid(i));
      for (int k = 0; k < 3; ++k) bad += hx3(i, k) != static_cast<double>(gid(i)) + 0.25 * k;
    }
    EXPECT_EQ(bad, 0) << "rank " << rank << (nodes ? " nodes" : " cells") << ": " << bad << " wrong entries of "
                      << plan.nLocal;
    int ghosts = plan.nLocal - plan.nOwned, anyGhosts = 0;
    MPI_Allreduce(&ghosts, &anyGhosts, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
    EXPECT_GT(anyGhosts, 0);
  }
}

/// The owned cells' ids summed through SolverComm: the exact global sum n(n-1)/2 on every rank,
/// and the same bits on every rank for a sum that rounds.
inline void checkGlobalSums(const HexMeshInput& in, const std::vector<int>& cellRank) {
  const int ranks = worldSize(), rank = worldRank();
  const HexMesh global = buildHexMesh(in);
  const LocalMeshPart part = localMeshPart(global, cellRank, ranks, rank);
  const SolverComm comm(MPI_COMM_WORLD, nullptr);
  EXPECT_EQ(comm.ranks(), ranks);
  double s[2] = {0, 0};
  for (lid_t c = 0; c < part.cells.nOwned; ++c) {
    const double id = static_cast<double>(part.input.cellGlobalIds[c]);
    s[0] += id;
    s[1] += std::sqrt(id + 0.1);
  }
  comm.globalSum(s, 2);
  const double n = static_cast<double>(global.nCells());
  EXPECT_EQ(s[0], n * (n - 1) / 2);
  double root[2] = {s[0], s[1]};
  MPI_Bcast(root, 2, MPI_DOUBLE, 0, MPI_COMM_WORLD);
  EXPECT_EQ(root[1], s[1]) << "rank " << rank << " summed differently from rank 0";
  EXPECT_EQ(comm.globalMax(static_cast<double>(rank)), static_cast<double>(ranks - 1));
}


/// The fluid regions (core/MeshRegions) of longBoxWithBaffle("outlet") under `cellRank`,
/// found on each rank's part: the whole mesh's two regions (the baffle spans the box), the left one
/// closed, numbered alike on every rank, for every cell a rank holds (owned and ghost).
inline void checkChamberRegions(const HexMeshInput& in, const std::vector<int>& cellRank) {
  const int ranks = worldSize(), rank = worldRank();
  const HexMesh global = buildHexMesh(in);
  const MeshRegions one = findMeshRegions(global, {"outlet"});
  ASSERT_EQ(one.count, 2);
  EXPECT_EQ(one.closed, (std::vector<char>{1, 0})) << "the left region (cell 0's) has no outlet";
  const LocalMeshPart part = localMeshPart(global, cellRank, ranks, rank);
  const HexMesh local = buildHexMesh(part.input);
  const MeshRegions many = findMeshRegions(local, {"outlet"}, worldDomain(part));
  EXPECT_EQ(many.count, 2) << "rank " << rank;
  EXPECT_EQ(many.closed, one.closed) << "rank " << rank;
  EXPECT_EQ(many.firstCell, one.firstCell) << "rank " << rank;
  auto gid = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), local.cellGlobalIds());
  int wrong = 0;
  for (lid_t c = 0; c < local.nCells(); ++c)
    wrong += many.cellRegion[static_cast<std::size_t>(c)] != one.cellRegion[static_cast<std::size_t>(gid(c))];
  EXPECT_EQ(wrong, 0) << "rank " << rank << ": cells in another region than on the whole mesh";
}


/// The membrane on longBoxWithBaffle's panel cut from the ranks' parts under `cellRank` (which
/// keeps the panel's cells on one rank): every rank gets the whole mesh's surface, bit for bit.
inline void checkMembraneOnRanks(const HexMeshInput& in, const std::vector<int>& cellRank) {
  const int ranks = worldSize(), rank = worldRank();
  const HexMesh global = buildHexMesh(in);
  const FluidSurfaceMembraneInput one = membraneMeshFromBaffle(global, "panel");
  ASSERT_GT(one.nElements(), 0);
  const LocalMeshPart part = localMeshPart(global, cellRank, ranks, rank);
  const HexMesh local = buildHexMesh(part.input);
  const FluidSurfaceMembraneInput many = cutMembraneOnRanks(local, {"panel", true}, MPI_COMM_WORLD);
  EXPECT_EQ(many.mesh.points, one.mesh.points) << "rank " << rank;
  EXPECT_EQ(many.mesh.elements, one.mesh.elements) << "rank " << rank;
  EXPECT_EQ(many.mesh.nodeSets, one.mesh.nodeSets) << "rank " << rank;
  EXPECT_EQ(many.fluidNode, one.fluidNode) << "rank " << rank;
  EXPECT_EQ(many.masterFaceNodes, one.masterFaceNodes) << "rank " << rank;
  EXPECT_EQ(many.slaveFaceNodes, one.slaveFaceNodes) << "rank " << rank;
  // The faces by index only where it was cut: the rank that owns the panel's cells.
  int cutHere = many.masterFace.empty() ? 0 : 1, cuts = 0;
  MPI_Allreduce(&cutHere, &cuts, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_EQ(cuts, 1);
}

/// A partition that splits the panel's cells over ranks: the same InputError on every rank.
inline void checkMembraneSplitOverRanks(const HexMeshInput& in, const std::vector<int>& cellRank) {
  const HexMesh global = buildHexMesh(in);
  const LocalMeshPart part = localMeshPart(global, cellRank, worldSize(), worldRank());
  const HexMesh local = buildHexMesh(part.input);
  try {
    cutMembraneOnRanks(local, {"panel", true}, MPI_COMM_WORLD);
    ADD_FAILURE() << "rank " << worldRank() << ": a panel split over ranks was cut";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("baffle 'panel' are owned by ranks"), std::string::npos) << e.what();
  }
}

}  // namespace mfsi::test

TEST(ChamberRegions, TheWholeMeshsRegionsOnEveryPart) {
  using namespace mfsi;
  const HexMeshInput in = test::longBoxWithBaffle("outlet");
  test::checkChamberRegions(in, partitionCells(in, test::keepPanelTogether(in, test::worldSize())).cellRank);
  test::checkChamberRegions(in, test::randomPartition(in.cells.size(), test::worldSize()));
}

TEST(MembraneOnRanks, TheOwnerCutsTheWholeMeshsSurfaceForEveryRank) {
  using namespace mfsi;
  const HexMeshInput in = test::longBoxWithBaffle();
  test::checkMembraneOnRanks(in, partitionCells(in, test::keepPanelTogether(in, test::worldSize())).cellRank);
  test::checkMembraneSplitOverRanks(in, test::randomPartition(in.cells.size(), test::worldSize()));
}
