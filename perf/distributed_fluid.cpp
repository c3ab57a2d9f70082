// The 3D lid-driven cube cavity (Re = 100, the settings of perf/bench_cavity3d.cpp: Euler, PISO
// with 2 correctors, lid Courant number 0.32) on the ranks of mpirun, decomposed by METIS: time per
// cell-step, pressure and momentum iterations per step, the cells' halo traffic per step, the edge
// cut. perf/distributed_fluid.sh runs it over ranks x threads and writes
// perf/results/distributed_fluid.txt.
//
//   mpirun -np 2 build/perf/perf_distributed_fluid 64 [steps] [untimed] [serial|distributed|overlapped]
// `serial` (one rank only) is the one-rank solver with its fast paths (fused passes, the lattice
// AMG); `distributed` (the default) is the decomposed solver, also on one rank; `overlapped` is the
// decomposed solver with the pressure solve's halo exchanges overlapped with the interior rows of
// the products that need them (FluidOptions::overlapHalo) instead of made before them.
#include "core/BlockMesh.hpp"
#include "core/parallel/Halo.hpp"
#include "core/parallel/LocalMesh.hpp"
#include "core/parallel/Partition.hpp"
#include "fluid/FluidSolver.hpp"
#include "kernels/Blas.hpp"
#include "kernels/CsrBuild.hpp"
#include "kernels/DistributedAmg.hpp"

#include <mpi.h>

#include <Kokkos_Core.hpp>
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

using namespace mfsi;
using namespace mfsi::fluid;

