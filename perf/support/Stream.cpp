#include "support/BenchMain.hpp"

#include "core/Types.hpp"

namespace mfsi::bench {

long streamSize() { return tiny() ? (1L << 12) : (1L << 25); }

void streamTriad(benchmark::State& state) {
  const long n = state.range(0);
  RealView a("mfsi::perf::stream::a", n), b("mfsi::perf::stream::b", n), c("mfsi::perf::stream::c", n);
  Kokkos::deep_copy(b, 1.0);
  Kokkos::deep_copy(c, 2.0);
  for (auto _ : state) {
    Kokkos::parallel_for(
        "mfsi::perf::stream::triad", Kokkos::RangePolicy<ExecSpace>(0, n),
        KOKKOS_LAMBDA(long i) { a(i) = b(i) + 3.0 * c(i); });
    Kokkos::fence();
  }
  setRates(state, 24.0 * n, double(n), "elem/s");
}

}  // namespace mfsi::bench
