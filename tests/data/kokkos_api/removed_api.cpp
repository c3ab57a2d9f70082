// Fixture for scripts/check-kokkos-api.sh: one use of each construct it rejects (never compiled).
// portability.kokkos4_api_detects checks that every rule fires on this file, once.
void removedApi() {
  Kokkos::Impl::SharedAllocationRecord<void, void>* record;
  KOKKOS_IMPL_DO_NOT_USE_PRINTF("x");
  Kokkos::InitArguments args;
  Kokkos::InitializationSettings settings;
  Kokkos::OpenMP::partition_master(f, 2, 1);
  int n = Kokkos::OpenMP::thread_pool_size();
  int c = Kokkos::OpenMP::concurrency();
  constexpr int r = ViewType::Rank;
  auto e = view.dimension_0();
  auto p = view.ptr_on_device();
  Kokkos::finalize_all();
  Kokkos::atomic_assign(&x, 1);
  int vl = policy.vector_length();
#ifdef KOKKOS_ENABLE_PROFILING
#endif
#ifdef KOKKOS_ENABLE_DEPRECATED_CODE
#endif
  Kokkos::Experimental::HIP hip;
  double s = Kokkos::Experimental::sqrt(2.0);
  double a = Kokkos::fabs(-1.0);
  const char* flag = "--kokkos-threads=2";
}
