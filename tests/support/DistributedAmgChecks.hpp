#pragma once
/// \file
/// \brief The distributed AMG tests (tests/mpi/test_distributed_amg_np*.cpp): AMG-preconditioned
/// CG on the cell Laplacian of a box, on every rank's part, against the same preconditioner on
/// the whole mesh in one process: the same answer, and the iterations the decoupled aggregation
/// costs.
#include "core/parallel/Partition.hpp"
#include "kernels/DistributedAmg.hpp"
#include "support/LocalParts.hpp"
#include "support/DistributedLaplacian.hpp"

#include <cstdint>
#include <limits>

namespace mfsi::test {

struct AmgSolve {
  LaplacianSolve solve;
  std::vector<DistributedAmgLevelInfo> levels;
  std::size_t bytes = 0;  ///< DistributedAmg::memoryBytes after the solve
};

inline AmgSolve solveWithAmg(MPI_Comm comm, const HexMesh& mesh, const HaloPlan& plan, const Halo* halo,
                             const DistributedAmgOptions& options = {}, bool dropRuns = false) {
  RealView b;
  CellCsr csr = laplacian(mesh, "xmin", b);
  if (dropRuns) csr.matrix.runs = CsrRowRuns{};  // CG's products by rows, as on a device
  auto gid = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.cellGlobalIds());
  DistributedAmg amg(comm, plan, std::vector<gid_t>(gid.data(), gid.data() + gid.extent(0)), options);
  const ExecSpace exec;
  amg.setup(exec, csr.matrix);
  KrylovOptions opt;
  opt.relTol = 1e-12;
  opt.maxIterations = 500;
  SolverComm solverComm = comm == MPI_COMM_SELF ? SolverComm{} : SolverComm(comm, halo);
  solverComm.setOverlap(options.overlapExchange);
  ConjugateGradient cg(opt, solverComm);
  RealView x("test::x", mesh.nCells());
  const KrylovResult r = cg.solve(exec, csr.matrix, b, x, amg);
  AmgSolve s;
  s.solve.iterations = r.iterations;
  s.solve.converged = r.status == KrylovStatus::Converged;
  auto hx = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), x);
  for (lid_t c = 0; c < mesh.nOwnedCells(); ++c) s.solve.x[gid(c)] = hx(c);
  s.levels = amg.levels();
  s.bytes = amg.memoryBytes();
  return s;
}

/// What checkDistributedAmg measured: the iterations on one process and on the ranks, and this
/// rank's levels of the distributed hierarchy and the bytes they hold.
struct AmgComparison {
  int one = 0, many = 0;
  std::vector<DistributedAmgLevelInfo> levels;
  std::size_t bytes = 0;
};

