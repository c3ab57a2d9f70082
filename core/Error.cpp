#include "core/Error.hpp"

#include <mpi.h>

namespace mfsi::detail {

void assertFail(const char* cond, const char* file, int line, const std::string& msg) {
  int rank = 0;
  int init = 0;
  MPI_Initialized(&init);
  if (init) MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  std::fprintf(stderr, "[rank %d] %s:%d: assertion '%s' failed: %s\n", rank, file, line, cond, msg.c_str());
  std::abort();
}

}  // namespace mfsi::detail
