#include "support/BenchMain.hpp"

#include <mpi.h>

#include <cstdlib>
#include <cstring>

namespace mfsi::bench {

bool tiny() {
  const char* v = std::getenv("MFSI_BENCH_TINY");
  return v != nullptr && std::strcmp(v, "0") != 0;
}

void setRates(benchmark::State& state, double bytesPerIter, double itemsPerIter, const char* itemName) {
  state.counters["GB/s"] = benchmark::Counter(bytesPerIter * 1e-9, benchmark::Counter::kIsIterationInvariantRate);
  state.counters[itemName] = benchmark::Counter(itemsPerIter, benchmark::Counter::kIsIterationInvariantRate);
}

}  // namespace mfsi::bench

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  {
    Kokkos::ScopeGuard kokkos(argc, argv);
    benchmark::AddCustomContext("kokkos_backend", Kokkos::DefaultExecutionSpace::name());
    benchmark::AddCustomContext("kokkos_concurrency", std::to_string(Kokkos::DefaultExecutionSpace().concurrency()));
    benchmark::Initialize(&argc, argv);
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
  }
  MPI_Finalize();
  return 0;
}