/// AMG-CG on the whole mesh (one process, default options) and on every rank's part (`options`);
/// returns the two iteration counts and the levels after checking the answers agree to 1e-9.
inline AmgComparison checkDistributedAmg(const HexMeshInput& in, const std::vector<int>& cellRank,
                                         const DistributedAmgOptions& options = {}) {
  int ranks = 1, rank = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  const HexMesh global = buildHexMesh(in);
  const LocalMeshPart whole = localMeshPart(global, std::vector<int>(global.nCells(), 0), 1, 0);
  const AmgSolve one = solveWithAmg(MPI_COMM_SELF, global, whole.cells, nullptr);
  EXPECT_TRUE(one.solve.converged);
  EXPECT_GE(one.levels.size(), 2u);

  const LocalMeshPart part = localMeshPart(global, cellRank, ranks, rank);
  const HexMesh local = buildHexMesh(part.input);
  const Halo halo(MPI_COMM_WORLD, part.cells);
  const AmgSolve dist = solveWithAmg(MPI_COMM_WORLD, local, part.cells, &halo, options);
  if (options.denseCoarseRows < DistributedAmgOptions{}.denseCoarseRows) {
    // The case asks for a gathered level solved by its one-process AMG: it must get one.
    EXPECT_GT(dist.levels.back().rows, options.denseCoarseRows);
  }
  EXPECT_TRUE(dist.solve.converged);
  double worst = 0;
  for (const auto& [g, v] : dist.solve.x)
    worst = std::max(worst, std::abs(v - one.solve.x.at(g)) / std::abs(one.solve.x.at(g)));
  EXPECT_LT(worst, 1e-9) << "rank " << rank;
  int its = dist.solve.iterations, minIts = 0, maxIts = 0;
  MPI_Allreduce(&its, &minIts, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  MPI_Allreduce(&its, &maxIts, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  EXPECT_EQ(minIts, maxIts);
  if (rank == 0) {
    std::printf("AMG-CG to 1e-12: %d iterations on one process, %d on %d ranks; levels (rows on ranks):",
                one.solve.iterations, dist.solve.iterations, ranks);
    for (const auto& l : dist.levels) std::printf(" %lld on %d", static_cast<long long>(l.rows), l.ranks);
    std::printf("\n");
  }
  return {one.solve.iterations, dist.solve.iterations, dist.levels, dist.bytes};
}

/// The coarsest level gathered early (at most 5,000 rows) and solved by a one-process AMG of the
/// gathered matrix (above 100 rows), as on many ranks: the answer of the one-process dense-coarse
/// hierarchy, within two iterations of it; and the same level moved onto one rank that solves it
/// alone.
inline void checkGatheredCoarseAmg(const HexMeshInput& in, const std::vector<int>& cellRank) {
  DistributedAmgOptions o;
  o.coarseSize = 5000;
  o.denseCoarseRows = 100;
  const AmgComparison c = checkDistributedAmg(in, cellRank, o);
  EXPECT_LE(c.many, c.one + 2);
  // The same level moved whole onto one rank, which solves it by its AMG alone.
  o.agglomerateRows = std::numeric_limits<std::int64_t>::max() / 64;
  const AmgComparison one = checkDistributedAmg(in, cellRank, o);
  EXPECT_LE(one.many, one.one + 2);
  EXPECT_EQ(one.levels.back().ranks, 1);
}

/// Coarse levels moved onto fewer ranks as they shrink (agglomerateRows 500): the one-process
/// answer within two iterations, each level on `expectedRanks` ranks, and a coarsest level on one
/// rank solved where it is, with no gather in any cycle. Without moving (agglomerateRows 0) every
/// level stays on every rank and each cycle gathers the coarsest.
inline void checkCoarseLevelsMoveOntoFewerRanks(const HexMeshInput& in, const std::vector<int>& cellRank,
                                                const std::vector<int>& expectedRanks) {
  int ranks = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  DistributedAmgOptions o;
  o.agglomerateRows = 500;
  const std::int64_t before = DistributedAmg::coarseGathers();
  const AmgComparison moved = checkDistributedAmg(in, cellRank, o);
  EXPECT_EQ(DistributedAmg::coarseGathers(), before) << "the coarsest level is on one rank: nothing to gather";
  EXPECT_LE(moved.many, moved.one + 2);
  ASSERT_EQ(moved.levels.size(), expectedRanks.size());
  for (std::size_t l = 0; l < expectedRanks.size(); ++l) EXPECT_EQ(moved.levels[l].ranks, expectedRanks[l]) << l;
  o.agglomerateRows = 0;
  const AmgComparison spread = checkDistributedAmg(in, cellRank, o);
  for (const auto& l : spread.levels) EXPECT_EQ(l.ranks, ranks);
  EXPECT_GE(DistributedAmg::coarseGathers(), before + spread.many);
}

/// The CG's and the AMG cycle's exchanges overlapped with the interior rows of their products
/// (Halo::begin/end, CsrGhostSplit) against made before them: the same iterations and answer bit
/// for bit, with every split exchange counted (none without overlap). `options` picks the levels
/// (moved onto fewer ranks or not); `dropRuns` makes CG multiply by rows instead of row runs.
inline void checkOverlapIsBitwise(const HexMeshInput& in, const std::vector<int>& cellRank,
                                  DistributedAmgOptions options, bool dropRuns) {
  int ranks = 1, rank = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  const HexMesh global = buildHexMesh(in);
  const LocalMeshPart part = localMeshPart(global, cellRank, ranks, rank);
  const HexMesh local = buildHexMesh(part.input);
  const Halo halo(MPI_COMM_WORLD, part.cells);
  AmgSolve solves[2];
  std::int64_t split[2] = {0, 0};
  for (int overlap = 0; overlap < 2; ++overlap) {
    options.overlapExchange = overlap == 1;
    const std::int64_t before = Halo::allSplitExchanges();
    solves[overlap] = solveWithAmg(MPI_COMM_WORLD, local, part.cells, &halo, options, dropRuns);
    split[overlap] = Halo::allSplitExchanges() - before;
    EXPECT_TRUE(solves[overlap].solve.converged);
  }
  EXPECT_EQ(solves[1].solve.iterations, solves[0].solve.iterations);
  int differ = 0;
  for (const auto& [g, v] : solves[0].solve.x) differ += solves[1].solve.x.at(g) != v;
  EXPECT_EQ(differ, 0) << "rank " << rank << ": " << differ << " of " << solves[0].solve.x.size()
                       << " values differ with the exchanges overlapped";
  EXPECT_EQ(split[0], 0) << "rank " << rank;
  // Every CG iteration's product and, per cycle, at least the finest level's 2 x degree + 2
  // products with an exchange (its smoothings' and residual's, the restriction's, the
  // prolongation's) overlap theirs; a rank whose rows all read ghosts would split none.
  const std::int64_t perCycle = 2 * options.chebyshevDegree + 2;
  EXPECT_GE(split[1], solves[1].solve.iterations * (1 + perCycle)) << "rank " << rank;
}

/// checkOverlapIsBitwise on `in` under METIS and a random partition into `parts`: levels kept on
/// every rank and moved onto fewer ranks (the finer prolongation then reads the moved level's
/// arrival layout); CG by row runs and by rows.
inline void checkOverlapOnBox(const HexMeshInput& in, int parts) {
  PartitionOptions opt;
  opt.parts = parts;
  const std::vector<int> metis = partitionCells(in, opt).cellRank;
  DistributedAmgOptions o;
  o.agglomerateRows = 0;
  checkOverlapIsBitwise(in, metis, o, false);
  checkOverlapIsBitwise(in, metis, o, true);
  o.agglomerateRows = 500;
  checkOverlapIsBitwise(in, metis, o, false);
  checkOverlapIsBitwise(in, randomPartition(in.cells.size(), parts), o, false);
}

}  // namespace mfsi::test
