#pragma once
/// \file
/// \brief The one place that names execution spaces, memory spaces, View aliases and policies.
///
/// Every kernel in membrane-fsi runs in `mfsi::ExecSpace` on data in `mfsi::MemSpace`; host
/// mirrors live in `mfsi::HostSpace`. Works against Kokkos 3.4 and 4.x (no deprecated API).
#include <Kokkos_Core.hpp>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace mfsi {

using ExecSpace = Kokkos::DefaultExecutionSpace;
using MemSpace = ExecSpace::memory_space;
using HostExecSpace = Kokkos::DefaultHostExecutionSpace;
using HostSpace = Kokkos::HostSpace;

using real = double;
/// Local (per-rank) index of a node, face or cell. 32 bits: one rank never holds 2^31 entities.
using lid_t = std::int32_t;
/// Global index across all ranks.
using gid_t = std::int64_t;

using RandomRead = Kokkos::MemoryTraits<Kokkos::RandomAccess>;

/// Whether kernels run where the host can read their data (OpenMP, Serial, Threads): host-only
/// kernel variants (loops over runs of rows that the compiler vectorises) are chosen on this.
constexpr bool kHostExec = Kokkos::SpaceAccessibility<ExecSpace, HostSpace>::accessible;

/// Before a host loop whose iterations are independent although it writes through pointers the
/// compiler cannot prove distinct from the ones it reads: lets the loop vectorise.
#if defined(__CUDACC__) || defined(__HIPCC__) || defined(__SYCL_DEVICE_ONLY__)
#define MFSI_IVDEP  // device compilers parse host code too; the hint matters to host builds only
#elif defined(__clang__)
#define MFSI_IVDEP _Pragma("clang loop vectorize(assume_safety)")
#elif defined(__GNUC__)
#define MFSI_IVDEP _Pragma("GCC ivdep")
#else
#define MFSI_IVDEP
#endif

/// \brief Unmanaged host view of n values at `data` (a source for deep_copy; no copy is made).
template <class T>
Kokkos::View<const T*, HostSpace, Kokkos::MemoryTraits<Kokkos::Unmanaged>> hostView(const T* data, std::size_t n) {
  return Kokkos::View<const T*, HostSpace, Kokkos::MemoryTraits<Kokkos::Unmanaged>>(data, n);
}

/// \brief Unmanaged host view of a vector's values.
template <class T>
Kokkos::View<const T*, HostSpace, Kokkos::MemoryTraits<Kokkos::Unmanaged>> hostView(const std::vector<T>& v) {
  return hostView(v.data(), v.size());
}

/// \brief A device copy of a host vector, labelled `label`.
template <class T>
Kokkos::View<T*, ExecSpace::memory_space> toDevice(const std::vector<T>& v, const std::string& label) {
  Kokkos::View<T*, ExecSpace::memory_space> d(Kokkos::view_alloc(Kokkos::WithoutInitializing, label), v.size());
  Kokkos::deep_copy(d, hostView(v));
  return d;
}

// Device views.
using RealView = Kokkos::View<real*, MemSpace>;
using Real3View = Kokkos::View<real* [3], MemSpace>;
using IndexView = Kokkos::View<lid_t*, MemSpace>;
using GlobalIndexView = Kokkos::View<gid_t*, MemSpace>;
using Hex8View = Kokkos::View<lid_t* [8], MemSpace>;
using Quad4View = Kokkos::View<lid_t* [4], MemSpace>;

// Read-only variants for kernel inputs (texture / read-only cache paths on GPUs).
using ConstRealView = Kokkos::View<const real*, MemSpace, RandomRead>;
using ConstReal3View = Kokkos::View<const real* [3], MemSpace, RandomRead>;
using ConstIndexView = Kokkos::View<const lid_t*, MemSpace, RandomRead>;
using ConstHex8View = Kokkos::View<const lid_t* [8], MemSpace, RandomRead>;
using ConstQuad4View = Kokkos::View<const lid_t* [4], MemSpace, RandomRead>;

// Policies.
using RangePolicy = Kokkos::RangePolicy<ExecSpace, Kokkos::IndexType<lid_t>>;
using TeamPolicy = Kokkos::TeamPolicy<ExecSpace>;
using HostRangePolicy = Kokkos::RangePolicy<HostExecSpace, Kokkos::IndexType<lid_t>>;

/// \brief Device-callable math, portable across Kokkos 3.4 (Kokkos::Experimental) and 4.x (Kokkos::).
namespace kmath {
#if KOKKOS_VERSION >= 30700
using Kokkos::acos;
using Kokkos::atan2;
using Kokkos::cos;
using Kokkos::exp;
using Kokkos::fabs;
using Kokkos::pow;
using Kokkos::sin;
using Kokkos::sqrt;
#else
using Kokkos::Experimental::acos;
using Kokkos::Experimental::atan2;
using Kokkos::Experimental::cos;
using Kokkos::Experimental::exp;
using Kokkos::Experimental::fabs;
using Kokkos::Experimental::pow;
using Kokkos::Experimental::sin;
using Kokkos::Experimental::sqrt;
#endif
}  // namespace kmath

/// \brief Name of the active default backend ("OpenMP", "Serial", "Cuda", ...).
inline std::string backendName() { return ExecSpace::name(); }

/// \brief RAII profiling region, named hierarchically (e.g. "mfsi::fluid::pressure").
/// Kokkos 3.4 has no Kokkos::Profiling::ScopedRegion, so we keep our own.
class ScopedRegion {
 public:
  explicit ScopedRegion(const std::string& name) { Kokkos::Profiling::pushRegion(name); }
  ~ScopedRegion() { Kokkos::Profiling::popRegion(); }
  ScopedRegion(const ScopedRegion&) = delete;
  ScopedRegion& operator=(const ScopedRegion&) = delete;
};

}  // namespace mfsi
