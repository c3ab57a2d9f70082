#pragma once
/// \file
/// \brief Shared benchmark support: MPI + Kokkos start-up, tiny mode for CTest, rate counters.
#include <benchmark/benchmark.h>

#include <Kokkos_Core.hpp>

namespace mfsi::bench {

/// True when run as a CTest smoke test (MFSI_BENCH_TINY=1): use the smallest sizes.
bool tiny();

/// Bytes/s and items/s counters from a byte and item count per iteration.
void setRates(benchmark::State& state, double bytesPerIter, double itemsPerIter, const char* itemName);

/// \brief STREAM triad a = b + 3 c on state.range(0) doubles, a Kokkos kernel on the default
/// execution space; counts 24 bytes per element. Register it in each benchmark executable so
/// kernel bandwidths are quoted as a fraction of STREAM measured in the same run:
///   BENCHMARK(mfsi::bench::streamTriad)->Arg(1 << 25)->UseRealTime();
void streamTriad(benchmark::State& state);

/// Element count for the triad: 2^25 (256 MiB per array set), 2^12 in tiny mode.
long streamSize();

}  // namespace mfsi::bench
