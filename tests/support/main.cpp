// Test entry point: MPI and Kokkos are initialised once for every test in the executable.
#include <gtest/gtest.h>
#include <mpi.h>

#include <Kokkos_Core.hpp>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

namespace {

/// A test started by ctest on its own (not by mpiexec) is an Open MPI singleton, which by default
/// starts a helper daemon: 0.2-0.4 s per test process, a third of the suite's time on 2 cores.
/// Isolated singletons skip it; each gets a session folder of its own (concurrent isolated
/// singletons would race for one) and only the "self" transport (no network probing). Returns the
/// folder to remove after MPI_Finalize ("" when started by a launcher or when the user chose).
std::string isolatedSingleton() {
  for (const char* launcher : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "SLURM_PROCID"})
    if (std::getenv(launcher) != nullptr) return "";
  if (std::getenv("OMPI_MCA_ess_singleton_isolated") != nullptr) return "";
  const char* tmp = std::getenv("TMPDIR");
  std::string dir = std::string(tmp != nullptr && *tmp != '\0' ? tmp : "/tmp") + "/mfsi-test-mpi-XXXXXX";
  if (mkdtemp(dir.data()) == nullptr) return "";
  setenv("OMPI_MCA_orte_tmpdir_base", dir.c_str(), 1);
  setenv("OMPI_MCA_ess_singleton_isolated", "1", 1);
  setenv("OMPI_MCA_pml", "ob1", 0);
  setenv("OMPI_MCA_btl", "self", 0);
  return dir;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string sessionDir = isolatedSingleton();
  MPI_Init(&argc, &argv);
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
  if (!sessionDir.empty()) {
    std::error_code ec;
    std::filesystem::remove_all(sessionDir, ec);
  }
  return rc;
}
