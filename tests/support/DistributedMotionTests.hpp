#pragma once
/// \file
/// \brief The distributed mesh-motion tests, for the rank count `kRanks` that the including file
/// (tests/mpi/test_distributed_motion_np<N>.cpp) defines. A box whose bottom bulges up by 15 % of
/// its height in three moves, its top fixed and its four sides sliding, is smoothed on every rank's
/// part (coupling::MeshSmoother on a RankDomain) and on the whole mesh in one process: the owned
/// nodes' positions (gathered by global id) agree, the minimum scaled Jacobian is the same on every
/// rank, and a repeat on the same ranks gives the same bits. Jacobi sweeps and CG (Jacobi- and
/// AMG-preconditioned), under METIS and under a random partition (nearly every node a ghost
/// somewhere). With columns above the bottom, which cross the ranks, the same.
#include "core/BlockMesh.hpp"
#include "core/parallel/LocalMesh.hpp"
#include "core/parallel/Partition.hpp"
#include "coupling/motion/MeshSmoother.hpp"
#include "support/LocalParts.hpp"

#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <vector>

namespace mfsi::test {

inline HexMeshInput bulgingBox(int n) {
  BlockMeshSpec spec = boxSpec({0, 0, 0}, {1, 1, 1}, {n, n, n});
  spec.blocks[0].patches = {"sides", "sides", "bottom", "top", "sides", "sides"};
  spec.patchKinds = {{"sides", PatchKind::Wall}, {"bottom", PatchKind::Wall}, {"top", PatchKind::Wall}};
  return generateBlockMesh(spec);
}

struct MotionRun {
  std::map<gid_t, std::array<double, 3>> nodes;  ///< owned nodes' positions by global id
  double minScaledJacobian = 0;
  int iterations = 0;
  lid_t columns = 0;  ///< with columns: how many (on all ranks)
};

/// The bottom's nodes of a whole mesh, by global id (its index), and their positions: with
/// columns, the feet.
struct BottomNodes {
  std::vector<gid_t> ids;
  std::vector<std::array<double, 3>> points;
};

inline BottomNodes bottomNodes(const HexMesh& whole) {
  auto X = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), whole.referencePoints());
  BottomNodes b;
  for (lid_t i = 0; i < whole.nNodes(); ++i)
    if (std::abs(X(i, 1)) < 1e-12) {
      b.ids.push_back(i);
      b.points.push_back({X(i, 0), X(i, 1), X(i, 2)});
    }
  return b;
}

/// Three moves of the bottom (u_y = a sin(pi x) sin(pi z), a = 0.05, 0.10, 0.15) on `mesh` (a
/// rank's part when `domain` is distributed); with o.columns, columns above the bottom's nodes.
inline MotionRun runMotion(HexMesh& mesh, const coupling::MeshSmootherOptions& o, const RankDomain& domain,
                           const BottomNodes& feet = {}) {
  auto smoother = domain.distributed() ? std::make_unique<coupling::MeshSmoother>(mesh, o, domain)
                                       : std::make_unique<coupling::MeshSmoother>(mesh, o);
  const double pi = 3.14159265358979323846;
  auto bump = [pi](int move, double x, double z) { return 0.05 * move * std::sin(pi * x) * std::sin(pi * z); };
  auto X = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.referencePoints());
  MotionRun run;
  run.columns = smoother->setColumnFeet(feet.ids);
  for (int move = 1; move <= 3; ++move) {
    auto d = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), smoother->displacement());
    for (lid_t i = 0; i < mesh.nNodes(); ++i)
      if (std::abs(X(i, 1)) < 1e-12) d(i, 1) = bump(move, X(i, 0), X(i, 2));
    Kokkos::deep_copy(smoother->displacement(), d);
    if (run.columns > 0) {  // every foot's row, on every rank
      auto f = Kokkos::create_mirror_view(smoother->columnFeet());
      for (std::size_t j = 0; j < feet.ids.size(); ++j) {
        f(j, 0) = f(j, 2) = 0;
        f(j, 1) = bump(move, feet.points[j][0], feet.points[j][2]);
      }
      Kokkos::deep_copy(smoother->columnFeet(), f);
    }
    const coupling::MotionReport r = smoother->move(ExecSpace());
    run.minScaledJacobian = r.minScaledJacobian;
    run.iterations += r.sweeps;
  }
  Kokkos::fence();
  auto x = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.points());
  auto gid = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.nodeGlobalIds());
  const lid_t owned = domain.distributed() ? mesh.nOwnedNodes() : mesh.nNodes();
  for (lid_t i = 0; i < owned; ++i) run.nodes[gid(i)] = {x(i, 0), x(i, 1), x(i, 2)};
  return run;
}

