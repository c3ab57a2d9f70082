#pragma once
/// \file
/// \brief The distributed fluid tests (tests/mpi/test_distributed_fluid_np*.cpp): a few PIMPLE
/// steps on every rank's part of a mesh, the owned cells' velocity and pressure gathered by global
/// id, against the same steps on the whole mesh in one process (the one-rank solver with its fast
/// paths), and against a second run on the same ranks (bitwise).
#include "core/HexMesh.hpp"
#include "core/parallel/Halo.hpp"
#include "core/parallel/LocalMesh.hpp"
#include "fluid/FluidSolver.hpp"

#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <map>
#include <vector>

namespace mfsi::test {

struct FluidRun {
  std::map<mfsi::gid_t, std::array<double, 4>> cells;  ///< U and p of the owned cells, by global id
  int pressureIterations = 0;
  bool ok = true;
};

/// `steps` steps of dt on `mesh` (a part when `domain` is distributed).
inline FluidRun runFluid(const HexMesh& mesh, const fluid::FluidOptions& o, const RankDomain& domain, int steps,
                         double dt) {
  fluid::FluidSolver f(mesh, o, domain);
  FluidRun run;
  for (int s = 0; s < steps; ++s) {
    const fluid::StepResult r = f.solveStep(s * dt, dt);
    run.ok = run.ok && r.ok;
    run.pressureIterations += r.pressureIterations;
  }
  auto U = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), f.velocity());
  auto p = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), f.pressure());
  auto gid = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.cellGlobalIds());
  for (lid_t c = 0; c < f.ownedCells(); ++c) run.cells[gid(c)] = {U(c, 0), U(c, 1), U(c, 2), p(c)};
  return run;
}

/// The fields of the run on this rank's part of `in` under `cellRank` against the whole-mesh run:
/// velocities to `tol` of the largest speed, pressures to `tol` of the pressure range; a repeated
/// run on the same ranks gives the same bits, and so does one with FluidOptions::overlapHalo
/// switched.
inline void checkDistributedFluid(const HexMeshInput& in, const fluid::FluidOptions& o,
                                  const std::vector<int>& cellRank, int steps, double dt, double tol = 1e-10) {
  int ranks = 1, rank = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  const HexMesh global = buildHexMesh(in);
  const FluidRun whole = runFluid(global, o, RankDomain{}, steps, dt);
  ASSERT_TRUE(whole.ok);
  double uMax = 0, pMin = 1e300, pMax = -1e300;
  for (const auto& [g, v] : whole.cells) {
    uMax = std::max(uMax, std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]));
    pMin = std::min(pMin, v[3]);
    pMax = std::max(pMax, v[3]);
  }
  ASSERT_GT(uMax, 1e-3) << "the flow did not start";
  ASSERT_GT(pMax - pMin, 0.0);

  const LocalMeshPart part = localMeshPart(global, cellRank, ranks, rank);
  RankDomain domain;
  domain.comm = MPI_COMM_WORLD;
  domain.cells = part.cells;
  domain.nodes = part.nodes;
  const HexMesh local = buildHexMesh(part.input);
  const FluidRun dist = runFluid(local, o, domain, steps, dt);
  ASSERT_TRUE(dist.ok);
  double du = 0, dp = 0;
  for (const auto& [g, v] : dist.cells) {
    const auto& w = whole.cells.at(g);
    for (int j = 0; j < 3; ++j) du = std::max(du, std::abs(v[j] - w[j]));
    dp = std::max(dp, std::abs(v[3] - w[3]));
  }
  std::printf("rank %d/%d: %zu owned cells, %d ghosts; |dU| %.2e of %.3g, |dp| %.2e of %.3g; pressure iterations %d "
              "(one rank: %d)\n",
              rank, ranks, dist.cells.size(), local.nCells() - local.nOwnedCells(), du, uMax, dp, pMax - pMin,
              dist.pressureIterations, whole.pressureIterations);
  EXPECT_LT(du, tol * uMax) << "rank " << rank;
  EXPECT_LT(dp, tol * (pMax - pMin)) << "rank " << rank;

  const HexMesh again = buildHexMesh(part.input);
  const FluidRun repeat = runFluid(again, o, domain, steps, dt);
  bool same = repeat.cells.size() == dist.cells.size();
  for (const auto& [g, v] : dist.cells) same = same && repeat.cells.at(g) == v;
  EXPECT_TRUE(same) << "rank " << rank << ": a repeated run gave other bits";

  // The pressure solve's exchanges overlapped with its products' interior rows: the same bits.
  fluid::FluidOptions overlapped = o;
  overlapped.overlapHalo = !o.overlapHalo;
  const std::int64_t split0 = Halo::allSplitExchanges();
  const FluidRun other = runFluid(again, overlapped, domain, steps, dt);
  const std::int64_t split = Halo::allSplitExchanges() - split0;
  EXPECT_GT(overlapped.overlapHalo ? split : 1, 0) << "rank " << rank << ": no exchange was overlapped";
  same = other.cells.size() == dist.cells.size();
  for (const auto& [g, v] : dist.cells) same = same && other.cells.at(g) == v;
  EXPECT_TRUE(same) << "rank " << rank << ": the run with overlapHalo " << overlapped.overlapHalo
                    << " gave other bits";
}

}  // namespace mfsi::test
