#include <core/BlockMesh.hpp>
#include <mpi.h>
#include <cstdio>
int main(int argc, char** argv) { MPI_Init(&argc, &argv); { Kokkos::ScopeGuard g(argc, argv);
  auto m = mfsi::buildHexMesh(mfsi::generateBlockMesh(mfsi::boxSpec({0,0,0},{1,1,1},{3,3,3})));
  std::printf("%d\n", m.nCells()); } MPI_Finalize(); }
