#pragma once
/// \file
/// \brief Device Views to host vectors for output (row-major, whatever the View's layout).
#include "core/Types.hpp"

#include <vector>

namespace mfsi::io {

/// The first `rows` entries of a rank-1 View, or its `rows` x extent(1) entries row by row.
template <class View>
std::vector<double> hostValues(const View& v, std::size_t rows) {
  auto h = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), v);
  std::vector<double> out;
  if constexpr (View::rank == 1) {
    out.reserve(rows);
    for (std::size_t i = 0; i < rows; ++i) out.push_back(static_cast<double>(h(i)));
  } else {
    const std::size_t cols = h.extent(1);
    out.reserve(rows * cols);
    for (std::size_t i = 0; i < rows; ++i)
      for (std::size_t k = 0; k < cols; ++k) out.push_back(static_cast<double>(h(i, k)));
  }
  return out;
}

}  // namespace mfsi::io
