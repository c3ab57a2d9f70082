#pragma once
/// \file
/// \brief A k-d tree of points (host): the squared distance from a query to the nearest of them,
/// exactly as a brute-force minimum gives it (the minimum of the same squared distances), in
/// O(log n) per query instead of O(n). Built once (O(n log n)).
#include "core/Types.hpp"

#include <array>
#include <vector>

namespace mfsi {

class PointTree {
 public:
  explicit PointTree(std::vector<std::array<real, 3>> points);
  /// Squared distance from x to the nearest point (+infinity when there are none).
  real nearestSquaredDistance(const std::array<real, 3>& x) const;
  std::size_t size() const { return points_.size(); }

 private:
  /// Points [lo, hi) of the node whose splitting point is points_[(lo + hi) / 2] on axis(lo, hi).
  void build(std::size_t lo, std::size_t hi, int depth);
  void search(std::size_t lo, std::size_t hi, const std::array<real, 3>& x, real& best) const;

  std::vector<std::array<real, 3>> points_;
  std::vector<unsigned char> axis_;  ///< splitting axis of the node centred at each index
};

}  // namespace mfsi
