#include "core/MpiStart.hpp"

#include <mpi.h>

#include <cstdlib>

namespace mfsi {

namespace {

bool startedByALauncher() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE", "SLURM_PROCID"}) {
    if (std::getenv(name) != nullptr) return true;
  }
  return false;
}

}  // namespace

void mpiInit(int* argc, char*** argv) {
  if (!startedByALauncher()) {
    setenv("OMPI_MCA_ess_singleton_isolated", "1", 0);
    setenv("OMPI_MCA_pml", "ob1", 0);
    setenv("OMPI_MCA_btl", "self", 0);
  }
  MPI_Init(argc, argv);
}

}  // namespace mfsi
