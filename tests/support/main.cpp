// Test entry point: MPI and Kokkos are initialised once for every test in the executable.
#include "core/MpiStart.hpp"

#include <gtest/gtest.h>
#include <mpi.h>

#include <Kokkos_Core.hpp>
#include <vector>

int main(int argc, char** argv) {
  mfsi::mpiInit(&argc, &argv);
  int rc = 0;
  {
    // Test discovery parses stdout, so Kokkos' start-up warnings (e.g. OMP_PROC_BIND) stay quiet.
    std::vector<char*> args(argv, argv + argc);
    static char quiet[] = "--kokkos-disable-warnings";
    args.push_back(quiet);
    int nargs = static_cast<int>(args.size());
    Kokkos::ScopeGuard kokkos(nargs, args.data());
    ::testing::InitGoogleTest(&argc, argv);
    int rank = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    if (rank != 0) {
      auto& listeners = ::testing::UnitTest::GetInstance()->listeners();
      delete listeners.Release(listeners.default_result_printer());
    }
    rc = RUN_ALL_TESTS();
  }
  MPI_Finalize();
  return rc;
}
