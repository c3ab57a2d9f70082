#pragma once
/// \file
/// \brief A membrane's slice of a host interface vector, to and from its device View.
#include "core/Types.hpp"

#include <Eigen/Dense>

namespace mfsi::coupling {

/// Device flat vector -> x[offset, offset + d.extent(0)).
inline void copySegmentToHost(const ConstRealView& d, Eigen::VectorXd& x, Eigen::Index offset) {
  auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), d);
  for (std::size_t i = 0; i < h.extent(0); ++i) x[offset + static_cast<Eigen::Index>(i)] = h(i);
}

/// x[offset, offset + d.extent(0)) -> the device flat vector d.
inline void copySegmentToDevice(const Eigen::VectorXd& x, Eigen::Index offset, const RealView& d) {
  auto h = Kokkos::create_mirror_view(d);
  for (std::size_t i = 0; i < h.extent(0); ++i) h(i) = x[offset + static_cast<Eigen::Index>(i)];
  Kokkos::deep_copy(d, h);
}

}  // namespace mfsi::coupling
