#pragma once
/// \file
/// \brief The distributed linear-solver tests (tests/mpi/test_distributed_cg_np*.cpp): the cell
/// Laplacian of a box, assembled on each rank's part (rows: owned cells, columns: owned + ghosts),
/// solved by the project's conjugate gradients with SolverComm over MPI_COMM_WORLD; the answer,
/// gathered by global id, against the same solve on the whole mesh in one process.
#include "core/BlockMesh.hpp"
#include "core/parallel/Halo.hpp"
#include "core/parallel/LocalMesh.hpp"
#include "kernels/CsrBuild.hpp"
#include "kernels/Krylov.hpp"
#include "kernels/Preconditioner.hpp"

#include <gtest/gtest.h>
#include <mpi.h>

#include <cmath>
#include <map>

namespace mfsi::test {

/// Unit-coefficient cell Laplacian (plus 2 per face of the `dirichlet` patch) of `mesh`'s owned
/// rows, and b = sin(0.37 gid) + 0.5: a decomposition-independent system.
inline CellCsr laplacian(const HexMesh& mesh, const std::string& dirichlet, RealView& b) {
  CellCsr csr = buildCellCsr(mesh, "test::laplacian");
  auto v = Kokkos::create_mirror_view(csr.matrix.values);
  auto diag = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), csr.matrix.diagIdx);
  auto ownerRow = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), csr.faceMap.ownerRow);
  auto neighbourRow = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), csr.faceMap.neighbourRow);
  auto owner = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.faceOwner());
  auto neighbour = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.faceNeighbour());
  Kokkos::deep_copy(v, 0.0);
  const lid_t nRows = mesh.nOwnedCells();
  for (lid_t f = 0; f < mesh.nInternalFaces(); ++f) {
    if (ownerRow(f) >= 0) {
      v(ownerRow(f)) -= 1;
      v(diag(owner(f))) += 1;
    }
    if (neighbourRow(f) >= 0) {
      v(neighbourRow(f)) -= 1;
      v(diag(neighbour(f))) += 1;
    }
  }
  const Patch& p = mesh.patches()[mesh.patchIndex(dirichlet)];
  for (lid_t f = p.start; f < p.start + p.size; ++f)
    if (owner(f) < nRows) v(diag(owner(f))) += 2;
  Kokkos::deep_copy(csr.matrix.values, v);
  const auto gid = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.cellGlobalIds());
  b = RealView("test::b", nRows);
  auto hb = Kokkos::create_mirror_view(b);
  for (lid_t c = 0; c < nRows; ++c) hb(c) = std::sin(0.37 * static_cast<double>(gid(c))) + 0.5;
  Kokkos::deep_copy(b, hb);
  return csr;
}

struct LaplacianSolve {
  std::map<gid_t, double> x;  ///< owned values by global id
  int iterations = 0;
  bool converged = false;
};

inline LaplacianSolve solveLaplacian(const HexMesh& mesh, const SolverComm& comm) {
  RealView b;
  const CellCsr csr = laplacian(mesh, "xmin", b);
  RealView x("test::x", mesh.nCells());
  KrylovOptions opt;
  opt.relTol = 1e-13;
  opt.maxIterations = 2000;
  ConjugateGradient cg(opt, comm);
  JacobiPreconditioner jacobi;
  const ExecSpace exec;
  jacobi.setup(exec, csr.matrix);
  const KrylovResult r = cg.solve(exec, csr.matrix, b, x, jacobi);
  LaplacianSolve s;
  s.iterations = r.iterations;
  s.converged = r.status == KrylovStatus::Converged;
  auto hx = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), x);
  const auto gid = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.cellGlobalIds());
  for (lid_t c = 0; c < mesh.nOwnedCells(); ++c) s.x[gid(c)] = hx(c);
  return s;
}

/// Solve on every rank's part of `global` under `cellRank`; compare with the one-process solve.
inline void checkDistributedCg(const HexMeshInput& in, const std::vector<int>& cellRank) {
  int ranks = 1, rank = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  const HexMesh global = buildHexMesh(in);
  const LaplacianSolve whole = solveLaplacian(global, SolverComm{});
  ASSERT_TRUE(whole.converged);

  const LocalMeshPart part = localMeshPart(global, cellRank, ranks, rank);
  const HexMesh local = buildHexMesh(part.input);
  const Halo halo(MPI_COMM_WORLD, part.cells);
  const LaplacianSolve dist = solveLaplacian(local, SolverComm(MPI_COMM_WORLD, &halo));
  EXPECT_TRUE(dist.converged);
  // Same operator and preconditioner, other summation orders: the same iterations (within one).
  EXPECT_LE(std::abs(dist.iterations - whole.iterations), 1)
      << "rank " << rank << ": " << dist.iterations << " iterations against " << whole.iterations;
  double worst = 0;
  for (const auto& [g, v] : dist.x) worst = std::max(worst, std::abs(v - whole.x.at(g)) / std::abs(whole.x.at(g)));
  EXPECT_LT(worst, 1e-10) << "rank " << rank;
  // Every rank reports the same iteration count (the reductions agree bit for bit).
  int its = dist.iterations, minIts = 0, maxIts = 0;
  MPI_Allreduce(&its, &minIts, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  MPI_Allreduce(&its, &maxIts, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  EXPECT_EQ(minIts, maxIts);
}

}  // namespace mfsi::test
