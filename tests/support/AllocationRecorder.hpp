#pragma once
/// \file
/// \brief Records the labels of every Kokkos View allocation while alive (Kokkos Tools callback),
/// so tests can prove which modules allocated memory and that every View is labelled.
#include <Kokkos_Core.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace mfsi::test {

class AllocationRecorder {
 public:
  AllocationRecorder() {
    labels().clear();
    Kokkos::Tools::Experimental::set_allocate_data_callback(&onAllocate);
  }
  ~AllocationRecorder() { Kokkos::Tools::Experimental::set_allocate_data_callback(nullptr); }
  AllocationRecorder(const AllocationRecorder&) = delete;
  AllocationRecorder& operator=(const AllocationRecorder&) = delete;

  const std::vector<std::string>& all() const { return labels(); }
  /// Number of allocations whose label starts with `prefix`.
  int countWithPrefix(const std::string& prefix) const {
    int n = 0;
    for (const auto& l : labels()) n += l.rfind(prefix, 0) == 0 ? 1 : 0;
    return n;
  }

 private:
  static std::vector<std::string>& labels() {
    static std::vector<std::string> l;
    return l;
  }
  static void onAllocate(Kokkos::Profiling::SpaceHandle, const char* label, const void* const, const std::uint64_t) {
    labels().emplace_back(label);
  }
};

}  // namespace mfsi::test