/// The motion on this rank's part under `cellRank` against the whole mesh's: node positions to
/// `tol` (absolute; the bulge is 0.15), the same minimum scaled Jacobian on every rank (to `tol`
/// of the one-process value), every node owned once, and a repeat on the same ranks bitwise.
inline void checkDistributedMotion(const HexMeshInput& in, const std::vector<int>& cellRank,
                                   const coupling::MeshSmootherOptions& o, double tol) {
  int ranks = 1, rank = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  HexMesh global = buildHexMesh(in);
  const HexMesh whole = buildHexMesh(in);  // the unmoved whole mesh, to cut the parts from
  const BottomNodes feet = o.columns ? bottomNodes(whole) : BottomNodes{};
  const MotionRun one = runMotion(global, o, RankDomain{}, feet);
  ASSERT_GT(one.minScaledJacobian, 0.3);  // a real deformation, not a trivial one
  const LocalMeshPart part = localMeshPart(whole, cellRank, ranks, rank);
  const RankDomain domain = worldDomain(part);
  HexMesh local = buildHexMesh(part.input);
  const MotionRun many = runMotion(local, o, domain, feet);
  HexMesh again = buildHexMesh(part.input);
  const MotionRun repeat = runMotion(again, o, domain, feet);
  EXPECT_EQ(many.columns, one.columns) << "rank " << rank;
  EXPECT_NEAR(many.minScaledJacobian, one.minScaledJacobian, tol * one.minScaledJacobian);
  double lo = many.minScaledJacobian, hi = many.minScaledJacobian;
  MPI_Allreduce(MPI_IN_PLACE, &lo, 1, MPI_DOUBLE, MPI_MIN, MPI_COMM_WORLD);
  MPI_Allreduce(MPI_IN_PLACE, &hi, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  EXPECT_EQ(lo, hi) << "the quality guard must see one value on every rank";
  double worst = 0;
  std::size_t bitwise = 0;
  for (const auto& [g, p] : many.nodes) {
    const auto& q = one.nodes.at(g);
    for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(p[c] - q[c]));
    bitwise += repeat.nodes.at(g) == p ? 1 : 0;
  }
  EXPECT_LE(worst, tol) << "rank " << rank << ": owned node positions against one process";
  EXPECT_EQ(bitwise, many.nodes.size()) << "rank " << rank << ": a repeat on the same ranks differs";
  long long owned = static_cast<long long>(many.nodes.size());
  MPI_Allreduce(MPI_IN_PLACE, &owned, 1, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_EQ(owned, static_cast<long long>(one.nodes.size()));
  if (rank == 0)
    std::printf("[ motion ] %d ranks: largest node difference %.2e, min scaled Jacobian %.6f, %d / %d iterations\n",
                ranks, worst, many.minScaledJacobian, one.iterations, many.iterations);
}

inline coupling::MeshSmootherOptions jacobiMotion() {
  coupling::MeshSmootherOptions o;
  o.method = coupling::MeshMotionMethod::Jacobi;
  o.sweeps = 30;
  o.retries = 0;
  o.minScaledJacobian = 0;
  o.slidingPatches = {"sides"};
  return o;
}

inline coupling::MeshSmootherOptions cgMotion(LaplacianPreconditioner pc) {
  coupling::MeshSmootherOptions o;
  o.method = coupling::MeshMotionMethod::ConjugateGradient;
  o.relTol = 1e-13;
  o.preconditioner = pc;
  o.slidingPatches = {"sides"};
  return o;
}

}  // namespace mfsi::test

TEST(DistributedMotion, ColumnsCrossRanksOnMetisParts) {
  // Columns from the bottom's interior nodes up to the top: the lines are handed from rank to
  // rank, and every one of the n - 1 by n - 1 is found on the parts as on the whole mesh.
  const mfsi::HexMeshInput in = mfsi::test::bulgingBox(8);
  mfsi::coupling::MeshSmootherOptions o = mfsi::test::jacobiMotion();
  o.columns = true;
  mfsi::test::checkDistributedMotion(in, mfsi::test::metisParts(in, kRanks), o, 1e-14);
  mfsi::HexMesh whole = mfsi::buildHexMesh(in);
  EXPECT_EQ(mfsi::test::runMotion(whole, o, mfsi::RankDomain{}, mfsi::test::bottomNodes(whole)).columns, 7 * 7);
}

TEST(DistributedMotion, ColumnsCrossRanksOnARandomPartition) {
  const mfsi::HexMeshInput in = mfsi::test::bulgingBox(6);
  mfsi::coupling::MeshSmootherOptions o = mfsi::test::cgMotion(mfsi::LaplacianPreconditioner::Amg);
  o.columns = true;
  mfsi::test::checkDistributedMotion(in, mfsi::test::randomPartition(in.cells.size(), kRanks), o, 1e-11);
}

TEST(DistributedMotion, JacobiSweepsOnMetisParts) {
  const mfsi::HexMeshInput in = mfsi::test::bulgingBox(8);
  mfsi::test::checkDistributedMotion(in, mfsi::test::metisParts(in, kRanks), mfsi::test::jacobiMotion(), 1e-14);
}

TEST(DistributedMotion, JacobiSweepsOnARandomPartition) {
  const mfsi::HexMeshInput in = mfsi::test::bulgingBox(6);
  mfsi::test::checkDistributedMotion(in, mfsi::test::randomPartition(in.cells.size(), kRanks),
                                     mfsi::test::jacobiMotion(), 1e-14);
}

TEST(DistributedMotion, CgWithJacobiOnMetisParts) {
  const mfsi::HexMeshInput in = mfsi::test::bulgingBox(8);
  mfsi::test::checkDistributedMotion(in, mfsi::test::metisParts(in, kRanks),
                                     mfsi::test::cgMotion(mfsi::LaplacianPreconditioner::Jacobi), 1e-11);
}

TEST(DistributedMotion, CgWithAmgPerRankOnARandomPartition) {
  const mfsi::HexMeshInput in = mfsi::test::bulgingBox(6);
  mfsi::test::checkDistributedMotion(in, mfsi::test::randomPartition(in.cells.size(), kRanks),
                                     mfsi::test::cgMotion(mfsi::LaplacianPreconditioner::Amg), 1e-11);
}
