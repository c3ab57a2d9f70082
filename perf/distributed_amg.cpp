// Distributed AMG-CG on the cell Laplacian of an n^3 box, decomposed by METIS over the ranks of
// mpirun: iterations, set-up and solve times, the levels, halo traffic. perf/distributed_amg.sh
// runs it on 1, 2 and 4 ranks and writes perf/results/distributed_amg.txt.
//
//   mpirun -np 4 build/perf/perf_distributed_amg 64 [neumann|dirichlet] [greedy] [double] [spread]
// (for comparison: "greedy" aggregates greedily even where the box is a lattice, "double" runs the
// V-cycle in double instead of float, "spread" keeps every level on every rank: agglomerateRows 0)
#include "core/BlockMesh.hpp"
#include "core/parallel/Halo.hpp"
#include "core/parallel/LocalMesh.hpp"
#include "core/parallel/Partition.hpp"
#include "kernels/Amg.hpp"
#include "kernels/CsrBuild.hpp"
#include "kernels/DistributedAmg.hpp"
#include "kernels/Krylov.hpp"

#include <mpi.h>

#include <Kokkos_Core.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

using namespace mfsi;

namespace {

/// Unit-coefficient Laplacian of the owned rows; Dirichlet (2 per face) on "xmin" unless Neumann.
CsrMatrix laplacian(const HexMesh& mesh, bool neumann) {
  CellCsr csr = buildCellCsr(mesh, "perf::laplacian");
  auto v = Kokkos::create_mirror_view(csr.matrix.values);
  auto diag = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), csr.matrix.diagIdx);
  auto oRow = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), csr.faceMap.ownerRow);
  auto nRow = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), csr.faceMap.neighbourRow);
  auto owner = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.faceOwner());
  auto neighbour = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.faceNeighbour());
  Kokkos::deep_copy(v, 0.0);
  for (lid_t f = 0; f < mesh.nInternalFaces(); ++f) {
    if (oRow(f) >= 0) {
      v(oRow(f)) -= 1;
      v(diag(owner(f))) += 1;
    }
    if (nRow(f) >= 0) {
      v(nRow(f)) -= 1;
      v(diag(neighbour(f))) += 1;
    }
  }
  if (!neumann) {
    const Patch& p = mesh.patches()[mesh.patchIndex("xmin")];
    for (lid_t f = p.start; f < p.start + p.size; ++f)
      if (owner(f) < mesh.nOwnedCells()) v(diag(owner(f))) += 2;
  }
  Kokkos::deep_copy(csr.matrix.values, v);
  return csr.matrix;
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  {
    Kokkos::ScopeGuard kokkos(argc, argv);
    int ranks = 1, rank = 0;
    MPI_Comm_size(MPI_COMM_WORLD, &ranks);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    const int n = argc > 1 ? std::atoi(argv[1]) : 32;
    bool neumann = false, greedy = false, inDouble = false, spread = false;
    for (int a = 2; a < argc; ++a) {
      const std::string w = argv[a];
      neumann = neumann || w == "neumann";
      greedy = greedy || w == "greedy";
      inDouble = inDouble || w == "double";
      spread = spread || w == "spread";
    }
    BlockMeshSpec spec = boxSpec({0, 0, 0}, {1, 1, 1}, {n, n, n});
    spec.blocks[0].patches[0] = "xmin";
    const HexMeshInput in = generateBlockMesh(spec);
    const HexMesh global = buildHexMesh(in);
    PartitionOptions popt;
    popt.parts = ranks;
    const Partition part = partitionCells(in, popt);
    const LocalMeshPart lp = localMeshPart(global, part.cellRank, ranks, rank);
    const HexMesh mesh = buildHexMesh(lp.input);
    const Halo halo(MPI_COMM_WORLD, lp.cells);
    const CsrMatrix A = laplacian(mesh, neumann);
    const ExecSpace exec;
    RealView b("b", mesh.nCells()), x("x", mesh.nCells());
    {
      auto gid = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.cellGlobalIds());
      auto hb = Kokkos::create_mirror_view(b);
      for (lid_t c = 0; c < mesh.nOwnedCells(); ++c) hb(c) = std::sin(0.37 * static_cast<double>(gid(c))) + 0.5;
      Kokkos::deep_copy(b, hb);
    }
    auto gid = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.cellGlobalIds());
    MPI_Barrier(MPI_COMM_WORLD);
    double t0 = MPI_Wtime();
    DistributedAmgOptions aopt;
    aopt.latticeAggregation = !greedy;
    aopt.mixedPrecision = !inDouble;
    if (spread) aopt.agglomerateRows = 0;
    DistributedAmg amg(MPI_COMM_WORLD, lp.cells, std::vector<mfsi::gid_t>(gid.data(), gid.data() + gid.extent(0)),
                       aopt);
    amg.setup(exec, A);
    exec.fence();
    MPI_Barrier(MPI_COMM_WORLD);
    const double tSetup = MPI_Wtime() - t0;
    KrylovOptions kopt;
    kopt.relTol = 1e-8;
    kopt.maxIterations = 500;
    kopt.nullSpace = neumann ? NullSpace::Constant : NullSpace::None;
    ConjugateGradient cg(kopt, SolverComm(MPI_COMM_WORLD, &halo));
    t0 = MPI_Wtime();
    const KrylovResult r = cg.solve(exec, A, b, x, amg);
    exec.fence();
    MPI_Barrier(MPI_COMM_WORLD);
    const double tSolve = MPI_Wtime() - t0;
    long long bytes = halo.sendBytes(1), allBytes = 0;
    int messages = halo.sendMessages(), allMessages = 0;
    MPI_Reduce(&bytes, &allBytes, 1, MPI_LONG_LONG, MPI_SUM, 0, MPI_COMM_WORLD);
    MPI_Reduce(&messages, &allMessages, 1, MPI_INT, MPI_SUM, 0, MPI_COMM_WORLD);
    long long held = static_cast<long long>(amg.memoryBytes()), allHeld = 0;
    MPI_Reduce(&held, &allHeld, 1, MPI_LONG_LONG, MPI_SUM, 0, MPI_COMM_WORLD);
    if (rank == 0) {
      std::printf("n=%d^3 %s %s %s ranks=%d threads=%d edgecut=%lld | distributed AMG-CG to 1e-8: %d iterations (%s), "
                  "set-up %.3f s, solve %.3f s (%.2f ms per iteration) | levels:",
                  n, neumann ? "neumann" : "dirichlet", amg.levels().front().lattice ? "lattice" : "greedy", inDouble ? "double" : "float", ranks, exec.concurrency(),
                  static_cast<long long>(part.edgeCut), r.iterations, toString(r.status), tSetup, tSolve,
                  1e3 * tSolve / std::max(1, r.iterations));
      for (const auto& l : amg.levels()) std::printf(" %lld@%d", static_cast<long long>(l.rows), l.ranks);
      std::printf(" | fine halo: %d messages, %lld bytes per exchange (all ranks) | hierarchy %.1f MB, %.0f bytes per "
                  "fine row (all ranks)\n",
                  allMessages, allBytes, 1e-6 * static_cast<double>(allHeld),
                  static_cast<double>(allHeld) / (static_cast<double>(n) * n * n));
    }
    if (ranks == 1 && rank == 0) {
      // The one-rank AMG of the fluid, same system, for scale.
      AmgPreconditioner serial;
      RealView y("y", mesh.nCells());
      t0 = MPI_Wtime();
      serial.setup(exec, A);
      exec.fence();
      const double sSetup = MPI_Wtime() - t0;
      ConjugateGradient cg1(kopt);
      t0 = MPI_Wtime();
      const KrylovResult r1 = cg1.solve(exec, A, b, y, serial);
      exec.fence();
      std::printf("  one-rank kernels/Amg (the fluid's): %d iterations, set-up %.3f s, solve %.3f s\n", r1.iterations,
                  sSetup, MPI_Wtime() - t0);
    }
  }
  MPI_Finalize();
  return 0;
}