namespace {

FluidOptions cavityOptions() {
  FluidOptions o;
  o.viscosity = 0.01;
  o.timeScheme = TimeScheme::Euler;
  o.pimple.nOuterCorrectors = 1;
  o.pimple.nCorrectors = 2;
  o.momentumSolver = {1e-5, 0.0, 1000};
  o.pressureSolver = {1e-6, 0.05, 1000};
  o.pressureFinalRelTol = 0.0;
  PatchBC lid;
  lid.type = BoundaryType::Wall;
  lid.velocity = {1, 0, 0};
  o.boundaries["lid"] = lid;
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int status = 0;
  {
    Kokkos::ScopeGuard kokkos(argc, argv);
    int ranks = 1, rank = 0;
    MPI_Comm_size(MPI_COMM_WORLD, &ranks);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    const int n = argc > 1 ? std::atoi(argv[1]) : 32;
    const int steps = argc > 2 ? std::atoi(argv[2]) : 20;
    const int untimed = argc > 3 ? std::atoi(argv[3]) : 5;
    const std::string mode = argc > 4 ? argv[4] : "distributed";
    const bool serial = mode == "serial";
    if (mode != "serial" && mode != "distributed" && mode != "overlapped") {
      if (rank == 0) std::fprintf(stderr, "mode: serial, distributed or overlapped, not '%s'\n", mode.c_str());
      MPI_Abort(MPI_COMM_WORLD, 2);
    }
    if (serial && ranks > 1) {
      if (rank == 0) std::fprintf(stderr, "serial mode runs on one rank\n");
      MPI_Abort(MPI_COMM_WORLD, 2);
    }
    auto spec = boxSpec({0, 0, 0}, {1, 1, 1}, {n, n, n});
    spec.blocks[0].patches = {"walls", "walls", "walls", "lid", "walls", "walls"};
    spec.patchKinds = {{"walls", PatchKind::Wall}, {"lid", PatchKind::Wall}};
    const HexMeshInput in = generateBlockMesh(spec);
    const HexMesh global = buildHexMesh(in);
    PartitionOptions popt;
    popt.parts = ranks;
    const Partition part = partitionCells(in, popt);
    const LocalMeshPart lp = localMeshPart(global, part.cellRank, ranks, rank);
    const HexMesh local = buildHexMesh(lp.input);
    RankDomain domain;
    if (!serial) {
      domain.comm = MPI_COMM_WORLD;
      domain.cells = lp.cells;
      domain.nodes = lp.nodes;
    }
    FluidOptions o = cavityOptions();
    o.overlapHalo = mode == "overlapped";
    const double dt = 0.32 / n;
    FluidSolver fluid(serial ? global : local, o, domain);
    bool ok = true;
    for (int s = 0; s < untimed; ++s) ok = fluid.solveStep(s * dt, dt).ok && ok;
    const Halo* halo = fluid.cellHalo();
    const long long bytes0 = halo ? halo->bytesSent() : 0, messages0 = halo ? halo->messagesSent() : 0;
    const long long haloBytes0 = Halo::allBytesSent(), haloMessages0 = Halo::allMessagesSent(),
                    exchanges0 = Halo::allExchanges(), split0 = Halo::allSplitExchanges(),
                    reductions0 = SolverComm::reductions(),
                    gathers0 = DistributedAmg::coarseGathers();
    const double transfer0 = Halo::allTransferSeconds(), reduction0 = SolverComm::reductionSeconds();
    Kokkos::fence();
    MPI_Barrier(MPI_COMM_WORLD);
    const double t0 = MPI_Wtime();
    long long pIts = 0, uIts = 0;
    for (int s = untimed; s < steps; ++s) {
      const StepResult r = fluid.solveStep(s * dt, dt);
      ok = ok && r.ok;
      pIts += r.pressureIterations;
      uIts += r.momentumIterations;
    }
    Kokkos::fence();
    MPI_Barrier(MPI_COMM_WORLD);
    const double wall = MPI_Wtime() - t0;
    const int timed = steps - untimed;
    long long bytes = (halo ? halo->bytesSent() : 0) - bytes0, messages = (halo ? halo->messagesSent() : 0) - messages0;
    // Every halo of the process (cells and the AMG's levels), the collectives and the AMG's
    // coarse gathers: the counts the scaling model in perf/RESULTS.md is built from.
    long long totals[3] = {Halo::allBytesSent() - haloBytes0, Halo::allMessagesSent() - haloMessages0, 0};
    long long allTotals[3] = {0, 0, 0};
    MPI_Reduce(totals, allTotals, 3, MPI_LONG_LONG, MPI_SUM, 0, MPI_COMM_WORLD);
    const long long split = Halo::allSplitExchanges() - split0;
    const long long exchanges = Halo::allExchanges() - exchanges0, reductions = SolverComm::reductions() - reductions0,
                    gathers = DistributedAmg::coarseGathers() - gathers0;
    long long allBytes = 0, allMessages = 0;
    MPI_Reduce(&bytes, &allBytes, 1, MPI_LONG_LONG, MPI_SUM, 0, MPI_COMM_WORLD);
    MPI_Reduce(&messages, &allMessages, 1, MPI_LONG_LONG, MPI_SUM, 0, MPI_COMM_WORLD);
    // Seconds in halo transfers and in reductions, the largest over the ranks.
    double waits[2] = {Halo::allTransferSeconds() - transfer0, SolverComm::reductionSeconds() - reduction0};
    double maxWaits[2] = {0, 0};
    MPI_Reduce(waits, maxWaits, 2, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
    // Rank 0's pressure rows (and blocks of kRowBlock rows) that read no ghost: what a product
    // can multiply while its exchange is under way.
    double interiorRows = 100, interiorBlocks = 100;
    if (!serial && ranks > 1) {
      const CsrGhostSplit split = buildCellCsr(local).matrix.ghostSplit;
      const auto fraction = [&](const IndexView (&parts)[2]) {
        const double a = static_cast<double>(parts[0].extent(0)), b = static_cast<double>(parts[1].extent(0));
        return a + b > 0 ? 100 * a / (a + b) : 100.0;
      };
      interiorRows = fraction(split.rows);
      interiorBlocks = fraction(split.blocks);
    }
    int okInt = ok ? 1 : 0, allOk = 0;
    MPI_Allreduce(&okInt, &allOk, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    const double cells = static_cast<double>(global.nCells());
    if (rank == 0) {
      std::printf("n=%d^3 cells=%.0f mode=%s ranks=%d threads=%d edgecut=%lld steps=%d | %.4e s/cell-step, "
                  "%.3f s/step | pressure its/step %.2f, momentum its/step %.2f | cell halo per step (all ranks): "
                  "%.0f messages, %.0f bytes | all halos per step (all ranks): %.0f messages, %.0f bytes; per rank "
                  "%.1f exchanges, %.1f reductions, %.1f coarse gathers, %.1f overlapped exchanges | halo transfers %.1f %%, reductions %.1f %% "
                  "of the step (the largest rank's) | interior rows %.1f %%, blocks %.1f %% | ok=%d\n",
                  n, cells, mode.c_str(), ranks, Kokkos::DefaultExecutionSpace().concurrency(),
                  static_cast<long long>(part.edgeCut), timed, wall / (timed * cells), wall / timed,
                  double(pIts) / timed, double(uIts) / timed, double(allMessages) / timed, double(allBytes) / timed,
                  double(allTotals[1]) / timed, double(allTotals[0]) / timed, double(exchanges) / timed,
                  double(reductions) / timed, double(gathers) / timed, double(split) / timed, 100 * maxWaits[0] / wall,
                  100 * maxWaits[1] / wall, interiorRows, interiorBlocks, allOk);
    }
    status = allOk ? 0 : 1;
  }
  MPI_Finalize();
  return status;
}
